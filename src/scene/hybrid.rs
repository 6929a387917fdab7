//! Hybrid fractals: an iteration written as a sequence of typed steps,
//! each a fold, a scale, a turn, a power or an addition, with a running
//! derivative carried through every one.

use super::param::Param;
use super::rule::{ParamSpec, Rule, spec};
use super::*;

/// The most operations one iteration of a [`Hybrid`] may run (every
/// stage's operations times its repeat count): each is written out in the
/// kernel.
pub const MAX_HYBRID_OPS: usize = 48;

/// One operation of a [`Hybrid`]'s iteration, on the orbit's point `z`
/// and its running derivative `dr` (how much the iteration so far
/// stretches distances).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(
    deny_unknown_fields,
    bound(deserialize = "S: serde::Deserialize<'de> + From<f64>")
)]
#[non_exhaustive]
pub enum HybridOp<S = Param> {
    /// Tom Lowe's box fold: each coordinate beyond `±limit` is reflected
    /// back, `z → clamp(z, −limit, limit) · 2 − z` (`limit > 0`).
    BoxFold {
        /// Where the fold reflects.
        limit: S,
    },
    /// Amazing Surf's fold: the box fold on `x` and `y` only.
    SurfFold {
        /// The limit along `x` (> 0).
        limit_x: S,
        /// The limit along `y` (> 0).
        limit_y: S,
    },
    /// The Mandelbox's sphere fold: a point within `min_radius` is scaled
    /// by `(fixed / min)²`, one between the radii is inverted in the sphere
    /// of `fixed_radius`, one beyond is left alone; `dr` is scaled alike.
    /// A `min_radius` above `fixed_radius` acts as `fixed_radius`.
    SphereFold {
        /// The inner radius (> 0).
        min_radius: S,
        /// The radius of inversion (> 0).
        fixed_radius: S,
    },
    /// `z → (z − center) · factor + center`; `dr` is scaled by
    /// `|factor|`.
    Scale {
        /// The scale, of magnitude in `[0.1, 4]`, either sign.
        factor: S,
        /// The point it scales about (in a scene file, *default* the
        /// origin).
        #[serde(default = "origin")]
        center: [S; 3],
    },
    /// A turn by `angles[0]` radians about `x`, then `angles[1]` about
    /// `y`, then `angles[2]` about `z`.
    Rotate {
        /// The angles, in radians.
        angles: [S; 3],
    },
    /// `z → |z|`, each coordinate.
    AbsFold,
    /// A mirror: a point on the side of the plane `dot(z, n) = offset`
    /// that the unit normal `n` points away from is reflected across it.
    /// A zero normal folds nothing.
    PlaneFold {
        /// The plane's normal (its length does not matter).
        normal: [S; 3],
        /// The plane's offset along the unit normal.
        offset: S,
    },
    /// The mirrors of a kaleidoscopic IFS's fold ([`Kifs`]); the Menger
    /// fold's are the octahedral fold's (`|z|`, then the coordinates sorted,
    /// largest first), its further mirror being part of the KIFS's scaling.
    Fold(KifsFold),
    /// The Mandelbulb's triplex power `z → z^power` in spherical
    /// coordinates; `dr → power · |z|^(power − 1) · dr`.
    Power {
        /// The power, in `[2, 16]`.
        power: S,
    },
    /// The classic power-2 Mandelbulb's step (White and Nylander's, in
    /// Cartesian form): the radius squared and the azimuth and the
    /// *latitude* (the angle from the `xy` plane, where
    /// [`Power`](HybridOp::Power) measures the angle from the `z` axis)
    /// doubled, `z → ((x² − y²)·k, 2xy·k, s·2zρ)` with `ρ = √(x² + y²)`,
    /// `k = 1 − z²/ρ²` and `s = −1` where `negate_z` (the classic sign; in
    /// a scene file, *default* `true`), `+1` otherwise. On the `z` axis the
    /// azimuth is 0. `dr → 2r · dr`, times the azimuth's stretch
    /// `|ρ² − z²| / (r·ρ)` where it is above 1: it has no bound, for the
    /// square sends a small circle about the `z` axis onto a circle of
    /// radius `r²` (the map is not continuous on the axis), and a capped
    /// stretch overestimates there.
    BulbSquare {
        /// Whether the new `z` is negated (the classic sign).
        #[serde(default = "yes")]
        negate_z: bool,
    },
    /// The square of the quaternion `x + y·i + z·j` (its fourth component
    /// 0, which squaring keeps): `z → (x² − y² − z², 2xy, 2xz)`; with
    /// [`AddPoint`](HybridOp::AddPoint), the quaternion Mandelbrot set's
    /// slice through `w = 0`. `dr → 2r · dr`, the square's largest
    /// stretch.
    QuaternionSquare,
    /// `z → z + p`, the point the orbit started from (the Mandelbrot
    /// form); `dr → dr + 1`.
    AddPoint,
    /// `z → z + c` (the Julia form).
    AddConstant {
        /// The constant.
        c: [S; 3],
    },
}

