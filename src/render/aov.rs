//! A rendered frame with its arbitrary output values (AOVs).

use image::RgbaImage;

/// An image plus, per pixel, what the ray through the pixel centre found.
///
/// Every vector is row-major with `width × height` entries, index
/// `y * width + x` (see [`Frame::index`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Frame {
    /// The shaded image.
    pub image: RgbaImage,
    /// Distance along the pixel-centre ray to the surface, in scene units;
    /// `f32::INFINITY` where the ray missed.
    pub depth: Vec<f32>,
    /// Whether the pixel-centre ray reached a surface.
    pub hit: Vec<bool>,
    /// World-space unit normal at the hit; `[0, 0, 0]` where the ray missed.
    pub normal: Vec<[f32; 3]>,
    /// Distance evaluations of the primary march, including the location
    /// of the hit, summed over the pixel's colour samples (a per-pixel cost
    /// map).
    pub steps: Vec<u32>,
    /// Every distance evaluation the pixel's colour cost, summed over its
    /// samples: the primary march, the normal (4), the colour lookup (1),
    /// ambient occlusion and shadow rays, and for a ray that starts inside
    /// a solid the step onto its surface (1). With supersampling, the extra
    /// march through the pixel centre that the other outputs need is not
    /// counted.
    pub evaluations: Vec<u32>,
    /// Where the pixel's rays started along the ray: the distance the
    /// coarse pass found free in front of its tile
    /// ([`Quality::cone_tile`](crate::quality::Quality::cone_tile)), 0
    /// without one.
    pub start: Vec<f32>,
    /// The shading layers and the linear colour, where the frame was
    /// rendered with them ([`Renderer::render_layers`](crate::render::Renderer::render_layers)).
    pub layers: Option<Layers>,
}

/// What a frame's pixels are made of, for compositing: the colour before
/// the display transform, and what the pixel-centre ray's hit is made of.
///
/// Every vector is row-major like [`Frame`]'s. A pixel whose centre ray
/// missed has position, albedo, occlusion, shadow, trap, object and
/// material 0. The layers
/// other than the colour describe the pixel-centre ray, as the depth and
/// normal do.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Layers {
    /// The pixel's linear colour scaled by the exposure
    /// ([`Effects::exposure`](crate::quality::Effects::exposure)), before
    /// the tone curve and gamma: the mean over its samples (and passes),
    /// not clipped at 1, background included. `[3]` is the fraction of
    /// those samples whose ray hit a surface (the coverage, a matte of
    /// what is not background; the colour is not premultiplied by it).
    pub linear: Vec<[f32; 4]>,
    /// World-space position of the hit.
    pub position: Vec<[f32; 3]>,
    /// Linear base colour at the hit (the node's colour, orbit-trap tint
    /// included), before any light.
    pub albedo: Vec<[f32; 3]>,
    /// Ambient occlusion at the hit: 1 open, towards 0 in creases (1 with
    /// the effect off).
    pub occlusion: Vec<f32>,
    /// How lit the hit is by the lights that face it, each weighted by
    /// the most it could add: 1 lit, 0 in shadow (1 with shadows off or
    /// no light facing it).
    pub shadow: Vec<f32>,
    /// The orbit-trap value at the hit: the one in `[0, 1]` that tints a
    /// fractal's colour, or on a fractal an
    /// [`OrbitColoring`](crate::scene::OrbitColoring) paints through a
    /// palette, the trap value the palette reads (the orbit's nearest
    /// approach to its trap, before the palette's range); 1 on surfaces
    /// that are not fractals.
    pub trap: Vec<f32>,
    /// Which shape the hit belongs to: `k` for shape `k − 1` of
    /// [`Ir::objects`](crate::ir::Ir::objects) (the shapes in the order
    /// the scene writes them), 0 on a miss. Across a boolean the nearer
    /// operand's shape, as the colour is the nearer operand's. Empty until
    /// [`Renderer::identify`](crate::render::Renderer::identify) fills it.
    pub object: Vec<u32>,
    /// Which material the hit has: `k` for material node `k − 1` of
    /// [`Ir::materials`](crate::ir::Ir::materials), 0 for the default
    /// material and on a miss. Empty until
    /// [`Renderer::identify`](crate::render::Renderer::identify) fills it.
    pub material: Vec<u32>,
}

/// Which outputs a launch writes, from least to most.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Outputs {
    /// The 8-bit image alone.
    Image,
    /// With depth, hit, normal and the costs.
    Aovs,
    /// With those, the shading layers and the linear colour.
    Layers,
}

impl Outputs {
    /// The kernel's `write_aovs` argument.
    pub(crate) fn write_aovs(self) -> i32 {
        match self {
            Outputs::Image => 0,
            Outputs::Aovs => crate::codegen::interface::layer::WRITE_AOVS,
            Outputs::Layers => crate::codegen::interface::layer::WRITE_LAYERS,
        }
    }
}

impl Frame {
    /// The image width in pixels.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.image.width()
    }

    /// The image height in pixels.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.image.height()
    }

    /// The index of pixel `(x, y)` in the AOV vectors.
    ///
    /// # Panics
    /// If the pixel is outside the image.
    #[must_use]
    pub fn index(&self, x: u32, y: u32) -> usize {
        assert!(
            x < self.width() && y < self.height(),
            "pixel ({x}, {y}) is outside the {}x{} frame",
            self.width(),
            self.height()
        );
        y as usize * self.width() as usize + x as usize
    }

    /// The mean of [`Frame::evaluations`]: distance evaluations per pixel.
    #[must_use]
    pub fn mean_evaluations(&self) -> f64 {
        mean(&self.evaluations)
    }

    /// The mean of [`Frame::steps`]: primary-march steps per pixel.
    #[must_use]
    pub fn mean_steps(&self) -> f64 {
        mean(&self.steps)
    }

    /// The fraction of pixels whose centre ray hit a surface.
    #[must_use]
    pub fn coverage(&self) -> f64 {
        if self.hit.is_empty() {
            return 0.0;
        }
        #[allow(clippy::cast_precision_loss)]
        let covered = self.hit.iter().filter(|&&h| h).count() as f64 / self.hit.len() as f64;
        covered
    }
}

fn mean(values: &[u32]) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    #[allow(clippy::cast_precision_loss)]
    let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / values.len() as f64;
    mean
}
