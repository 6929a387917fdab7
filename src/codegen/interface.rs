//! The kernel interface, defined once: the argument lists of the kernels
//! and the layouts of the camera and light buffers.
//!
//! The generated header turns these tables into `#define`s
//! (`RENDER_TILE_ARGS`, `CAMERA_ORIGIN`, `LIGHT_STRIDE`, ...), which
//! the render kernel (`kernels/march.cl`, `shade.cl`, `optics.cl`,
//! `paths.cl`, `render.cl`) and `kernels/eval.cl` use in place of positions and
//! offsets of their own, and the executor binds arguments and packs buffers
//! from the same tables. Neither side can drift from the other.
//!
//! Without the `opencl` feature there is no executor: only the kernel's
//! half (the declarations) is used, and the host's half lies idle.
#![cfg_attr(not(feature = "opencl"), allow(dead_code))]

use std::fmt::Write as _;

/// A field of a packed buffer of reals: where it starts and how many reals
/// it spans.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct Field {
    /// The name the kernel sees, after the buffer's prefix
    /// (`CAMERA_ORIGIN`).
    pub name: &'static str,
    /// The index of its first real.
    pub offset: usize,
    /// How many reals it spans (3 for a vector).
    pub len: usize,
}

const fn field(name: &'static str, offset: usize, len: usize) -> Field {
    Field { name, offset, len }
}

/// The camera buffer (`camera` argument of `render_tile`).
pub mod camera {
    use super::{Field, field};

    /// The ray origin (perspective) or the image centre (orthographic),
    /// relative to the program's origin.
    pub const ORIGIN: Field = field("ORIGIN", 0, 3);
    /// 1 for an orthographic camera, 0 for a perspective one.
    pub const ORTHOGRAPHIC: Field = field("ORTHOGRAPHIC", 3, 1);
    /// The unit vector to the right of the image.
    pub const RIGHT: Field = field("RIGHT", 4, 3);
    /// Half the image width at unit distance (orthographic: in scene
    /// units).
    pub const HALF_WIDTH: Field = field("HALF_WIDTH", 7, 1);
    /// The unit vector up the image.
    pub const UP: Field = field("UP", 8, 3);
    /// Half the image height, likewise.
    pub const HALF_HEIGHT: Field = field("HALF_HEIGHT", 11, 1);
    /// The unit view direction.
    pub const FORWARD: Field = field("FORWARD", 12, 3);
    /// The pixel footprint at distance 0 along a ray.
    pub const FOOTPRINT_BASE: Field = field("FOOTPRINT_BASE", 15, 1);
    /// The growth of the pixel footprint per unit along a ray.
    pub const FOOTPRINT_PER_UNIT: Field = field("FOOTPRINT_PER_UNIT", 16, 1);
    /// The image's width in pixels (the size the camera maps; the kernel's
    /// `width` is the size it renders, smaller by the resolution scale).
    pub const IMAGE_WIDTH: Field = field("IMAGE_WIDTH", 17, 1);
    /// The image's height in pixels.
    pub const IMAGE_HEIGHT: Field = field("IMAGE_HEIGHT", 18, 1);
    /// Image pixels per rendered pixel along each axis
    /// ([`Quality::resolution_scale`](crate::quality::Quality::resolution_scale)).
    pub const PIXEL_SCALE: Field = field("PIXEL_SCALE", 19, 1);
    /// The lens shift: how far the image window is moved along `RIGHT` and
    /// `UP`, in units of `HALF_HEIGHT` (off-axis stereo eyes).
    pub const SHIFT: Field = field("SHIFT", 20, 2);
    /// The thin lens's radius in scene units (0: a pinhole).
    pub const APERTURE: Field = field("APERTURE", 22, 1);
    /// The distance along `FORWARD` at which the thin lens is in focus.
    pub const FOCUS_DISTANCE: Field = field("FOCUS_DISTANCE", 23, 1);
    /// Every field, in buffer order.
    pub const FIELDS: [Field; 15] = [
        ORIGIN,
        ORTHOGRAPHIC,
        RIGHT,
        HALF_WIDTH,
        UP,
        HALF_HEIGHT,
        FORWARD,
        FOOTPRINT_BASE,
        FOOTPRINT_PER_UNIT,
        IMAGE_WIDTH,
        IMAGE_HEIGHT,
        PIXEL_SCALE,
        SHIFT,
        APERTURE,
        FOCUS_DISTANCE,
    ];
    /// Reals in the buffer.
    pub const LEN: usize = 24;
}