/// A run of operations repeated `repeat` times in each iteration of a
/// [`Hybrid`].
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(
    deny_unknown_fields,
    rename = "Stage",
    bound(deserialize = "S: serde::Deserialize<'de> + From<f64>")
)]
#[non_exhaustive]
pub struct HybridStage<S = Param> {
    /// How many times the stage runs in one iteration (0 skips it; in a
    /// scene file, *default* 1).
    #[serde(default = "once")]
    pub repeat: u32,
    /// The operations, in order.
    pub ops: Vec<HybridOp<S>>,
}

/// A hybrid fractal: each iteration runs its stages in order, each stage
/// its operations `repeat` times, so "power 8 and add the point twice,
/// then a box fold, a sphere fold, a scale by 2 and add the point once" is
/// two stages. The running derivative `dr` is carried through every
/// operation, so the distance estimate follows whatever the steps are.
///
/// The drawn set is the points within the ball of radius
/// [`bailout`](Hybrid::bailout) whose orbit is within it at the end of
/// each of `iterations` iterations, and which no operation takes past
/// [`HYBRID_FOLLOW`](crate::cpu::sdf::HYBRID_FOLLOW) times the bailout
/// (the bailout is checked where an iteration ends, as the established
/// renderers do: within one, a scale may overshoot what the next
/// addition brings back). An orbit is followed until it
/// passes [`HYBRID_FOLLOW`](crate::cpu::sdf::HYBRID_FOLLOW) times the
/// bailout (or its iterations end), and with its radius `r` and running
/// derivative `dr` there the estimate is, with a power step
/// ([`HybridOp::is_power`]), the Mandelbulb's
/// `0.5 · r · ln(r / bailout) / dr`, and without one `(r − bailout) / dr`,
/// the form of the box fractals; it is negative exactly inside the set,
/// and at least the distance to the ball. The running derivative takes
/// each operation's largest stretch (for a power, its stretch along the
/// azimuth too: up to `power` times more near the poles, and for
/// [`BulbSquare`](HybridOp::BulbSquare) with no bound).
///
/// The estimate is not a proven bound; it is multiplied by a factor set
/// from the largest ratio of estimate to distance measured against
/// brute-force membership ([`testing::hybrid_inside`](crate::testing::hybrid_inside)):
/// [`HYBRID_SAFETY`](crate::cpu::sdf::HYBRID_SAFETY) without a power
/// and [`HYBRID_POWER_SAFETY`](crate::cpu::sdf::HYBRID_POWER_SAFETY) with
/// one, each covering the classic hybrids and 400 random ones (see the
/// [guide](crate::guide::fractals#hybrids)). With a power, the estimate
/// is also at most what each power step's
/// [reach](crate::cpu::sdf::HYBRID_POWER_REACH) allows, where an orbit
/// passes close to the origin. A real
/// (not integer) power's map is discontinuous across the half-plane
/// `y = 0, x < 0`, where no estimate from a derivative holds. The trap is
/// the orbit's smallest radius (at most 1).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Hybrid<S = Param> {
    /// The stages of one iteration, in order.
    pub stages: Vec<HybridStage<S>>,
    /// Iterations, 0 (the ball) to [`MAX_ESCAPE_ITERATIONS`].
    pub iterations: u32,
    /// The radius the orbit must stay within, in `[1, 1000]`.
    pub bailout: S,
    /// The factor the estimate is multiplied by, in `[0.01, 4]`; `None` is
    /// the measured one for every hybrid of its kind
    /// ([`HYBRID_SAFETY`](crate::cpu::sdf::HYBRID_SAFETY) or
    /// [`HYBRID_POWER_SAFETY`](crate::cpu::sdf::HYBRID_POWER_SAFETY)). A
    /// hybrid measured on its own (as the guide shows) may take a larger
    /// one: fewer steps, and less of the swelling a low estimate gives
    /// thin parts.
    pub safety: Option<S>,
}

