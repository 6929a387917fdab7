//! The parameter buffer: one slot per dynamic parameter, every rule its
//! values must keep (its own, and those that relate it to other
//! parameters), and the values themselves, checked as they are set.

use std::collections::HashMap;
use std::sync::Arc;

use super::{NodePath, Scalar, Vector};
use crate::error::{Error, Result, fmt_value};
use crate::math::{F64_LIMITS, Limits, reduce_angle};
use crate::scene::Rule;

/// One slot of the parameter buffer.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ParamSlot {
    /// The dynamic parameter's name.
    pub name: String,
    /// Its initial value.
    pub default: f64,
    /// What every value set later must satisfy.
    pub rule: Rule,
    /// Where it was first used, for error messages (the node's path and
    /// the parameter's name).
    pub used_at: (NodePath, String),
}

/// A rule that relates several parameters of one node.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Relation {
    /// `value` is at most the smallest component of `bound` (a round box's
    /// edge radius and its half extents).
    AtMostSmallest {
        /// The limited parameter.
        value: Scalar,
        /// The vector whose smallest component limits it.
        bound: Vector,
        /// What `bound` is, for the message (`"half extent"`).
        bound_name: &'static str,
    },
    /// The vector is not zero (a plane's normal, which is normalised).
    NonZero {
        /// The vector.
        vector: Vector,
    },
    /// `value` differs from `other` (the two ends of an orbit colouring's
    /// range).
    Distinct {
        /// The parameter the error names.
        value: Scalar,
        /// The one it must differ from.
        other: Scalar,
        /// What `other` is, for the message (`"near"`).
        other_name: &'static str,
    },
}

/// A [`Relation`] at one node, with the parameter it is reported against.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Constraint {
    /// The node's path, as in every validation error.
    pub node: NodePath,
    /// The parameter the error names.
    pub param: &'static str,
    /// What must hold.
    pub relation: Relation,
}

impl Constraint {
    /// Checks the relation with parameter values from `value`; the error is
    /// the same whether the values are baked or dynamic, and names the
    /// node by `node`.
    pub(crate) fn check(
        &self,
        value: impl Fn(Scalar) -> f64,
        node: impl Fn() -> String,
    ) -> Result<()> {
        match &self.relation {
            Relation::AtMostSmallest {
                value: v,
                bound,
                bound_name,
            } => {
                let (v, smallest) = (
                    value(*v),
                    bound.map(&value).into_iter().fold(f64::INFINITY, f64::min),
                );
                if v > smallest {
                    return Err(Error::OutOfRange {
                        node: node(),
                        param: self.param.into(),
                        value: v,
                        expected: format!("<= the smallest {bound_name} ({})", fmt_value(smallest)),
                    });
                }
            }
            Relation::NonZero { vector } => {
                if vector.iter().all(|s| value(*s) == 0.0) {
                    return Err(Error::ZeroVector {
                        node: node(),
                        param: self.param.into(),
                    });
                }
            }
            Relation::Distinct {
                value: v,
                other,
                other_name,
            } => {
                let (v, other) = (value(*v), value(*other));
                if v == other {
                    return Err(Error::OutOfRange {
                        node: node(),
                        param: self.param.into(),
                        value: v,
                        expected: format!("!= {other_name} ({})", fmt_value(other)),
                    });
                }
            }
        }
        Ok(())
    }

    /// The dynamic slots the relation reads.
    fn slots(&self) -> impl Iterator<Item = u32> + '_ {
        let scalars: Vec<Scalar> = match &self.relation {
            Relation::AtMostSmallest { value, bound, .. } => std::iter::once(*value)
                .chain(bound.iter().copied())
                .collect(),
            Relation::NonZero { vector } => vector.to_vec(),
            Relation::Distinct { value, other, .. } => vec![*value, *other],
        };
        scalars.into_iter().filter_map(|s| match s {
            Scalar::Dynamic(slot) => Some(slot),
            Scalar::Baked(_) => None,
        })
    }

    /// Whether the relation reads any dynamic parameter (otherwise lowering
    /// has checked it for good).
    pub(crate) fn is_dynamic(&self) -> bool {
        self.slots().next().is_some()
    }
}

/// The layout of the parameter buffer: its slots and every rule between
/// them.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ParamLayout {
    pub(crate) slots: Vec<ParamSlot>,
    pub(crate) constraints: Vec<Constraint>,
    /// Each slot's index by its parameter's name.
    by_name: HashMap<String, u32>,
    /// For each slot, the constraints that read it.
    constraints_of: Vec<Vec<u32>>,
}

impl ParamLayout {
    /// The layout of `slots` and `constraints`, indexed so that setting a
    /// parameter costs the same in a scene of ten parameters as in one of
    /// a hundred thousand.
    pub(crate) fn new(slots: Vec<ParamSlot>, constraints: Vec<Constraint>) -> Self {
        let by_name = slots
            .iter()
            .enumerate()
            .map(|(i, s)| (s.name.clone(), u32::try_from(i).expect("slots in u32")))
            .collect();
        let mut constraints_of = vec![Vec::new(); slots.len()];
        for (i, c) in constraints.iter().enumerate() {
            let i = u32::try_from(i).expect("constraints in u32");
            for slot in c.slots() {
                let of = &mut constraints_of[slot as usize];
                if of.last() != Some(&i) {
                    of.push(i);
                }
            }
        }
        ParamLayout {
            slots,
            constraints,
            by_name,
            constraints_of,
        }
    }

    /// The slot of the parameter `name`.
    fn slot(&self, name: &str) -> Option<usize> {
        self.by_name.get(name).map(|&s| s as usize)
    }

