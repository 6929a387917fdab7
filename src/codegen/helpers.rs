//! The OpenCL C helper library and the dependencies between its functions:
//! helpers printed from the formulas' expression IR
//! ([`formulas`](super::formulas)), and the fractal estimators still
//! hand-written in `kernels/sdf/*.cl` (embedded at compile time).

use super::formulas;
use crate::expr::Unprintable;

/// One file of the helper library. Code generation records which helpers a
/// scene calls and emits those (with their dependencies) and no others.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(crate) enum Helper {
    Sphere,
    Cuboid,
    RoundBox,
    Torus,
    Cylinder,
    Capsule,
    Plane,
    Octahedron,
    CappedCone,
    Ellipsoid,
    Mandelbulb,
    Menger,
    Tetrahedron,
    Sierpinski,
    Julia,
    SmoothMin,
    Rotate,
    Warp,
}

macro_rules! source {
    ($file:literal) => {
        include_str!(concat!("../../kernels/sdf/", $file, ".cl"))
    };
}

impl Helper {
    /// Every helper, each after the helpers it depends on: the order they
    /// are emitted in.
    pub(crate) const ALL: [Helper; 18] = [
        Helper::Sphere,
        Helper::Cuboid,
        Helper::RoundBox,
        Helper::Torus,
        Helper::Cylinder,
        Helper::Capsule,
        Helper::Plane,
        Helper::Octahedron,
        Helper::CappedCone,
        Helper::Ellipsoid,
        Helper::Mandelbulb,
        Helper::Menger,
        Helper::Tetrahedron,
        Helper::Sierpinski,
        Helper::Julia,
        Helper::SmoothMin,
        Helper::Rotate,
        Helper::Warp,
    ];

    /// The helper's name, in the program's section comments.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Helper::Sphere => "sphere",
            Helper::Cuboid => "cuboid",
            Helper::RoundBox => "round_box",
            Helper::Torus => "torus",
            Helper::Cylinder => "cylinder",
            Helper::Capsule => "capsule",
            Helper::Plane => "plane",
            Helper::Octahedron => "octahedron",
            Helper::CappedCone => "capped_cone",
            Helper::Ellipsoid => "ellipsoid",
            Helper::Mandelbulb => "mandelbulb",
            Helper::Menger => "menger",
            Helper::Tetrahedron => "tetrahedron",
            Helper::Sierpinski => "sierpinski",
            Helper::Julia => "julia",
            Helper::SmoothMin => "smooth_min",
            Helper::Rotate => "rotate",
            Helper::Warp => "warp",
        }
    }

    /// The OpenCL C source: printed from the formula, or the fractal's
    /// hand-written file.
    pub(crate) fn source(self) -> Result<String, Unprintable> {
        match self {
            Helper::Sphere => formulas::sphere(),
            Helper::Cuboid => formulas::cuboid(),
            Helper::RoundBox => formulas::round_box(),
            Helper::Torus => formulas::torus(),
            Helper::Cylinder => formulas::cylinder(),
            Helper::Capsule => formulas::capsule(),
            Helper::Plane => formulas::plane(),
            Helper::Octahedron => formulas::octahedron(),
            Helper::CappedCone => formulas::capped_cone(),
            Helper::Ellipsoid => formulas::ellipsoid(),
            Helper::Tetrahedron => formulas::tetrahedron(),
            Helper::SmoothMin => formulas::smooth_min(),
            Helper::Rotate => formulas::rotate(),
            Helper::Warp => formulas::warp(),
            Helper::Mandelbulb => Ok(source!("mandelbulb").to_string()),
            Helper::Menger => Ok(source!("menger").to_string()),
            Helper::Sierpinski => Ok(source!("sierpinski").to_string()),
            Helper::Julia => Ok(source!("julia").to_string()),
        }
    }

    /// The helpers this one calls.
    pub(crate) fn deps(self) -> &'static [Helper] {
        match self {
            Helper::Menger => &[Helper::Cuboid],
            Helper::Sierpinski => &[Helper::Tetrahedron],
            _ => &[],
        }
    }
}

/// The helpers needed for `used` (adding dependencies), in library order.
pub(crate) fn closure(used: impl IntoIterator<Item = Helper>) -> Vec<Helper> {
    let mut needed: Vec<Helper> = used.into_iter().collect();
    // Dependencies come first in ALL, so one backwards pass adds them all.
    for h in Helper::ALL.iter().rev() {
        if needed.contains(h) {
            needed.extend_from_slice(h.deps());
        }
    }
    Helper::ALL
        .into_iter()
        .filter(|h| needed.contains(h))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dependencies_come_first_and_are_added() {
        for (i, h) in Helper::ALL.iter().enumerate() {
            for d in h.deps() {
                let at = Helper::ALL.iter().position(|x| x == d).unwrap();
                assert!(at < i, "{} is listed after {}", d.name(), h.name());
            }
        }
        assert_eq!(
            closure([Helper::Sierpinski]),
            vec![Helper::Tetrahedron, Helper::Sierpinski]
        );
    }

    #[test]
    fn every_helper_prints() {
        for h in Helper::ALL {
            let source = h.source().unwrap();
            assert!(
                source.contains('{') && source.ends_with("}\n"),
                "{}",
                h.name()
            );
        }
    }
}