/// The origin, a scale's default centre in a scene file.
fn origin<S: From<f64>>() -> [S; 3] {
    [0.0.into(), 0.0.into(), 0.0.into()]
}

/// A stage's default repeat count in a scene file.
fn once() -> u32 {
    1
}

/// [`HybridOp::BulbSquare`]'s default sign in a scene file.
fn yes() -> bool {
    true
}

impl From<Hybrid> for Node {
    fn from(f: Hybrid) -> Self {
        Kind::Hybrid(f).into()
    }
}

impl Default for Hybrid {
    fn default() -> Self {
        Hybrid::new()
    }
}

impl Hybrid {
    /// A hybrid with no stages, 12 iterations and bailout 16; add stages
    /// with [`stage`](Hybrid::stage).
    #[must_use]
    pub fn new() -> Self {
        Hybrid {
            stages: Vec::new(),
            iterations: 12,
            bailout: 16.0.into(),
            safety: None,
        }
    }

    /// Appends a stage: `ops` run `repeat` times in each iteration.
    #[must_use]
    pub fn stage(mut self, repeat: u32, ops: impl IntoIterator<Item = HybridOp>) -> Self {
        self.stages.push(HybridStage {
            ops: ops.into_iter().collect(),
            repeat,
        });
        self
    }

    /// Sets the iteration count.
    #[must_use]
    pub fn iterations(mut self, iterations: u32) -> Self {
        self.iterations = iterations;
        self
    }

    /// Sets the radius the orbit must stay within.
    #[must_use]
    pub fn bailout(mut self, bailout: impl Into<Param>) -> Self {
        self.bailout = bailout.into();
        self
    }

    /// Sets the factor the estimate is multiplied by (see
    /// [`safety`](Hybrid::safety)).
    #[must_use]
    pub fn safety(mut self, factor: impl Into<Param>) -> Self {
        self.safety = Some(factor.into());
        self
    }

    /// Tom Lowe's Mandelbox as a hybrid: box fold at 1, sphere fold with
    /// radii 0.5 and 1, scale by `scale`, add the point.
    #[must_use]
    pub fn mandelbox(scale: impl Into<Param>) -> Self {
        Hybrid::new().stage(
            1,
            [
                HybridOp::box_fold(1.0),
                HybridOp::sphere_fold(0.5, 1.0),
                HybridOp::scale(scale),
                HybridOp::AddPoint,
            ],
        )
    }

    /// The classic power-2 Mandelbulb: [`HybridOp::bulb_square`], then add
    /// the point.
    #[must_use]
    pub fn power2_mandelbulb() -> Self {
        Hybrid::new().stage(1, [HybridOp::bulb_square(), HybridOp::AddPoint])
    }

    /// The quaternion Mandelbrot set's slice through `w = 0`:
    /// [`HybridOp::QuaternionSquare`], then add the point.
    #[must_use]
    pub fn quaternion_mandelbrot() -> Self {
        Hybrid::new().stage(1, [HybridOp::QuaternionSquare, HybridOp::AddPoint])
    }

    /// Amazing Surf (Kali): the box fold on `x` and `y` at 1, a sphere
    /// fold with radii 0.5 and 1, scale by `scale`, add the point, then a
    /// turn by `angles`.
    #[must_use]
    pub fn amazing_surf(scale: impl Into<Param>, angles: [impl Into<Param>; 3]) -> Self {
        Hybrid::new().stage(
            1,
            [
                HybridOp::surf_fold(1.0, 1.0),
                HybridOp::sphere_fold(0.5, 1.0),
                HybridOp::scale(scale),
                HybridOp::AddPoint,
                HybridOp::rotate(angles),
            ],
        )
    }
}

impl HybridOp {
    /// [`HybridOp::BulbSquare`] with the classic sign (`negate_z`).
    #[must_use]
    pub fn bulb_square() -> Self {
        HybridOp::BulbSquare { negate_z: true }
    }

    /// [`HybridOp::BoxFold`].
    #[must_use]
    pub fn box_fold(limit: impl Into<Param>) -> Self {
        HybridOp::BoxFold {
            limit: limit.into(),
        }
    }

