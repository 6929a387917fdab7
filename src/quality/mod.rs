//! Render settings: how accurately to march ([`Quality`]) and which
//! lighting effects to compile in ([`Effects`]).
//!
//! Both are plain data read by code generation: an effect that is off, or a
//! sample count of zero, produces no code at all. [`Precision`] also says
//! which magnitudes the kernel can compute with ([`Precision::limits`]), the
//! bounds every scene value, camera, light, knob and effect setting keeps.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::math::{F32_LIMITS, F64_LIMITS, Limits, Magnitude};

mod effects;
mod tone;

pub use effects::{
    Effects, GlobalIllumination, Glow, MAX_EXPOSURE, MAX_FOG_SAMPLES, MAX_GI_BOUNCES, Volumetric,
};
pub use tone::{Encoding, ToneMap, display, display_formula};

/// Floating-point precision of the generated kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Precision {
    /// 32-bit floats: fastest, every device supports them.
    #[default]
    F32,
    /// 64-bit floats via `cl_khr_fp64`: for deep zooms and huge or tiny
    /// scales. Slower, and not every device has it.
    F64,
}

impl Precision {
    /// The magnitudes a kernel of this precision computes with safely
    /// (the table and the reasons are in [`math::Limits`](crate::math::Limits)):
    ///
    /// | precision | values at most | sizes 0 or at least | knobs in footprints at least |
    /// |---|---|---|---|
    /// | `F32` | `1e18` | `1e-18` | `2^-20` (about `9.5e-7`) |
    /// | `F64` | `1e150` | `1e-150` | `2^-49` (about `1.8e-15`) |
    ///
    /// Scene values keep the `F64` limits when a scene is compiled, and
    /// the limits of the kernel's precision when a program is generated
    /// and a renderer uploads its inputs; a value beyond them is an
    /// [`Error::Precision`].
    ///
    /// ```
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::quality::Precision;
    /// assert_eq!(Precision::F32.limits().max, 1e18);
    /// assert_eq!(Precision::F64.limits().min, 1e-150);
    /// ```
    #[must_use]
    pub fn limits(self) -> &'static Limits {
        match self {
            Precision::F32 => &F32_LIMITS,
            Precision::F64 => &F64_LIMITS,
        }
    }
}

/// A setting's magnitude against `limits`, as [`Error::Precision`] at the
/// node `quality` or `effects`.
fn within(
    node: &str,
    setting: &str,
    value: f64,
    magnitude: Magnitude,
    limits: &Limits,
) -> Result<()> {
    match limits.crossed(value, magnitude) {
        None => Ok(()),
        Some(limit) => Err(Error::Precision {
            node: node.into(),
            param: setting.into(),
            value,
            precision: limits.precision,
            limit,
        }),
    }
}

/// A knob measured in pixel footprints: at least the precision's
/// resolution, at most its largest value.
fn footprints(setting: &str, value: f64, limits: &Limits) -> Result<()> {
    if value < limits.resolution {
        return Err(Error::Precision {
            node: "quality".into(),
            param: setting.into(),
            value,
            precision: limits.precision,
            limit: limits.resolution,
        });
    }
    within("quality", setting, value, Magnitude::Size, limits)
}

