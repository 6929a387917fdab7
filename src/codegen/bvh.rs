//! A bounding volume hierarchy over an instanced group's bounds, flattened
//! into the parameter buffer so that a kernel walks it with a fixed stack
//! and evaluates only the instances near a point.
//!
//! Each node is [`NODE_LEN`] values: the box's low corner, its high corner,
//! then `first` and `count`. A leaf (`count > 0`) holds the instances
//! `first .. first + count` of the reordered table; an inner node
//! (`count == 0`) has its two children at nodes `first` and `first + 1`.
//! Boxes hold their instances' bounding spheres, so the distance from a
//! point to a node's box, times the smallest slope of its instances'
//! bounds, is at most any of their estimates wherever it is positive
//! ([`Bound`]): a node that far beyond the nearest estimate found so far
//! cannot change the union's minimum, and is skipped.

use std::convert::Infallible;

use glam::DVec3;

use super::writer::INSTANCE_SLOT;
use crate::ir::{Bound, IrNode, NodeId, Scalar, Vector, bound};
use crate::math::F32_LIMITS;
use crate::scene::{Mapper, ParamSpec};

/// Values per node: low corner, high corner, `first`, `count`.
pub(crate) const NODE_LEN: usize = 8;

/// The most instances a leaf holds.
const LEAF_SIZE: usize = 4;

/// The deepest tree a kernel's fixed stack walks: median splits make a
/// tree of `n` instances about `log2(n / LEAF_SIZE) + 1` deep, so this is
/// reached only past `2^33` instances, far beyond [`MAX_INSTANCES`].
pub(crate) const STACK: usize = 32;

/// The most instances a hierarchy indexes: node and instance numbers are
/// stored as `real`s, exact in `f32` up to `2^24`, and a tree has fewer
/// than two nodes per instance.
pub(crate) const MAX_INSTANCES: usize = 1 << 22;

/// A flattened hierarchy.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Bvh {
    /// [`NODE_LEN`] values per node, the root first.
    pub(crate) nodes: Vec<f64>,
    /// The instances in the order the leaves hold them (indices into the
    /// bounds it was built from).
    pub(crate) order: Vec<usize>,
    /// The number of nodes on the longest path from the root to a leaf.
    pub(crate) depth: usize,
    /// The smallest slope of the instances' bounds.
    pub(crate) slope: f64,
}

/// An axis-aligned box.
#[derive(Debug, Clone, Copy)]
struct Aabb {
    lo: DVec3,
    hi: DVec3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        lo: DVec3::INFINITY,
        hi: DVec3::NEG_INFINITY,
    };

    /// A box that holds every point a kernel computes with: for an
    /// instance without a bound at its current values.
    const EVERYWHERE: Aabb = Aabb {
        lo: DVec3::splat(-F32_LIMITS.max),
        hi: DVec3::splat(F32_LIMITS.max),
    };

    /// The box around a bounding sphere, padded outwards so that rounding
    /// its corners to `f32` never cuts into the sphere.
    fn around(b: &Bound) -> Aabb {
        let pad = DVec3::splat(b.radius) + (b.centre.abs() + b.radius) * 1e-6;
        Aabb {
            lo: b.centre - pad,
            hi: b.centre + pad,
        }
    }

    fn join(self, other: Aabb) -> Aabb {
        Aabb {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
        }
    }

    fn centre(&self) -> DVec3 {
        (self.lo + self.hi) * 0.5
    }
}