    /// [`HybridOp::SurfFold`].
    #[must_use]
    pub fn surf_fold(limit_x: impl Into<Param>, limit_y: impl Into<Param>) -> Self {
        HybridOp::SurfFold {
            limit_x: limit_x.into(),
            limit_y: limit_y.into(),
        }
    }

    /// [`HybridOp::SphereFold`].
    #[must_use]
    pub fn sphere_fold(min_radius: impl Into<Param>, fixed_radius: impl Into<Param>) -> Self {
        HybridOp::SphereFold {
            min_radius: min_radius.into(),
            fixed_radius: fixed_radius.into(),
        }
    }

    /// [`HybridOp::Scale`] about the origin.
    #[must_use]
    pub fn scale(factor: impl Into<Param>) -> Self {
        HybridOp::scale_about(factor, [0.0, 0.0, 0.0])
    }

    /// [`HybridOp::Scale`] about `center`.
    #[must_use]
    pub fn scale_about(factor: impl Into<Param>, center: [impl Into<Param>; 3]) -> Self {
        HybridOp::Scale {
            factor: factor.into(),
            center: center.map(Into::into),
        }
    }

    /// [`HybridOp::Rotate`].
    #[must_use]
    pub fn rotate(angles: [impl Into<Param>; 3]) -> Self {
        HybridOp::Rotate {
            angles: angles.map(Into::into),
        }
    }

    /// [`HybridOp::PlaneFold`].
    #[must_use]
    pub fn plane_fold(normal: [impl Into<Param>; 3], offset: impl Into<Param>) -> Self {
        HybridOp::PlaneFold {
            normal: normal.map(Into::into),
            offset: offset.into(),
        }
    }

    /// [`HybridOp::Power`].
    #[must_use]
    pub fn power(power: impl Into<Param>) -> Self {
        HybridOp::Power {
            power: power.into(),
        }
    }

    /// [`HybridOp::AddConstant`].
    #[must_use]
    pub fn add_constant(c: [impl Into<Param>; 3]) -> Self {
        HybridOp::AddConstant {
            c: c.map(Into::into),
        }
    }
}

impl<S> HybridOp<S> {
    /// Whether the operation raises the point to a power (the orbit then
    /// grows geometrically, and the estimate takes the logarithmic form).
    #[must_use]
    pub fn is_power(&self) -> bool {
        matches!(
            self,
            HybridOp::Power { .. } | HybridOp::BulbSquare { .. } | HybridOp::QuaternionSquare
        )
    }

    /// The operation's name in a scene file (`BoxFold`).
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            HybridOp::BoxFold { .. } => "BoxFold",
            HybridOp::SurfFold { .. } => "SurfFold",
            HybridOp::SphereFold { .. } => "SphereFold",
            HybridOp::Scale { .. } => "Scale",
            HybridOp::Rotate { .. } => "Rotate",
            HybridOp::AbsFold => "AbsFold",
            HybridOp::PlaneFold { .. } => "PlaneFold",
            HybridOp::Fold(_) => "Fold",
            HybridOp::Power { .. } => "Power",
            HybridOp::BulbSquare { .. } => "BulbSquare",
            HybridOp::QuaternionSquare => "QuaternionSquare",
            HybridOp::AddPoint => "AddPoint",
            HybridOp::AddConstant { .. } => "AddConstant",
        }
    }
}

impl<S> Hybrid<S> {
    /// The operations one iteration runs: every stage's, times its
    /// repeat count.
    #[must_use]
    pub fn ops_per_iteration(&self) -> usize {
        self.stages
            .iter()
            .map(|s| s.ops.len() * s.repeat as usize)
            .sum()
    }

    /// Whether an iteration raises the point to a power ([`Power`](HybridOp::Power),
    /// [`BulbSquare`](HybridOp::BulbSquare) or
    /// [`QuaternionSquare`](HybridOp::QuaternionSquare)): the estimate is
    /// then the Mandelbulb's logarithmic form.
    #[must_use]
    pub fn has_power(&self) -> bool {
        self.stages
            .iter()
            .any(|s| s.repeat > 0 && s.ops.iter().any(HybridOp::is_power))
    }

    /// The operations of one iteration in the order they run, each with
    /// its stage's index and its own.
    pub fn unrolled(&self) -> impl Iterator<Item = (usize, usize, &HybridOp<S>)> {
        self.stages.iter().enumerate().flat_map(|(i, s)| {
            (0..s.repeat).flat_map(move |_| s.ops.iter().enumerate().map(move |(j, o)| (i, j, o)))
        })
    }

