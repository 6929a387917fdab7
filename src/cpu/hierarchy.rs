//! The CPU reference's walk of a large union: the operands of a tree of
//! hard unions that have a bound at the current values, indexed by the
//! kind of bounding volume hierarchy the kernels walk over a group of
//! alike operands (`ir::bvh`), so a point evaluates only the operands it
//! can be nearest to.
//!
//! The result is the plain union's: the least distance, and on an exact
//! tie the later operand's colour, as the chain's order places them. An
//! operand, or a box of them, is skipped only where its bound is positive
//! and beyond the nearest distance found so far, so nothing skipped could
//! have been the minimum or tied with it.

use super::Sample;
use crate::ir::bvh::{Bvh, Entry, MIN_HIERARCHY, WIDTH};
use crate::ir::{Bound, NodeId, SHRINK};
use crate::math::{Real, V3};

/// One union tree's operands, split into those evaluated in turn and
/// those found through the hierarchy.
#[derive(Debug, Clone)]
pub(super) struct Hierarchy {
    /// The operands without a bound at the current values, with their
    /// places in the chain: evaluated first, in turn.
    loose: Vec<(NodeId, usize)>,
    /// The bounded operands, with their places and bounds, in the order
    /// the hierarchy's leaves hold them.
    members: Vec<(NodeId, usize, Bound)>,
    bvh: Bvh,
}

impl Hierarchy {
    /// The hierarchy over a chain's `operands` (in the chain's order),
    /// with each node's bound at the current values in `bounds`; `None`
    /// where fewer than [`MIN_HIERARCHY`] operands have one, or the build
    /// refuses them.
    pub(super) fn build(operands: &[NodeId], bounds: &[Option<Bound>]) -> Option<Self> {
        let (mut loose, mut bounded) = (Vec::new(), Vec::new());
        for (place, &o) in operands.iter().enumerate() {
            match bounds[o.index()] {
                Some(b) => bounded.push((o, place, b)),
                None => loose.push((o, place)),
            }
        }
        if bounded.len() < MIN_HIERARCHY {
            return None;
        }
        let spheres: Vec<Bound> = bounded.iter().map(|m| m.2).collect();
        let bvh = Bvh::build(&spheres)?;
        let members = bvh.order.iter().map(|&i| bounded[i]).collect();
        Some(Hierarchy {
            loose,
            members,
            bvh,
        })
    }
}

/// What a walk looks at next.
#[derive(Debug, Clone, Copy)]
enum Item {
    Node(usize),
    Member(usize),
}

/// A walk in progress at one point: the evaluator asks it for the next
/// operand to evaluate and hands back that operand's sample.
#[derive(Debug, Clone)]
pub(super) struct Walk<T> {
    /// The union tree's root.
    pub(super) root: usize,
    pub(super) p: V3<T>,
    /// The next loose operand.
    loose: usize,
    stack: Vec<Item>,
    /// The nearest sample so far and its operand's place.
    best: Option<(Sample<T>, usize)>,
    /// The place of the operand being evaluated.
    pending: Option<usize>,
}

impl<T: Real> Walk<T> {
    pub(super) fn new(root: usize, p: V3<T>) -> Self {
        Walk {
            root,
            p,
            loose: 0,
            stack: vec![Item::Node(0)],
            best: None,
            pending: None,
        }
    }

    /// Whether the walk waits for the sample of the operand it named.
    pub(super) fn waits(&self) -> bool {
        self.pending.is_some()
    }

    /// Takes the sample of the operand the last [`Walk::next`] named;
    /// `union` combines two samples, the earlier operand's first.
    pub(super) fn give(
        &mut self,
        sample: Sample<T>,
        union: impl Fn(Sample<T>, Sample<T>) -> Sample<T>,
    ) {
        let place = self.pending.take().expect("an operand was asked for");
        self.best = Some(match self.best.take() {
            None => (sample, place),
            Some((best, at)) => {
                let (earlier, later) = if place > at {
                    ((best, at), (sample, place))
                } else {
                    ((sample, place), (best, at))
                };
                // A union keeps its first operand only where it is nearer.
                let kept = if earlier.0.distance < later.0.distance {
                    earlier.1
                } else {
                    later.1
                };
                (union(earlier.0, later.0), kept)
            }
        });
    }

