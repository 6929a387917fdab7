//! Progressive passes until the image is quiet enough: a stopping rule
//! from the passes' own noise ([`Renderer::render_converged`]).

use super::{Error, Frame, Renderer, Result};
use crate::quality::{Effects, display};

/// When [`Renderer::render_converged`] stops adding passes.
///
/// The mean of `n` passes has an error whose spread falls as `1 / sqrt(n)`
/// where the samples are independent (path-traced light, a lens, glow
/// through a jittered pixel). The mean of all `n` less the mean of the
/// first `m` is `(n - m) / n` times the difference of two independent
/// means, of `m` and of `n - m` passes, whose variance is
/// `σ² (1 / m + 1 / (n - m))`: its variance is `σ² (n - m) / (n m)`, and
/// its root mean square over the image times `sqrt(m / (n - m))` (1 for
/// `m = n / 2`) estimates the noise `σ / sqrt(n)` of the mean of `n`
/// itself, with no reference image. It is taken on the displayed colour
/// (exposure, tone curve and gamma applied), so the rule speaks of what
/// the eye sees, in `[0, 1]` display units: `1 / 255` is one step of an
/// 8-bit image.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct StopRule {
    /// The noise to reach: the estimated root mean square error of the
    /// displayed colour over the image's pixels and channels, in `[0, 1]`
    /// display units (`1 / 255` is one 8-bit step). Above 0.
    pub noise: f64,
    /// The most passes, whatever the noise (at least 2; at most
    /// [`Renderer::MAX_PROGRESSIVE_SAMPLES`] samples per pixel).
    pub max_passes: u32,
}

impl StopRule {
    /// Stops at an estimated noise of `noise` (in display units), or after
    /// `max_passes` passes.
    #[must_use]
    pub fn new(noise: f64, max_passes: u32) -> Self {
        StopRule { noise, max_passes }
    }

    fn validate(&self) -> Result<()> {
        if !(self.noise.is_finite() && self.noise > 0.0) {
            return Err(Error::Quality {
                setting: "noise",
                value: self.noise,
                expected: "finite and > 0 (display units: 1/255 is one 8-bit step)".into(),
            });
        }
        if self.max_passes < 2 {
            return Err(Error::Quality {
                setting: "max_passes",
                value: f64::from(self.max_passes),
                expected: "2 at least (the noise is estimated from two means)".into(),
            });
        }
        Ok(())
    }
}

/// What [`Renderer::render_converged`] reached.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ConvergedFrame {
    /// The mean of the passes, with every layer of
    /// [`Renderer::render_layers`].
    pub frame: Frame,
    /// The passes rendered.
    pub passes: u32,
    /// The noise estimated after the last of them, in display units.
    pub noise: f64,
}

impl ConvergedFrame {
    /// Whether the noise reached the rule's, rather than the passes
    /// running out.
    #[must_use]
    pub fn reached(&self, rule: &StopRule) -> bool {
        self.noise <= rule.noise
    }
}

impl Renderer {
    /// Renders progressive passes ([`Renderer::render_progressive_layers`])
    /// until the image's estimated noise is at most `rule.noise`, or
    /// `rule.max_passes` have run. The noise is estimated after 2, 4, 8,
    /// ... passes and after the last, from the difference between the
    /// mean of all the passes and the mean at the power of two before
    /// (see [`StopRule`]): for independent samples it is the root
    /// mean square error of the image, without a reference. It starts from
    /// the first pass, and continues no earlier passes.
    ///
    /// ```no_run
    /// use fractal_sdf::prelude::*;
    /// use fractal_sdf::quality::GlobalIllumination;
    /// use fractal_sdf::render::{RenderOptions, Renderer, StopRule};
    ///
    /// let effects = Effects::default().global_illumination(GlobalIllumination::default());
    /// let options = RenderOptions::default().quality(Quality::preview()).effects(effects);
    /// let mut renderer = Renderer::with_options(&fractal_sdf::gallery::csg(), &options)?;
    /// // Two 8-bit steps of noise, at most 256 passes.
    /// let done = renderer.render_converged(320, 240, &StopRule::new(2.0 / 255.0, 256))?;
    /// println!("{} passes, noise {:.4}", done.passes, done.noise);
    /// # Ok::<(), fractal_sdf::Error>(())
    /// ```
    ///
    /// # Errors
    /// [`Error::Quality`] for a noise that is not finite and above 0, or
    /// fewer than 2 passes; else as [`Renderer::render_progressive`].
    pub fn render_converged(
        &mut self,
        width: u32,
        height: u32,
        rule: &StopRule,
    ) -> Result<ConvergedFrame> {
        rule.validate()?;
        let last = rule.max_passes.min(self.most_passes()).max(2);
        // The linear colour already holds the exposure.
        let effects = self.options.effects.exposure(0.0);
        self.restart_progressive();
        // The displayed mean at the last power of two, and its passes.
        let mut earlier: Option<(Vec<[f32; 3]>, u32)> = None;
        let mut noise = f64::INFINITY;
        loop {
            let frame = self.render_progressive_layers(width, height)?;
            let passes = self.progressive_passes();
            if !(passes.is_power_of_two() || passes >= last) {
                continue;
            }
            let shown = displayed(&frame, &effects);
            if let Some((before, m)) = &earlier {
                let (n, m) = (f64::from(passes), f64::from(*m));
                noise = rms_difference(before, &shown) * (m / (n - m)).sqrt();
            }
            if passes >= last || noise <= rule.noise {
                return Ok(ConvergedFrame {
                    frame,
                    passes,
                    noise,
                });
            }
            earlier = Some((shown, passes));
        }
    }
}

/// The displayed colour of every pixel of `frame`'s linear layer.
fn displayed(frame: &Frame, effects: &Effects) -> Vec<[f32; 3]> {
    let layers = frame
        .layers
        .as_ref()
        .expect("progressive layers hold the linear colour");
    layers
        .linear
        .iter()
        .map(|&[r, g, b, _]| display([r, g, b], effects))
        .collect()
}

/// The root mean square of the channels' differences.
fn rms_difference(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let sum: f64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| f64::from(p[c] - q[c]).powi(2)))
        .sum();
    #[allow(clippy::cast_precision_loss)] // pixel counts are far below 2^52
    let count = (3 * a.len().max(1)) as f64;
    (sum / count).sqrt()
}
