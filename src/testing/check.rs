//! Invariant checkers: Lipschitz bound, never overestimating, exactness.

use std::fmt;
use std::path::PathBuf;

use glam::DVec3;

use crate::cpu::Evaluator;
use crate::scene::Node;

/// Relative slack of the Lipschitz check:
/// `|d(p) - d(q)| <= bound * |p - q| * (1 + LIPSCHITZ_TOLERANCE)`.
pub const LIPSCHITZ_TOLERANCE: f64 = 1e-9;

/// Absolute slack for rounding, per unit of magnitude: the checks allow an
/// extra `ROUNDING_ALLOWANCE * (1 + |p| + |q| + |d(p)| + |d(q)|)` (with
/// `|p|` the largest coordinate), a few ulps of the numbers involved.
pub const ROUNDING_ALLOWANCE: f64 = 16.0 * f64::EPSILON;

/// Where [`check_never_overestimates`] samples the boundary of each ball:
/// at `SHELL_FACTOR` times its radius, so an exact distance, whose ball
/// touches the surface, is not reported. Overestimates by a relative
/// `1 - SHELL_FACTOR` or less go unnoticed.
pub const SHELL_FACTOR: f64 = 1.0 - 1e-6;

/// The least share of a [`check_never_overestimates`] run's points that
/// must have a positive distance, so that balls (the property itself) and
/// not only signs were tested: a point set that is almost all inside the
/// set says little about overestimating. Sample near the surface with
/// [`near_surface_points`](super::near_surface_points) to meet it.
pub const MIN_BALL_FRACTION: f64 = 0.125;

/// What a checker examined. Every checker returns it on success, and fails
/// with [`Check::TooFewTested`] when the count is below its minimum (at
/// least one input; for [`check_never_overestimates`], balls around at
/// least [`MIN_BALL_FRACTION`] of the points).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct Tested {
    /// Inputs examined: points, or pairs for [`check_lipschitz`].
    pub inputs: usize,
    /// For [`check_never_overestimates`]: balls tested, one around every
    /// point with a positive distance. Equal to `inputs` elsewhere.
    pub balls: usize,
    /// For [`check_never_overestimates`]: points with `d(p) <= 0` whose
    /// membership was checked. Zero elsewhere.
    pub signs: usize,
    /// How close the check came to failing: the largest measured value
    /// over its allowance, in `[0, 1]` on success. For [`check_lipschitz`]
    /// the steepest pair's change over its allowed change, for
    /// [`check_exact`] and `check_device_matches_cpu` the largest error
    /// over the tolerance; 0 for [`check_never_overestimates`], whose
    /// balls pass or fail. A tolerance can be set from it: a stated margin
    /// over the worst value measured.
    pub worst: f64,
}

/// Which invariant a [`Failure`] breaks. Non-exhaustive: more checks
/// (such as agreement between a device and the CPU reference) can join.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Check {
    /// The node does not validate.
    Valid,
    /// A distance is NaN or infinite.
    Finite,
    /// `|d(p) - d(q)| <= bound * |p - q|`.
    Lipschitz,
    /// No point closer than `d(p)` to `p` is inside the set.
    NeverOverestimates,
    /// A point where `d(p) < 0` (the field says "inside") is outside the
    /// set.
    Sign,
    /// Too few inputs were tested for the check to mean anything: `measured`
    /// is how many were, `allowed` the minimum.
    TooFewTested,
    /// `d(p)` equals the analytic distance.
    Exact,
    /// The OpenCL twin agrees with the CPU reference (distance and colour).
    DeviceMatchesCpu,
    /// The generated OpenCL program builds.
    Build,
    /// The device can run the check (there is an OpenCL platform and
    /// device, with double precision if asked, and the kernel runs).
    Device,
    /// An inside shape's OpenCL test agrees with its CPU test.
    InsideMatchesDevice,
    /// A distance estimate and a membership test describe the same set:
    /// the estimate's sign is the membership wherever it is farther than a
    /// margin from 0.
    InsideAgreesWithDe,
}

