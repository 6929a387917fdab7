//! A scene file's own shape, as serde reads and writes it.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::animation::{Keyframe, Motion};
use crate::quality::{Effects, Precision, Preset, Quality, ScreenNormals};
use crate::scene::{
    Axis, Camera, HybridStage, KifsFold, Light, Material, Palette, Param, Param3, Profile, Rule,
    Scene, Trap,
};

use super::sites::Located;
use super::values::count;

// ---------------------------------------------------------------------------
// The file's shape

/// A whole file.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Scene")]
pub(super) struct FileRepr {
    pub(super) version: u32,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) formulas: Vec<Located<FormulaRepr>>,
    pub(super) geometry: Located<NodeRepr>,
    #[serde(default)]
    pub(super) camera: Located<Camera>,
    #[serde(default = "default_lights")]
    pub(super) lights: Vec<Located<Light>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) environment: Option<Located<EnvironmentRepr>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) quality: Option<Located<QualityRepr>>,
    #[serde(default)]
    pub(super) effects: Located<Effects>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) path: Option<Located<Vec<Keyframe>>>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) motions: Vec<Located<Motion>>,
}

/// The environment light: an image file (relative to the scene file's
/// folder, or absolute), its turn about +Y and its intensity.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Environment")]
pub(super) struct EnvironmentRepr {
    pub(super) image: std::path::PathBuf,
    #[serde(default)]
    pub(super) rotation_degrees: f64,
    #[serde(default = "unit")]
    pub(super) intensity: f64,
}

fn unit() -> f64 {
    1.0
}

/// A custom shape written as a text formula: `Custom(name: ..)` nodes use
/// it by name.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Formula")]
pub(super) struct FormulaRepr {
    pub(super) name: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) params: Vec<FormulaParam>,
    pub(super) distance: String,
}

/// A formula's parameter and the values it accepts: any finite value, or
/// at least `min`, at most `max`.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Param")]
pub(super) struct FormulaParam {
    pub(super) name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) min: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(super) max: Option<f64>,
}

impl FormulaParam {
    /// The rule its bounds state.
    pub(super) fn rule(&self) -> Rule {
        match (self.min, self.max) {
            (None, None) => Rule::Finite,
            (Some(0.0), None) => Rule::NonNegative,
            (lo, hi) => Rule::Range(lo.unwrap_or(-f64::MAX), hi.unwrap_or(f64::MAX)),
        }
    }

    /// The bounds that state `rule`.
    pub(super) fn from_rule(name: &str, rule: Rule) -> Self {
        let (min, max) = match rule {
            Rule::NonNegative => (Some(0.0), None),
            Rule::Positive => (Some(f64::MIN_POSITIVE), None),
            Rule::Range(lo, hi) => (
                (lo > -f64::MAX).then_some(lo),
                (hi < f64::MAX).then_some(hi),
            ),
            // A formula's bounds state only the rules above; a magnitude
            // rule is written as its outer interval.
            Rule::Magnitude(_, hi) => (Some(-hi), Some(hi)),
            Rule::Finite | Rule::Angle | Rule::Direction => (None, None),
        };
        FormulaParam {
            name: name.to_string(),
            min,
            max,
        }
    }
}

pub(super) fn default_lights() -> Vec<Located<Light>> {
    Scene::empty()
        .lights
        .into_iter()
        .map(Located::new)
        .collect()
}

/// A quality preset and the settings that differ from it.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Quality")]
pub(super) struct QualityRepr {
    preset: Preset,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "count::max_steps"
    )]
    max_steps: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    detail: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    hit_epsilon: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    max_distance: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    normal_epsilon: Option<f64>,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "count::ao_samples"
    )]
    ao_samples: Option<u32>,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "count::shadow_steps"
    )]
    shadow_steps: Option<u32>,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "count::fractal_iterations"
    )]
    fractal_iterations: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    precision: Option<Precision>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    over_relaxation: Option<f64>,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "count::supersampling"
    )]
    supersampling: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    fast_math: Option<bool>,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "count::resolution_scale"
    )]
    resolution_scale: Option<u32>,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "count::cone_tile"
    )]
    cone_tile: Option<u32>,
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "count::bounces"
    )]
    bounces: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    brute_step: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    screen_normals: Option<ScreenNormals>,
}

