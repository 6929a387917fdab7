//! Lighting effects: ambient occlusion, shadows, glow, fog, the sky,
//! global illumination, and the display transform (exposure, tone curve,
//! gamma), each compiled into the program only when it is on.

use super::*;

/// Glow around surfaces, from how closely a ray passed them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub struct Glow {
    /// Linear RGB colour of the glow.
    pub color: DVec3,
    /// Strength; 0.5 is subtle, 2 is strong.
    pub strength: f64,
}

impl Glow {
    /// A glow of `color` (linear RGB) and `strength`.
    #[must_use]
    pub fn new(color: DVec3, strength: f64) -> Self {
        Glow { color, strength }
    }
}

/// Path-traced global illumination ([`Effects::global_illumination`]):
/// light that bounces between surfaces and arrives from the whole sky.
///
/// Each sample follows one path from the camera. At every surface it
/// meets, the lights are sampled directly through a shadow ray (next-event
/// estimation), and the path goes on in a direction drawn from the
/// surface's material: a cosine-weighted diffuse bounce (Lambert's, or
/// Oren-Nayar's with a material's roughness), a normalised Phong lobe
/// for the specular share, or a mirror or refracted ray for a material's
/// reflectivity and transparency. A path that leaves the scene brings the
/// sky's light along its direction (the gradient from
/// [`Effects::sky_bottom`] to [`Effects::sky_top`]). After three bounces,
/// Russian roulette ends paths in proportion to how little they can still
/// bring, dividing the survivors' weight by their chance, so the mean is
/// unchanged.
///
/// A path meets at most `max_bounces` surfaces after its first hit, and
/// the light each of them receives is counted: the lights' (sampled at
/// it) and the sky's and environment's (along its bounce, the last
/// surface's included). The estimate of that light is unbiased:
/// progressive passes ([`crate::render::Renderer::render_progressive`])
/// converge on the image, their noise falling as one over the square root
/// of the passes. Light that needs more bounces is lost. Inside shapes
/// (brute-force marched) cannot be path traced, having no distance to
/// bounce from; a material's subsurface light is left to direct lighting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct GlobalIllumination {
    /// The most bounces of a path, in `1..=`[`MAX_GI_BOUNCES`].
    pub max_bounces: u32,
}

impl Default for GlobalIllumination {
    /// Paths of up to 16 bounces.
    fn default() -> Self {
        GlobalIllumination { max_bounces: 16 }
    }
}

impl GlobalIllumination {
    /// Paths of up to `max_bounces` bounces.
    #[must_use]
    pub fn new(max_bounces: u32) -> Self {
        GlobalIllumination { max_bounces }
    }
}

/// The most bounces a path of [`GlobalIllumination`] may take.
pub const MAX_GI_BOUNCES: u32 = 64;

/// Fog as a lit medium ([`Effects::volumetric`]): the fog of
/// [`Effects::fog_density`] thinning with height, and lit by the lights.
///
/// The density at height `y` is `fog_density · exp(−falloff · (y −
/// height))`: uniform at `falloff` 0, a ground fog that thins upwards
/// above 0. Light is lost along a camera ray by the density integrated
/// along it (in closed form), and gained twice:
///
/// - from the sky, as without it: what the fog takes away is replaced by
///   the background in the ray's direction;
/// - from every light, scattered once towards the camera (single
///   scattering) at `samples` points along the ray, spread in proportion
///   to how much light each stretch scatters and jittered afresh in every
///   pass, each point lit through a shadow ray: shadows cast shafts in
///   the fog. The phase function is Henyey and Greenstein's, with
///   `anisotropy` `g` (0 scatters alike in every direction; towards 1
///   forwards, a bright halo around lights in front of the camera).
///
/// Each light adds what it would to a white surface facing it, scaled by
/// the phase function and π: a uniform fog under a directional light of
/// radiance `L` adds `π p(θ) L` to a ray that leaves the scene whatever
/// its density (`L / 4` with `anisotropy` 0), and a thinner fog adds
/// less where the ray meets a surface sooner. Sphere and rectangle
/// lights count as points at their centres. Fog acts on camera rays;
/// reflected, refracted and path-traced rays see none.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct Volumetric {
    /// How fast the fog thins upwards, per unit of height (>= 0; 0:
    /// uniform).
    pub falloff: f64,
    /// The height at which the density is [`Effects::fog_density`].
    pub height: f64,
    /// Points along each ray at which the lights are sampled, in
    /// `1..=`[`MAX_FOG_SAMPLES`]; passes add more.
    pub samples: u32,
    /// Henyey–Greenstein's `g`, in `[-0.95, 0.95]`: 0 scatters evenly,
    /// above 0 forwards, below 0 backwards.
    pub anisotropy: f64,
}