/// One light's entry in the light buffer (`lights` argument of
/// `render_tile`), repeated every [`STRIDE`](light::STRIDE) reals.
pub mod light {
    use super::{Field, field};

    /// The unit direction towards a directional light, or a point or
    /// sphere light's position relative to the program's origin.
    pub const POSITION: Field = field("POSITION", 0, 3);
    /// [`KIND_DIRECTIONAL`], [`KIND_POINT`], [`KIND_SPHERE`] or
    /// [`KIND_RECT`].
    pub const KIND: Field = field("KIND", 3, 1);
    /// Colour times intensity, linear RGB.
    pub const RADIANCE: Field = field("RADIANCE", 4, 3);
    /// The penumbra softness (0: hard shadows).
    pub const SOFTNESS: Field = field("SOFTNESS", 7, 1);
    /// A sphere light's radius (0 for the others).
    pub const RADIUS: Field = field("RADIUS", 8, 1);
    /// A rectangle light's half side `u` (0 for the others).
    pub const EDGE_U: Field = field("EDGE_U", 9, 3);
    /// A rectangle light's half side `v`: it shines along `u × v`.
    pub const EDGE_V: Field = field("EDGE_V", 12, 3);
    /// Every field, in buffer order.
    pub const FIELDS: [Field; 7] = [POSITION, KIND, RADIANCE, SOFTNESS, RADIUS, EDGE_U, EDGE_V];
    /// Reals per light.
    pub const STRIDE: usize = 15;
    /// The `KIND` of a directional light.
    pub const KIND_DIRECTIONAL: f64 = 0.0;
    /// The `KIND` of a point light (falling off with `1/r²`).
    pub const KIND_POINT: f64 = 1.0;
    /// The `KIND` of a sphere light: a point light to direct lighting, a
    /// ball of light to global illumination.
    pub const KIND_SPHERE: f64 = 2.0;
    /// The `KIND` of a rectangle light: a point light on its lit side to
    /// direct lighting, a rectangle of light to global illumination.
    pub const KIND_RECT: f64 = 3.0;
}

/// One pixel's entry in the shading-layer buffer (`layers` argument of
/// `render_tile`), repeated every [`STRIDE`](layer::STRIDE) floats: what
/// the pixel-centre ray's hit is made of, written when `write_aovs` is
/// [`WRITE_LAYERS`](layer::WRITE_LAYERS).
pub mod layer {
    use super::{Field, field};

    /// World-space position of the hit, relative to the program's origin
    /// (0 on a miss).
    pub const POSITION: Field = field("POSITION", 0, 3);
    /// Linear base colour at the hit, orbit-trap tint included (0 on a
    /// miss).
    pub const ALBEDO: Field = field("ALBEDO", 3, 3);
    /// Ambient occlusion at the hit: 1 open, 0 fully occluded (1 without
    /// the effect, 0 on a miss).
    pub const OCCLUSION: Field = field("OCCLUSION", 6, 1);
    /// The lights' visibility at the hit, weighted by what each could add:
    /// 1 lit, 0 in shadow (1 without shadows or lights, 0 on a miss).
    pub const SHADOW: Field = field("SHADOW", 7, 1);
    /// The orbit-trap value at the hit that tints a fractal, or that a
    /// palette reads on a fractal it paints; 1 on other surfaces (0 on a
    /// miss).
    pub const TRAP: Field = field("TRAP", 8, 1);
    /// Every field, in buffer order.
    pub const FIELDS: [Field; 5] = [POSITION, ALBEDO, OCCLUSION, SHADOW, TRAP];
    /// Floats per pixel.
    pub const STRIDE: usize = 9;
    /// `write_aovs` for the depth, hit, normal and cost outputs alone.
    pub const WRITE_AOVS: i32 = 1;
    /// `write_aovs` for those, the shading layers and the linear colour.
    pub const WRITE_LAYERS: i32 = 2;
}

