//! Stereo views: how far apart two eyes are, where their images
//! coincide, and how the pair is laid out in one picture. The eyes are
//! cameras ([`Camera::eyes`]); the renderer draws and lays them out
//! (`Renderer::render_stereo`).

use serde::{Deserialize, Serialize};

use super::Camera;
use crate::error::Result;

/// How the two eyes' images share one picture.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[non_exhaustive]
pub enum StereoLayout {
    /// Red–cyan glasses: the left eye's brightness in red, the right
    /// eye's green and blue (a half-colour anaglyph, which keeps most
    /// colour and avoids the rivalry of saturated reds). One image of the
    /// requested size.
    Anaglyph,
    /// Left eye on the left, right eye on the right: twice the requested
    /// width (for parallel viewing and side-by-side displays).
    SideBySide,
    /// Left eye above, right eye below: twice the requested height.
    OverUnder,
}

impl StereoLayout {
    /// Every layout, in the order the viewer cycles through them.
    pub const ALL: [StereoLayout; 3] = [
        StereoLayout::Anaglyph,
        StereoLayout::SideBySide,
        StereoLayout::OverUnder,
    ];

    /// The layout's name on the command line and in the viewer.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            StereoLayout::Anaglyph => "anaglyph",
            StereoLayout::SideBySide => "side-by-side",
            StereoLayout::OverUnder => "over-under",
        }
    }

    /// The layout called `name` ([`StereoLayout::name`]).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|l| l.name() == name)
    }

    /// The picture's size for eyes of `width` × `height` pixels.
    #[must_use]
    pub fn size(self, width: u32, height: u32) -> (u32, u32) {
        match self {
            StereoLayout::Anaglyph => (width, height),
            StereoLayout::SideBySide => (width.saturating_mul(2), height),
            StereoLayout::OverUnder => (width, height.saturating_mul(2)),
        }
    }
}

/// A stereo view: the layout, how far apart the eyes are and at what
/// distance their images coincide.
///
/// ```no_run
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::render::Renderer;
/// use fractal_sdf::scene::{Stereo, StereoLayout};
///
/// let mut renderer = Renderer::new(&fractal_sdf::gallery::mandelbulb(), Quality::preview())?;
/// let picture = renderer.render_stereo(640, 480, &Stereo::new(StereoLayout::Anaglyph))?;
/// # let _ = picture;
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub struct Stereo {
    /// How the eyes share the picture.
    pub layout: StereoLayout,
    /// The distance between the eyes in scene units; `None`: a thirtieth
    /// of the convergence distance, the usual comfortable depth.
    pub eye_separation: Option<f64>,
    /// The distance along the view at which the eyes' images coincide (the
    /// screen's depth); `None`: the camera's focus distance
    /// ([`Camera::focus_distance`]), its target unless set.
    pub convergence: Option<f64>,
}

setters!(Stereo {
    /// Sets [`Stereo::layout`].
    layout: StereoLayout,
});

impl Stereo {
    /// The default eye separation over the convergence distance.
    pub const DEFAULT_SEPARATION_RATIO: f64 = 1.0 / 30.0;

    /// `layout` with the default separation and convergence.
    #[must_use]
    pub fn new(layout: StereoLayout) -> Self {
        Stereo {
            layout,
            eye_separation: None,
            convergence: None,
        }
    }

    /// Sets the eye separation.
    #[must_use]
    pub fn separation(mut self, separation: f64) -> Self {
        self.eye_separation = Some(separation);
        self
    }

    /// Sets the convergence distance.
    #[must_use]
    pub fn convergence(mut self, distance: f64) -> Self {
        self.convergence = Some(distance);
        self
    }

    /// The left and right eyes around `camera`.
    ///
    /// # Errors
    /// As [`Camera::eyes`].
    ///
    /// ```
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::scene::{Stereo, StereoLayout};
    /// let stereo = Stereo::new(StereoLayout::Anaglyph).convergence(f64::NAN);
    /// let err = stereo.eyes(&Camera::default()).unwrap_err().to_string();
    /// assert!(err.contains("convergence distance must be finite and > 0, got NaN"), "{err}");
    /// ```
    pub fn eyes(&self, camera: &Camera) -> Result<[Camera; 2]> {
        let convergence = self.convergence.unwrap_or_else(|| camera.focus_distance());
        let separation = self
            .eye_separation
            .unwrap_or(convergence * Self::DEFAULT_SEPARATION_RATIO);
        camera.eyes(separation, convergence)
    }
}