/// A broken invariant: the worst violation a checker found, and how many
/// inputs broke it.
///
/// What `points`, `values`, `measured` and `allowed` hold depends on the
/// check:
///
/// | `check` | `points` | `values` | `measured` | `allowed` |
/// |---|---|---|---|---|
/// | `Valid` | none | none | 0 | 0 |
/// | `Finite` | `[p]` | `[value]` | the value | 0 |
/// | `Lipschitz` | `[p, q]` | `[d(p), d(q)]` | `\|d(p) - d(q)\| / \|p - q\|` | the bound |
/// | `NeverOverestimates` | `[p, q]`, `q` inside | `[d(p)]` | `d(p)` | `\|p - q\|` |
/// | `Sign` | `[p]`, outside | `[d(p)]` | `-d(p)` | the rounding allowance |
/// | `TooFewTested` | none | none | inputs tested | the minimum |
/// | `Exact` | `[p]` | `[d(p), analytic(p)]` | `\|d(p) - analytic(p)\|` | the tolerance at `p` |
/// | `DeviceMatchesCpu` | `[p]` | `[device, cpu]` | the relative error | the tolerance |
/// | `Build`, `Device` | none | none | 0 | 0 |
/// | `InsideMatchesDevice` | `[p]`, the first disagreement | `[device, cpu]` (1 inside, 0 outside) | the fraction of points that disagree | the fraction allowed |
/// | `InsideAgreesWithDe` | `[p]` | `[d(p)]` | `\|d(p)\|` where its sign is wrong | the margin |
///
/// A check that ran generated OpenCL code keeps the program in `program`
/// (and saves it to a file it names), so a failure can be read against the
/// code that produced it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Failure {
    /// Which invariant broke.
    pub check: Check,
    /// Where it broke.
    pub points: Vec<DVec3>,
    /// Distances (and for `Exact` the analytic value) at the points.
    pub values: Vec<f64>,
    /// The measured quantity that exceeded `allowed`.
    pub measured: f64,
    /// The largest value the invariant allows.
    pub allowed: f64,
    /// How many inputs (pairs, balls, points) broke the invariant.
    pub violations: usize,
    /// How many inputs were checked.
    pub checked: usize,
    /// For `Valid`, the validation error; for `Build` and `Device`, the
    /// error (for a custom shape's body, the line of the body and the
    /// compiler's message); for `Finite` and `DeviceMatchesCpu`, which
    /// value.
    pub detail: String,
    /// The generated OpenCL program, for checks that ran one (or tried to
    /// build it).
    pub program: Option<Box<GeneratedProgram>>,
}

/// The generated OpenCL program a device check ran, or failed to build.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct GeneratedProgram {
    /// The complete source.
    pub source: String,
    /// Where the failing check saved it: a file in the temporary directory
    /// named after the program's hash, or `None` if it could not be
    /// written.
    pub path: Option<PathBuf>,
}

impl Failure {
    /// How many times the allowed value was exceeded: `measured / allowed`
    /// (infinite when nothing was allowed, as for a point with a positive
    /// distance that is itself inside).
    #[must_use]
    pub fn factor(&self) -> f64 {
        if self.allowed == 0.0 {
            f64::INFINITY
        } else {
            self.measured / self.allowed
        }
    }

    pub(crate) fn new(
        check: Check,
        points: Vec<DVec3>,
        values: Vec<f64>,
        measured: f64,
        allowed: f64,
    ) -> Self {
        Failure {
            check,
            points,
            values,
            measured,
            allowed,
            violations: 1,
            checked: 1,
            detail: String::new(),
            program: None,
        }
    }

    fn not_finite(what: &str, p: DVec3, value: f64, checked: usize) -> Self {
        Failure {
            detail: what.into(),
            checked,
            ..Failure::new(Check::Finite, vec![p], vec![value], value, 0.0)
        }
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.describe(f)?;
        match self.program.as_deref() {
            Some(GeneratedProgram {
                path: Some(path), ..
            }) => write!(f, "\ngenerated program: {}", path.display()),
            Some(_) => write!(f, "\ngenerated program: kept in `Failure::program`"),
            None => Ok(()),
        }
    }
}