/// The environment buffer (`environment` argument of `render_tile`), in
/// floats whatever the precision: the header's fields, then from
/// [`TEXELS`](environment::TEXELS) the image's texels (RGB, row by row from
/// the top), the marginal distribution of its rows (`height + 1`
/// cumulative sums from 0 to 1 of each row's luminance times the sine of
/// its polar angle), each row's conditional distribution of texels
/// (`width + 1` cumulative sums from 0 to 1 each), and the irradiance
/// map's texels (RGB). A scene without an environment passes the header
/// alone, all zeros.
pub mod environment {
    use super::{Field, field};

    /// The image's width in texels.
    pub const WIDTH: Field = field("WIDTH", 0, 1);
    /// The image's height in texels.
    pub const HEIGHT: Field = field("HEIGHT", 1, 1);
    /// The cosine of the image's turn about +Y.
    pub const ROTATION_COS: Field = field("ROTATION_COS", 2, 1);
    /// The sine of the image's turn about +Y.
    pub const ROTATION_SIN: Field = field("ROTATION_SIN", 3, 1);
    /// What every radiance is multiplied by.
    pub const INTENSITY: Field = field("INTENSITY", 4, 1);
    /// The sum of the texels' weights before normalising (0: nothing to
    /// sample; the light is black).
    pub const TOTAL: Field = field("TOTAL", 5, 1);
    /// The irradiance map's width in texels.
    pub const IRRADIANCE_WIDTH: Field = field("IRRADIANCE_WIDTH", 6, 1);
    /// The irradiance map's height in texels.
    pub const IRRADIANCE_HEIGHT: Field = field("IRRADIANCE_HEIGHT", 7, 1);
    /// Every field, in buffer order.
    pub const FIELDS: [Field; 8] = [
        WIDTH,
        HEIGHT,
        ROTATION_COS,
        ROTATION_SIN,
        INTENSITY,
        TOTAL,
        IRRADIANCE_WIDTH,
        IRRADIANCE_HEIGHT,
    ];
    /// Where the image's texels start: the header's length.
    pub const TEXELS: usize = 8;

    /// Floats in the buffer of a `width` × `height` image with an
    /// `irradiance_width` × `irradiance_height` irradiance map.
    #[must_use]
    pub const fn len(width: usize, height: usize, irradiance: (usize, usize)) -> usize {
        TEXELS
            + 3 * width * height
            + (height + 1)
            + height * (width + 1)
            + 3 * irradiance.0 * irradiance.1
    }
}

/// The arguments of the rendering kernel `render_tile`, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)] // Each is described by its declaration in `RENDER_TILE`.
#[non_exhaustive]
pub enum RenderArg {
    Params,
    Camera,
    Lights,
    LightCount,
    Width,
    Height,
    X0,
    Y0,
    TileWidth,
    TileHeight,
    WriteAovs,
    Rgba,
    Depth,
    Hit,
    Normals,
    Steps,
    Evaluations,
    Starts,
    Pass,
    Accumulation,
    RefineOnly,
    Refine,
    BruteDepths,
    BruteSteps,
    Linear,
    Layers,
    Environment,
}