impl Bvh {
    /// Builds the hierarchy over `bounds` by median splits along the
    /// longest side of each node's box of centres, without recursion.
    /// `None` for fewer than two bounds or more than [`MAX_INSTANCES`].
    pub(crate) fn build(bounds: &[Bound]) -> Option<Bvh> {
        if bounds.len() < 2 || bounds.len() > MAX_INSTANCES {
            return None;
        }
        let boxes: Vec<Aabb> = bounds.iter().map(Aabb::around).collect();
        let mut order: Vec<usize> = (0..bounds.len()).collect();
        let mut nodes = vec![0.0; NODE_LEN];
        let mut depth = 0;
        // Work: (node, first, end, depth) over `order`.
        let mut work = vec![(0usize, 0usize, bounds.len(), 1usize)];
        while let Some((node, first, end, level)) = work.pop() {
            depth = depth.max(level);
            let members = &mut order[first..end];
            let all = members
                .iter()
                .fold(Aabb::EMPTY, |acc, &i| acc.join(boxes[i]));
            let at = node * NODE_LEN;
            nodes[at..at + 3].copy_from_slice(&all.lo.to_array());
            nodes[at + 3..at + 6].copy_from_slice(&all.hi.to_array());
            if members.len() <= LEAF_SIZE {
                nodes[at + 6] = first as f64;
                nodes[at + 7] = members.len() as f64;
                continue;
            }
            let centres = members.iter().fold(Aabb::EMPTY, |acc, &i| {
                let c = boxes[i].centre();
                acc.join(Aabb { lo: c, hi: c })
            });
            let extent = centres.hi - centres.lo;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let half = members.len() / 2;
            members.select_nth_unstable_by(half, |&a, &b| {
                boxes[a].centre()[axis].total_cmp(&boxes[b].centre()[axis])
            });
            let child = nodes.len() / NODE_LEN;
            nodes.resize(nodes.len() + 2 * NODE_LEN, 0.0);
            nodes[at + 6] = child as f64;
            nodes[at + 7] = 0.0;
            work.push((child + 1, first + half, end, level + 1));
            work.push((child, first, first + half, level + 1));
        }
        let slope = bounds.iter().map(|b| b.slope).fold(1.0, f64::min);
        Some(Bvh {
            nodes,
            order,
            depth,
            slope,
        })
    }

    /// The number of nodes.
    pub(crate) fn len(&self) -> usize {
        self.nodes.len() / NODE_LEN
    }
}

/// How a program's instance tables follow its dynamic parameters: the
/// table entries that copy a dynamic parameter's value, and the
/// hierarchies whose boxes are fitted again around their instances at the
/// new values. A host fills them in
/// [`KernelSource::param_buffer`](super::KernelSource::param_buffer);
/// changing a value never changes the program.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct InstanceTables {
    /// `(entry, slot)`: the entry of the tables (counted from their
    /// start) that holds the value of dynamic parameter `slot`.
    pub(crate) copies: Vec<(usize, u32)>,
    /// The hierarchies over instances that read a dynamic value.
    pub(crate) refits: Vec<Refit>,
}

impl InstanceTables {
    /// Whether every entry of the tables is baked.
    #[must_use]
    pub fn is_baked(&self) -> bool {
        self.copies.is_empty()
    }

    /// Writes the dynamic `values` into `tables` (the entries after the
    /// values in the parameter buffer) and fits each hierarchy that reads
    /// them around its instances again.
    pub(crate) fn fill(&self, tables: &mut [f64], values: &[f64]) {
        for &(entry, slot) in &self.copies {
            tables[entry] = values[slot as usize];
        }
        for refit in &self.refits {
            refit.apply(tables);
        }
    }
}

/// What fitting one hierarchy again takes: where its table and nodes lie
/// among the tables, and its instances' chain of nodes.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Refit {
    /// The first entry of its table.
    pub(crate) table: usize,
    /// Entries per row: an instance's values, then its place.
    pub(crate) row: usize,
    /// Rows.
    pub(crate) members: usize,
    /// The entry its first node starts at.
    pub(crate) nodes: usize,
    /// Nodes.
    pub(crate) count: usize,
    /// The instances' nodes from the leaf up, each reading its row
    /// (`Scalar::Dynamic(INSTANCE_SLOT + entry)`) and with its child
    /// renumbered to the node before it.
    pub(crate) chain: Vec<IrNode>,
    /// The slope the kernel's walk multiplies box distances by.
    pub(crate) slope: f64,
}

impl Refit {
    /// Fits every node's box around its instances' bounds at the values in
    /// `tables`: leaves from their rows, inner nodes from their children
    /// (which follow them). An instance whose bound is missing at these
    /// values, or grows slower than the walk assumes, gets a box that
    /// holds everything: its node is always entered.
    fn apply(&self, tables: &mut [f64]) {
        let boxes: Vec<Aabb> = (0..self.members)
            .map(|j| {
                let at = self.table + j * self.row;
                chain_bound(&self.chain, &tables[at..at + self.row - 1])
                    .filter(|b| b.slope >= self.slope)
                    .map_or(Aabb::EVERYWHERE, |b| Aabb::around(&b))
            })
            .collect();
        for n in (0..self.count).rev() {
            let at = self.nodes + n * NODE_LEN;
            let (first, count) = (tables[at + 6] as usize, tables[at + 7] as usize);
            let fitted = if count > 0 {
                boxes[first..first + count]
                    .iter()
                    .fold(Aabb::EMPTY, |acc, b| acc.join(*b))
            } else {
                let child = |c: usize| {
                    let v = &tables[self.nodes + c * NODE_LEN..];
                    Aabb {
                        lo: DVec3::new(v[0], v[1], v[2]),
                        hi: DVec3::new(v[3], v[4], v[5]),
                    }
                };
                child(first).join(child(first + 1))
            };
            tables[at..at + 3].copy_from_slice(&fitted.lo.to_array());
            tables[at + 3..at + 6].copy_from_slice(&fitted.hi.to_array());
        }
    }
}

