//! Stopping a render between tiles: a token another thread can trip, and
//! the check the renderer makes before each tile launch.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// A flag that stops a render between tiles. Clone it, hand the clone to
/// [`RenderOptions::cancel`](super::RenderOptions::cancel), and call
/// [`CancelToken::cancel`] from any thread: the render launches no further
/// tile, waits for the tiles already launched and returns
/// [`Error::Cancelled`](crate::Error::Cancelled).
///
/// A tile is one kernel launch, which OpenCL cannot interrupt: a
/// cancellation takes effect when the tiles in flight finish. A scene whose
/// distance function runs long (a custom shape with a long or endless
/// loop) is therefore bounded per tile, not per image: a smaller
/// [`RenderOptions::tile_size`](super::RenderOptions::tile_size) makes each
/// launch shorter and a cancellation quicker. A launch that never returns
/// cannot be stopped at all.
///
/// A token stays cancelled: every later render with it returns at once,
/// until [`CancelToken::reset`].
///
/// ```no_run
/// use fractal_sdf::prelude::*;
/// use fractal_sdf::render::{CancelToken, RenderOptions, Renderer};
///
/// let token = CancelToken::new();
/// let options = RenderOptions::default()
///     .cancel(Some(token.clone()))
///     .tile_size(64);
/// let mut renderer = Renderer::with_options(&Scene::new(sphere(1.0)), &options)?;
/// let stopper = std::thread::spawn(move || token.cancel());
/// match renderer.render(1920, 1080) {
///     Ok(_) | Err(Error::Cancelled { .. }) => {}
///     Err(other) => return Err(other),
/// }
/// stopper.join().unwrap();
/// # Ok::<(), fractal_sdf::Error>(())
/// ```
#[derive(Debug, Clone, Default)]
pub struct CancelToken(Arc<AtomicBool>);

impl CancelToken {
    /// A token that is not cancelled.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Asks every render holding this token to stop before its next tile.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::SeqCst);
    }

    /// Whether [`CancelToken::cancel`] was called (and not reset since).
    #[must_use]
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }

    /// Makes the token usable again.
    pub fn reset(&self) {
        self.0.store(false, Ordering::SeqCst);
    }
}

impl PartialEq for CancelToken {
    /// The same token (clones of one another).
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}