impl Failure {
    fn describe(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (p, v) = (&self.points, &self.values);
        let tally = |noun: &str| format!("{} of {} {noun} fail", self.violations, self.checked);
        match self.check {
            Check::Valid => write!(f, "the node does not validate: {}", self.detail),
            Check::Build => write!(
                f,
                "the generated OpenCL program does not build: {}",
                self.detail
            ),
            Check::Device => write!(f, "the device cannot run the check: {}", self.detail),
            Check::Finite => write!(
                f,
                "{} is not finite at p = {}: {}",
                self.detail, p[0], self.measured
            ),
            Check::Lipschitz => write!(
                f,
                "not {}-Lipschitz: |d(p) - d(q)| / |p - q| = {} at p = {}, q = {} \
                 (|p - q| = {}, d(p) = {}, d(q) = {}); {}",
                self.allowed,
                self.measured,
                p[0],
                p[1],
                p[0].distance(p[1]),
                v[0],
                v[1],
                tally("pairs")
            ),
            Check::Sign => write!(
                f,
                "wrong sign: d(p) = {} < 0 says p = {} is inside, but it is outside the set; {}",
                v[0],
                p[0],
                tally("points with d <= 0")
            ),
            Check::TooFewTested => write!(
                f,
                "too few inputs tested: {} {} of {}, below the minimum of {}",
                self.measured, self.detail, self.checked, self.allowed
            ),
            Check::NeverOverestimates if self.allowed == 0.0 => write!(
                f,
                "overestimates: d(p) = {} > 0 at p = {}, which is itself inside the set; {}",
                self.measured,
                p[0],
                tally("balls")
            ),
            Check::NeverOverestimates => write!(
                f,
                "overestimates: d(p) = {} at p = {}, but q = {} at distance {} is inside the \
                 set (the estimate is at least {} times the true distance); {}",
                self.measured,
                p[0],
                p[1],
                self.allowed,
                self.factor(),
                tally("balls")
            ),
            Check::DeviceMatchesCpu => write!(
                f,
                "the device disagrees with the CPU reference: {} = {} on the device but {} on \
                 the CPU at p = {} (relative error {:e} > allowed {:e}); {}",
                self.detail,
                v[0],
                v[1],
                p[0],
                self.measured,
                self.allowed,
                tally("points")
            ),
            Check::Exact => write!(
                f,
                "not exact: d(p) = {} but the analytic distance is {} at p = {} \
                 (error {:e} > allowed {:e}); {}",
                v[0],
                v[1],
                p[0],
                self.measured,
                self.allowed,
                tally("points")
            ),
            Check::InsideMatchesDevice => write!(
                f,
                "the device's membership test disagrees with the CPU's on a fraction {} of the \
                 points (allowed {}): first at p = {}, {} on the device but {} on the CPU; {}",
                self.measured,
                self.allowed,
                p[0],
                if v[0] > 0.5 { "inside" } else { "outside" },
                if v[1] > 0.5 { "inside" } else { "outside" },
                tally("points")
            ),
            Check::InsideAgreesWithDe => write!(
                f,
                "the distance estimate and the membership test disagree: d(p) = {} at p = {}, \
                 but p is {} the set (only |d| <= {} may disagree); {}",
                v[0],
                p[0],
                if v[0] > 0.0 { "inside" } else { "outside" },
                self.allowed,
                tally("points beyond the margin")
            ),
        }
    }
}

impl std::error::Error for Failure {}

/// Something with a distance at every point: a [`Node`] (validated and
/// lowered once per check), a [`cpu::Evaluator`](Evaluator) (with its
/// current dynamic parameter values) or any closure `Fn(DVec3) -> f64`.
pub trait DistanceField {
    /// The distance function.
    ///
    /// # Errors
    /// A [`Check::Valid`] failure if there is no distance function, as for a
    /// node that does not validate.
    fn distance_fn(&self) -> Result<Box<dyn Fn(DVec3) -> f64 + '_>, Failure>;
}

