//! A bounding volume hierarchy over an instanced group's bounds, flattened
//! into the parameter buffer so that a kernel walks it with a fixed stack
//! and evaluates only the instances near a point.
//!
//! Each node has [`WIDTH`] entries and takes [`NODE_LEN`] values, laid out
//! so that a kernel loads each coordinate of all four entries' boxes as one
//! vector: the low corners' x, y and z, the high corners' x, y and z (four
//! values each), then each entry's `first` and each entry's `count`. An
//! entry with `count > 0` is a leaf: the instances `first .. first +
//! count` of the reordered table; `count == 0` is the node numbered
//! `first`; `count < 0` is empty. Boxes hold their instances' bounding
//! spheres, so the distance from a point to an entry's box, times the
//! smallest slope of its instances' bounds, is at most any of their
//! estimates wherever it is positive ([`Bound`]): an entry that far beyond
//! the nearest estimate found so far cannot change the union's minimum,
//! and is skipped.

use std::convert::Infallible;

use glam::DVec3;

use super::writer::INSTANCE_SLOT;
use crate::ir::{Bound, IrNode, NodeId, Scalar, Vector, bound};
use crate::math::F32_LIMITS;
use crate::scene::{Mapper, ParamSpec};

/// Entries per node.
pub(crate) const WIDTH: usize = 4;

/// Values per node: six corner coordinates, `first` and `count`, each for
/// [`WIDTH`] entries.
pub(crate) const NODE_LEN: usize = 8 * WIDTH;

/// The most instances a leaf holds.
const LEAF_SIZE: usize = 8;

/// The kernel's stack: a node's visit takes one entry off it and puts at
/// most [`WIDTH`] on, so a walk of a tree `depth` nodes deep holds at most
/// `(WIDTH − 1) · depth + 1`. Median splits make a tree of `n` instances
/// about `log4(n / LEAF_SIZE)` deep: 10 levels hold [`MAX_INSTANCES`].
pub(crate) const STACK: usize = 32;

/// The most instances a hierarchy indexes: node and instance numbers are
/// stored as `real`s, exact in `f32` up to `2^24`.
pub(crate) const MAX_INSTANCES: usize = 1 << 22;