/// `render_tile`'s declarations, in argument order: the one list of its
/// arguments. `pass` is -1 for a frame of its own; from 0 up it is the
/// index of a progressive pass, which adds its samples to `accumulation`
/// (linear colour sums, reset by pass 0) and writes their mean to `rgba`.
/// With `refine_only` set, only the pixels `refine` marks are rendered
/// (adaptive supersampling's further passes). `brute_depths` and
/// `brute_steps` are what `brute_depths` left for this pass (read only by
/// programs that march inside shapes by brute force). With `write_aovs`
/// at [`layer::WRITE_LAYERS`], every pass writes the exposed linear colour
/// and the fraction of samples that hit to `linear`, and the first the
/// shading layers to `layers`. `environment` holds the environment light
/// ([`environment`]).
pub const RENDER_TILE: [(RenderArg, &str); 27] = [
    (RenderArg::Params, "__global const real* params"),
    (RenderArg::Camera, "__global const real* camera"),
    (RenderArg::Lights, "__global const real* lights"),
    (RenderArg::LightCount, "const int light_count"),
    (RenderArg::Width, "const int width"),
    (RenderArg::Height, "const int height"),
    (RenderArg::X0, "const int x0"),
    (RenderArg::Y0, "const int y0"),
    (RenderArg::TileWidth, "const int tile_w"),
    (RenderArg::TileHeight, "const int tile_h"),
    (RenderArg::WriteAovs, "const int write_aovs"),
    (RenderArg::Rgba, "__global uchar4* rgba"),
    (RenderArg::Depth, "__global float* depth"),
    (RenderArg::Hit, "__global uchar* hit_mask"),
    (RenderArg::Normals, "__global float* normals"),
    (RenderArg::Steps, "__global uint* steps"),
    (RenderArg::Evaluations, "__global uint* evaluations"),
    (RenderArg::Starts, "__global const float* starts"),
    (RenderArg::Pass, "const int pass"),
    (RenderArg::Accumulation, "__global float4* accumulation"),
    (RenderArg::RefineOnly, "const int refine_only"),
    (RenderArg::Refine, "__global const uchar* refine"),
    (RenderArg::BruteDepths, "__global const float* brute_depths"),
    (RenderArg::BruteSteps, "__global const uint* brute_steps"),
    (RenderArg::Linear, "__global float4* linear"),
    (RenderArg::Layers, "__global float* layers"),
    (RenderArg::Environment, "__global const float* environment"),
];

/// The arguments of the coarse pass `cone_starts` (see
/// [`Quality::cone_tile`](crate::quality::Quality::cone_tile)), in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)] // Each is described by its declaration in `CONE_STARTS`.
#[non_exhaustive]
pub enum ConeArg {
    Params,
    Camera,
    Width,
    Height,
    Starts,
}

/// `cone_starts`' declarations, in argument order.
pub const CONE_STARTS: [(ConeArg, &str); 5] = [
    (ConeArg::Params, "__global const real* params"),
    (ConeArg::Camera, "__global const real* camera"),
    (ConeArg::Width, "const int width"),
    (ConeArg::Height, "const int height"),
    (ConeArg::Starts, "__global float* starts"),
];

impl ConeArg {
    /// The argument's position in `cone_starts`.
    #[must_use]
    pub fn index(self) -> u32 {
        position(&CONE_STARTS, &self)
    }
}

/// The arguments of `brute_depths`, the pass that marches every sample of
/// a progressive pass before `render_tile` shades it, in programs that
/// march inside shapes by brute force (see
/// [`Quality::brute_step`](crate::quality::Quality::brute_step)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)] // Each is described by its declaration in `BRUTE_DEPTHS`.
#[non_exhaustive]
pub enum BruteArg {
    Params,
    Camera,
    Width,
    Height,
    Pass,
    Depths,
    Steps,
}

/// `brute_depths`' declarations, in argument order. Sample `s` of the
/// pass at pixel `(x, y)` is written at `(s · height + y) · width + x`:
/// its depth along its ray (on a miss, `-1` less the angle of the ray's
/// nearest miss, which drives the glow: a negative value) and its distance
/// evaluations.
pub const BRUTE_DEPTHS: [(BruteArg, &str); 7] = [
    (BruteArg::Params, "__global const real* params"),
    (BruteArg::Camera, "__global const real* camera"),
    (BruteArg::Width, "const int width"),
    (BruteArg::Height, "const int height"),
    (BruteArg::Pass, "const int pass"),
    (BruteArg::Depths, "__global float* depths"),
    (BruteArg::Steps, "__global uint* steps"),
];