impl DistanceField for Node {
    fn distance_fn(&self) -> Result<Box<dyn Fn(DVec3) -> f64 + '_>, Failure> {
        let eval = Evaluator::new(self).map_err(|e| Failure {
            detail: e.to_string(),
            violations: 1,
            checked: 1,
            ..Failure::new(Check::Valid, vec![], vec![], 0.0, 0.0)
        })?;
        Ok(Box::new(move |p| eval.distance(p)))
    }
}

impl DistanceField for Evaluator {
    fn distance_fn(&self) -> Result<Box<dyn Fn(DVec3) -> f64 + '_>, Failure> {
        Ok(Box::new(|p| self.distance(p)))
    }
}

impl<F: Fn(DVec3) -> f64> DistanceField for F {
    fn distance_fn(&self) -> Result<Box<dyn Fn(DVec3) -> f64 + '_>, Failure> {
        Ok(Box::new(self))
    }
}

/// Checks that the distance estimate `de` and the membership test `inside`
/// describe the same set: at every point where `|d(p)| > margin`, `d(p) <
/// 0` exactly where `inside(p)`. Near the surface the two legitimately
/// differ (an estimate's zero level and an escape-time set at a finite
/// iteration count are not the same surface), so `margin` is the width of
/// the band that is not compared: a few pixel footprints of the view the
/// two are drawn at.
///
/// Returns how many points lay beyond the margin (`inputs`) and, as
/// `worst`, the largest `|d|` among points in the band whose sign
/// disagrees, over the margin (so at most 1).
///
/// # Errors
/// The point beyond the margin with the largest `|d|` whose sign is wrong;
/// the first non-finite distance; [`Check::TooFewTested`] when no point
/// lies beyond the margin.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::testing::check_inside_agrees_with_de;
/// let points = [dvec3(0.2, 0.0, 0.0), dvec3(1.5, 0.3, 0.0), dvec3(0.99, 0.0, 0.0)];
/// let ball = |p: DVec3| p.length() < 1.0;
/// check_inside_agrees_with_de(&sphere(1.0), ball, &points, 0.05)?;
/// // A sphere of radius 1.2 says (1.1, 0, 0) is inside.
/// let far = [dvec3(1.1, 0.0, 0.0)];
/// assert!(check_inside_agrees_with_de(&sphere(1.2), ball, &far, 0.05).is_err());
/// # Ok::<(), fractal_sdf::testing::Failure>(())
/// ```
pub fn check_inside_agrees_with_de<F: DistanceField + ?Sized>(
    de: &F,
    inside: impl Fn(DVec3) -> bool,
    points: &[DVec3],
    margin: f64,
) -> Result<Tested, Failure> {
    let d = de.distance_fn()?;
    let mut tally = Tally::new();
    let mut band = 0.0f64;
    for &p in points {
        let v = d(p);
        if !v.is_finite() {
            tally.fail(Failure::new(Check::Finite, vec![p], vec![v], v, 0.0));
            continue;
        }
        let agrees = (v < 0.0) == inside(p);
        if v.abs() <= margin {
            if !agrees {
                band = band.max(v.abs() / margin.max(f64::MIN_POSITIVE));
            }
            continue;
        }
        if agrees {
            tally.pass(0.0);
        } else {
            tally.fail(Failure::new(
                Check::InsideAgreesWithDe,
                vec![p],
                vec![v],
                v.abs(),
                margin,
            ));
        }
    }
    let tested = tally.finish()?;
    Ok(Tested {
        worst: band,
        ..tested
    })
}

/// Keeps the worst of a run of violations and counts them.
pub(crate) struct Tally {
    checked: usize,
    worst: Option<Failure>,
    violations: usize,
    closest: f64,
}

impl Tally {
    pub(crate) fn new() -> Self {
        Tally {
            checked: 0,
            worst: None,
            violations: 0,
            closest: 0.0,
        }
    }

    /// Ends a check whose every input was tested the one way: the worst
    /// violation, or too few inputs (none), or what was tested.
    pub(crate) fn finish(self) -> Result<Tested, Failure> {
        let (inputs, worst) = (self.checked, self.closest);
        self.outcome()?;
        at_least(inputs, 1, "inputs", inputs)?;
        Ok(Tested {
            inputs,
            balls: inputs,
            signs: 0,
            worst,
        })
    }