impl QualityRepr {
    /// The preset `quality` differs least from, and the differences.
    pub(super) fn from_quality(quality: &Quality) -> Self {
        let diff = |preset: Preset| {
            let p = preset.quality();
            let differs = |same: bool| (!same).then_some(());
            QualityRepr {
                preset,
                max_steps: differs(p.max_steps == quality.max_steps).map(|()| quality.max_steps),
                detail: differs(p.detail == quality.detail).map(|()| quality.detail),
                hit_epsilon: differs(p.hit_epsilon == quality.hit_epsilon)
                    .map(|()| quality.hit_epsilon),
                max_distance: differs(p.max_distance == quality.max_distance)
                    .map(|()| quality.max_distance),
                normal_epsilon: differs(p.normal_epsilon == quality.normal_epsilon)
                    .map(|()| quality.normal_epsilon),
                ao_samples: differs(p.ao_samples == quality.ao_samples)
                    .map(|()| quality.ao_samples),
                shadow_steps: differs(p.shadow_steps == quality.shadow_steps)
                    .map(|()| quality.shadow_steps),
                // No preset caps iterations: a cap is always written.
                fractal_iterations: quality.fractal_iterations,
                precision: differs(p.precision == quality.precision).map(|()| quality.precision),
                over_relaxation: differs(p.over_relaxation == quality.over_relaxation)
                    .map(|()| quality.over_relaxation),
                supersampling: differs(p.supersampling == quality.supersampling)
                    .map(|()| quality.supersampling),
                fast_math: differs(p.fast_math == quality.fast_math).map(|()| quality.fast_math),
                resolution_scale: differs(p.resolution_scale == quality.resolution_scale)
                    .map(|()| quality.resolution_scale),
                cone_tile: differs(p.cone_tile == quality.cone_tile).map(|()| quality.cone_tile),
                bounces: differs(p.bounces == quality.bounces).map(|()| quality.bounces),
                brute_step: differs(p.brute_step == quality.brute_step)
                    .map(|()| quality.brute_step),
                screen_normals: differs(p.screen_normals == quality.screen_normals)
                    .map(|()| quality.screen_normals),
            }
        };
        Preset::ALL
            .into_iter()
            .rev()
            .map(diff)
            .min_by_key(QualityRepr::changes)
            .expect("four presets")
    }

    pub(super) fn changes(&self) -> usize {
        [
            self.max_steps.is_some(),
            self.detail.is_some(),
            self.hit_epsilon.is_some(),
            self.max_distance.is_some(),
            self.normal_epsilon.is_some(),
            self.ao_samples.is_some(),
            self.shadow_steps.is_some(),
            self.fractal_iterations.is_some(),
            self.precision.is_some(),
            self.over_relaxation.is_some(),
            self.supersampling.is_some(),
            self.fast_math.is_some(),
            self.resolution_scale.is_some(),
            self.cone_tile.is_some(),
            self.bounces.is_some(),
            self.brute_step.is_some(),
            self.screen_normals.is_some(),
        ]
        .into_iter()
        .filter(|&b| b)
        .count()
    }

