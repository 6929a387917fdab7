//! The fractals' parameters: the Mandelbulb, the Menger sponge, the
//! quaternion Julia set, the Sierpinski tetrahedron, the Mandelbox and the
//! kaleidoscopic IFS, each a node of the scene through `From` and validated
//! with the rest of its node.

use super::param::Param;
use super::*;

/// The Mandelbulb: the escape-time fractal of the "triplex" power map
/// `z -> z^power + p` in spherical coordinates (White and Nylander).
///
/// Extent: the set lies in the ball of radius `2^(1/(power - 1))` about the
/// origin, for any iterations and bailout (beyond it every orbit grows);
/// that is about 1.104 for power 8, which reaches it, and 2 for power 2.
///
/// Distance estimate: `0.5 * ln(r) * r / dr` with the running derivative
/// `dr`, a bound (it does not overestimate within the sampled tests). The
/// orbit trap is the smallest `|z|` the orbit reaches, mapped to `[0, 1]`.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Mandelbulb<S = Param> {
    /// The power of the map; at least 2. An integer 8 is the classic bulb.
    pub power: S,
    /// Escape-time iterations, 1 to [`MAX_ESCAPE_ITERATIONS`].
    pub iterations: u32,
    /// The escape radius; at least 1 (2 is usual).
    pub bailout: S,
}

/// The Menger sponge as a folding (KIFS) fractal in the cube `[-1, 1]^3`.
///
/// Extent: for every scale and level the sponge fills that cube: it lies in
/// it and keeps its eight corners. Scale 3 is the classic sponge; other
/// scales in `[2, 4]` give related sponges. Distance: the exact box distance of the folded point divided by
/// `scale^iterations`, a bound. Iterations 0 is the solid cube.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Menger<S = Param> {
    /// Folding levels, 0 to [`MAX_FOLD_ITERATIONS`].
    pub iterations: u32,
    /// The scale factor of each level, in `[2, 4]`; 3 is the classic sponge.
    pub scale: S,
}

/// A quaternion Julia set `z -> z^2 + c`, sliced at `w = slice_w`: the
/// points whose orbits stay within the bailout (for a bailout of at least
/// `1/2 + sqrt(1/4 + |c|)`, the radius of the ball that holds the set, the
/// whole filled Julia set).
///
/// Extent: the 4D set lies in the ball of radius
/// `R = (1 + sqrt(1 + 4|c|)) / 2` about the origin (beyond it every orbit
/// grows), so the slice lies in the 3D ball of radius `sqrt(R^2 - w^2)`
/// and is empty for `|w| > R`. `R` is 1 for `c = 0` (the unit ball) and 2
/// for `|c| = 2`.
///
/// Distance: a bound for every valid `c`, whether the set is connected or
/// dust and `c` baked or dynamic (proven, or measured where said so);
/// [`cpu::sdf::julia`](crate::cpu::sdf::julia) has the details.
///
/// - Far away (beyond 1.5 ball radii): 0.9 times the distance to the ball.
/// - Where it is safe, the escape-time estimate `0.5 |z| ln|z| / |dz|`:
///   the bailout is at least 2.5 ball radii and the critical orbit `0, c,
///   c^2 + c, ...` stays within 0.9 for the iterations used and 2 more.
///   Measured, not proven: below the distance at points that escape within
///   the iterations; at points that do not, at most a thin band above 0
///   (about 0.06 with 4 iterations, 0.016 with 8, 0.009 with 12).
/// - Elsewhere, no more than a proven bound: positive only where the orbit
///   proves escape, 0 or less where it stays within the bailout. That is
///   the case when `c' = c.x + i |(c.y, c.z, c.w)|` is outside the
///   Mandelbrot set (its complex Julia set is then dust, and the
///   escape-time estimate overestimates by any factor near the set) or the
///   critical orbit reaches beyond the unit ball (as for a cycle out there,
///   which makes that estimate positive inside the set). The bound is
///   smaller than the escape-time estimate, most of all near the set, so
///   such sets take more steps and are drawn a little fatter.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct QuaternionJulia<S = Param> {
    /// The constant `c` as (x, y, z, w).
    pub c: [S; 4],
    /// Escape-time iterations, 1 to [`MAX_ESCAPE_ITERATIONS`].
    pub iterations: u32,
    /// The escape radius; at least 1 (4 is usual).
    pub bailout: S,
    /// The w coordinate of the 3D slice through the 4D set.
    pub slice_w: S,
}

/// The Sierpinski tetrahedron as a folding (KIFS) fractal, with vertices at
/// `(1,1,1)`, `(-1,-1,1)`, `(1,-1,-1)` and `(-1,1,-1)`.
///
/// Extent: for every scale and level it lies in the solid tetrahedron of
/// those vertices (inside the cube `[-1, 1]^3`) and keeps the four
/// vertices. Scale 2 is the classic gasket; other scales in `[1.5, 4]` give related
/// sets. Distance: a tetrahedron bound of the folded point divided by
/// `scale^iterations`, a bound. Iterations 0 is the solid tetrahedron.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Sierpinski<S = Param> {
    /// Folding levels, 0 to [`MAX_FOLD_ITERATIONS`].
    pub iterations: u32,
    /// The scale factor of each level, in `[1.5, 4]`; 2 is the classic.
    pub scale: S,
}