    /// A passing input that used `share` of its allowance.
    pub(crate) fn pass(&mut self, share: f64) {
        self.checked += 1;
        if share > self.closest {
            self.closest = share;
        }
    }

    pub(crate) fn fail(&mut self, failure: Failure) {
        self.checked += 1;
        self.violations += 1;
        if self
            .worst
            .as_ref()
            .is_none_or(|w| failure.factor() > w.factor())
        {
            self.worst = Some(failure);
        }
    }

    fn outcome(self) -> Result<(), Failure> {
        match self.worst {
            None => Ok(()),
            Some(worst) => Err(Failure {
                violations: self.violations,
                checked: self.checked,
                ..worst
            }),
        }
    }
}

/// Fails with [`Check::TooFewTested`] when `tested` is below `minimum`.
fn at_least(tested: usize, minimum: usize, what: &str, of: usize) -> Result<(), Failure> {
    if tested >= minimum {
        return Ok(());
    }
    #[allow(clippy::cast_precision_loss)]
    Err(Failure {
        detail: what.into(),
        violations: 1,
        checked: of,
        ..Failure::new(
            Check::TooFewTested,
            vec![],
            vec![],
            tested as f64,
            minimum as f64,
        )
    })
}

fn rounding(p: DVec3, q: DVec3, a: f64, b: f64) -> f64 {
    ROUNDING_ALLOWANCE * (1.0 + p.abs().max_element() + q.abs().max_element() + a.abs() + b.abs())
}

/// Checks that the field changes no faster than `bound` per unit of
/// distance between the two points of every pair:
/// `|d(p) - d(q)| <= bound * |p - q| * (1 + LIPSCHITZ_TOLERANCE)` plus a
/// rounding allowance ([`ROUNDING_ALLOWANCE`]). A 1-Lipschitz field never
/// overestimates the distance to its zero set.
///
/// Generate pairs with [`point_pair`](super::point_pair): violations are
/// local, so close pairs find them.
///
/// # Errors
/// The pair with the largest ratio `|d(p) - d(q)| / |p - q|`, or the first
/// non-finite distance.
///
/// # Panics
/// If `bound` is not positive and finite.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::testing::check_lipschitz;
/// let pairs = [(dvec3(2.0, 0.0, 0.0), dvec3(2.0, 0.1, 0.0))];
/// assert!(check_lipschitz(&sphere(1.0), 1.0, &pairs).is_ok());
/// // Doubling a distance breaks the bound of 1.
/// let err = check_lipschitz(&|p: DVec3| 2.0 * p.length(), 1.0, &[(DVec3::ZERO, DVec3::X)])
///     .unwrap_err();
/// assert_eq!(err.measured, 2.0);
/// ```
pub fn check_lipschitz<F: DistanceField + ?Sized>(
    field: &F,
    bound: f64,
    pairs: &[(DVec3, DVec3)],
) -> Result<Tested, Failure> {
    assert!(
        bound > 0.0 && bound.is_finite(),
        "the Lipschitz bound must be finite and > 0"
    );
    let d = field.distance_fn()?;
    let mut tally = Tally::new();
    for (i, &(p, q)) in pairs.iter().enumerate() {
        let (dp, dq) = (d(p), d(q));
        for (x, v) in [(p, dp), (q, dq)] {
            if !v.is_finite() {
                return Err(Failure::not_finite("the distance", x, v, i + 1));
            }
        }
        let separation = p.distance(q);
        let change = (dp - dq).abs();
        let allowed = bound * separation * (1.0 + LIPSCHITZ_TOLERANCE) + rounding(p, q, dp, dq);
        if change > allowed {
            tally.fail(Failure::new(
                Check::Lipschitz,
                vec![p, q],
                vec![dp, dq],
                change / separation,
                bound,
            ));
        } else {
            tally.pass(change / allowed);
        }
    }
    tally.finish()
}