    pub(super) fn to_quality(&self) -> Quality {
        let p = self.preset.quality();
        Quality {
            max_steps: self.max_steps.unwrap_or(p.max_steps),
            detail: self.detail.unwrap_or(p.detail),
            hit_epsilon: self.hit_epsilon.unwrap_or(p.hit_epsilon),
            max_distance: self.max_distance.unwrap_or(p.max_distance),
            normal_epsilon: self.normal_epsilon.unwrap_or(p.normal_epsilon),
            ao_samples: self.ao_samples.unwrap_or(p.ao_samples),
            shadow_steps: self.shadow_steps.unwrap_or(p.shadow_steps),
            fractal_iterations: self.fractal_iterations.or(p.fractal_iterations),
            precision: self.precision.unwrap_or(p.precision),
            over_relaxation: self.over_relaxation.unwrap_or(p.over_relaxation),
            supersampling: self.supersampling.unwrap_or(p.supersampling),
            fast_math: self.fast_math.unwrap_or(p.fast_math),
            resolution_scale: self.resolution_scale.unwrap_or(p.resolution_scale),
            cone_tile: self.cone_tile.unwrap_or(p.cone_tile),
            bounces: self.bounces.unwrap_or(p.bounces),
            brute_step: self.brute_step.unwrap_or(p.brute_step),
            screen_normals: self.screen_normals.unwrap_or(p.screen_normals),
        }
    }
}

pub(super) type Child = Box<Located<NodeRepr>>;

pub(super) fn twelve() -> u32 {
    12
}
pub(super) fn two() -> Param {
    Param::Value(2.0)
}
pub(super) fn three() -> Param {
    Param::Value(3.0)
}
pub(super) fn four() -> Param {
    Param::Value(4.0)
}
pub(super) fn zero() -> Param {
    Param::Value(0.0)
}
pub(super) fn half() -> Param {
    Param::Value(0.5)
}
pub(super) fn one() -> Param {
    Param::Value(1.0)
}
pub(super) fn sixteen_steps() -> u32 {
    16
}
pub(super) fn twelve_steps() -> u32 {
    12
}
pub(super) fn sixteen() -> Param {
    Param::Value(16.0)
}

/// A material as written in a file: only the values that differ from
/// [`Material::default`] need be named.
#[derive(Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields, rename = "Material")]
pub(super) struct MaterialRepr {
    #[serde(skip_serializing_if = "Option::is_none")]
    roughness: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    specular: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    shininess: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    subsurface: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    scatter_depth: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    reflectivity: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    transparency: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    ior: Option<Param>,
    #[serde(skip_serializing_if = "Option::is_none")]
    emission: Option<Param>,
}

/// A palette: one of the named ones, or a gradient of `(position, (r,
/// g, b))` stops in linear RGB.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Palette")]
pub(super) enum PaletteRepr {
    Fire,
    Ocean,
    Viridis,
    Magma,
    Copper,
    Rainbow,
    Grey,
    Gradient(Vec<(f64, [f64; 3])>),
}

impl PaletteRepr {
    pub(super) fn from_palette(p: &Palette) -> Self {
        match p.name() {
            Some("fire") => PaletteRepr::Fire,
            Some("ocean") => PaletteRepr::Ocean,
            Some("viridis") => PaletteRepr::Viridis,
            Some("magma") => PaletteRepr::Magma,
            Some("copper") => PaletteRepr::Copper,
            Some("rainbow") => PaletteRepr::Rainbow,
            Some("grey") => PaletteRepr::Grey,
            _ => PaletteRepr::Gradient(p.stops().to_vec()),
        }
    }

    pub(super) fn to_palette(&self) -> Palette {
        let named = |n: &str| Palette::named(n).expect("a named palette");
        match self {
            PaletteRepr::Fire => named("fire"),
            PaletteRepr::Ocean => named("ocean"),
            PaletteRepr::Viridis => named("viridis"),
            PaletteRepr::Magma => named("magma"),
            PaletteRepr::Copper => named("copper"),
            PaletteRepr::Rainbow => named("rainbow"),
            PaletteRepr::Grey => named("grey"),
            PaletteRepr::Gradient(stops) => Palette::gradient(stops.iter().copied()),
        }
    }
}

impl MaterialRepr {
    pub(super) fn from_material(m: &Material) -> Self {
        let defaults = Material::default();
        let [a, b, c, d, e, f, g, h, i] = std::array::from_fn(|i| {
            let (value, default) = (m.values()[i], defaults.values()[i]);
            (value != default).then(|| value.clone())
        });
        MaterialRepr {
            roughness: a,
            specular: b,
            shininess: c,
            subsurface: d,
            scatter_depth: e,
            reflectivity: f,
            transparency: g,
            ior: h,
            emission: i,
        }
    }