    /// Rebuilds the hybrid with every parameter converted by `f`, which
    /// sees each one's name (`stages[0].ops[1].limit`) and rule. This is
    /// the one place that lists the operations' parameters.
    pub(crate) fn try_map<S2, E>(
        &self,
        f: &mut impl FnMut(&S, ParamSpec<'_>) -> Result<S2, E>,
    ) -> Result<Hybrid<S2>, E> {
        use Rule::{Angle, Direction, Finite, Magnitude, Positive, Range};
        let mut stages = Vec::with_capacity(self.stages.len());
        for (i, stage) in self.stages.iter().enumerate() {
            let mut ops = Vec::with_capacity(stage.ops.len());
            for (j, op) in stage.ops.iter().enumerate() {
                let at = |field: &str| format!("stages[{i}].ops[{j}].{field}");
                ops.push(match op {
                    HybridOp::BoxFold { limit } => HybridOp::BoxFold {
                        limit: f(limit, spec(&at("limit"), Positive))?,
                    },
                    HybridOp::SurfFold { limit_x, limit_y } => HybridOp::SurfFold {
                        limit_x: f(limit_x, spec(&at("limit_x"), Positive))?,
                        limit_y: f(limit_y, spec(&at("limit_y"), Positive))?,
                    },
                    HybridOp::SphereFold {
                        min_radius,
                        fixed_radius,
                    } => HybridOp::SphereFold {
                        min_radius: f(min_radius, spec(&at("min_radius"), Positive))?,
                        fixed_radius: f(fixed_radius, spec(&at("fixed_radius"), Positive))?,
                    },
                    HybridOp::Scale { factor, center } => {
                        let factor = f(factor, spec(&at("factor"), Magnitude(0.1, 4.0)))?;
                        HybridOp::Scale {
                            factor,
                            center: three(f, center, &at("center"), Finite)?,
                        }
                    }
                    HybridOp::Rotate { angles } => HybridOp::Rotate {
                        angles: three(f, angles, &at("angles"), Angle)?,
                    },
                    HybridOp::AbsFold => HybridOp::AbsFold,
                    HybridOp::PlaneFold { normal, offset } => {
                        let normal = three(f, normal, &at("normal"), Direction)?;
                        HybridOp::PlaneFold {
                            normal,
                            offset: f(offset, spec(&at("offset"), Finite))?,
                        }
                    }
                    HybridOp::Fold(fold) => HybridOp::Fold(*fold),
                    HybridOp::Power { power } => HybridOp::Power {
                        power: f(power, spec(&at("power"), Range(2.0, 16.0)))?,
                    },
                    HybridOp::BulbSquare { negate_z } => HybridOp::BulbSquare {
                        negate_z: *negate_z,
                    },
                    HybridOp::QuaternionSquare => HybridOp::QuaternionSquare,
                    HybridOp::AddPoint => HybridOp::AddPoint,
                    HybridOp::AddConstant { c } => HybridOp::AddConstant {
                        c: three(f, c, &at("c"), Finite)?,
                    },
                });
            }
            stages.push(HybridStage {
                ops,
                repeat: stage.repeat,
            });
        }
        Ok(Hybrid {
            stages,
            iterations: self.iterations,
            bailout: f(&self.bailout, spec("bailout", Range(1.0, 1000.0)))?,
            safety: match &self.safety {
                Some(k) => Some(f(k, spec("safety", Range(0.01, 4.0)))?),
                None => None,
            },
        })
    }

    /// The hybrid with every parameter converted by `f`.
    pub(crate) fn map<S2>(&self, mut f: impl FnMut(&S) -> S2) -> Hybrid<S2> {
        let mapped: Result<_, std::convert::Infallible> = self.try_map(&mut |s, _| Ok(f(s)));
        match mapped {
            Ok(h) => h,
        }
    }
}

/// The three components of a vector parameter, named `name.x` to `name.z`.
fn three<S, S2, E>(
    f: &mut impl FnMut(&S, ParamSpec<'_>) -> Result<S2, E>,
    v: &[S; 3],
    name: &str,
    rule: Rule,
) -> Result<[S2; 3], E> {
    let [x, y, z] = v;
    Ok([
        f(x, spec(&format!("{name}.x"), rule))?,
        f(y, spec(&format!("{name}.y"), rule))?,
        f(z, spec(&format!("{name}.z"), rule))?,
    ])
}
