//! Frame times: what one frame cost ([`FrameTiming`]), statistics over many
//! frames ([`FrameStats`]), and the render-resolution choice of an
//! interactive view ([`ResolutionScaler`], [`reduced_size`]).

use std::time::Duration;

/// What one rendered frame cost, as the renderer reports it
/// (`render::Renderer::last_timing`, feature `opencl`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub struct FrameTiming {
    /// Time the device spent running the ray-marching kernel, summed over
    /// the frame's tiles. From OpenCL profiling events where the device
    /// reports them (see [`FrameTiming::profiled`]), else the host's wall
    /// time from the first launch until the queue drained.
    pub kernel: Duration,
    /// Time spent copying the outputs from the device to the host.
    pub readback: Duration,
    /// Wall time of the whole frame on the host: uploading the inputs,
    /// launching, waiting and reading back.
    pub total: Duration,
    /// Whether [`FrameTiming::kernel`] comes from profiling events.
    pub profiled: bool,
}

impl FrameTiming {
    /// A frame timed by the host alone, from submitting the work until the
    /// device finished it (the wgpu backend's): the kernel's time and the
    /// frame's, no profiling events.
    #[cfg(feature = "wgpu")]
    pub(crate) fn wall(elapsed: Duration) -> Self {
        FrameTiming {
            kernel: elapsed,
            readback: Duration::ZERO,
            total: elapsed,
            profiled: false,
        }
    }
}

/// Running statistics over frame times: count, total, minimum, maximum,
/// mean, and the frame rates they imply.
///
/// ```
/// use std::time::Duration;
/// use fractal_sdf::view::FrameStats;
///
/// let mut stats = FrameStats::new();
/// for ms in [20, 25, 30] {
///     stats.push(Duration::from_millis(ms));
/// }
/// assert_eq!(stats.count(), 3);
/// assert_eq!(stats.mean(), Some(Duration::from_millis(25)));
/// assert_eq!(stats.max_fps(), Some(50.0)); // 1 / 20 ms
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FrameStats {
    count: u64,
    total: Duration,
    min: Option<Duration>,
    max: Option<Duration>,
}

impl FrameStats {
    /// No frames yet.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one frame's time. The count and the total saturate (at
    /// `u64::MAX` frames and [`Duration::MAX`]) instead of overflowing.
    pub fn push(&mut self, frame: Duration) {
        self.count = self.count.saturating_add(1);
        self.total = self.total.saturating_add(frame);
        self.min = Some(self.min.map_or(frame, |m| m.min(frame)));
        self.max = Some(self.max.map_or(frame, |m| m.max(frame)));
    }

    /// Frames added.
    #[must_use]
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The sum of the frame times.
    #[must_use]
    pub fn total(&self) -> Duration {
        self.total
    }

    /// The shortest frame, if any.
    #[must_use]
    pub fn min(&self) -> Option<Duration> {
        self.min
    }

    /// The longest frame, if any.
    #[must_use]
    pub fn max(&self) -> Option<Duration> {
        self.max
    }

    /// The mean frame time, if any frame was added.
    #[must_use]
    pub fn mean(&self) -> Option<Duration> {
        let n = u32::try_from(self.count).ok().filter(|&n| n > 0)?;
        Some(self.total / n)
    }

    /// Frames per second at the mean frame time.
    #[must_use]
    pub fn mean_fps(&self) -> Option<f64> {
        self.mean().and_then(fps)
    }

    /// Frames per second of the slowest frame.
    #[must_use]
    pub fn min_fps(&self) -> Option<f64> {
        self.max.and_then(fps)
    }

    /// Frames per second of the fastest frame.
    #[must_use]
    pub fn max_fps(&self) -> Option<f64> {
        self.min.and_then(fps)
    }
}

/// Frames per second for a frame time; `None` for a zero time.
#[must_use]
pub fn fps(frame: Duration) -> Option<f64> {
    let s = frame.as_secs_f64();
    (s > 0.0).then(|| 1.0 / s)
}

/// Chooses the resolution of each frame of an interactive view: reduced
/// while the view changes (so moving stays responsive), full once it stops
/// (so the still image is sharp), and nothing at all while a full-size
/// frame is already on screen.
///
/// The reduction is a divisor of both sides, adapted after every reduced
/// frame so that frames take about [`ResolutionScaler::target`].
///
/// ```
/// use std::time::Duration;
/// use fractal_sdf::view::ResolutionScaler;
///
/// let mut s = ResolutionScaler::new(Duration::from_millis(50), 8);
/// assert_eq!(s.next(true), Some(2)); // moving: start at half size
/// s.record(2, Duration::from_millis(200)); // 4x too slow: halve again
/// assert_eq!(s.next(true), Some(4));
/// assert_eq!(s.next(false), Some(1)); // still: one full-size frame
/// assert_eq!(s.next(false), None); // ...then nothing to do
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct ResolutionScaler {
    /// The wanted duration of a reduced frame.
    pub target: Duration,
    /// The largest divisor.
    pub max_divisor: u32,
    divisor: u32,
    sharp: bool,
}

impl ResolutionScaler {
    /// A scaler aiming at `target` per reduced frame, dividing each side by
    /// at most `max_divisor` (at least 1).
    #[must_use]
    pub fn new(target: Duration, max_divisor: u32) -> Self {
        let max_divisor = max_divisor.max(1);
        ResolutionScaler {
            target,
            max_divisor,
            divisor: 2.min(max_divisor),
            sharp: false,
        }
    }