/// Every speed-versus-accuracy knob. Start from a preset and adjust.
///
/// The presets, cheapest first: [`Quality::draft`], [`Quality::preview`],
/// [`Quality::production`] and [`Quality::reference`]. Their measured
/// cost and error are in [the guide](crate::guide::quality), produced by
/// `cargo run --release --example tradeoff`.
///
/// Two knobs decide *what* is drawn: `detail` (the surface lies where the
/// distance estimate falls to that many pixel footprints, so fractal detail
/// finer than it merges) and `normal_epsilon` (the scale the shading
/// sees). Every preset uses the same values, so the presets differ in cost
/// and accuracy and converge on one image, rather than drawing different
/// surfaces. The other knobs converge: beyond a point they change almost
/// nothing.
///
/// Every knob is also bounded by what [`Quality::precision`] can compute
/// with ([`Precision::limits`]; checked by [`Quality::validate`], which
/// every renderer and code generation run): `detail`, `hit_epsilon` and
/// `normal_epsilon` are thresholds in pixel footprints and must be at
/// least the precision's resolution (`2^-20`, about `9.5e-7`, in `F32`;
/// `2^-49`, about `1.8e-15`, in `F64`) and at most its largest value
/// (`1e18` in `F32`, `1e150` in `F64`); `max_distance` lies between the
/// smallest size and the largest value (`1e-18` to `1e18` in `F32`,
/// `1e-150` to `1e150` in `F64`). [`Effects`] values keep the same
/// bounds on sizes.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct Quality {
    /// Give up on a ray after this many steps.
    pub max_steps: u32,
    /// The drawn surface, in pixel footprints at the hit distance: a ray
    /// hits where the distance estimate falls to `detail` footprints
    /// (0.5: the surface is resolved to half a pixel; fractal detail finer
    /// than that merges). Part of the look: the same in every preset.
    pub detail: f64,
    /// How precisely a hit is located on that surface, in pixel footprints
    /// along the ray: the march's crossing of the surface is refined until
    /// it is bracketed this tightly.
    pub hit_epsilon: f64,
    /// Rays stop beyond this distance from the camera.
    pub max_distance: f64,
    /// Normal finite-difference step as a multiple of the pixel footprint.
    /// Part of the look: the same in every preset.
    pub normal_epsilon: f64,
    /// Samples of the ambient-occlusion integral along the normal (0: no
    /// occlusion term). Its reach is [`Effects::ao_distance`].
    pub ao_samples: u32,
    /// Maximum steps of each shadow ray (0: no shadows).
    pub shadow_steps: u32,
    /// If set, no fractal uses more than this many iterations (escape-time
    /// iterations or folding levels): a cap, so a preset can trade detail
    /// for speed without raising the cost of fractals that use fewer.
    pub fractal_iterations: Option<u32>,
    /// Kernel precision.
    pub precision: Precision,
    /// Relaxation factor ω of sphere tracing, in `[0.25, 2)`: each step is
    /// ω times the distance to the drawn surface. 1 is plain sphere
    /// tracing; below 1 guards against estimators that overestimate
    /// (fractals) at the cost of more steps; above 1 takes longer steps and
    /// falls back to plain ones where they overshoot.
    pub over_relaxation: f64,
    /// Samples per pixel along each axis (N×N jittered samples; 1: one
    /// sample at the pixel centre).
    pub supersampling: u32,
    /// Lets the OpenCL compiler trade exactness for speed
    /// (`-cl-unsafe-math-optimizations`: reassociation, multiply-adds,
    /// reciprocals, and contracted expressions): faster on some devices,
    /// with results that differ from the CPU reference by more than
    /// rounding. Not `-cl-fast-relaxed-math`, which also lets the compiler
    /// assume no value is infinite: the march marks misses and unbounded
    /// reach with infinities. On in `draft` and `preview`, off in
    /// `production` and `reference`; its cost and error are measured in
    /// `examples/tradeoff`.
    pub fast_math: bool,
    /// Renders one pixel for every `resolution_scale` × `resolution_scale`
    /// pixels of the image, and scales the result up to the image's size,
    /// blending neighbours only where their depths say they show the same
    /// surface (1: every pixel rendered). The surface is the full-size
    /// image's (thresholds stay in the image's pixels); the image is
    /// softer. The renderer's [`Frame`](crate::render::Frame) outputs
    /// come from the nearest rendered pixel.
    pub resolution_scale: u32,
    /// The side, in rendered pixels, of the tiles of the coarse pass (0:
    /// no coarse pass). Before the pixels are marched, one cone per tile,
    /// wide enough to hold every ray of the tile, is marched until it
    /// comes near a surface; each ray then starts where its tile's cone
    /// stopped rather than at the camera. The surface is the same; the
    /// march finds it in fewer steps (or, where the cone skips only
    /// empty space a few steps long, costs a little more).
    pub cone_tile: u32,
    /// How many times a path may bounce off mirrors or pass through glass
    /// (0 to 8): the most secondary rays, reflected or refracted, between
    /// the camera and the last surface a pixel's path reaches. A path that
    /// would bounce once more takes the sky's colour in that direction
    /// instead. Only scenes with a reflective or transparent
    /// [`Material`](crate::scene::Material) use it; each bounce at most
    /// doubles the rays of a pixel, so the cost stays within `2^(bounces
    /// + 1)` times a frame without them.
    pub bounces: u32,
    /// The brute-force step of scenes with an
    /// [`InsideShape`](crate::scene::InsideShape), in pixel footprints:
    /// within the inside shapes' bounds a ray steps this far (or to the
    /// nearest distance-estimated surface, where that is nearer), asking
    /// only whether it is in a set, and features thinner than a step may
    /// be missed. Each pixel and progressive pass starts its steps at a
    /// different offset, so passes converge on the set's surface. In
    /// `[0.125, 64]` ([`MIN_BRUTE_STEP`]); 4 in `draft`, 2 in `preview`, 1
    /// in `production`, 0.5 in `reference`. Scenes without inside shapes
    /// ignore it.
    pub brute_step: f64,
    /// How a scene with inside shapes estimates the normal where a ray
    /// meets an inside shape, which has no distance to differentiate: from
    /// the hit points of neighbouring pixels (see [`ScreenNormals`]).
    pub screen_normals: ScreenNormals,
}