/// The Mandelbox (Tom Lowe): each iteration folds the point into the box
/// `[-fold_limit, fold_limit]^3` (a box fold), scales it up by
/// `(fixed_radius / min_radius)^2` inside `min_radius` or inverts it in the
/// sphere of `fixed_radius` between the two radii (a sphere fold),
/// multiplies it by `scale` and adds `p` (or, in Julia mode, a constant).
///
/// Extent: the set lies in a cube centred on the origin, of half side
/// `2 L (s + 1) / (s − 1)` for a positive scale `s` and `2 L` for a
/// negative one with the fold limit `L` (6 and 2 for the classic 2 and
/// −1.5), and `(2 L |s| + |c|∞) / (|s| − 1)` in Julia mode
/// ([`math::mandelbox_extent`](crate::math::mandelbox_extent)
/// has the proof). An orbit past a threshold of the same kind never
/// returns, so the drawn set (the points whose orbit is still within it
/// after `iterations` steps) shrinks towards the Mandelbox as the count
/// grows.
///
/// Distance estimate: the orbit's distance past that threshold over the
/// running derivative, times a measured safety factor
/// ([`cpu::sdf::MANDELBOX_SAFETY`](crate::cpu::sdf::MANDELBOX_SAFETY)),
/// since this estimate is not a proven bound; continuous, and negative
/// inside. The trap is the orbit's smallest radius over `fixed_radius`.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Mandelbox<S = Param> {
    /// The scale of each iteration, of magnitude in `[1.1, 4]`; 2 and −1.5
    /// are classic.
    pub scale: S,
    /// The sphere fold's inner radius, greater than 0 (0.5 is usual); taken
    /// as `fixed_radius` where it is larger.
    pub min_radius: S,
    /// The sphere fold's outer radius, greater than 0 (1 is usual).
    pub fixed_radius: S,
    /// The box fold's half side, greater than 0 (1 is usual).
    pub fold_limit: S,
    /// Iterations, 1 to [`MAX_ESCAPE_ITERATIONS`].
    pub iterations: u32,
    /// Julia mode: the constant added in each iteration instead of `p`.
    pub julia: Option<[S; 3]>,
}

/// The mirrors a kaleidoscopic IFS ([`Kifs`]) folds space with in each
/// iteration: all of them planes through the origin, except the Menger
/// fold's last.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
#[non_exhaustive]
pub enum KifsFold {
    /// The three mirrors `x = −y`, `x = −z`, `y = −z` of the regular
    /// tetrahedron with a vertex at `(1, 1, 1)`: with offset `(1, 1, 1)` and
    /// scale 2, the Sierpinski tetrahedron.
    Tetrahedral,
    /// The cube's mirrors (`|x|`, `|y|`, `|z|`, then the coordinates
    /// sorted, largest first): with offset `(1, 0, 0)` and scale 2, the
    /// Sierpinski octahedron.
    Octahedral,
    /// The icosahedron's mirrors (Knighty's three rounds of `|·|` and the
    /// two planes normal to `(−φ, φ − 1, 1)` and `(1, −φ, φ + 1)`): with the
    /// vertex offset `(0.8507, 0.5257, 0)` and scale `φ² ≈ 2.618`, a
    /// Sierpinski icosahedron.
    Icosahedral,
    /// The octahedral fold, and after the scale a mirror across the plane
    /// `z = offset.z (scale − 1) / 2`, with no shift along `z`: with offset
    /// `(1, 1, 1)` and scale 3, the Menger sponge.
    Menger,
}

/// A kaleidoscopic iterated function system (Knighty): each iteration
/// turns the point by `rotate_before`, folds it by the mirrors of
/// [`fold`](Kifs::fold), turns it by `rotate_after`, and scales it by
/// `scale` about `offset` (`z → scale · z − offset · (scale − 1)`).
///
/// Extent and estimate, both proven
/// ([`math::kifs_radius`](crate::math::kifs_radius)): an orbit that leaves
/// the ball of radius `R` (`|offset|`; for the Menger fold
/// `|(offset.x, offset.y)| + |offset.z|`) never returns, so the drawn set
/// (the points whose orbit is within `R` after `iterations` steps) shrinks
/// as the count grows, towards the fractal; each iteration stretches
/// distances by at most `scale`, so `(|z_n| − R) / scale^n` never
/// overestimates the distance to it, with no safety factor. The trap is the
/// orbit's smallest radius over `R`.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Kifs<S = Param> {
    /// The mirrors of each iteration.
    pub fold: KifsFold,
    /// The scale of each iteration, in `[1.1, 4]`.
    pub scale: S,
    /// The point each iteration scales about (finite).
    pub offset: [S; 3],
    /// A turn before the fold: angles in radians about `x`, then `y`, then
    /// `z` (any finite values).
    pub rotate_before: Option<[S; 3]>,
    /// A turn after the fold, as `rotate_before`.
    pub rotate_after: Option<[S; 3]>,
    /// Folding levels, 0 (the ball of radius `R`) to
    /// [`MAX_FOLD_ITERATIONS`].
    pub iterations: u32,
}

impl From<Kifs> for Node {
    fn from(f: Kifs) -> Self {
        Kind::Kifs(f).into()
    }
}

impl From<Mandelbox> for Node {
    fn from(f: Mandelbox) -> Self {
        Kind::Mandelbox(f).into()
    }
}

impl From<Mandelbulb> for Node {
    fn from(f: Mandelbulb) -> Self {
        Kind::Mandelbulb(f).into()
    }
}

impl From<Menger> for Node {
    fn from(f: Menger) -> Self {
        Kind::Menger(f).into()
    }
}

impl From<QuaternionJulia> for Node {
    fn from(f: QuaternionJulia) -> Self {
        Kind::Julia(f).into()
    }
}

impl From<Sierpinski> for Node {
    fn from(f: Sierpinski) -> Self {
        Kind::Sierpinski(f).into()
    }
}
