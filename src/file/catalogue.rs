//! Every node a scene file can hold, as data: its name, its kind of node,
//! whether its distance is exact, the fields the parser reads and the
//! [reference](super::reference)'s description of them.
//!
//! The data comes from two places that cannot drift from what they
//! describe: the fields are the ones the parser's own schema asks for, and
//! each node's category and description are its row in the reference
//! (which a test holds to the same schema). `fractal-sdf nodes` prints it,
//! as text or (`--json`) as JSON.
//!
//! ```
//! use fractal_sdf::file::{NodeCategory, node_kinds};
//!
//! let nodes = node_kinds();
//! let sphere = nodes.iter().find(|n| n.name == "Sphere").unwrap();
//! assert_eq!(sphere.category, NodeCategory::Primitive);
//! assert_eq!(sphere.exact, Some(true));
//! assert_eq!(sphere.fields, ["radius"]);
//! ```

use std::fmt;

use serde::Serialize;
use serde::de::{self, Deserialize, Deserializer, EnumAccess, VariantAccess, Visitor};

use super::schema::NodeRepr;

/// The reference's text, whose node tables this module reads.
const REFERENCE: &str = include_str!("reference.md");

/// The primitives whose distance is exact, by file name. Each is held to an
/// independent oracle within 1e-13 by the crate's tests (the torus and the
/// link where the tube is no thicker than its major radius); a test checks
/// that this list is exactly the primitives those tests draw.
const EXACT: [&str; 31] = [
    "Sphere",
    "Cuboid",
    "RoundBox",
    "Torus",
    "Cylinder",
    "Capsule",
    "Plane",
    "Octahedron",
    "CappedCone",
    "HexPrism",
    "RoundCone",
    "Link",
    "CutSphere",
    "SolidAngle",
    "CappedTorus",
    "Triangle",
    "Quad",
    "Pyramid",
    "Rhombus",
    "TriPrism",
    "RoundedCylinder",
    "Cone",
    "InfiniteCylinder",
    "InfiniteCone",
    "CutHollowSphere",
    "DeathStar",
    "CylinderBetween",
    "ConeBetween",
    "RoundConeBetween",
    "Extrude",
    "Revolve",
];

/// What kind of node a scene-file node is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum NodeCategory {
    /// A shape with no children: a sphere, a box, ...
    Primitive,
    /// A fractal with a distance estimate.
    Fractal,
    /// An operation on one child: a transform, a domain operation, a
    /// colour or material.
    Operation,
    /// A boolean of two or more nodes, hard or smooth.
    Csg,
    /// A shape given by a formula or an inside test.
    Custom,
}

impl fmt::Display for NodeCategory {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            NodeCategory::Primitive => "primitive",
            NodeCategory::Fractal => "fractal",
            NodeCategory::Operation => "operation",
            NodeCategory::Csg => "csg",
            NodeCategory::Custom => "custom",
        })
    }
}

/// One node a scene file can hold.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[non_exhaustive]
pub struct NodeKindInfo {
    /// Its name in a file (`Sphere`).
    pub name: &'static str,
    /// What kind of node it is.
    pub category: NodeCategory,
    /// Whether its distance is exact: `true` for the exact primitives,
    /// `false` for a bound (the ellipsoid and the fractals' estimates),
    /// `None` where the node is not a shape of its own (operations,
    /// booleans, custom shapes, whose distance depends on their parts).
    pub exact: Option<bool>,
    /// The fields the parser reads, in the order it declares them.
    pub fields: Vec<&'static str>,
    /// The reference's description of the fields: ranges, units,
    /// defaults.
    pub description: &'static str,
}

/// Every node a scene file can hold, in the reference's order.
///
/// # Panics
/// Never for the crate as built: a test checks that the reference has a
/// row, in a known section, for every node the parser reads.
#[must_use]
pub fn node_kinds() -> Vec<NodeKindInfo> {
    let mut out = Vec::new();
    let mut category = None;
    for line in REFERENCE.lines() {
        if line.starts_with('#') {
            category = match line.strip_prefix("## ").unwrap_or_default() {
                "Shapes" => Some(NodeCategory::Primitive),
                "Fractals" => Some(NodeCategory::Fractal),
                "Operations on one child" => Some(NodeCategory::Operation),
                "Booleans" => Some(NodeCategory::Csg),
                "Custom shapes" => Some(NodeCategory::Custom),
                _ => None,
            };
            continue;
        }
        let (Some(category), Some(rest)) = (category, line.strip_prefix("| `")) else {
            continue;
        };
        let Some((name, rest)) = rest.split_once("` | ") else {
            continue;
        };
        let index = node_names()
            .iter()
            .position(|n| *n == name)
            .unwrap_or_else(|| panic!("the reference's `{name}` is not a node the parser reads"));
        let exact = match category {
            NodeCategory::Primitive => Some(EXACT.contains(&name)),
            NodeCategory::Fractal => Some(false),
            _ => None,
        };
        out.push(NodeKindInfo {
            name: node_names()[index],
            category,
            exact,
            fields: names::<NodeRepr>(Some(index)),
            description: rest.trim_end_matches(" |").trim(),
        });
    }
    out
}

