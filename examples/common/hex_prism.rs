//! The custom shape of `examples/custom_node.rs`, shared with
//! `tests/custom_node.rs`.

use fractal_sdf::prelude::*;
use fractal_sdf::scene::{CustomShape, Rule};

/// A hexagonal prism along z with inradius `radius` and half-length
/// `half_length` (after Quilez's `sdHexPrism`): fold into one sixth of the
/// hexagon, then take the distance to the side face and the caps.
pub fn hex_prism() -> Result<CustomShape> {
    CustomShape::new(
        "hex_prism",
        &[
            ("radius", Rule::NonNegative),
            ("half_length", Rule::NonNegative),
        ],
        |p, a| {
            let (radius, half_length) = (a[0], a[1]);
            let k = dvec3(-0.866_025_403_784_438_6, 0.5, 0.577_350_269_189_625_8);
            let mut q = p.abs();
            let fold = 2.0 * (k.x * q.x + k.y * q.y).min(0.0);
            q.x -= fold * k.x;
            q.y -= fold * k.y;
            let side = q.x.clamp(-k.z * radius, k.z * radius);
            let dx = (q.x - side).hypot(q.y - radius) * (q.y - radius).signum();
            let dy = q.z - half_length;
            dx.max(dy).min(0.0) + dx.max(0.0).hypot(dy.max(0.0))
        },
        "const real3 k = (real3)(R(-0.8660254037844386), R(0.5), R(0.5773502691896258));
         real3 q = fabs(p);
         real fold = R(2.0) * fmin(k.x * q.x + k.y * q.y, R(0.0));
         q.x -= fold * k.x;
         q.y -= fold * k.y;
         real side = clamp(q.x, -k.z * radius, k.z * radius);
         real dx = hypot(q.x - side, q.y - radius) * sign(q.y - radius);
         real dy = q.z - half_length;
         return fmin(fmax(dx, dy), R(0.0)) + hypot(fmax(dx, R(0.0)), fmax(dy, R(0.0)));",
    )
}
