//! What a parameter must be ([`Rule`]) and its name beside it
//! ([`ParamSpec`]): the one list every node's and material's values are
//! checked against.

use crate::math::Magnitude;

/// What a parameter must satisfy. Every rule also requires a finite value,
/// within the magnitudes the kernels can compute with (see
/// [`Rule::magnitude`] and [`math::Limits`](crate::math::Limits)).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Rule {
    /// Any finite value: a coordinate, an offset or a rate (at most the
    /// largest magnitude of the precision).
    Finite,
    /// At least 0: a size (0, or between the smallest and the largest
    /// magnitude of the precision).
    NonNegative,
    /// Greater than 0: a size, as for `NonNegative`.
    Positive,
    /// Within `[min, max]`.
    Range(f64, f64),
    /// Of magnitude within `[min, max]`, either sign: a scale that must
    /// grow, such as the Mandelbox's.
    Magnitude(f64, f64),
    /// Any finite angle in radians. Angles are reduced modulo a full turn
    /// (see [`math::reduce_angle`](crate::math::reduce_angle)) before the
    /// CPU reference or a kernel uses them, so no magnitude limit applies.
    Angle,
    /// A component of a direction, which is normalised: any finite value.
    /// A baked direction is normalised in `f64` when the scene is compiled,
    /// so no magnitude limit applies to it; the components of a dynamic one
    /// reach the kernel as they are, and are held to the limits of a size.
    Direction,
}

impl Rule {
    /// Whether `v` satisfies the rule.
    #[must_use]
    pub fn accepts(self, v: f64) -> bool {
        v.is_finite()
            && match self {
                Rule::Finite | Rule::Angle | Rule::Direction => true,
                Rule::NonNegative => v >= 0.0,
                Rule::Positive => v > 0.0,
                Rule::Range(lo, hi) => (lo..=hi).contains(&v),
                Rule::Magnitude(lo, hi) => (lo..=hi).contains(&v.abs()),
            }
    }

    /// A short human description, such as `">= 0"`.
    #[must_use]
    pub fn describe(self) -> String {
        match self {
            Rule::Finite | Rule::Angle | Rule::Direction => "finite".into(),
            Rule::NonNegative => ">= 0".into(),
            Rule::Positive => "> 0".into(),
            Rule::Range(lo, hi) => format!("in [{lo}, {hi}]"),
            Rule::Magnitude(lo, hi) => format!("in [-{hi}, -{lo}] or [{lo}, {hi}]"),
        }
    }

    /// How the kernels use a value under this rule, which decides the
    /// magnitude limits it keeps: sizes (`NonNegative`, `Positive`) are
    /// squared and divided by, so they are 0 or at least the precision's
    /// smallest size; coordinates (`Finite`, `Range`) are only added and
    /// multiplied; angles and baked directions are reduced or normalised
    /// in `f64` first, and keep none.
    #[must_use]
    pub fn magnitude(self, baked: bool) -> Magnitude {
        match self {
            Rule::Finite | Rule::Range(..) | Rule::Magnitude(..) => Magnitude::Coordinate,
            Rule::NonNegative | Rule::Positive => Magnitude::Size,
            Rule::Angle => Magnitude::Free,
            Rule::Direction if baked => Magnitude::Free,
            Rule::Direction => Magnitude::Size,
        }
    }
}

/// A parameter's name within its node and the rule it must satisfy.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct ParamSpec<'a> {
    /// The field name, such as `"radius"`.
    pub name: &'a str,
    /// What the value must satisfy.
    pub rule: Rule,
}

pub(super) const fn spec(name: &str, rule: Rule) -> ParamSpec<'_> {
    ParamSpec { name, rule }
}
