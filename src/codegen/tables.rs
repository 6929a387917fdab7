//! How an instanced group's hierarchy (`ir::bvh`) follows dynamic
//! values: the table entries that copy a dynamic parameter, and the boxes
//! fitted again around the instances' bounds at new values.

use super::writer::INSTANCE_SLOT;
use crate::ir::bvh::{Aabb, NODE_LEN, WIDTH, put_box};
use crate::ir::{Baking, Bound, IrNode, bound};
use crate::math::F32_LIMITS;

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
        let mut fill = Baking(|slot: u32| {
            (slot >= INSTANCE_SLOT).then(|| row[(slot - INSTANCE_SLOT) as usize])
        });
        let Ok(filled) = node.try_map(&mut fill);
        let b = bound(&filled, &done);
        done.push(b);
    }
    done.pop().flatten().filter(|b| b.fits(&F32_LIMITS))
}
