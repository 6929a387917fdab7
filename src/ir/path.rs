//! Where a node is in the scene: the path of node names from the root,
//! kept as one shared tree and written out only when a message needs it.

use std::fmt;
use std::sync::Arc;

/// The label of every node of a lowered scene (`b:torus`) and its parent's
/// index: every node's path in space linear in the scene, where the paths
/// written out would take space quadratic in its depth.
#[derive(Debug, Default)]
pub(crate) struct PathTree {
    labels: Vec<String>,
    parents: Vec<Option<u32>>,
}

impl PathTree {
    /// The tree of `nodes`, each its label and its parent's index.
    pub(crate) fn new(nodes: impl IntoIterator<Item = (String, Option<usize>)>) -> Self {
        let (labels, parents) = nodes
            .into_iter()
            .map(|(label, parent)| {
                let parent = parent.map(|p| u32::try_from(p).expect("fewer than 2^32 nodes"));
                (label, parent)
            })
            .unzip();
        PathTree { labels, parents }
    }
}

/// A node's path from the root (`union/b:torus`), as every validation
/// error names it: a place in a tree the scene's parameters share,
/// written out by `Display`.
#[derive(Clone)]
pub struct NodePath {
    tree: Arc<PathTree>,
    at: u32,
}

impl NodePath {
    /// The path of node `at` of `tree`.
    pub(crate) fn new(tree: &Arc<PathTree>, at: usize) -> Self {
        NodePath {
            tree: Arc::clone(tree),
            at: u32::try_from(at).expect("fewer than 2^32 nodes"),
        }
    }

    /// A path not yet placed in its tree (replaced when the tree is built).
    pub(crate) fn pending() -> Self {
        NodePath {
            tree: Arc::new(PathTree::new([(String::new(), None)])),
            at: 0,
        }
    }
}

impl NodePath {
    /// The labels from the root down to the node.
    fn labels(&self) -> Vec<&str> {
        let tree = &self.tree;
        let mut steps = vec![tree.labels[self.at as usize].as_str()];
        let mut at = self.at as usize;
        while let Some(parent) = tree.parents[at] {
            at = parent as usize;
            steps.push(&tree.labels[at]);
        }
        steps.reverse();
        steps
    }
}

impl fmt::Display for NodePath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, label) in self.labels().into_iter().enumerate() {
            if i > 0 {
                f.write_str("/")?;
            }
            f.write_str(label)?;
        }
        Ok(())
    }
}

impl fmt::Debug for NodePath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:?}", self.to_string())
    }
}

impl PartialEq for NodePath {
    fn eq(&self, other: &Self) -> bool {
        (Arc::ptr_eq(&self.tree, &other.tree) && self.at == other.at)
            || self.labels() == other.labels()
    }
}