impl Default for Volumetric {
    /// Uniform fog scattering evenly, eight samples along each ray.
    fn default() -> Self {
        Volumetric {
            falloff: 0.0,
            height: 0.0,
            samples: 8,
            anisotropy: 0.0,
        }
    }
}

impl Volumetric {
    /// Fog that thins upwards by `falloff` per unit above `height`.
    #[must_use]
    pub fn height(falloff: f64, height: f64) -> Self {
        Volumetric {
            falloff,
            height,
            ..Self::default()
        }
    }

    /// The same fog, sampled at `samples` points along each ray.
    #[must_use]
    pub fn samples(mut self, samples: u32) -> Self {
        self.samples = samples;
        self
    }

    /// The same fog, with Henyey–Greenstein's `g`.
    #[must_use]
    pub fn anisotropy(mut self, g: f64) -> Self {
        self.anisotropy = g;
        self
    }
}

/// The most light samples along a ray of [`Volumetric`] fog.
pub const MAX_FOG_SAMPLES: u32 = 64;

/// Lighting effects. Each one that is off is left out of the kernel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
#[non_exhaustive]
pub struct Effects {
    /// Ambient occlusion (needs [`Quality::ao_samples`] > 0).
    pub ambient_occlusion: bool,
    /// Reach of ambient occlusion along the normal, in scene units:
    /// surfaces closer than this darken a crease. Where a fifth of the
    /// image's height at the surface's distance is shorter, occlusion
    /// reaches that far instead (in perspective, `0.4 tan(fov / 2)` times
    /// the distance along the ray; orthographic, a fifth of the visible
    /// height), so a magnified view is shaded like the view unmagnified
    /// and the image does not change with the resolution. The default 0.25
    /// is kept wherever the image is more than 1.25 units high at the
    /// surface (a scene of unit size seen from a few units away), and by a
    /// camera inside a solid, which sees the surface from no distance.
    pub ao_distance: f64,
    /// Shadows from every light (needs [`Quality::shadow_steps`] > 0);
    /// soft where the light's softness is above 0.
    pub shadows: bool,
    /// Glow on rays that pass close to a surface.
    pub glow: Option<Glow>,
    /// Fog: the fraction of light lost per unit of distance, 0 for none.
    /// Alone, a uniform haze in which surfaces fade into the background
    /// with distance; with [`Effects::volumetric`], the density of a lit
    /// medium at its height.
    pub fog_density: f64,
    /// The fog as a medium thinning with height and lit by the lights
    /// ([`Volumetric`]); `None` (the default) leaves it an unlit uniform
    /// haze. Nothing without a [`Effects::fog_density`] above 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub volumetric: Option<Volumetric>,
    /// Colour of the background at the top of the image (linear RGB).
    pub sky_top: DVec3,
    /// Colour of the background at the bottom of the image (linear RGB).
    pub sky_bottom: DVec3,
    /// Output gamma (2.2 for sRGB-like output; 1 for linear).
    pub gamma: f64,
    /// Exposure in stops: every linear colour is scaled by
    /// `2^exposure` before anything else sees it (the 8- and 16-bit
    /// images through the tone curve, and the linear beauty of an
    /// OpenEXR file as it is). In `[-32, 32]`; 0 leaves colours as lit.
    pub exposure: f64,
    /// The curve that takes exposed linear colours into `[0, 1]` for
    /// display ([`ToneMap`]; the default clips at 1). Linear outputs
    /// (OpenEXR) are written before it.
    pub tone_map: ToneMap,
    /// How displayed values are encoded after the tone curve
    /// ([`Encoding`]): by [`Effects::gamma`] (the default), or by the exact
    /// sRGB curve.
    #[serde(skip_serializing_if = "Encoding::is_gamma")]
    pub encoding: Encoding,
    /// Path-traced global illumination in place of direct lighting
    /// ([`GlobalIllumination`]); `None` (the default) lights each hit
    /// directly, with ambient occlusion standing in for the sky's light.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub global_illumination: Option<GlobalIllumination>,
}

impl Default for Effects {
    /// Ambient occlusion and shadows on, no glow, no fog, a blue-grey
    /// gradient background.
    fn default() -> Self {
        Effects {
            ambient_occlusion: true,
            ao_distance: 0.25,
            shadows: true,
            glow: None,
            fog_density: 0.0,
            volumetric: None,
            sky_top: DVec3::new(0.32, 0.42, 0.58),
            sky_bottom: DVec3::new(0.06, 0.07, 0.09),
            gamma: 2.2,
            exposure: 0.0,
            tone_map: ToneMap::Clip,
            encoding: Encoding::Gamma,
            global_illumination: None,
        }
    }
}

