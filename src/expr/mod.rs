//! The expression IR: each formula written once, in Rust.
//!
//! A formula is a function generic over [`Num`]. The same function runs
//!
//! - in `f64` or `f32`: the CPU reference, the mesher, the testing toolkit;
//! - in [`Interval`]s: a range that holds every value over a box, for
//!   bounds;
//! - in [`Var`]s, under [`trace`]: a [`Program`] of scalar operations and
//!   `select`s, which a [`Printer`] writes as a kernel function
//!   ([`OpenCl`] C, or [`Wgsl`] for WebGPU).
//!
//! A program has no loop, no recursion and no side effect, so it always
//! terminates, and a printer writes only its operations and literals, so
//! no text a user gave can reach the kernel as source.
//!
//! ```
//! use fractal_sdf::expr::{Interval, Num, OpenCl, Printer, Shape, Signature, trace};
//! use fractal_sdf::expr::{V3, v3};
//!
//! // One formula...
//! fn rounded_sphere<N: Num>(p: V3<N>, r: N) -> N {
//!     p.length() - r
//! }
//!
//! // ...as a value,
//! assert_eq!(rounded_sphere(v3(3.0_f64, 4.0, 0.0), 1.0), 4.0);
//! // as a range over a box,
//! let x = Interval::new(2.0, 3.0);
//! let d = rounded_sphere(v3(x, Interval::point(0.0), Interval::point(0.0)), Interval::point(1.0));
//! assert!(d.contains(1.0) && d.contains(2.0));
//! // and as OpenCL C.
//! let program = trace(4, |a| vec![rounded_sphere(v3(a[0], a[1], a[2]), a[3])]);
//! let params = [("p", Shape::Vec3), ("r", Shape::Scalar)];
//! let signature = Signature::new("sd_ball", &params, Shape::Scalar);
//! let source = OpenCl.function(&signature, &program).unwrap();
//! assert!(source.contains("return length(p) - r;"), "{source}");
//! ```

mod bound;
mod count;
mod interval;
mod num;
mod ops;
mod print;
mod program;
mod text;
mod trace;
mod vector;

pub use bound::surface_box;
pub use count::{CALL_FLOPS, Counted, Operations, counting};

/// A distance formula written once, for custom shapes
/// ([`CustomShape::formula`](crate::scene::CustomShape::formula)): one
/// generic function that the CPU reference runs in `f64`, bounds run in
/// intervals and code generation traces into OpenCL.
///
/// Value-dependent choices are [`Num::select`]s; a loop with a fixed count
/// is fine (it is unrolled when traced).
pub trait Distance: Send + Sync + 'static {
    /// The distance at `p` with the shape's parameter values `params`
    /// (in declaration order).
    fn distance<N: Num>(&self, p: V3<N>, params: &[N]) -> N;
}

impl Distance for Formula {
    fn distance<N: Num>(&self, p: V3<N>, params: &[N]) -> N {
        Formula::distance(self, p, params)
    }
}
pub use interval::{Interval, Maybe};
pub use num::{DERIVATIVE_CAP, Logic, MAGNITUDE_CAP, MAX_LOOP_STEPS, Num, REAL_TINY, Step};
pub use ops::{Binary, Unary};
pub use print::{Inline, OpenCl, Printer, Shape, Signature, Unprintable, Wgsl};
pub use program::{Loop, Op, Program, ValueId};
pub use text::{
    FUNCTIONS, Formula, FormulaError, MAX_DEPTH, MAX_ITERATIONS, MAX_LENGTH, MAX_NESTING,
};
pub use trace::{Var, VarBool, trace};
pub use vector::{V3, v3};
