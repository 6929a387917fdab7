//! The hand-written OpenCL C helper library (`kernels/sdf/*.cl`), embedded
//! at compile time, and the dependencies between its functions.

/// One helper function: its source and the helpers it calls.
pub(crate) struct Helper {
    pub(crate) name: &'static str,
    pub(crate) source: &'static str,
    pub(crate) deps: &'static [&'static str],
}

macro_rules! helper {
    ($name:literal $(, $dep:literal)*) => {
        Helper {
            name: $name,
            source: include_str!(concat!("../../kernels/sdf/", $name, ".cl")),
            deps: &[$($dep),*],
        }
    };
}

/// Every helper, each listed after the helpers it depends on.
pub(crate) const HELPERS: &[Helper] = &[
    helper!("sphere"),
    helper!("cuboid"),
    helper!("round_box"),
    helper!("torus"),
    helper!("cylinder"),
    helper!("capsule"),
    helper!("plane"),
    helper!("octahedron"),
    helper!("capped_cone"),
    helper!("ellipsoid"),
    helper!("mandelbulb"),
    helper!("menger", "cuboid"),
    helper!("tetrahedron"),
    helper!("sierpinski", "tetrahedron"),
    helper!("julia"),
    helper!("smooth_min"),
    helper!("rotate"),
    helper!("warp"),
];

/// The helpers needed for `used` (adding dependencies), in library order.
pub(crate) fn closure(used: &[&'static str]) -> Vec<&'static Helper> {
    let mut needed: Vec<&str> = used.to_vec();
    // Dependencies come first in HELPERS, so one backwards pass adds them all.
    for h in HELPERS.iter().rev() {
        if needed.contains(&h.name) {
            needed.extend_from_slice(h.deps);
        }
    }
    HELPERS
        .iter()
        .filter(|h| needed.contains(&h.name))
        .collect()
}