impl Effects {
    /// Everything off: plain diffuse shading on the background.
    #[must_use]
    pub fn none() -> Self {
        Effects {
            ambient_occlusion: false,
            shadows: false,
            glow: None,
            fog_density: 0.0,
            ..Self::default()
        }
    }

    /// Checks every value, for its own range and for the `F64` limits
    /// (the widest; a renderer checks its own precision's with
    /// [`Effects::validate_for`]).
    ///
    /// # Errors
    /// As [`Effects::validate_for`].
    pub fn validate(&self) -> Result<()> {
        self.validate_for(Precision::F64)
    }

    /// Checks every value, for its own range and for what a kernel of
    /// `precision` can compute with: each is a size within
    /// [`Precision::limits`].
    ///
    /// # Errors
    /// [`Error::Effects`] naming the first setting outside its own range;
    /// [`Error::Precision`] for one the precision cannot compute with.
    pub fn validate_for(&self, precision: Precision) -> Result<()> {
        self.check_ranges()?;
        let limits = precision.limits();
        let size =
            |setting: &str, value: f64| within("effects", setting, value, Magnitude::Size, limits);
        let rgb = |setting: &str, c: DVec3| -> Result<()> {
            for (value, axis) in c.to_array().into_iter().zip(["x", "y", "z"]) {
                size(&format!("{setting}.{axis}"), value)?;
            }
            Ok(())
        };
        if let Some(g) = self.glow {
            rgb("glow.color", g.color)?;
            size("glow.strength", g.strength)?;
        }
        size("ao_distance", self.ao_distance)?;
        size("fog_density", self.fog_density)?;
        if let Some(v) = self.volumetric {
            size("volumetric.falloff", v.falloff)?;
            within(
                "effects",
                "volumetric.height",
                v.height,
                Magnitude::Coordinate,
                limits,
            )?;
        }
        rgb("sky_top", self.sky_top)?;
        rgb("sky_bottom", self.sky_bottom)?;
        size("gamma", self.gamma)
    }

    /// Each value's own range.
    fn check_ranges(&self) -> Result<()> {
        let bad = |setting: &'static str, value: f64, expected: &str| Error::Effects {
            setting,
            value,
            expected: expected.into(),
        };
        // The first component that is NaN, infinite or negative (a
        // minimum would hide a NaN).
        let wrong = |c: DVec3| {
            c.to_array()
                .into_iter()
                .find(|v| !(v.is_finite() && *v >= 0.0))
        };
        if let Some(g) = self.glow {
            if let Some(v) = wrong(g.color) {
                return Err(bad("glow.color", v, "finite and >= 0"));
            }
            if !(g.strength.is_finite() && g.strength >= 0.0) {
                return Err(bad("glow.strength", g.strength, "finite and >= 0"));
            }
        }
        if !(self.ao_distance.is_finite() && self.ao_distance > 0.0) {
            return Err(bad("ao_distance", self.ao_distance, "finite and > 0"));
        }
        if !(self.fog_density.is_finite() && self.fog_density >= 0.0) {
            return Err(bad("fog_density", self.fog_density, "finite and >= 0"));
        }
        if let Some(v) = self.volumetric {
            if !(v.falloff.is_finite() && v.falloff >= 0.0) {
                return Err(bad("volumetric.falloff", v.falloff, "finite and >= 0"));
            }
            if !v.height.is_finite() {
                return Err(bad("volumetric.height", v.height, "finite"));
            }
            if !(1..=MAX_FOG_SAMPLES).contains(&v.samples) {
                return Err(bad(
                    "volumetric.samples",
                    f64::from(v.samples),
                    "in [1, 64]",
                ));
            }
            if !(v.anisotropy.is_finite() && v.anisotropy.abs() <= 0.95) {
                return Err(bad(
                    "volumetric.anisotropy",
                    v.anisotropy,
                    "in [-0.95, 0.95]",
                ));
            }
        }
        for (name, c) in [("sky_top", self.sky_top), ("sky_bottom", self.sky_bottom)] {
            if let Some(v) = wrong(c) {
                return Err(bad(name, v, "finite and >= 0"));
            }
        }
        if !(self.gamma.is_finite() && self.gamma > 0.0) {
            return Err(bad("gamma", self.gamma, "> 0"));
        }
        if !(self.exposure.is_finite() && self.exposure.abs() <= MAX_EXPOSURE) {
            return Err(bad("exposure", self.exposure, "in [-32, 32] stops"));
        }
        if let Some(gi) = self.global_illumination
            && !(1..=MAX_GI_BOUNCES).contains(&gi.max_bounces)
        {
            return Err(bad(
                "global_illumination.max_bounces",
                f64::from(gi.max_bounces),
                "in [1, 64]",
            ));
        }
        Ok(())
    }
}

