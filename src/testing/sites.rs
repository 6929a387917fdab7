//! A node's parameter sites, from the one list of every node's parameters
//! (`Kind::try_map`): every scalar, and each component of every vector,
//! named as validation names it, with a way to replace one. Hostile-input
//! tests substitute values at every site of every node kind without
//! listing any node's parameters themselves.

use crate::scene::{Mapper, Node, NodeKind, Param, Param3, ParamSpec, Rule};

/// One scalar parameter of a node: its name as errors give it (`radius`,
/// `half_extents.x`, `c.w`) and its rule.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Site {
    /// The parameter's name, with `.x`/`.y`/`.z` for a vector component.
    pub name: String,
    /// What the parameter's values must satisfy.
    pub rule: Rule,
    /// Its value in the node: a baked value, or a dynamic default.
    pub value: f64,
}

/// Every parameter site of `kind`, in `try_map` order (its children's
/// sites are not included).
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::testing::parameter_sites;
/// let names: Vec<String> = parameter_sites(round_box(dvec3(1.0, 1.0, 1.0), 0.1).kind())
///     .into_iter()
///     .map(|s| s.name)
///     .collect();
/// assert_eq!(names, ["half_extents.x", "half_extents.y", "half_extents.z", "radius"]);
/// ```
#[must_use]
pub fn parameter_sites(kind: &NodeKind) -> Vec<Site> {
    let mut m = Substitute {
        sites: Vec::new(),
        target: None,
    };
    let Ok(_) = kind.try_map(&mut m);
    m.sites
}

/// `node` with its parameter site `index` (in [`parameter_sites`] order)
/// replaced by `value`, a plain value or a dynamic parameter; its children
/// are kept.
///
/// # Panics
/// If `index` is not a site of `node`.
#[must_use]
pub fn substitute(node: &Node, index: usize, value: Param) -> Node {
    let mut m = Substitute {
        sites: Vec::new(),
        target: Some((index, value)),
    };
    let Ok(kind) = node.kind().try_map(&mut m);
    assert!(
        index < m.sites.len(),
        "site {index} of {}",
        node.kind().name()
    );
    kind.into()
}

/// Counts sites as `try_map` meets them, replacing the target one.
struct Substitute {
    sites: Vec<Site>,
    target: Option<(usize, Param)>,
}

impl Substitute {
    fn site(&mut self, p: &Param, name: String, rule: Rule) -> Param {
        let at = self.sites.len();
        self.sites.push(Site {
            name,
            rule,
            value: p.default_value(),
        });
        match &self.target {
            Some((index, value)) if *index == at => value.clone(),
            _ => p.clone(),
        }
    }
}

impl Mapper<Param, Param3, Node> for Substitute {
    type S2 = Param;
    type V2 = Param3;
    type C2 = Node;
    type E = std::convert::Infallible;

    fn scalar(&mut self, s: &Param, spec: ParamSpec<'_>) -> Result<Param, Self::E> {
        Ok(self.site(s, spec.name.to_string(), spec.rule))
    }

    fn vector(&mut self, v: &Param3, spec: ParamSpec<'_>) -> Result<Param3, Self::E> {
        let [x, y, z] = v.components();
        let out: [Param; 3] = [
            self.site(x, format!("{}.x", spec.name), spec.rule),
            self.site(y, format!("{}.y", spec.name), spec.rule),
            self.site(z, format!("{}.z", spec.name), spec.rule),
        ];
        Ok(out.into())
    }

    fn child(&mut self, c: &Node) -> Result<Node, Self::E> {
        Ok(c.clone())
    }
}