/// Normals from neighbouring pixels' hit points, for surfaces without a
/// distance estimate ([`Quality::screen_normals`]). Both read the depth of
/// the same progressive pass's neighbours, and take only neighbours whose
/// depth is within a few brute-force steps of the pixel's (the same
/// surface).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub enum ScreenNormals {
    /// The cross product of central differences of the hit points left and
    /// right, above and below (one-sided where a neighbour is on another
    /// surface): from the depth buffer, as a screen-space renderer does.
    Differences,
    /// The plane fitted by least squares through the pixel's hit point and
    /// its eight neighbours' (Englund's estimate): less noisy where the
    /// jittered steps leave depth noise.
    #[default]
    LeastSquares,
}

/// The most bounces [`Quality::bounces`] allows.
pub const MAX_BOUNCES: u32 = 8;

impl Quality {
    /// The detail level shared by every preset, in pixel footprints.
    pub const DETAIL: f64 = 0.5;
    /// The normal step shared by every preset, in pixel footprints.
    pub const NORMAL_EPSILON: f64 = 1.0;

    /// For moving the camera: the cheapest image of the same surface. One
    /// pixel rendered in 3×3 ([`Quality::resolution_scale`]; 2×2 is
    /// sharper and about half as fast), 128 steps
    /// (rays grazing a floor may run out), hits located to half a pixel,
    /// no occlusion and no shadows, relaxed math, rays started by the
    /// coarse pass.
    #[must_use]
    pub fn draft() -> Self {
        Quality {
            max_steps: 128,
            detail: Self::DETAIL,
            hit_epsilon: 0.5,
            max_distance: 100.0,
            normal_epsilon: Self::NORMAL_EPSILON,
            ao_samples: 0,
            shadow_steps: 0,
            fractal_iterations: None,
            precision: Precision::F32,
            over_relaxation: 1.0,
            supersampling: 1,
            fast_math: true,
            resolution_scale: 3,
            cone_tile: 8,
            bounces: 1,
            brute_step: 4.0,
            screen_normals: ScreenNormals::LeastSquares,
        }
    }

    /// Interactive quality: every pixel, every effect on, hits located to a
    /// seventh of a pixel, three occlusion samples and 64-step shadow rays,
    /// relaxed math, rays started by the coarse pass.
    #[must_use]
    pub fn preview() -> Self {
        Quality {
            max_steps: 256,
            hit_epsilon: 0.15,
            ao_samples: 3,
            shadow_steps: 64,
            resolution_scale: 1,
            bounces: 2,
            brute_step: 2.0,
            ..Self::draft()
        }
    }

    /// Final images: hits located to a twentieth of a pixel, every effect
    /// converged, exact math, rays started by the coarse pass. Add
    /// [`Quality::supersampling`] for anti-aliasing.
    #[must_use]
    pub fn production() -> Self {
        Quality {
            max_steps: 512,
            hit_epsilon: 0.05,
            ao_samples: 5,
            shadow_steps: 96,
            fast_math: false,
            bounces: 4,
            brute_step: 1.0,
            ..Self::preview()
        }
    }

    /// The accuracy reference the others are measured against: F64, 2048
    /// steps, hits located to a thousandth of a pixel, eight occlusion
    /// samples, 256 shadow steps, exact math, every ray marched from the
    /// camera (no coarse pass). It is converged: halving its relaxation
    /// factor or dividing its `hit_epsilon` by ten changes its image by
    /// less than the presets differ from it (see [the guide](crate::guide::quality)).
    #[must_use]
    pub fn reference() -> Self {
        Quality {
            max_steps: 2048,
            hit_epsilon: 0.001,
            ao_samples: 8,
            shadow_steps: 256,
            precision: Precision::F64,
            cone_tile: 0,
            bounces: 8,
            brute_step: 0.5,
            ..Self::production()
        }
    }