impl BruteArg {
    /// The argument's position in `brute_depths`.
    #[must_use]
    pub fn index(self) -> u32 {
        position(&BRUTE_DEPTHS, &self)
    }
}

/// The position of `arg` in a kernel's list of declarations.
fn position<A: PartialEq>(list: &[(A, &str)], arg: &A) -> u32 {
    let i = list
        .iter()
        .position(|(a, _)| a == arg)
        .expect("every argument is in its kernel's list");
    u32::try_from(i).expect("few arguments")
}

impl RenderArg {
    /// The argument's position in `render_tile`.
    #[must_use]
    pub fn index(self) -> u32 {
        position(&RENDER_TILE, &self)
    }
}

/// The arguments of the point-evaluation kernel `eval_points`, in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)] // Each is described by its declaration in `EVAL_POINTS`.
#[non_exhaustive]
pub enum EvalArg {
    Points,
    Params,
    Out,
    Count,
}

/// `eval_points`' declarations, in argument order.
pub const EVAL_POINTS: [(EvalArg, &str); 4] = [
    (EvalArg::Points, "__global const real4* points"),
    (EvalArg::Params, "__global const real* params"),
    (EvalArg::Out, "__global real4* out"),
    (EvalArg::Count, "const uint count"),
];

/// `eval_distances`' declarations, in argument order: the arguments of
/// `eval_points`, but only `DE` is written, one real per point.
pub const EVAL_DISTANCES: [(EvalArg, &str); 4] = [
    (EvalArg::Points, "__global const real4* points"),
    (EvalArg::Params, "__global const real* params"),
    (EvalArg::Out, "__global real* out"),
    (EvalArg::Count, "const uint count"),
];

/// Reals `eval_points` writes per point: `(DE, DE_shade, trap, orbit)`
/// (the trap that tints, and the trap the layers show) then `(colour, 0)`.
pub const EVAL_OUT_STRIDE: usize = 8;

/// The arguments of the grid-evaluation kernel `eval_grid`, in order: `DE`
/// at every sample of cubic blocks of a regular grid (meshes, volumes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)] // Each is described by its declaration in `EVAL_GRID`.
#[non_exhaustive]
pub enum GridArg {
    Blocks,
    Grid,
    Side,
    Params,
    Out,
    Count,
}

/// `eval_grid`'s declarations, in argument order. `blocks` holds each
/// block's first sample as grid indices; `grid` the grid's origin and
/// spacing `(x, y, z, spacing)`; `side` the samples along a block's edge.
/// Sample `s` of block `b` is written to `out[b·side³ + s]`, `s = x + side
/// (y + side z)`.
pub const EVAL_GRID: [(GridArg, &str); 6] = [
    (GridArg::Blocks, "__global const int4* blocks"),
    (GridArg::Grid, "__global const real* grid"),
    (GridArg::Side, "const uint side"),
    (GridArg::Params, "__global const real* params"),
    (GridArg::Out, "__global real* out"),
    (GridArg::Count, "const uint count"),
];