/// A flattened hierarchy.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Bvh {
    /// [`NODE_LEN`] values per node, the root first; a node's children
    /// follow it.
    pub(crate) nodes: Vec<f64>,
    /// The instances in the order the leaves hold them (indices into the
    /// bounds it was built from).
    pub(crate) order: Vec<usize>,
    /// The number of nodes on the longest path from the root down.
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

    /// A box that holds every finite point of single precision (local
    /// points beyond the precisions' limits come of scales): for an
    /// instance without a bound at its current values.
    const EVERYWHERE: Aabb = Aabb {
        lo: DVec3::splat(-(f32::MAX as f64)),
        hi: DVec3::splat(f32::MAX as f64),
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
    /// longest side of each range's box of centres, two splits a node,
    /// without recursion. `None` for fewer than two bounds, more than
    /// [`MAX_INSTANCES`], or a tree deeper than the kernel's stack walks.
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
            // Up to `WIDTH` parts: the range halved, and each part halved
            // again while it is more than a leaf, `log2(WIDTH)` times.
            let mut parts = vec![(first, end)];
            for _ in 0..WIDTH.trailing_zeros() {
                let mut halves = Vec::with_capacity(WIDTH);
                for (a, b) in parts {
                    if b - a > LEAF_SIZE {
                        halves.extend(split(&mut order, &boxes, a, b));
                    } else {
                        halves.push((a, b));
                    }
                }
                parts = halves;
            }
            let at = node * NODE_LEN;
            for j in 0..WIDTH {
                let Some(&(a, b)) = parts.get(j) else {
                    nodes[at + 7 * WIDTH + j] = -1.0;
                    continue;
                };
                let all = order[a..b]
                    .iter()
                    .fold(Aabb::EMPTY, |acc, &i| acc.join(boxes[i]));
                put_box(&mut nodes[at..at + NODE_LEN], j, all);
                if b - a <= LEAF_SIZE {
                    nodes[at + 6 * WIDTH + j] = a as f64;
                    nodes[at + 7 * WIDTH + j] = (b - a) as f64;
                } else {
                    let child = nodes.len() / NODE_LEN;
                    nodes.resize(nodes.len() + NODE_LEN, 0.0);
                    nodes[at + 6 * WIDTH + j] = child as f64;
                    nodes[at + 7 * WIDTH + j] = 0.0;
                    work.push((child, a, b, level + 1));
                }
            }
        }
        if (WIDTH - 1) * depth + 1 > STACK {
            return None;
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

/// Splits `order[first..end]` at its median along the longest side of its
/// box of centres: the two halves' ranges.
fn split(order: &mut [usize], boxes: &[Aabb], first: usize, end: usize) -> [(usize, usize); 2] {
    let members = &mut order[first..end];
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
    [(first, first + half), (first + half, end)]
}

/// Writes entry `j`'s box into a node's values.
fn put_box(node: &mut [f64], j: usize, b: Aabb) {
    for k in 0..3 {
        node[k * WIDTH + j] = b.lo[k];
        node[(3 + k) * WIDTH + j] = b.hi[k];
    }
}

/// Entry `j`'s box in a node's values.
#[cfg(test)]
fn get_box(node: &[f64], j: usize) -> Aabb {
    let corner = |c: usize| DVec3::from_array(std::array::from_fn(|k| node[(c + k) * WIDTH + j]));
    Aabb {
        lo: corner(0),
        hi: corner(3),
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

    /// Whether the tables copy a dynamic value that differs between
    /// `old` and `new` (both by slot): only then must they be filled
    /// again.
    #[cfg(feature = "opencl")]
    pub(crate) fn differ(&self, old: &[f64], new: &[f64]) -> bool {
        self.copies.iter().any(|&(_, slot)| {
            let s = slot as usize;
            old[s].to_bits() != new[s].to_bits()
        })
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
        // Each node's box around all its entries, children first.
        let mut totals = vec![Aabb::EMPTY; self.count];
        for n in (0..self.count).rev() {
            let at = self.nodes + n * NODE_LEN;
            let node = &mut tables[at..at + NODE_LEN];
            let mut total = Aabb::EMPTY;
            for j in 0..WIDTH {
                let (first, count) = (node[6 * WIDTH + j], node[7 * WIDTH + j]);
                let fitted = if count < 0.0 {
                    continue;
                } else if count > 0.0 {
                    let (a, b) = (first as usize, (first + count) as usize);
                    boxes[a..b].iter().fold(Aabb::EMPTY, |acc, b| acc.join(*b))
                } else {
                    totals[first as usize]
                };
                put_box(node, j, fitted);
                total = total.join(fitted);
            }
            totals[n] = total;
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

    /// Every instance is in exactly one leaf, and every entry's box holds
    /// the spheres of every instance under it.
    #[test]
    fn leaves_partition_the_instances_and_boxes_hold_them() {
        for n in [2, 3, 5, 16, 17, 100, 1000, 5000] {
            let bounds = scattered(n);
            let bvh = Bvh::build(&bounds).expect("a hierarchy");
            let mut seen = vec![0; n];
            // (node, the boxes above it, its level)
            let mut stack = vec![(0usize, Vec::<Aabb>::new(), 1usize)];
            let mut deepest = 0;
            while let Some((node, above, level)) = stack.pop() {
                deepest = deepest.max(level);
                let v = &bvh.nodes[node * NODE_LEN..(node + 1) * NODE_LEN];
                for j in 0..WIDTH {
                    let (first, count) = (v[6 * WIDTH + j], v[7 * WIDTH + j]);
                    if count < 0.0 {
                        continue;
                    }
                    let mut boxes = above.clone();
                    boxes.push(get_box(v, j));
                    if count == 0.0 {
                        assert!(first as usize > node, "children follow their parent");
                        stack.push((first as usize, boxes, level + 1));
                        continue;
                    }
                    assert!(count as usize <= LEAF_SIZE);
                    let (a, b) = (first as usize, (first + count) as usize);
                    for &i in &bvh.order[a..b] {
                        seen[i] += 1;
                        let s = bounds[i];
                        for w in &boxes {
                            for k in 0..3 {
                                assert!(w.lo[k] <= s.centre[k] - s.radius);
                                assert!(w.hi[k] >= s.centre[k] + s.radius);
                            }
                        }
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "{n}: {seen:?}");
            assert_eq!(deepest, bvh.depth);
            assert!((WIDTH - 1) * bvh.depth < STACK);
            let balanced = (n as f64 / LEAF_SIZE as f64).log(4.0).ceil().max(1.0) as usize;
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