/// Builder methods, one per setting, as for [`Quality`]: each returns the
/// effects with that setting changed; [`Effects::validate`] checks them.
///
/// ```
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::quality::Glow;
///
/// let effects = Effects::default()
///     .shadows(false)
///     .glow(Glow::new(dvec3(0.6, 0.75, 1.0), 0.6))
///     .fog_density(0.05);
/// assert!(effects.ambient_occlusion && !effects.shadows);
/// assert_eq!(effects.glow.map(|g| g.strength), Some(0.6));
/// assert_eq!(effects.glow(None).glow, None);
/// effects.validate()?;
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
impl Effects {
    /// Turns ambient occlusion on or off (on needs
    /// [`Quality::ao_samples`] > 0).
    #[must_use]
    pub fn ambient_occlusion(mut self, on: bool) -> Self {
        self.ambient_occlusion = on;
        self
    }

    /// Sets the reach of ambient occlusion along the normal, in scene
    /// units (> 0).
    #[must_use]
    pub fn ao_distance(mut self, distance: f64) -> Self {
        self.ao_distance = distance;
        self
    }

    /// Turns shadows on or off (on needs [`Quality::shadow_steps`] > 0).
    #[must_use]
    pub fn shadows(mut self, on: bool) -> Self {
        self.shadows = on;
        self
    }

    /// Sets the glow, or turns it off with `None`.
    #[must_use]
    pub fn glow(mut self, glow: impl Into<Option<Glow>>) -> Self {
        self.glow = glow.into();
        self
    }

    /// Sets the fog: the fraction of light lost per unit of distance
    /// (>= 0; 0: no fog).
    #[must_use]
    pub fn fog_density(mut self, density: f64) -> Self {
        self.fog_density = density;
        self
    }

    /// Makes the fog a medium thinning with height and lit by the lights,
    /// or an unlit uniform haze again with `None`.
    #[must_use]
    pub fn volumetric(mut self, fog: impl Into<Option<Volumetric>>) -> Self {
        self.volumetric = fog.into();
        self
    }

    /// Sets the background colour at the top of the image (linear RGB).
    #[must_use]
    pub fn sky_top(mut self, color: DVec3) -> Self {
        self.sky_top = color;
        self
    }

    /// Sets the background colour at the bottom of the image (linear RGB).
    #[must_use]
    pub fn sky_bottom(mut self, color: DVec3) -> Self {
        self.sky_bottom = color;
        self
    }

    /// Sets the output gamma (> 0; 2.2 for sRGB-like output, 1 for
    /// linear).
    #[must_use]
    pub fn gamma(mut self, gamma: f64) -> Self {
        self.gamma = gamma;
        self
    }

    /// Sets the exposure in stops (in `[-32, 32]`): linear colours are
    /// scaled by `2^stops`.
    #[must_use]
    pub fn exposure(mut self, stops: f64) -> Self {
        self.exposure = stops;
        self
    }

    /// Sets the tone curve that maps exposed linear colours into `[0, 1]`.
    #[must_use]
    pub fn tone_map(mut self, tone_map: ToneMap) -> Self {
        self.tone_map = tone_map;
        self
    }

    /// Sets how displayed values are encoded: by the gamma, or by the
    /// exact sRGB curve.
    #[must_use]
    pub fn encoding(mut self, encoding: Encoding) -> Self {
        self.encoding = encoding;
        self
    }

    /// Sets path-traced global illumination, or turns it off with `None`.
    #[must_use]
    pub fn global_illumination(mut self, gi: impl Into<Option<GlobalIllumination>>) -> Self {
        self.global_illumination = gi.into();
        self
    }

    /// The factor [`Effects::exposure`] scales linear colours by:
    /// `2^exposure`.
    #[must_use]
    pub fn exposure_scale(&self) -> f64 {
        self.exposure.exp2()
    }
}

/// The largest exposure, in stops, either way ([`Effects::exposure`]):
/// `2^32` keeps every scaled colour within the `F32` kernel's limits.
pub const MAX_EXPOSURE: f64 = 32.0;