/// A small deterministic generator (SplitMix64), so a check's samples
/// depend only on its inputs.
struct SplitMix(u64);

impl SplitMix {
    fn seeded(p: DVec3) -> Self {
        SplitMix(p.x.to_bits() ^ p.y.to_bits().rotate_left(21) ^ p.z.to_bits().rotate_left(42))
    }

    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    #[allow(clippy::cast_precision_loss)]
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform on the unit sphere.
    fn direction(&mut self) -> DVec3 {
        let z = 2.0 * self.unit() - 1.0;
        let phi = std::f64::consts::TAU * self.unit();
        let rho = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(rho * phi.cos(), rho * phi.sin(), z)
    }
}

/// Checks that the field never overestimates the distance to the set that
/// `inside` describes. For every point `p` with `d(p) > 0`, the open ball
/// of radius `d(p)` around `p` must hold no point of the set: the check
/// tests `p` itself, `samples` points evenly spaced along the direction in
/// which `d` decreases fastest (a central-difference gradient; where an
/// overestimating step would land), `samples` points on the ball's
/// boundary (at [`SHELL_FACTOR`] times the radius) and `samples` points
/// spread uniformly through its interior, in directions drawn by a
/// generator seeded from `p`. A point with `d(p) <= 0` (the field says
/// "inside or on the surface") must itself be inside the set, give or take
/// rounding: otherwise the field has the wrong sign there ([`Check::Sign`]).
/// A positive distance within rounding of 0 ([`ROUNDING_ALLOWANCE`]) is on
/// the surface too: its ball is too small to test.
///
/// `inside` should be an independent description of the set, such as the
/// membership tests in this module or a simpler field's sign. The property
/// is at risk near the surface, where balls are small and the set's detail
/// is fine: [`near_surface_points`](super::near_surface_points) draws
/// points there from `inside` alone.
///
/// Returns how many balls and signs were tested.
///
/// # Errors
/// The ball whose inside point gives the largest overestimate factor
/// `d(p) / |p - q|` (`q` the inside point nearest to `p`), else the worst
/// wrong sign, or the first non-finite distance; or
/// [`Check::TooFewTested`] when fewer than [`MIN_BALL_FRACTION`] of the
/// points (and at least one) had a positive distance.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::testing::{check_never_overestimates, menger_inside};
/// let sponge = menger(3);
/// let points = [dvec3(1.5, 0.2, 0.1), dvec3(0.0, 0.0, 0.0), dvec3(0.9, 0.9, 1.4)];
/// check_never_overestimates(&sponge, |p| menger_inside(p, 3), &points, 64)?;
/// // Twice the sphere's distance overestimates.
/// let err = check_never_overestimates(
///     &|p: DVec3| 2.0 * (p.length() - 1.0),
///     |p| p.length() <= 1.0,
///     &[dvec3(3.0, 0.0, 0.0)],
///     64,
/// )
/// .unwrap_err();
/// assert!(err.factor() > 1.9);
/// # Ok::<(), fractal_sdf::testing::Failure>(())
/// ```
pub fn check_never_overestimates<F: DistanceField + ?Sized>(
    field: &F,
    inside: impl Fn(DVec3) -> bool,
    points: &[DVec3],
    samples: usize,
) -> Result<Tested, Failure> {
    let d = field.distance_fn()?;
    let mut tally = Tally::new();
    let mut signs = Tally::new();
    for (i, &p) in points.iter().enumerate() {
        let dp = d(p);
        if !dp.is_finite() {
            return Err(Failure::not_finite("the distance", p, dp, i + 1));
        }
        if dp <= 0.0 {
            let allowed = rounding(p, p, dp, 0.0);
            if -dp > allowed && !inside(p) {
                signs.fail(Failure::new(Check::Sign, vec![p], vec![dp], -dp, allowed));
            } else {
                signs.pass(0.0);
            }
            continue;
        }
        if dp <= rounding(p, p, dp, 0.0) {
            // Within rounding of the surface: a ball that small holds
            // nothing a distance could be wrong about.
            tally.pass(0.0);
            continue;
        }
        let descent = -gradient(&d, p, dp).unwrap_or(DVec3::ZERO);
        #[allow(clippy::cast_precision_loss)]
        let along =
            (1..=samples).map(|i| p + descent * (dp * SHELL_FACTOR * i as f64 / samples as f64));
        let mut rng = SplitMix::seeded(p);
        let interior = |rng: &mut SplitMix| dp * rng.unit().cbrt();
        let random = (0..samples).flat_map(|_| {
            let shell = p + rng.direction() * (dp * SHELL_FACTOR);
            let inner = p + rng.direction() * interior(&mut rng);
            [shell, inner]
        });
        let candidates = std::iter::once(p).chain(along).chain(random);
        let nearest_inside = candidates
            .filter(|&q| inside(q))
            .min_by(|a, b| a.distance(p).total_cmp(&b.distance(p)));
        match nearest_inside {
            Some(q) => tally.fail(Failure::new(
                Check::NeverOverestimates,
                vec![p, q],
                vec![dp],
                dp,
                p.distance(q),
            )),
            None => tally.pass(0.0),
        }
    }
    let tested = Tested {
        inputs: points.len(),
        balls: tally.checked,
        signs: signs.checked,
        worst: 0.0,
    };
    tally.outcome()?;
    signs.outcome()?;
    #[allow(
        clippy::cast_possible_truncation,
        clippy::cast_sign_loss,
        clippy::cast_precision_loss
    )]
    let minimum = ((points.len() as f64 * MIN_BALL_FRACTION).ceil() as usize).max(1);
    at_least(
        tested.balls,
        minimum,
        "points with a positive distance (balls)",
        points.len(),
    )?;
    Ok(tested)
}

