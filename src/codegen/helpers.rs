//! The OpenCL C helper library: every helper printed from a formula's
//! expression IR ([`formulas`](super::formulas)), once per program, and
//! only those the scene calls.

use super::formulas;
use crate::expr::{Printer, Unprintable};
use crate::scene::KifsFold;

/// One helper of the library. Code generation records which helpers a
/// scene calls and emits those and no others.
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
    OctahedronBound,
    CappedCone,
    HexPrism,
    RoundCone,
    Link,
    CutSphere,
    SolidAngle,
    CappedTorus,
    Triangle,
    Quad,
    Pyramid,
    Rhombus,
    TriPrism,
    RoundedCylinder,
    Cone,
    InfiniteCylinder,
    InfiniteCone,
    CutHollowSphere,
    DeathStar,
    BoxFrame,
    CylinderBetween,
    ConeBetween,
    RoundConeBetween,
    Ellipsoid,
    Mandelbulb,
    Menger,
    Sierpinski,
    Julia,
    Mandelbox,
    MandelboxJulia,
    PseudoKleinian,
    /// A kaleidoscopic IFS of the fold, with turns (`true`) or without.
    Kifs(KifsFold, bool),
}

impl Helper {
    /// Every helper, in the order they are emitted.
    pub(crate) const ALL: [Helper; 47] = [
        Helper::Sphere,
        Helper::Cuboid,
        Helper::RoundBox,
        Helper::Torus,
        Helper::Cylinder,
        Helper::Capsule,
        Helper::Plane,
        Helper::Octahedron,
        Helper::OctahedronBound,
        Helper::CappedCone,
        Helper::HexPrism,
        Helper::RoundCone,
        Helper::Link,
        Helper::CutSphere,
        Helper::SolidAngle,
        Helper::CappedTorus,
        Helper::Triangle,
        Helper::Quad,
        Helper::Pyramid,
        Helper::Rhombus,
        Helper::TriPrism,
        Helper::RoundedCylinder,
        Helper::Cone,
        Helper::InfiniteCylinder,
        Helper::InfiniteCone,
        Helper::CutHollowSphere,
        Helper::DeathStar,
        Helper::BoxFrame,
        Helper::CylinderBetween,
        Helper::ConeBetween,
        Helper::RoundConeBetween,
        Helper::Ellipsoid,
        Helper::Mandelbulb,
        Helper::Menger,
        Helper::Sierpinski,
        Helper::Julia,
        Helper::Mandelbox,
        Helper::MandelboxJulia,
        Helper::PseudoKleinian,
        Helper::Kifs(KifsFold::Tetrahedral, false),
        Helper::Kifs(KifsFold::Tetrahedral, true),
        Helper::Kifs(KifsFold::Octahedral, false),
        Helper::Kifs(KifsFold::Octahedral, true),
        Helper::Kifs(KifsFold::Icosahedral, false),
        Helper::Kifs(KifsFold::Icosahedral, true),
        Helper::Kifs(KifsFold::Menger, false),
        Helper::Kifs(KifsFold::Menger, true),
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
            Helper::OctahedronBound => "octahedron_bound",
            Helper::CappedCone => "capped_cone",
            Helper::HexPrism => "hex_prism",
            Helper::RoundCone => "round_cone",
            Helper::Link => "link",
            Helper::CutSphere => "cut_sphere",
            Helper::SolidAngle => "solid_angle",
            Helper::CappedTorus => "capped_torus",
            Helper::Triangle => "triangle",
            Helper::Quad => "quad",
            Helper::Pyramid => "pyramid",
            Helper::Rhombus => "rhombus",
            Helper::TriPrism => "tri_prism",
            Helper::RoundedCylinder => "rounded_cylinder",
            Helper::Cone => "cone",
            Helper::InfiniteCylinder => "infinite_cylinder",
            Helper::InfiniteCone => "infinite_cone",
            Helper::CutHollowSphere => "cut_hollow_sphere",
            Helper::DeathStar => "death_star",
            Helper::BoxFrame => "box_frame",
            Helper::CylinderBetween => "cylinder_between",
            Helper::ConeBetween => "cone_between",
            Helper::RoundConeBetween => "round_cone_between",
            Helper::Ellipsoid => "ellipsoid",
            Helper::Mandelbulb => "mandelbulb",
            Helper::Menger => "menger",
            Helper::Sierpinski => "sierpinski",
            Helper::Julia => "julia",
            Helper::Mandelbox => "mandelbox",
            Helper::MandelboxJulia => "mandelbox_julia",
            Helper::PseudoKleinian => "pseudo_kleinian",
            Helper::Kifs(fold, turned) => match (fold, turned) {
                (KifsFold::Tetrahedral, false) => "kifs_tetrahedral",
                (KifsFold::Tetrahedral, true) => "kifs_tetrahedral_turned",
                (KifsFold::Octahedral, false) => "kifs_octahedral",
                (KifsFold::Octahedral, true) => "kifs_octahedral_turned",
                (KifsFold::Icosahedral, false) => "kifs_icosahedral",
                (KifsFold::Icosahedral, true) => "kifs_icosahedral_turned",
                (KifsFold::Menger, false) => "kifs_menger",
                (KifsFold::Menger, true) => "kifs_menger_turned",
            },
        }
    }

    /// The helper's source, printed from the formula by `to`.
    pub(crate) fn source(self, to: &dyn Printer) -> Result<String, Unprintable> {
        match self {
            Helper::Sphere => formulas::sphere(to),
            Helper::Cuboid => formulas::cuboid(to),
            Helper::RoundBox => formulas::round_box(to),
            Helper::Torus => formulas::torus(to),
            Helper::Cylinder => formulas::cylinder(to),
            Helper::Capsule => formulas::capsule(to),
            Helper::Plane => formulas::plane(to),
            Helper::Octahedron => formulas::octahedron(to),
            Helper::OctahedronBound => formulas::octahedron_bound(to),
            Helper::CappedCone => formulas::capped_cone(to),
            Helper::HexPrism => formulas::hex_prism(to),
            Helper::RoundCone => formulas::round_cone(to),
            Helper::Link => formulas::link(to),
            Helper::CutSphere => formulas::cut_sphere(to),
            Helper::SolidAngle => formulas::solid_angle(to),
            Helper::CappedTorus => formulas::capped_torus(to),
            Helper::Triangle => formulas::triangle(to),
            Helper::Quad => formulas::quad(to),
            Helper::Pyramid => formulas::pyramid(to),
            Helper::Rhombus => formulas::rhombus(to),
            Helper::TriPrism => formulas::tri_prism(to),
            Helper::RoundedCylinder => formulas::rounded_cylinder(to),
            Helper::Cone => formulas::cone(to),
            Helper::InfiniteCylinder => formulas::infinite_cylinder(to),
            Helper::InfiniteCone => formulas::infinite_cone(to),
            Helper::CutHollowSphere => formulas::cut_hollow_sphere(to),
            Helper::DeathStar => formulas::death_star(to),
            Helper::BoxFrame => formulas::box_frame(to),
            Helper::CylinderBetween => formulas::cylinder_between(to),
            Helper::ConeBetween => formulas::cone_between(to),
            Helper::RoundConeBetween => formulas::round_cone_between(to),
            Helper::Ellipsoid => formulas::ellipsoid(to),
            Helper::Mandelbulb
            | Helper::Menger
            | Helper::Sierpinski
            | Helper::Julia
            | Helper::Mandelbox
            | Helper::MandelboxJulia
            | Helper::PseudoKleinian
            | Helper::Kifs(..) => self.fractal_source(to, false).expect("a fractal's helper"),
        }
    }

    /// A fractal helper's source, trapped (see
    /// [`formulas::fractal_name`]) or not; `None` for the primitives.
    pub(crate) fn fractal_source(
        self,
        to: &dyn Printer,
        trap: bool,
    ) -> Option<Result<String, Unprintable>> {
        Some(match self {
            Helper::Mandelbulb => formulas::mandelbulb(to, trap),
            Helper::Menger => formulas::menger(to, trap),
            Helper::Sierpinski => formulas::sierpinski(to, trap),
            Helper::Julia => formulas::julia(to, trap),
            Helper::Mandelbox => formulas::mandelbox(to, false, trap),
            Helper::MandelboxJulia => formulas::mandelbox(to, true, trap),
            Helper::PseudoKleinian => formulas::pseudo_kleinian(to, trap),
            Helper::Kifs(fold, turned) => formulas::kifs(to, fold, turned, self.name(), trap),
            _ => return None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::OpenCl;

    #[test]
    fn every_helper_prints() {
        for h in Helper::ALL {
            let source = h.source(&OpenCl).unwrap();
            assert!(
                source.contains('{') && source.ends_with("}\n"),
                "{}",
                h.name()
            );
        }
    }

    #[test]
    fn every_fractal_has_a_trapped_form_that_takes_the_shape() {
        for h in Helper::ALL {
            let Some(trapped) = h.fractal_source(&OpenCl, true) else {
                continue;
            };
            let trapped = trapped.unwrap();
            let name = format!("real2 {}(", formulas::fractal_name(h.name(), true));
            assert!(trapped.contains(&name), "{trapped}");
            assert!(trapped.contains("trap_radius"), "{trapped}");
            assert!(
                !h.source(&OpenCl).unwrap().contains("trap_radius"),
                "{}",
                h.name()
            );
        }
    }
}