    /// Checks every knob, for the knob's own range and for what
    /// [`Quality::precision`] can compute with: `detail`, `hit_epsilon`
    /// and `normal_epsilon` are thresholds in pixel footprints, so each is
    /// at least the precision's resolution (`Precision::limits`; about
    /// `9.5e-7` in `F32`, `1.8e-15` in `F64`: below it a threshold is finer
    /// than positions can be told apart, and in `F32` it underflows to 0,
    /// so the march can no longer stop); `max_distance` is a size within
    /// the precision's limits.
    ///
    /// # Errors
    /// [`Error::Quality`] naming the first setting outside its own range;
    /// [`Error::Precision`] for one the precision cannot compute with.
    pub fn validate(&self) -> Result<()> {
        self.check_ranges()?;
        let limits = self.precision.limits();
        footprints("detail", self.detail, limits)?;
        footprints("hit_epsilon", self.hit_epsilon, limits)?;
        footprints("normal_epsilon", self.normal_epsilon, limits)?;
        within(
            "quality",
            "max_distance",
            self.max_distance,
            Magnitude::Size,
            limits,
        )
    }

    /// Each knob's own range.
    fn check_ranges(&self) -> Result<()> {
        let check = |setting: &'static str, value: f64, ok: bool, expected: &str| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(Error::Quality {
                    setting,
                    value,
                    expected: expected.into(),
                })
            }
        };
        let steps = f64::from(self.max_steps);
        check(
            "max_steps",
            steps,
            (1..=100_000).contains(&self.max_steps),
            "in 1..=100000",
        )?;
        check("detail", self.detail, self.detail > 0.0, "> 0")?;
        check(
            "hit_epsilon",
            self.hit_epsilon,
            self.hit_epsilon > 0.0 && self.hit_epsilon <= self.detail,
            "in (0, detail]",
        )?;
        check(
            "max_distance",
            self.max_distance,
            self.max_distance > 0.0,
            "> 0",
        )?;
        check(
            "normal_epsilon",
            self.normal_epsilon,
            self.normal_epsilon > 0.0,
            "> 0",
        )?;
        check(
            "ao_samples",
            f64::from(self.ao_samples),
            self.ao_samples <= 32,
            "<= 32",
        )?;
        check(
            "shadow_steps",
            f64::from(self.shadow_steps),
            self.shadow_steps <= 10_000,
            "<= 10000",
        )?;
        if let Some(n) = self.fractal_iterations {
            check(
                "fractal_iterations",
                f64::from(n),
                (1..=256).contains(&n),
                "in 1..=256",
            )?;
        }
        check(
            "over_relaxation",
            self.over_relaxation,
            (0.25..2.0).contains(&self.over_relaxation),
            "in [0.25, 2)",
        )?;
        check(
            "supersampling",
            f64::from(self.supersampling),
            (1..=8).contains(&self.supersampling),
            "in 1..=8",
        )?;
        check(
            "resolution_scale",
            f64::from(self.resolution_scale),
            (1..=8).contains(&self.resolution_scale),
            "in 1..=8",
        )?;
        check(
            "cone_tile",
            f64::from(self.cone_tile),
            self.cone_tile == 0 || (2..=64).contains(&self.cone_tile),
            "0 (off) or in 2..=64",
        )?;
        check(
            "bounces",
            f64::from(self.bounces),
            self.bounces <= MAX_BOUNCES,
            "<= 8",
        )?;
        check(
            "brute_step",
            self.brute_step,
            (MIN_BRUTE_STEP..=64.0).contains(&self.brute_step),
            "in [0.125, 64] pixel footprints",
        )
    }
}

/// The smallest [`Quality::brute_step`], in pixel footprints. A ray takes
/// at most [`BRUTE_MAX_STEPS`](crate::scene::BRUTE_MAX_STEPS) brute-force
/// steps, so smaller steps would stop short of the sets they are meant to
/// find (an image of sky) instead of seeing them finer: at this step the
/// budget still crosses 2,048 footprints, a region deeper than a 4K
/// image is wide.
pub const MIN_BRUTE_STEP: f64 = 0.125;