/// The header's `#define`s of the interface of `target`'s kernel: its
/// argument list and the layouts of its buffers.
pub(crate) fn defines(target: super::Target) -> String {
    let mut out = String::new();
    let w = &mut out;
    match target {
        super::Target::Render => {
            let _ = writeln!(w, "#define RENDER_TILE_ARGS \\\n    {}", args(&RENDER_TILE));
            let _ = writeln!(w, "#define CONE_STARTS_ARGS \\\n    {}", args(&CONE_STARTS));
            let _ = writeln!(
                w,
                "#define BRUTE_DEPTHS_ARGS \\\n    {}",
                args(&BRUTE_DEPTHS)
            );
            for f in camera::FIELDS {
                let _ = writeln!(w, "#define CAMERA_{} {}", f.name, f.offset);
            }
            for f in light::FIELDS {
                let _ = writeln!(w, "#define LIGHT_{} {}", f.name, f.offset);
            }
            let _ = writeln!(w, "#define LIGHT_STRIDE {}", light::STRIDE);
            for f in layer::FIELDS {
                let _ = writeln!(w, "#define LAYER_{} {}", f.name, f.offset);
            }
            let _ = writeln!(w, "#define LAYER_STRIDE {}", layer::STRIDE);
            let _ = writeln!(w, "#define WRITE_LAYERS {}", layer::WRITE_LAYERS);
            for f in environment::FIELDS {
                let _ = writeln!(w, "#define ENV_{} {}", f.name, f.offset);
            }
            let _ = writeln!(w, "#define ENV_TEXELS {}", environment::TEXELS);
        }
        super::Target::Evaluate => {
            let _ = writeln!(w, "#define EVAL_POINTS_ARGS \\\n    {}", args(&EVAL_POINTS));
            let _ = writeln!(w, "#define EVAL_OUT_STRIDE {EVAL_OUT_STRIDE}");
            let _ = writeln!(
                w,
                "#define EVAL_DISTANCES_ARGS \\\n    {}",
                args(&EVAL_DISTANCES)
            );
            let _ = writeln!(w, "#define EVAL_GRID_ARGS \\\n    {}", args(&EVAL_GRID));
        }
    }
    out
}

/// The buffer layouts a WGSL render module reads, as constants
/// (`const CAMERA_ORIGIN: uint = 0u;`): the same tables as the OpenCL
/// program's `#define`s.
pub(crate) fn wgsl_constants() -> String {
    let mut out = String::new();
    let w = &mut out;
    for f in camera::FIELDS {
        let _ = writeln!(w, "const CAMERA_{}: uint = {}u;", f.name, f.offset);
    }
    for f in light::FIELDS {
        let _ = writeln!(w, "const LIGHT_{}: uint = {}u;", f.name, f.offset);
    }
    let _ = writeln!(w, "const LIGHT_STRIDE: uint = {}u;", light::STRIDE);
    for f in environment::FIELDS {
        let _ = writeln!(w, "const ENV_{}: uint = {}u;", f.name, f.offset);
    }
    let _ = writeln!(w, "const ENV_TEXELS: uint = {}u;", environment::TEXELS);
    out
}

/// A kernel's declarations as the body of a multi-line `#define`.
fn args<A>(list: &[(A, &str)]) -> String {
    let decls: Vec<&str> = list.iter().map(|(_, d)| *d).collect();
    decls.join(", \\\n    ")
}

/// Writes `values` into `field` of `buffer` (of a layout above).
///
/// # Panics
/// If `values` is not as long as the field.
pub fn put(buffer: &mut [f64], field: Field, values: &[f64]) {
    assert_eq!(
        values.len(),
        field.len,
        "field {} spans {} reals",
        field.name,
        field.len
    );
    buffer[field.offset..field.offset + field.len].copy_from_slice(values);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fields tile their buffer: in order, without gaps or overlaps.
    #[test]
    fn layouts_tile_their_buffers() {
        for (fields, len) in [
            (&camera::FIELDS[..], camera::LEN),
            (&light::FIELDS[..], light::STRIDE),
            (&layer::FIELDS[..], layer::STRIDE),
        ] {
            let mut next = 0;
            for f in fields {
                assert_eq!(
                    f.offset, next,
                    "{} starts where the last field ends",
                    f.name
                );
                next += f.len;
            }
            assert_eq!(next, len);
        }
        assert_eq!(RenderArg::Evaluations.index(), 16);
        assert_eq!(RenderArg::Params.index(), 0);
    }
}