    /// Whether something whose distance is at least `g` (where positive)
    /// cannot be the nearest.
    fn beyond(&self, g: T) -> bool {
        self.best
            .as_ref()
            .is_some_and(|(best, _)| g > best.distance && g > T::zero())
    }

    /// The next operand to evaluate, or `None` when the walk is done.
    pub(super) fn next(&mut self, h: &Hierarchy) -> Option<NodeId> {
        if let Some(&(o, place)) = h.loose.get(self.loose) {
            self.loose += 1;
            self.pending = Some(place);
            return Some(o);
        }
        while let Some(item) = self.stack.pop() {
            match item {
                Item::Member(i) => {
                    let (o, place, bound) = h.members[i];
                    if !self.beyond(bound.distance_at(self.p)) {
                        self.pending = Some(place);
                        return Some(o);
                    }
                }
                Item::Node(n) => self.open(h, n),
            }
        }
        None
    }

    /// Puts the entries of node `n` that can hold the nearest operand on
    /// the stack, the nearest on top.
    fn open(&mut self, h: &Hierarchy, n: usize) {
        // Every member's estimate grows at least this fast away from its
        // box (shortened as every bound is, for rounding).
        let slope = T::of(h.bvh.slope * SHRINK);
        let mut open: Vec<(T, Entry)> = Vec::with_capacity(WIDTH);
        for j in 0..WIDTH {
            let (lo, hi, entry) = h.bvh.entry(n, j);
            if entry == Entry::Empty {
                continue;
            }
            let axis = |k: usize| {
                let p = self.p.to_array()[k];
                (T::of(lo[k]) - p).max(p - T::of(hi[k])).max(T::zero())
            };
            let (x, y, z) = (axis(0), axis(1), axis(2));
            let gap = slope * (x * x + y * y + z * z).sqrt();
            if !self.beyond(gap) {
                open.push((gap, entry));
            }
        }
        open.sort_by(|a, b| b.0.partial_cmp(&a.0).unwrap_or(std::cmp::Ordering::Equal));
        for (_, entry) in open {
            match entry {
                Entry::Node(child) => self.stack.push(Item::Node(child)),
                Entry::Leaf(places) => self.stack.extend(places.rev().map(Item::Member)),
                Entry::Empty => {}
            }
        }
    }

    /// The union's sample, once [`Walk::next`] has said it is done.
    pub(super) fn result(self) -> Sample<T> {
        self.best.expect("a union has operands").0
    }
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::cpu::Evaluator;

    /// A walk over a thousand spheres of a grid evaluates a few of them,
    /// and finds the nearest: the least distance of all thousand, computed
    /// here one by one.
    #[test]
    fn a_walk_evaluates_few_operands_and_finds_the_nearest() {
        let centres: Vec<DVec3> = (0..1000)
            .map(|i| {
                DVec3::new(
                    f64::from(i % 10),
                    f64::from(i / 10 % 10),
                    f64::from(i / 100),
                )
            })
            .collect();
        let radius = 0.3;
        let bounds: Vec<Option<Bound>> = centres
            .iter()
            .map(|&centre| {
                Some(Bound {
                    centre,
                    radius,
                    slope: 1.0,
                })
            })
            .collect();
        let operands: Vec<NodeId> = (0..centres.len()).map(NodeId::from_index).collect();
        let h = Hierarchy::build(&operands, &bounds).expect("a hierarchy");
        for (k, p) in [
            DVec3::new(4.2, 5.1, 3.0),
            DVec3::new(-3.0, 4.0, 20.0),
            DVec3::new(9.5, 0.0, 0.4),
        ]
        .into_iter()
        .enumerate()
        {
            let mut walk = Walk::new(0, V3::from(p));
            let mut evaluated = 0;
            while let Some(o) = walk.next(&h) {
                evaluated += 1;
                let d = (p - centres[o.index()]).length() - radius;
                walk.give(Evaluator::leaf(d), |a, b| {
                    super::super::combine(crate::scene::CsgOp::Union, None, a, b)
                });
            }
            let nearest = centres
                .iter()
                .map(|&c| (p - c).length() - radius)
                .fold(f64::INFINITY, f64::min);
            assert_eq!(walk.result().distance, nearest, "point {k}");
            assert!(evaluated <= 40, "point {k}: {evaluated} of 1000 evaluated");
        }
    }
}