/// The unit gradient of `d` at `p` by central differences, with a step
/// small next to `d(p)`; `None` where it vanishes or is not finite.
fn gradient(d: &dyn Fn(DVec3) -> f64, p: DVec3, dp: f64) -> Option<DVec3> {
    let h = 1e-6 * dp.abs().max(1e-6);
    let g = DVec3::new(
        d(p + DVec3::X * h) - d(p - DVec3::X * h),
        d(p + DVec3::Y * h) - d(p - DVec3::Y * h),
        d(p + DVec3::Z * h) - d(p - DVec3::Z * h),
    );
    g.try_normalize()
}

/// Checks that the field equals `analytic` at every point, within
/// `tolerance` times `max(1, |analytic(p)|)` (absolute for distances up to
/// 1, relative beyond).
///
/// # Errors
/// The point with the largest error relative to its tolerance, or the
/// first non-finite distance or analytic value.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::testing::check_exact;
/// let points = [dvec3(0.3, -2.0, 0.5), DVec3::ZERO, dvec3(0.0, 0.0, 1.0)];
/// check_exact(&sphere(1.0).translate(dvec3(0.0, 0.0, 1.0)), |p| {
///     (p - dvec3(0.0, 0.0, 1.0)).length() - 1.0
/// }, &points, 1e-12)?;
/// # Ok::<(), fractal_sdf::testing::Failure>(())
/// ```
pub fn check_exact<F: DistanceField + ?Sized>(
    field: &F,
    analytic: impl Fn(DVec3) -> f64,
    points: &[DVec3],
    tolerance: f64,
) -> Result<Tested, Failure> {
    let d = field.distance_fn()?;
    let mut tally = Tally::new();
    for (i, &p) in points.iter().enumerate() {
        let (dp, a) = (d(p), analytic(p));
        if !dp.is_finite() {
            return Err(Failure::not_finite("the distance", p, dp, i + 1));
        }
        if !a.is_finite() {
            return Err(Failure::not_finite("the analytic distance", p, a, i + 1));
        }
        let error = (dp - a).abs();
        let allowed = tolerance * a.abs().max(1.0);
        if error > allowed {
            tally.fail(Failure::new(
                Check::Exact,
                vec![p],
                vec![dp, a],
                error,
                allowed,
            ));
        } else {
            tally.pass(error / allowed);
        }
    }
    tally.finish()
}