/// The nodes the parser reads, in the schema's order.
fn node_names() -> Vec<&'static str> {
    names::<NodeRepr>(None)
}

/// The names `T` asks a deserializer for (its variants or fields), or
/// those of its variant `variant`: the schema's own names, as serde derives
/// them.
pub(super) fn names<'de, T: Deserialize<'de>>(variant: Option<usize>) -> Vec<&'static str> {
    let mut seen = Vec::new();
    let _ = T::deserialize(Names {
        variant,
        seen: &mut seen,
    });
    seen
}

/// The error that stops a deserializer once it has shown its names.
#[derive(Debug)]
struct Stop;

impl fmt::Display for Stop {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("stop")
    }
}

impl std::error::Error for Stop {}

impl de::Error for Stop {
    fn custom<T: fmt::Display>(_: T) -> Self {
        Stop
    }
}

/// A deserializer that records the names a type asks for: its variants,
/// or its fields, or (given `variant`) that variant's fields.
struct Names<'a> {
    variant: Option<usize>,
    seen: &'a mut Vec<&'static str>,
}

impl<'de> Deserializer<'de> for Names<'_> {
    type Error = Stop;

    fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Stop> {
        Err(Stop)
    }

    fn deserialize_struct<V: Visitor<'de>>(
        self,
        _: &'static str,
        fields: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Stop> {
        self.seen.extend(fields);
        Err(Stop)
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _: &'static str,
        variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Stop> {
        match self.variant {
            None => {
                self.seen.extend(variants);
                Err(Stop)
            }
            Some(index) => visitor.visit_enum(Variant {
                index,
                seen: self.seen,
            }),
        }
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf option unit unit_struct newtype_struct seq tuple
        tuple_struct map identifier ignored_any
    }
}

/// One variant of an enum, chosen by index.
struct Variant<'a> {
    index: usize,
    seen: &'a mut Vec<&'static str>,
}

impl<'de, 'a> EnumAccess<'de> for Variant<'a> {
    type Error = Stop;
    type Variant = Self;

    fn variant_seed<S: de::DeserializeSeed<'de>>(self, seed: S) -> Result<(S::Value, Self), Stop> {
        let index = u64::try_from(self.index).map_err(|_| Stop)?;
        let value = seed.deserialize(de::value::U64Deserializer::<Stop>::new(index))?;
        Ok((value, self))
    }
}

impl<'de> VariantAccess<'de> for Variant<'_> {
    type Error = Stop;

    fn unit_variant(self) -> Result<(), Stop> {
        Ok(())
    }

    fn newtype_variant_seed<T: de::DeserializeSeed<'de>>(self, _: T) -> Result<T::Value, Stop> {
        Err(Stop)
    }

    fn tuple_variant<V: Visitor<'de>>(self, _: usize, _: V) -> Result<V::Value, Stop> {
        Err(Stop)
    }

    fn struct_variant<V: Visitor<'de>>(
        self,
        fields: &'static [&'static str],
        _: V,
    ) -> Result<V::Value, Stop> {
        self.seen.extend(fields);
        Err(Stop)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_node_the_parser_reads_is_listed_once() {
        let listed: Vec<&str> = node_kinds().iter().map(|n| n.name).collect();
        let mut parsed = node_names();
        assert!(parsed.len() > 40, "{parsed:?}");
        let mut sorted = listed.clone();
        sorted.sort_unstable();
        parsed.sort_unstable();
        assert_eq!(sorted, parsed);
        for name in EXACT {
            let node = node_kinds().into_iter().find(|n| n.name == name).unwrap();
            assert_eq!(node.category, NodeCategory::Primitive, "{name}");
        }
    }

    #[test]
    fn categories_and_fields_are_the_references() {
        let nodes = node_kinds();
        let find = |name: &str| nodes.iter().find(|n| n.name == name).unwrap();
        assert_eq!(find("Torus").fields, ["major_radius", "minor_radius"]);
        assert_eq!(find("Kifs").category, NodeCategory::Fractal);
        assert_eq!(find("Kifs").exact, Some(false));
        assert_eq!(find("Hybrid").category, NodeCategory::Fractal);
        assert_eq!(
            find("Hybrid").fields,
            ["stages", "iterations", "bailout", "safety"]
        );
        assert_eq!(find("Ellipsoid").exact, Some(false));
        assert_eq!(find("Translate").category, NodeCategory::Operation);
        assert_eq!(find("Translate").exact, None);
        assert_eq!(find("SmoothUnion").category, NodeCategory::Csg);
        assert_eq!(find("Custom").category, NodeCategory::Custom);
        assert!(find("Sphere").description.contains(">= 0"));
    }
}