    /// The divisor of the next frame, or `None` if nothing needs drawing.
    /// `changing`: whether the view differs from the last frame (the camera
    /// moved, a parameter is animated, a setting changed).
    pub fn next(&mut self, changing: bool) -> Option<u32> {
        if changing {
            self.sharp = false;
            Some(self.divisor)
        } else if self.sharp {
            None
        } else {
            self.sharp = true;
            Some(1)
        }
    }

    /// Forces a full-size frame next time, even with nothing changing (for
    /// example after the window was resized or uncovered).
    pub fn invalidate(&mut self) {
        self.sharp = false;
    }

    /// Records how long a frame at `divisor` took, and adapts the divisor
    /// of changing frames: the cost of a frame goes with its pixel count,
    /// the inverse square of the divisor.
    pub fn record(&mut self, divisor: u32, took: Duration) {
        if self.target.is_zero() {
            return;
        }
        let divisor = divisor.max(1);
        let ratio = took.as_secs_f64() / self.target.as_secs_f64();
        let ideal = f64::from(divisor) * ratio.sqrt();
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let wanted = ideal.round().clamp(1.0, f64::from(self.max_divisor)) as u32;
        self.divisor = wanted;
    }

    /// The divisor used while the view changes.
    #[must_use]
    pub fn divisor(&self) -> u32 {
        self.divisor
    }
}

/// The size of a frame rendered at `divisor` for a `width` × `height`
/// view: each side divided and rounded up, at least 1.
#[must_use]
pub fn reduced_size(width: u32, height: u32, divisor: u32) -> (u32, u32) {
    let d = divisor.max(1);
    (width.div_ceil(d).max(1), height.div_ceil(d).max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: Duration = Duration::from_millis(1);

    #[test]
    fn stats_track_min_max_mean_and_rates() {
        let mut s = FrameStats::new();
        assert_eq!(s.mean(), None);
        assert_eq!(s.mean_fps(), None);
        assert_eq!(s.min(), None);
        for ms in [40, 10, 25] {
            s.push(ms * MS);
        }
        assert_eq!(s.count(), 3);
        assert_eq!(s.total(), 75 * MS);
        assert_eq!(s.min(), Some(10 * MS));
        assert_eq!(s.max(), Some(40 * MS));
        assert_eq!(s.mean(), Some(25 * MS));
        approx::assert_relative_eq!(s.mean_fps().unwrap(), 40.0, epsilon = 1e-9);
        approx::assert_relative_eq!(s.min_fps().unwrap(), 25.0, epsilon = 1e-9);
        approx::assert_relative_eq!(s.max_fps().unwrap(), 100.0, epsilon = 1e-9);
    }

    #[test]
    fn huge_frame_times_saturate() {
        let mut s = FrameStats::new();
        s.push(Duration::MAX);
        s.push(Duration::MAX);
        assert_eq!(s.total(), Duration::MAX);
        assert_eq!(s.count(), 2);
        assert_eq!(s.max(), Some(Duration::MAX));
        assert_eq!(s.mean(), Some(Duration::MAX / 2));
        assert!(s.mean_fps().unwrap() > 0.0);
    }

    #[test]
    fn a_zero_frame_time_has_no_rate() {
        assert_eq!(fps(Duration::ZERO), None);
        let mut s = FrameStats::new();
        s.push(Duration::ZERO);
        assert_eq!(s.max_fps(), None);
        assert_eq!(s.mean(), Some(Duration::ZERO));
    }

    #[test]
    fn scaler_reduces_while_changing_and_sharpens_once_when_still() {
        let mut s = ResolutionScaler::new(50 * MS, 8);
        assert_eq!(s.next(false), Some(1));
        assert_eq!(s.next(false), None);
        assert_eq!(s.next(true), Some(2));
        assert_eq!(s.next(true), Some(2));
        assert_eq!(s.next(false), Some(1));
        assert_eq!(s.next(false), None);
        s.invalidate();
        assert_eq!(s.next(false), Some(1));
        assert_eq!(s.next(false), None);
    }

    #[test]
    fn scaler_adapts_the_divisor_to_the_target_within_bounds() {
        let mut s = ResolutionScaler::new(50 * MS, 6);
        // 16 times too slow at divisor 2: 4 times fewer pixels per side.
        s.record(2, 800 * MS);
        assert_eq!(s.divisor(), 6, "clamped to max_divisor");
        // Far faster than needed: back to full size.
        s.record(6, MS);
        assert_eq!(s.divisor(), 1);
        // A full-size frame 9 times over the target: a third per side.
        s.record(1, 450 * MS);
        assert_eq!(s.divisor(), 3);
        s.record(3, 50 * MS);
        assert_eq!(s.divisor(), 3, "on target: unchanged");
        assert_eq!(ResolutionScaler::new(MS, 0).max_divisor, 1);
        assert_eq!(ResolutionScaler::new(MS, 1).next(true), Some(1));
    }

    #[test]
    fn reduced_sizes_round_up_and_never_vanish() {
        assert_eq!(reduced_size(640, 480, 1), (640, 480));
        assert_eq!(reduced_size(640, 480, 3), (214, 160));
        assert_eq!(reduced_size(5, 1, 8), (1, 1));
        assert_eq!(reduced_size(5, 3, 0), (5, 3));
    }
}