/// Builder methods, one per knob: each returns the settings with that knob
/// changed, so a preset is adjusted in one expression. Like the fields,
/// they check nothing; [`Quality::validate`] (which every renderer runs)
/// reports a bad value.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::quality::Precision;
///
/// let q = Quality::production()
///     .supersampling(2)
///     .max_steps(1024)
///     .fractal_iterations(8)
///     .precision(Precision::F64);
/// assert_eq!((q.supersampling, q.max_steps), (2, 1024));
/// assert_eq!(q.fractal_iterations, Some(8));
/// // Every other knob is the preset's.
/// assert_eq!(q.hit_epsilon, Quality::production().hit_epsilon);
/// q.validate()?;
/// assert!(Quality::draft().over_relaxation(2.5).validate().is_err());
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
impl Quality {
    /// Gives up on a ray after `steps` steps (1 to 100 000).
    #[must_use]
    pub fn max_steps(mut self, steps: u32) -> Self {
        self.max_steps = steps;
        self
    }

    /// Sets the drawn surface, in pixel footprints (> 0): a ray hits where
    /// the distance estimate falls to `detail` footprints. Changes the
    /// look, not only the cost; every preset uses [`Quality::DETAIL`].
    #[must_use]
    pub fn detail(mut self, detail: f64) -> Self {
        self.detail = detail;
        self
    }

    /// Locates hits on the surface to `epsilon` pixel footprints along the
    /// ray (in `(0, detail]`).
    #[must_use]
    pub fn hit_epsilon(mut self, epsilon: f64) -> Self {
        self.hit_epsilon = epsilon;
        self
    }

    /// Stops rays beyond `distance` from the camera (> 0), in scene units.
    #[must_use]
    pub fn max_distance(mut self, distance: f64) -> Self {
        self.max_distance = distance;
        self
    }

    /// Sets the normals' finite-difference step, in pixel footprints (> 0).
    /// Changes the look; every preset uses [`Quality::NORMAL_EPSILON`].
    #[must_use]
    pub fn normal_epsilon(mut self, epsilon: f64) -> Self {
        self.normal_epsilon = epsilon;
        self
    }

    /// Takes `samples` ambient-occlusion samples (0 to 32; 0: no occlusion).
    #[must_use]
    pub fn ao_samples(mut self, samples: u32) -> Self {
        self.ao_samples = samples;
        self
    }

    /// Marches each shadow ray at most `steps` steps (up to 10 000; 0: no
    /// shadows).
    #[must_use]
    pub fn shadow_steps(mut self, steps: u32) -> Self {
        self.shadow_steps = steps;
        self
    }

    /// Caps every fractal's iterations at `cap` (1 to 256), or lifts the
    /// cap with `None`.
    #[must_use]
    pub fn fractal_iterations(mut self, cap: impl Into<Option<u32>>) -> Self {
        self.fractal_iterations = cap.into();
        self
    }

    /// Sets the kernel's floating-point precision.
    #[must_use]
    pub fn precision(mut self, precision: Precision) -> Self {
        self.precision = precision;
        self
    }

    /// Sets the relaxation factor ω of sphere tracing, in `[0.25, 2)`
    /// (1: plain sphere tracing).
    #[must_use]
    pub fn over_relaxation(mut self, omega: f64) -> Self {
        self.over_relaxation = omega;
        self
    }

    /// Takes `n`×`n` jittered samples per pixel (1 to 8; 1: one sample at
    /// the pixel centre, no anti-aliasing).
    #[must_use]
    pub fn supersampling(mut self, n: u32) -> Self {
        self.supersampling = n;
        self
    }

    /// Renders one pixel in `k`×`k` and scales the image up (1 to 8; 1:
    /// every pixel rendered). See [`Quality::resolution_scale`].
    #[must_use]
    pub fn resolution_scale(mut self, k: u32) -> Self {
        self.resolution_scale = k;
        self
    }

    /// Starts rays after a coarse pass over tiles of `side` × `side`
    /// pixels (0: off). See [`Quality::cone_tile`].
    #[must_use]
    pub fn cone_tile(mut self, side: u32) -> Self {
        self.cone_tile = side;
        self
    }

    /// Lets paths bounce off mirrors or pass through glass up to `bounces`
    /// times (0 to 8). See [`Quality::bounces`].
    #[must_use]
    pub fn bounces(mut self, bounces: u32) -> Self {
        self.bounces = bounces;
        self
    }

    /// Steps `footprints` pixel footprints at a time within inside shapes'
    /// bounds. See [`Quality::brute_step`].
    #[must_use]
    pub fn brute_step(mut self, footprints: f64) -> Self {
        self.brute_step = footprints;
        self
    }

