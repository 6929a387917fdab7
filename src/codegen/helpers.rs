//! The hand-written OpenCL C helper library (`kernels/sdf/*.cl`), embedded
//! at compile time, and the dependencies between its functions.

/// One file of the helper library. Code generation records which helpers a
/// scene calls and emits those (with their dependencies) and no others.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(crate) enum Helper {
    Length,
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
    pub(crate) const ALL: [Helper; 19] = [
        Helper::Length,
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

    /// The file's name in `kernels/sdf/`, without `.cl`.
    pub(crate) fn name(self) -> &'static str {
        self.file().0
    }

    /// The OpenCL C source.
    pub(crate) fn source(self) -> &'static str {
        self.file().1
    }

    fn file(self) -> (&'static str, &'static str) {
        match self {
            Helper::Length => ("length", source!("length")),
            Helper::Sphere => ("sphere", source!("sphere")),
            Helper::Cuboid => ("cuboid", source!("cuboid")),
            Helper::RoundBox => ("round_box", source!("round_box")),
            Helper::Torus => ("torus", source!("torus")),
            Helper::Cylinder => ("cylinder", source!("cylinder")),
            Helper::Capsule => ("capsule", source!("capsule")),
            Helper::Plane => ("plane", source!("plane")),
            Helper::Octahedron => ("octahedron", source!("octahedron")),
            Helper::CappedCone => ("capped_cone", source!("capped_cone")),
            Helper::Ellipsoid => ("ellipsoid", source!("ellipsoid")),
            Helper::Mandelbulb => ("mandelbulb", source!("mandelbulb")),
            Helper::Menger => ("menger", source!("menger")),
            Helper::Tetrahedron => ("tetrahedron", source!("tetrahedron")),
            Helper::Sierpinski => ("sierpinski", source!("sierpinski")),
            Helper::Julia => ("julia", source!("julia")),
            Helper::SmoothMin => ("smooth_min", source!("smooth_min")),
            Helper::Rotate => ("rotate", source!("rotate")),
            Helper::Warp => ("warp", source!("warp")),
        }
    }

    /// The helpers this one calls.
    pub(crate) fn deps(self) -> &'static [Helper] {
        match self {
            Helper::Menger => &[Helper::Cuboid],
            Helper::Ellipsoid => &[Helper::Length],
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
}