    pub(super) fn to_material(&self) -> Material {
        let defaults = Material::default();
        let given = [
            &self.roughness,
            &self.specular,
            &self.shininess,
            &self.subsurface,
            &self.scatter_depth,
            &self.reflectivity,
            &self.transparency,
            &self.ior,
            &self.emission,
        ];
        Material::from_values(std::array::from_fn(|i| {
            given[i]
                .clone()
                .unwrap_or_else(|| defaults.values()[i].clone())
        }))
    }
}

/// A node as written in a file.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Node")]
pub(super) enum NodeRepr {
    Sphere {
        radius: Param,
    },
    Cuboid {
        half_extents: Param3,
    },
    RoundBox {
        half_extents: Param3,
        radius: Param,
    },
    Torus {
        major_radius: Param,
        minor_radius: Param,
    },
    Cylinder {
        radius: Param,
        half_height: Param,
    },
    Capsule {
        a: Param3,
        b: Param3,
        radius: Param,
    },
    Plane {
        normal: Param3,
        offset: Param,
    },
    Octahedron {
        size: Param,
    },
    OctahedronBound {
        size: Param,
    },
    CappedCone {
        half_height: Param,
        bottom_radius: Param,
        top_radius: Param,
    },
    HexPrism {
        radius: Param,
        half_height: Param,
    },
    RoundCone {
        half_height: Param,
        bottom_radius: Param,
        top_radius: Param,
    },
    Link {
        half_length: Param,
        major_radius: Param,
        minor_radius: Param,
    },
    CutSphere {
        radius: Param,
        height: Param,
    },
    SolidAngle {
        angle: Param,
        radius: Param,
    },
    CappedTorus {
        angle: Param,
        major_radius: Param,
        minor_radius: Param,
    },
    Triangle {
        a: Param3,
        b: Param3,
        c: Param3,
        thickness: Param,
    },
    Quad {
        a: Param3,
        b: Param3,
        c: Param3,
        d: Param3,
        thickness: Param,
    },
    Pyramid {
        half_base: Param,
        height: Param,
    },
    Rhombus {
        half_x: Param,
        half_z: Param,
        half_height: Param,
        radius: Param,
    },
    TriPrism {
        radius: Param,
        half_height: Param,
    },
    RoundedCylinder {
        radius: Param,
        half_height: Param,
        rounding: Param,
    },
    Cone {
        radius: Param,
        height: Param,
    },
    InfiniteCylinder {
        radius: Param,
    },
    InfiniteCone {
        angle: Param,
    },
    CutHollowSphere {
        radius: Param,
        height: Param,
        thickness: Param,
    },
    DeathStar {
        radius: Param,
        carve_radius: Param,
        carve_distance: Param,
    },
    BoxFrame {
        half_extents: Param3,
        thickness: Param,
    },
    CylinderBetween {
        a: Param3,
        b: Param3,
        radius: Param,
    },
    ConeBetween {
        a: Param3,
        b: Param3,
        radius_a: Param,
        radius_b: Param,
    },
    RoundConeBetween {
        a: Param3,
        b: Param3,
        radius_a: Param,
        radius_b: Param,
    },
    Extrude {
        profile: Profile,
        half_height: Param,
    },
    Revolve {
        profile: Profile,
        #[serde(default = "zero")]
        offset: Param,
    },
    Ellipsoid {
        radii: Param3,
    },
    Mandelbulb {
        power: Param,
        #[serde(default = "twelve", deserialize_with = "count::iterations")]
        iterations: u32,
        #[serde(default = "two")]
        bailout: Param,
    },
    Menger {
        #[serde(deserialize_with = "count::iterations")]
        iterations: u32,
        #[serde(default = "three")]
        scale: Param,
    },
    Julia {
        c: [Param; 4],
        #[serde(default = "twelve", deserialize_with = "count::iterations")]
        iterations: u32,
        #[serde(default = "four")]
        bailout: Param,
        #[serde(default = "zero")]
        slice_w: Param,
    },
    Sierpinski {
        #[serde(deserialize_with = "count::iterations")]
        iterations: u32,
        #[serde(default = "two")]
        scale: Param,
    },
    Mandelbox {
        scale: Param,
        #[serde(default = "half")]
        min_radius: Param,
        #[serde(default = "one")]
        fixed_radius: Param,
        #[serde(default = "one")]
        fold_limit: Param,
        #[serde(default = "sixteen_steps", deserialize_with = "count::iterations")]
        iterations: u32,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        julia: Option<[Param; 3]>,
    },
    /// Each setting left out takes the published preset's
    /// ([`PseudoKleinian::new`](crate::scene::PseudoKleinian::new)).
    PseudoKleinian {
        #[serde(default, skip_serializing_if = "Option::is_none")]
        fold_size: Option<[Param; 3]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        inversion: Option<Param>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        offset: Option<[Param; 3]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        thickness: Option<Param>,
        #[serde(
            default,
            skip_serializing_if = "Option::is_none",
            deserialize_with = "count::optional_iterations"
        )]
        iterations: Option<u32>,
    },
    /// Each setting left out takes the classic one of the fold
    /// ([`Kifs::new`](crate::scene::Kifs::new)).
    Kifs {
        fold: KifsFold,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        scale: Option<Param>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        offset: Option<[Param; 3]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        rotate_before: Option<[Param; 3]>,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        rotate_after: Option<[Param; 3]>,
        #[serde(
            default,
            skip_serializing_if = "Option::is_none",
            deserialize_with = "count::optional_iterations"
        )]
        iterations: Option<u32>,
    },
    Hybrid {
        stages: Vec<HybridStage>,
        #[serde(default = "twelve_steps", deserialize_with = "count::iterations")]
        iterations: u32,
        #[serde(default = "sixteen")]
        bailout: Param,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        safety: Option<Param>,
    },
    Translate {
        offset: Param3,
        child: Child,
    },
    Rotate {
        axis: DVec3,
        angle: Param,
        child: Child,
    },
    Scale {
        factor: Param,
        child: Child,
    },
    Mirror {
        axis: Axis,
        child: Child,
    },
    Round {
        radius: Param,
        child: Child,
    },
    Onion {
        thickness: Param,
        child: Child,
    },
    Elongate {
        extents: Param3,
        child: Child,
    },
    Repeat {
        period: Param3,
        child: Child,
    },
    RepeatLimited {
        period: Param3,
        #[serde(deserialize_with = "count::limit")]
        limit: [u32; 3],
        child: Child,
    },
    Twist {
        rate: Param,
        child: Child,
    },
    Bend {
        rate: Param,
        child: Child,
    },
    Color {
        color: Param3,
        child: Child,
    },
    Glow {
        color: Param3,
        strength: Param,
        child: Child,
    },
    Material {
        material: MaterialRepr,
        child: Child,
    },
    OrbitTrap {
        trap: Trap,
        palette: PaletteRepr,
        #[serde(default = "zero")]
        near: Param,
        #[serde(default = "one")]
        far: Param,
        child: Child,
    },
    Union(Vec<Located<NodeRepr>>),
    Subtract {
        a: Child,
        b: Child,
    },
    Intersect {
        a: Child,
        b: Child,
    },
    SmoothUnion {
        k: Param,
        a: Child,
        b: Child,
    },
    SmoothSubtract {
        k: Param,
        a: Child,
        b: Child,
    },
    SmoothIntersect {
        k: Param,
        a: Child,
        b: Child,
    },
    Cut {
        a: Child,
        b: Child,
    },
    CutPlane {
        normal: Param3,
        offset: Param,
        child: Child,
    },
    SmoothCut {
        k: Param,
        a: Child,
        b: Child,
    },
    Custom {
        name: String,
        args: Vec<Param>,
    },
}