    /// Estimates inside shapes' normals by `method`. See
    /// [`Quality::screen_normals`].
    #[must_use]
    pub fn screen_normals(mut self, method: ScreenNormals) -> Self {
        self.screen_normals = method;
        self
    }

    /// Builds the program with relaxed, fast math. See
    /// [`Quality::fast_math`].
    #[must_use]
    pub fn fast_math(mut self, on: bool) -> Self {
        self.fast_math = on;
        self
    }
}

impl Default for Quality {
    /// [`Quality::production`].
    fn default() -> Self {
        Self::production()
    }
}

/// The named quality presets, in increasing cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Preset {
    /// [`Quality::draft`].
    Draft,
    /// [`Quality::preview`].
    #[default]
    Preview,
    /// [`Quality::production`].
    Production,
    /// [`Quality::reference`].
    Reference,
}

impl Preset {
    /// Every preset, cheapest first.
    pub const ALL: [Preset; 4] = [
        Preset::Draft,
        Preset::Preview,
        Preset::Production,
        Preset::Reference,
    ];

    /// The preset's settings.
    #[must_use]
    pub fn quality(self) -> Quality {
        match self {
            Preset::Draft => Quality::draft(),
            Preset::Preview => Quality::preview(),
            Preset::Production => Quality::production(),
            Preset::Reference => Quality::reference(),
        }
    }

    /// The lower-case name: `draft`, `preview`, `production`, `reference`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Preset::Draft => "draft",
            Preset::Preview => "preview",
            Preset::Production => "production",
            Preset::Reference => "reference",
        }
    }

    /// The preset called `name` (case-insensitive).
    ///
    /// ```
    /// use fractal_sdf::quality::{Preset, Quality};
    /// assert_eq!(Preset::from_name("Draft"), Some(Preset::Draft));
    /// assert_eq!(Preset::from_name("draft").unwrap().quality(), Quality::draft());
    /// assert_eq!(Preset::from_name("ultra"), None);
    /// ```
    #[must_use]
    pub fn from_name(name: &str) -> Option<Preset> {
        Self::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name.trim()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refused(q: Quality) -> &'static str {
        match q.validate() {
            Err(Error::Quality { setting, .. }) => setting,
            other => panic!("expected Error::Quality, got {other:?}"),
        }
    }

    #[test]
    fn every_preset_is_valid_and_draws_the_same_surface() {
        let presets = [
            Quality::draft(),
            Quality::preview(),
            Quality::production(),
            Quality::reference(),
        ];
        for q in presets {
            q.validate().unwrap();
            assert_eq!(
                (q.detail, q.normal_epsilon),
                (Quality::DETAIL, Quality::NORMAL_EPSILON)
            );
            assert_eq!(q.max_distance, Quality::reference().max_distance);
        }
        // Each preset locates hits at least as precisely as the one before.
        for pair in presets.windows(2) {
            assert!(pair[1].hit_epsilon <= pair[0].hit_epsilon);
            assert!(pair[1].max_steps >= pair[0].max_steps);
        }
    }

    #[test]
    fn hits_cannot_be_located_more_loosely_than_the_detail() {
        let q = Quality::production();
        let loose = Quality {
            hit_epsilon: q.detail * 1.5,
            ..q
        };
        assert_eq!(refused(loose), "hit_epsilon");
        assert_eq!(refused(Quality { detail: 0.0, ..q }), "detail");
        Quality {
            hit_epsilon: q.detail,
            ..q
        }
        .validate()
        .unwrap();
    }

    #[test]
    fn relaxation_may_shorten_or_lengthen_steps_within_bounds() {
        let q = Quality::production();
        for ok in [0.25, 0.5, 1.0, 1.9] {
            Quality {
                over_relaxation: ok,
                ..q
            }
            .validate()
            .unwrap();
        }
        for bad in [0.2, 2.0, f64::NAN] {
            let bad = Quality {
                over_relaxation: bad,
                ..q
            };
            assert_eq!(refused(bad), "over_relaxation");
        }
    }

    #[test]
    fn occlusion_needs_a_positive_reach() {
        let e = Effects {
            ao_distance: 0.0,
            ..Effects::default()
        };
        let err = e.validate().unwrap_err();
        assert!(
            matches!(
                err,
                Error::Effects {
                    setting: "ao_distance",
                    ..
                }
            ),
            "{err:?}"
        );
        // Effects are not part of the quality: their errors say so.
        assert_eq!(
            err.to_string(),
            "effects setting `ao_distance` must be finite and > 0, got 0"
        );
    }
}
