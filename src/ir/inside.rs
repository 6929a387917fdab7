//! Scenes with inside shapes (see
//! [`InsideShape`](crate::scene::InsideShape)): which combinations can be
//! marched, and the region a march must cross by brute force.

use super::bounds::{Bound, bound};
use super::{Ir, NodeId};
use crate::error::{Error, Result};
use crate::scene::{CsgOp, Kind};

/// What a node's inside shapes occupy, in the coordinates the node sees.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Region {
    /// It holds no inside shape.
    Empty,
    /// Its inside shapes lie in this sphere.
    Within(Bound),
    /// Its inside shapes may lie anywhere.
    Unbounded,
}

impl Ir {
    /// Whether the scene holds an inside shape.
    #[must_use]
    pub fn has_inside_shapes(&self) -> bool {
        (0..self.nodes().len()).any(|i| self.is_inside_leaf(i))
    }

    /// Refuses path-traced global illumination for a scene with inside
    /// shapes: a path bounces off a surface's normal at every hit, and an
    /// inside shape has one only on screen.
    pub(crate) fn check_paths(&self) -> Result<()> {
        match (0..self.nodes().len()).find(|&i| self.is_inside_leaf(i)) {
            Some(i) => Err(Error::InsideShape {
                name: match &self.nodes()[i] {
                    Kind::Custom { shape, .. } => shape.name().to_string(),
                    _ => unreachable!("found as a custom shape"),
                },
                node: self.path(NodeId::from_index(i)),
                reason: "global illumination bounces a path off the surface's normal at every \
                         hit, which an inside shape has only on screen: light its scene \
                         directly (no global_illumination)"
                    .into(),
            }),
            None => Ok(()),
        }
    }

    fn is_inside_leaf(&self, i: usize) -> bool {
        matches!(&self.nodes()[i], Kind::Custom { shape, .. } if shape.inside_bounds().is_some())
    }

    /// Whether `node` is `ancestor` or lies below it.
    fn descends(&self, node: NodeId, ancestor: NodeId) -> bool {
        let mut at = Some(node);
        while let Some(n) = at {
            if n == ancestor {
                return true;
            }
            at = self.parent(n);
        }
        false
    }

    /// The sphere, in the scene's coordinates, that holds every inside
    /// shape's bounds as the scene places them: where a march steps by
    /// brute force. `None` when the scene holds no inside shape (lowering
    /// refuses scenes whose inside shapes have no such sphere).
    #[must_use]
    pub fn brute_region(&self) -> Option<Bound> {
        match self.regions()[self.root().index()] {
            Region::Within(b) => Some(b),
            Region::Empty | Region::Unbounded => None,
        }
    }

    fn regions(&self) -> Vec<Region> {
        let mut out: Vec<Region> = Vec::with_capacity(self.nodes().len());
        // The children's regions as `bound` reads them.
        let mut spheres: Vec<Option<Bound>> = Vec::with_capacity(self.nodes().len());
        for node in self.nodes() {
            let children = node.children();
            let region = if let Kind::Custom { shape, .. } = node {
                match shape.inside_bounds() {
                    Some(_) => bound(node, &spheres).map_or(Region::Unbounded, Region::Within),
                    None => Region::Empty,
                }
            } else if children.iter().all(|c| out[c.index()] == Region::Empty) {
                Region::Empty
            } else if children.iter().any(|c| out[c.index()] == Region::Unbounded) {
                Region::Unbounded
            } else if let Kind::Csg { a, b, .. } = node {
                match (out[a.index()], out[b.index()]) {
                    (Region::Within(x), Region::Within(y)) => Region::Within(x.around(y)),
                    (Region::Within(x), _) | (_, Region::Within(x)) => Region::Within(x),
                    _ => Region::Empty,
                }
            } else {
                bound(node, &spheres).map_or(Region::Unbounded, Region::Within)
            };
            spheres.push(match region {
                Region::Within(b) => Some(b),
                _ => None,
            });
            out.push(region);
        }
        out
    }

    /// Refuses what an inside shape cannot take part in: a smooth boolean,
    /// rounding or an onion shell over it (each needs a distance), a node
    /// that leaves its region unbounded, and materials in its scene.
    pub(super) fn check_inside(&self) -> Result<()> {
        let Some(first) = (0..self.nodes().len()).find(|&i| self.is_inside_leaf(i)) else {
            return Ok(());
        };
        let regions = self.regions();
        let id = |i: usize| NodeId::from_index(i);
        for (i, node) in self.nodes().iter().enumerate() {
            let holds = regions[i] != Region::Empty;
            let why = match node {
                Kind::Csg {
                    smoothing: Some(_),
                    op,
                    ..
                } if holds => Some(format!(
                    "a smooth {} blends two distances, and an inside shape has none: use the \
                     hard {}",
                    op_name(*op),
                    op_name(*op)
                )),
                Kind::Round { .. } if holds => Some(
                    "rounding offsets a distance, and an inside shape has none: round the \
                     membership test itself"
                        .into(),
                ),
                Kind::Onion { .. } if holds => Some(
                    "an onion shell needs a distance, and an inside shape has none: subtract a \
                     smaller copy instead"
                        .into(),
                ),
                Kind::Twist { .. } | Kind::Bend { .. } if holds => Some(
                    "a twist or a bend divides a distance by its stretch, and an inside shape \
                     has none: warp the point in the membership test itself"
                        .into(),
                ),
                Kind::Material { .. } => Some(
                    "materials need a normal at every hit of a reflected or refracted ray, which \
                     a scene with inside shapes has only on screen: colour its nodes instead"
                        .into(),
                ),
                _ if regions[i] == Region::Unbounded
                    && node
                        .children()
                        .iter()
                        .all(|c| regions[c.index()] != Region::Unbounded) =>
                {
                    Some(
                        "this node spreads an inside shape without bound (an unlimited \
                         repetition, or a dynamic translation or scale), so \
                         there is no region to march by brute force: use a limited repetition \
                         or baked values"
                            .into(),
                    )
                }
                _ => None,
            };
            if let Some(reason) = why {
                // The inside shape below the node, or the scene's first.
                let below =
                    (0..=i).find(|&j| self.is_inside_leaf(j) && self.descends(id(j), id(i)));
                let name = match &self.nodes()[below.unwrap_or(first)] {
                    Kind::Custom { shape, .. } => shape.name().to_string(),
                    _ => unreachable!("found as a custom shape"),
                };
                return Err(Error::InsideShape {
                    name,
                    node: self.path(id(i)),
                    reason,
                });
            }
        }
        Ok(())
    }
}

fn op_name(op: CsgOp) -> &'static str {
    match op {
        CsgOp::Union => "union",
        CsgOp::Subtract => "subtraction",
        CsgOp::Intersect => "intersection",
        CsgOp::Cut => "cut",
    }
}
