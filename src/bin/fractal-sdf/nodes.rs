//! `fractal-sdf nodes`: every node a scene file can hold, as text or JSON.

use std::fmt::Write;

use clap::Args;
use fractal_sdf::file::{NodeCategory, NodeKindInfo, node_kinds};

use super::{Outcome, write_out};

#[derive(Args)]
pub(crate) struct NodesArgs {
    /// Print a JSON array instead: one object per node with `name`,
    /// `category` (primitive, fractal, operation, csg or custom), `exact`
    /// (true, false for a bound, or null where the node is not a shape of
    /// its own), `fields` and `description`.
    #[arg(long)]
    json: bool,
}

pub(crate) fn nodes(args: &NodesArgs) -> Outcome {
    let nodes = node_kinds();
    if args.json {
        let mut text = serde_json::to_string_pretty(&nodes).expect("the listing is plain data");
        text.push('\n');
        return write_out(&text);
    }
    write_out(&listing(&nodes))
}

/// The nodes grouped by category, one line each, in plain text.
fn listing(nodes: &[NodeKindInfo]) -> String {
    let mut text = String::new();
    let mut category = None;
    for node in nodes {
        if category != Some(node.category) {
            if category.is_some() {
                text.push('\n');
            }
            category = Some(node.category);
            let heading = match node.category {
                NodeCategory::Primitive => "Primitives (exact distances unless marked as a bound)",
                NodeCategory::Fractal => "Fractals (distance estimates)",
                NodeCategory::Operation => "Operations on one child",
                NodeCategory::Csg => "Booleans",
                _ => "Custom shapes",
            };
            let _ = writeln!(text, "{heading}:");
        }
        let mark = if node.category == NodeCategory::Primitive && node.exact == Some(false) {
            " [bound]"
        } else {
            ""
        };
        let _ = writeln!(text, "  {}{mark}: {}", node.name, plain(node.description));
    }
    let exact = nodes.iter().filter(|n| n.exact == Some(true)).count();
    let _ = writeln!(
        text,
        "\n{} nodes, {exact} exact primitives; `--json` gives the same as JSON",
        nodes.len()
    );
    text
}

/// The reference's Markdown as plain text: no emphasis or code marks, and a
/// link's text without its target.
fn plain(markdown: &str) -> String {
    let mut out = String::new();
    let mut rest = markdown;
    while let Some(start) = rest.find('[') {
        let link = rest[start..]
            .split_once("](")
            .and_then(|(text, tail)| Some((text, tail.split_once(')')?.1)));
        let Some((text, tail)) = link else { break };
        out.push_str(&rest[..start]);
        out.push_str(&text[1..]);
        rest = tail;
    }
    out.push_str(rest);
    out.replace(['`', '*'], "")
}

#[cfg(test)]
mod tests {
    use super::plain;

    #[test]
    fn markdown_becomes_plain_text() {
        assert_eq!(
            plain("`name` (see [`SceneFile::parse`](crate::file::SceneFile::parse)), **radians**"),
            "name (see SceneFile::parse), radians"
        );
        assert_eq!(plain("a [b] c"), "a [b] c");
    }
}
