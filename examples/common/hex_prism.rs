//! The custom shape of `examples/custom_node.rs`, shared with
//! `tests/kernel/custom_node.rs`.

use fractal_sdf::expr::V3;
use fractal_sdf::expr::{Distance, Num};
use fractal_sdf::prelude::*;
use fractal_sdf::scene::{CustomShape, Rule};

/// A hexagonal prism along z with inradius `radius` and half-length
/// `half_length` (after Quilez's `sdHexPrism`): fold into one sixth of the
/// hexagon, then take the distance to the side face and the caps.
///
/// Written once: the CPU reference runs it in `f64`, the renderer runs the
/// OpenCL printed from it, and its bounds come from running it on
/// intervals.
pub struct HexPrism;

impl Distance for HexPrism {
    fn distance<N: Num>(&self, p: V3<N>, a: &[N]) -> N {
        let (radius, half_length) = (a[0], a[1]);
        let (kx, ky, kz) = (
            N::of(-0.866_025_403_784_438_6),
            N::of(0.5),
            N::of(0.577_350_269_189_625_8),
        );
        let q = p.abs();
        let fold = N::of(2.0) * (kx * q.x + ky * q.y).min(N::zero());
        let (qx, qy) = (q.x - fold * kx, q.y - fold * ky);
        let side = qx.clamp(-kz * radius, kz * radius);
        let below = (qy - radius).lt(N::zero());
        let dx = (qx - side).hypot(qy - radius) * N::select(below, -N::one(), N::one());
        let dy = q.z - half_length;
        dx.max(dy).min(N::zero()) + dx.max(N::zero()).hypot(dy.max(N::zero()))
    }
}

/// The prism as a shape: parameters `radius` and `half_length`.
pub fn hex_prism() -> Result<CustomShape> {
    CustomShape::formula(
        "hex_prism",
        &[
            ("radius", Rule::NonNegative),
            ("half_length", Rule::NonNegative),
        ],
        HexPrism,
    )
}
