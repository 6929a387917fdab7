//! What builds and what does not: lowering, code generation and program
//! builds are counted per process, so the tests here take turns (`serial`).
//!
//! One test binary per concern: each file here is a module.

#[path = "../gpu/mod.rs"]
mod gpu;

mod compile_once;
mod render_dynamic;

use std::sync::{Mutex, MutexGuard, PoisonError};

static SERIAL: Mutex<()> = Mutex::new(());

/// A turn: the tests here read process-wide counts, so they run one at a
/// time.
fn serial() -> MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(PoisonError::into_inner)
}
