//! Adaptive supersampling: more samples only where a pixel differs from
//! its neighbours.

use image::RgbaImage;

use super::aov::Frame;

/// What an adaptive frame found and drew (see
/// [`Renderer::render_adaptive`](super::Renderer::render_adaptive)).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct AdaptiveFrame {
    /// The image: the mean of every pass's samples where a pixel was
    /// refined, the first pass's elsewhere.
    pub image: RgbaImage,
    /// The first pass with its outputs (depth, hit, normal, cost), which
    /// chose the pixels to refine.
    pub first: Frame,
    /// Which rendered pixels took the further passes, row-major (the
    /// rendered size is the image's divided by
    /// [`Quality::resolution_scale`](crate::quality::Quality::resolution_scale)).
    pub refined: Vec<bool>,
    /// The passes: 1 everywhere, this many where refined.
    pub passes: u32,
}

impl AdaptiveFrame {
    /// The fraction of rendered pixels refined.
    #[must_use]
    pub fn refined_fraction(&self) -> f64 {
        if self.refined.is_empty() {
            return 0.0;
        }
        #[allow(clippy::cast_precision_loss)]
        let fraction =
            self.refined.iter().filter(|&&r| r).count() as f64 / self.refined.len() as f64;
        fraction
    }

    /// Distance evaluations per pixel, estimated: the first pass's, plus
    /// each refined pixel's first-pass cost for each further pass (a
    /// further pass traces the same pixel at new points, at about the same
    /// cost). With a resolution scale, refined pixels are counted at the
    /// mean pixel's cost.
    #[must_use]
    pub fn mean_evaluations(&self) -> f64 {
        let first = &self.first.evaluations;
        if first.is_empty() {
            return 0.0;
        }
        #[allow(clippy::cast_precision_loss)]
        let refined_cost = if first.len() == self.refined.len() {
            first
                .iter()
                .zip(&self.refined)
                .filter(|(_, r)| **r)
                .map(|(&e, _)| f64::from(e))
                .sum::<f64>()
                / first.len() as f64
        } else {
            self.refined_fraction() * self.first.mean_evaluations()
        };
        self.first.mean_evaluations() + refined_cost * f64::from(self.passes - 1)
    }
}

/// How far apart two neighbouring pixels' first samples may be before
/// both are refined.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct EdgeThresholds {
    /// The largest difference in any colour channel, in 8-bit levels.
    pub color: u8,
    /// The smallest cosine between the normals of two hits.
    pub normal_cosine: f32,
    /// The largest difference in depth between two hits, relative to the
    /// nearer one.
    pub depth: f32,
}

impl Default for EdgeThresholds {
    /// 8 levels, 25° and 10%.
    fn default() -> Self {
        EdgeThresholds {
            color: 8,
            normal_cosine: 0.906,
            depth: 0.1,
        }
    }
}

/// The pixels of `frame` that differ from a 4-neighbour: one hits and the
/// other misses, or both hit with normals or depths apart, or their colours
/// differ by more than the thresholds. Both pixels of such a pair are
/// marked.
#[must_use]
pub fn edges(frame: &Frame, limits: &EdgeThresholds) -> Vec<bool> {
    let (w, h) = (frame.width() as usize, frame.height() as usize);
    let mut marked = vec![false; w * h];
    let apart = |i: usize, j: usize| {
        if frame.hit[i] != frame.hit[j] {
            return true;
        }
        let rgba = frame.image.as_raw();
        let color = (0..3).any(|c| rgba[4 * i + c].abs_diff(rgba[4 * j + c]) > limits.color);
        if color || !frame.hit[i] {
            return color;
        }
        let (n, m) = (frame.normal[i], frame.normal[j]);
        let cosine = n[0] * m[0] + n[1] * m[1] + n[2] * m[2];
        let (a, b) = (frame.depth[i], frame.depth[j]);
        cosine < limits.normal_cosine || (a - b).abs() > limits.depth * a.min(b)
    };
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            for j in [(x + 1 < w).then(|| i + 1), (y + 1 < h).then(|| i + w)]
                .into_iter()
                .flatten()
            {
                if apart(i, j) {
                    marked[i] = true;
                    marked[j] = true;
                }
            }
        }
    }
    marked
}
