//! Knighty's pseudo-Kleinian fractal: box folds and sphere inversions, the
//! group a Kleinian limit set comes from, without its proof of one.

use super::param::Param;
use super::*;

/// Knighty's pseudo-Kleinian fractal: each iteration folds the point into
/// the box of half extents [`fold_size`](PseudoKleinian::fold_size) (a box
/// fold per axis, `z → 2 clamp(z, −b, b) − z`), inverts it in the sphere of
/// squared radius [`inversion`](PseudoKleinian::inversion) where it lies
/// within that sphere (`z → z · inversion / |z|²`), and adds
/// [`offset`](PseudoKleinian::offset). The drawn set is the points whose
/// orbit ends, after `iterations` steps, in Knighty's shape
/// `ρ·|z| < thickness` (with `ρ = √(x² + y²)`: a slab about the plane
/// `z = 0` thinning away from the `z` axis, and a tube about that axis
/// thinning away from the plane).
///
/// The set is not bounded: far from the origin the folds only reflect (each
/// iteration brings a far coordinate at most twice the fold size nearer),
/// the orbit never reaches the inversion sphere, and the set thins into
/// the plane `z = 0` and the `z` axis. Its detail is near the origin:
/// frame it from inside, or intersect it with a shape. A point within
/// 1e-6 of the origin after a fold is inverted as if it were that far,
/// so that its image stays finite in single precision.
///
/// Distance estimate: Knighty's, `(ρ·|z| − thickness) / √(|z|² +
/// thickness)` of the orbit's end over the running derivative (each
/// inversion's stretch `inversion / |z|²` multiplied in; the folds
/// stretch nothing), times a measured safety factor
/// ([`cpu::sdf::PSEUDO_KLEINIAN_SAFETY`](crate::cpu::sdf::PSEUDO_KLEINIAN_SAFETY)),
/// since it is not a proven bound; negative exactly inside. The trap is
/// the orbit's smallest radius over the inversion sphere's, at most 1.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PseudoKleinian<S = Param> {
    /// The box fold's half extents along `x`, `y` and `z`, each greater
    /// than 0 (Knighty's `CSize`).
    pub fold_size: [S; 3],
    /// The squared radius of the inversion sphere, in `[0.05, 4]`
    /// (Knighty's `Size`).
    pub inversion: S,
    /// The constant added in each iteration, finite (Knighty's `C`).
    pub offset: [S; 3],
    /// The thickness of the final shape, in `[0.0001, 2]` (Knighty's
    /// `TThickness`).
    pub thickness: S,
    /// Iterations, 0 (the final shape alone) to [`MAX_ESCAPE_ITERATIONS`].
    pub iterations: u32,
}

impl From<PseudoKleinian> for Node {
    fn from(f: PseudoKleinian) -> Self {
        Kind::PseudoKleinian(f).into()
    }
}

impl Default for PseudoKleinian {
    fn default() -> Self {
        PseudoKleinian::new()
    }
}

/// Knighty's pseudo-Kleinian fractal with the settings of his published
/// preset: fold sizes `(0.92436, 0.90756, 0.92436)`, inversion 1, no
/// offset, thickness 0.01, 8 iterations. Build a [`PseudoKleinian`] to
/// change them.
#[must_use]
pub fn pseudo_kleinian() -> Node {
    PseudoKleinian::new().into()
}

impl PseudoKleinian {
    /// The settings of [`pseudo_kleinian`].
    #[must_use]
    pub fn new() -> Self {
        PseudoKleinian {
            fold_size: [0.92436.into(), 0.90756.into(), 0.92436.into()],
            inversion: 1.0.into(),
            offset: [0.0.into(), 0.0.into(), 0.0.into()],
            thickness: 0.01.into(),
            iterations: 8,
        }
    }

    /// Sets the box fold's half extents.
    #[must_use]
    pub fn fold_size(mut self, size: [impl Into<Param>; 3]) -> Self {
        self.fold_size = size.map(Into::into);
        self
    }

    /// Sets the inversion sphere's squared radius.
    #[must_use]
    pub fn inversion(mut self, size: impl Into<Param>) -> Self {
        self.inversion = size.into();
        self
    }

    /// Sets the constant added in each iteration.
    #[must_use]
    pub fn offset(mut self, c: [impl Into<Param>; 3]) -> Self {
        self.offset = c.map(Into::into);
        self
    }

    /// Sets the final shape's thickness.
    #[must_use]
    pub fn thickness(mut self, thickness: impl Into<Param>) -> Self {
        self.thickness = thickness.into();
        self
    }

    /// Sets the iteration count.
    #[must_use]
    pub fn iterations(mut self, iterations: u32) -> Self {
        self.iterations = iterations;
        self
    }
}

impl<S> PseudoKleinian<S> {
    /// The fractal with every parameter converted by `f`.
    pub(crate) fn map<S2>(&self, mut f: impl FnMut(&S) -> S2) -> PseudoKleinian<S2> {
        PseudoKleinian {
            fold_size: [
                f(&self.fold_size[0]),
                f(&self.fold_size[1]),
                f(&self.fold_size[2]),
            ],
            inversion: f(&self.inversion),
            offset: [f(&self.offset[0]), f(&self.offset[1]), f(&self.offset[2])],
            thickness: f(&self.thickness),
            iterations: self.iterations,
        }
    }
}