/// An instance's bound with the values of its row: its chain (from the
/// leaf up, as [`Refit::chain`]) with every table entry read from `row`,
/// bounded as [`Ir::bounds`](crate::ir::Ir::bounds) bounds it, where a
/// kernel in single precision can evaluate that bound.
pub(crate) fn chain_bound(chain: &[IrNode], row: &[f64]) -> Option<Bound> {
    let mut done: Vec<Option<Bound>> = Vec::with_capacity(chain.len());
    for node in chain {
        let Ok(filled) = node.try_map(&mut Fill { row });
        let b = bound(&filled, &done);
        done.push(b);
    }
    done.pop().flatten().filter(|b| b.fits(&F32_LIMITS))
}

/// Reads a row's entries as baked values.
struct Fill<'a> {
    row: &'a [f64],
}

impl Fill<'_> {
    fn read(&self, s: Scalar) -> Scalar {
        match s {
            Scalar::Dynamic(slot) if slot >= INSTANCE_SLOT => {
                Scalar::Baked(self.row[(slot - INSTANCE_SLOT) as usize])
            }
            other => other,
        }
    }
}

impl Mapper<Scalar, Vector, NodeId> for Fill<'_> {
    type S2 = Scalar;
    type V2 = Vector;
    type C2 = NodeId;
    type E = Infallible;

    fn scalar(&mut self, s: &Scalar, _: ParamSpec<'_>) -> Result<Scalar, Infallible> {
        Ok(self.read(*s))
    }

    fn vector(&mut self, v: &Vector, _: ParamSpec<'_>) -> Result<Vector, Infallible> {
        Ok(v.map(|s| self.read(s)))
    }

    fn child(&mut self, c: &NodeId) -> Result<NodeId, Infallible> {
        Ok(*c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(c: DVec3, r: f64) -> Bound {
        Bound {
            centre: c,
            radius: r,
            slope: 1.0,
        }
    }

    fn scattered(n: usize) -> Vec<Bound> {
        (0..n)
            .map(|i| {
                let t = i as f64;
                ball(
                    DVec3::new((t * 1.7).sin(), (t * 0.37).cos(), (t * 2.9).sin()) * 10.0,
                    0.05 + (t * 0.13).sin().abs() * 0.5,
                )
            })
            .collect()
    }

    /// Every instance is in exactly one leaf, and every node's box holds
    /// the spheres of every instance under it.
    #[test]
    fn leaves_partition_the_instances_and_boxes_hold_them() {
        for n in [2, 3, 5, 16, 17, 100, 1000] {
            let bounds = scattered(n);
            let bvh = Bvh::build(&bounds).expect("a hierarchy");
            let mut seen = vec![0; n];
            let mut stack = vec![(0usize, Vec::<usize>::new())];
            let mut deepest = 0;
            while let Some((node, mut above)) = stack.pop() {
                above.push(node);
                deepest = deepest.max(above.len());
                let v = &bvh.nodes[node * NODE_LEN..(node + 1) * NODE_LEN];
                let (first, count) = (v[6] as usize, v[7] as usize);
                if count == 0 {
                    stack.push((first, above.clone()));
                    stack.push((first + 1, above));
                    continue;
                }
                assert!(count <= LEAF_SIZE);
                for &i in &bvh.order[first..first + count] {
                    seen[i] += 1;
                    let b = bounds[i];
                    for &a in &above {
                        let w = &bvh.nodes[a * NODE_LEN..a * NODE_LEN + 6];
                        for k in 0..3 {
                            assert!(w[k] <= b.centre[k] - b.radius);
                            assert!(w[k + 3] >= b.centre[k] + b.radius);
                        }
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "{n}: {seen:?}");
            assert_eq!(deepest, bvh.depth);
            assert!(bvh.depth <= STACK);
            let balanced = (n as f64 / LEAF_SIZE as f64).log2().ceil().max(0.0) as usize + 1;
            assert!(bvh.depth <= balanced + 1, "{n}: depth {}", bvh.depth);
        }
    }

    #[test]
    fn too_few_or_too_many_instances_have_no_hierarchy() {
        assert!(Bvh::build(&[]).is_none());
        assert!(Bvh::build(&scattered(1)).is_none());
        assert!(Bvh::build(&scattered(2)).is_some());
    }
}