    /// The slots, in buffer order.
    #[must_use]
    pub fn slots(&self) -> &[ParamSlot] {
        &self.slots
    }

    /// The rules that relate parameters and read at least one dynamic one.
    #[must_use]
    pub fn constraints(&self) -> &[Constraint] {
        &self.constraints
    }
}

/// Values for the dynamic parameters of one scene, checked as they are set
/// against every rule a baked value would have to keep, with the same
/// error.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamValues {
    layout: Arc<ParamLayout>,
    values: Vec<f64>,
}

impl ParamValues {
    /// Every slot at its default (angles reduced).
    pub(crate) fn defaults(layout: Arc<ParamLayout>) -> Self {
        let values = layout
            .slots
            .iter()
            .map(|s| stored(s.rule, s.default))
            .collect();
        ParamValues { layout, values }
    }

    /// Sets the dynamic parameter `name`.
    ///
    /// # Errors
    /// [`Error::UnknownParam`] if there is no such parameter; otherwise the
    /// error a baked `value` would get at lowering: [`Error::NonFinite`] or
    /// [`Error::OutOfRange`] if it breaks the parameter's rule, or a rule
    /// relating it to the node's other parameters (a round box's radius
    /// above its smallest half extent, a plane normal that becomes zero).
    pub fn set(&mut self, name: &str, value: f64) -> Result<()> {
        self.set_within(name, value, &F64_LIMITS)
    }

    /// Sets the dynamic parameter `name`, as [`ParamValues::set`], for a
    /// kernel of the precision whose `limits` are given: a value it cannot
    /// compute with is refused as well.
    ///
    /// # Errors
    /// As [`ParamValues::set`], and [`Error::Precision`] for a value beyond
    /// `limits`.
    pub fn set_within(&mut self, name: &str, value: f64, limits: &Limits) -> Result<()> {
        let slot = self.layout.slot(name).ok_or_else(|| Error::UnknownParam {
            name: name.into(),
            known: self.layout.slots.iter().map(|s| s.name.clone()).collect(),
        })?;
        let spec = &self.layout.slots[slot];
        check_rule(
            || spec.used_at.0.to_string(),
            &spec.used_at.1,
            value,
            spec.rule,
            false,
        )?;
        let value = stored(spec.rule, value);
        check_limits(
            || spec.used_at.0.to_string(),
            &spec.used_at.1,
            value,
            spec.rule,
            false,
            limits,
        )?;
        let old = std::mem::replace(&mut self.values[slot], value);
        let slot = u32::try_from(slot).expect("slots are numbered in u32");
        let broken = self.layout.constraints_of[slot as usize]
            .iter()
            .map(|&c| &self.layout.constraints[c as usize])
            .try_for_each(|c| c.check(|s| self.value(s), || c.node.to_string()));
        if broken.is_err() {
            self.values[slot as usize] = old;
        }
        broken
    }

    /// Checks every current value against the `limits` of a kernel
    /// precision: what a renderer does before it uploads them.
    ///
    /// # Errors
    /// [`Error::Precision`] for the first value beyond `limits`, naming the
    /// node and parameter where it is first used.
    pub fn check_within(&self, limits: &Limits) -> Result<()> {
        for (slot, &value) in self.layout.slots.iter().zip(&self.values) {
            let (node, param) = &slot.used_at;
            check_limits(|| node.to_string(), param, value, slot.rule, false, limits)?;
        }
        Ok(())
    }

    /// The current value of `name`, if it exists (an angle reduced modulo
    /// a full turn).
    #[must_use]
    pub fn get(&self, name: &str) -> Option<f64> {
        Some(self.values[self.layout.slot(name)?])
    }

    /// The value of a lowered scalar: its literal, or its slot's value.
    #[must_use]
    pub fn value(&self, s: Scalar) -> f64 {
        match s {
            Scalar::Baked(v) => v,
            Scalar::Dynamic(slot) => self.values[slot as usize],
        }
    }

    /// The values in slot order, as the parameter buffer holds them.
    #[must_use]
    pub fn as_slice(&self) -> &[f64] {
        &self.values
    }
}

/// How a slot keeps a value: an angle reduced modulo a full turn, every
/// other value as it is.
fn stored(rule: Rule, value: f64) -> f64 {
    if rule == Rule::Angle {
        reduce_angle(value)
    } else {
        value
    }
}

/// A value's magnitude against the `limits` of a precision, for a value
/// under `rule`, baked or dynamic ([`Rule::magnitude`]).
pub(crate) fn check_limits(
    node: impl FnOnce() -> String,
    param: &str,
    value: f64,
    rule: Rule,
    baked: bool,
    limits: &Limits,
) -> Result<()> {
    match limits.crossed(value, rule.magnitude(baked)) {
        None => Ok(()),
        Some(limit) => Err(Error::Precision {
            node: node(),
            param: param.into(),
            value,
            precision: limits.precision,
            limit,
        }),
    }
}

/// A value's own rule, and the `F64` limits every scene value keeps (the
/// CPU reference computes in `f64`), with the error every validation
/// reports.
pub(crate) fn check_rule(
    node: impl Fn() -> String,
    param: &str,
    value: f64,
    rule: Rule,
    baked: bool,
) -> Result<()> {
    if !value.is_finite() {
        return Err(Error::NonFinite {
            node: node(),
            param: param.into(),
            value,
        });
    }
    if !rule.accepts(value) {
        return Err(Error::OutOfRange {
            node: node(),
            param: param.into(),
            value,
            expected: rule.describe(),
        });
    }
    check_limits(node, param, value, rule, baked, &F64_LIMITS)
}
