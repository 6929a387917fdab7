//! The OpenCL helpers printed from the formulas in [`crate::cpu::sdf`]:
//! each is traced into the expression IR and written by the OpenCL
//! printer, so the kernel and the CPU reference run one definition.

use crate::cpu::sdf::{self, Estimate, TrapShape};
use crate::expr::{Num, Printer, Shape, Signature, Unprintable, Var, trace};
use crate::math::{V3, v3};
use crate::quality::{Encoding, ToneMap, display_formula};
use crate::scene::{Hybrid, KifsFold, ParamSpec, PseudoKleinian};

use Shape::{Pair, Scalar, Vec3};

/// The 3-vector of inputs `i..i + 3`.
pub(crate) fn vector(a: &[Var], i: usize) -> V3<Var> {
    v3(a[i], a[i + 1], a[i + 2])
}

/// Traces `formula` with the signature's inputs and prints it.
fn print(
    to: &dyn Printer,
    name: &str,
    params: &[(&str, Shape)],
    result: Shape,
    formula: impl FnOnce(&[Var]) -> Vec<Var>,
) -> Result<String, Unprintable> {
    let signature = Signature {
        name,
        params,
        result,
    };
    to.function(&signature, &trace(signature.inputs(), formula))
}

/// A scalar distance formula of the point `p` and further parameters.
fn distance(
    to: &dyn Printer,
    name: &str,
    params: &[(&str, Shape)],
    formula: impl FnOnce(V3<Var>, &[Var]) -> Var,
) -> Result<String, Unprintable> {
    let mut all = vec![("p", Vec3)];
    all.extend_from_slice(params);
    print(to, name, &all, Scalar, |a| {
        vec![formula(vector(a, 0), &a[3..])]
    })
}

/// The render kernel's display transform, `display_color(c, scale,
/// inverse_gamma)`: exposure, `tone_map` and `encoding`
/// ([`display_formula`]).
pub(crate) fn display(
    to: &dyn Printer,
    tone_map: ToneMap,
    encoding: Encoding,
) -> Result<String, Unprintable> {
    print(
        to,
        "display_color",
        &[("c", Vec3), ("scale", Scalar), ("inverse_gamma", Scalar)],
        Vec3,
        |a| {
            let out = display_formula(vector(a, 0), a[3], a[4], tone_map, encoding);
            vec![out.x, out.y, out.z]
        },
    )
}

pub(crate) fn sphere(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(to, "sd_sphere", &[("r", Scalar)], |p, a| {
        sdf::sphere(p, a[0])
    })
}

pub(crate) fn cuboid(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(to, "sd_box", &[("b", Vec3)], |p, a| {
        sdf::cuboid(p, vector(a, 0))
    })
}

pub(crate) fn round_box(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(to, "sd_round_box", &[("b", Vec3), ("r", Scalar)], |p, a| {
        sdf::round_box(p, vector(a, 0), a[3])
    })
}

pub(crate) fn torus(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_torus",
        &[("major", Scalar), ("minor", Scalar)],
        |p, a| sdf::torus(p, a[0], a[1]),
    )
}

pub(crate) fn cylinder(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_cylinder",
        &[("r", Scalar), ("h", Scalar)],
        |p, a| sdf::cylinder(p, a[0], a[1]),
    )
}

pub(crate) fn capsule(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_capsule",
        &[("a", Vec3), ("b", Vec3), ("r", Scalar)],
        |p, a| sdf::capsule(p, vector(a, 0), vector(a, 3), a[6]),
    )
}

pub(crate) fn plane(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_plane",
        &[("n", Vec3), ("offset", Scalar)],
        |p, a| sdf::plane(p, vector(a, 0), a[3]),
    )
}

pub(crate) fn octahedron(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(to, "sd_octahedron", &[("s", Scalar)], |p, a| {
        sdf::octahedron(p, a[0])
    })
}

pub(crate) fn octahedron_bound(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(to, "sd_octahedron_bound", &[("s", Scalar)], |p, a| {
        sdf::octahedron_bound(p, a[0])
    })
}

pub(crate) fn capped_cone(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_capped_cone",
        &[("h", Scalar), ("r1", Scalar), ("r2", Scalar)],
        |p, a| sdf::capped_cone(p, a[0], a[1], a[2]),
    )
}

pub(crate) fn hex_prism(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_hex_prism",
        &[("r", Scalar), ("h", Scalar)],
        |p, a| sdf::hex_prism(p, a[0], a[1]),
    )
}

pub(crate) fn round_cone(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_round_cone",
        &[("h", Scalar), ("r1", Scalar), ("r2", Scalar)],
        |p, a| sdf::round_cone(p, a[0], a[1], a[2]),
    )
}

pub(crate) fn cut_sphere(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_cut_sphere",
        &[("r", Scalar), ("h", Scalar)],
        |p, a| sdf::cut_sphere(p, a[0], a[1]),
    )
}

pub(crate) fn solid_angle(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_solid_angle",
        &[("angle", Scalar), ("r", Scalar)],
        |p, a| sdf::solid_angle(p, a[0], a[1]),
    )
}

pub(crate) fn capped_torus(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_capped_torus",
        &[("angle", Scalar), ("ra", Scalar), ("rb", Scalar)],
        |p, a| sdf::capped_torus(p, a[0], a[1], a[2]),
    )
}

pub(crate) fn link(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_link",
        &[("le", Scalar), ("r1", Scalar), ("r2", Scalar)],
        |p, a| sdf::link(p, a[0], a[1], a[2]),
    )
}

pub(crate) fn triangle(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_triangle",
        &[("a", Vec3), ("b", Vec3), ("c", Vec3), ("t", Scalar)],
        |p, a| sdf::triangle(p, vector(a, 0), vector(a, 3), vector(a, 6), a[9]),
    )
}

pub(crate) fn quad(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_quad",
        &[
            ("a", Vec3),
            ("b", Vec3),
            ("c", Vec3),
            ("d", Vec3),
            ("t", Scalar),
        ],
        |p, a| {
            sdf::quad(
                p,
                vector(a, 0),
                vector(a, 3),
                vector(a, 6),
                vector(a, 9),
                a[12],
            )
        },
    )
}

pub(crate) fn pyramid(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(to, "sd_pyramid", &[("w", Scalar), ("h", Scalar)], |p, a| {
        sdf::pyramid(p, a[0], a[1])
    })
}

pub(crate) fn rhombus(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_rhombus",
        &[("la", Scalar), ("lb", Scalar), ("h", Scalar), ("r", Scalar)],
        |p, a| sdf::rhombus(p, a[0], a[1], a[2], a[3]),
    )
}

pub(crate) fn tri_prism(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_tri_prism",
        &[("r", Scalar), ("h", Scalar)],
        |p, a| sdf::tri_prism(p, a[0], a[1]),
    )
}

pub(crate) fn rounded_cylinder(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_rounded_cylinder",
        &[("r", Scalar), ("h", Scalar), ("e", Scalar)],
        |p, a| sdf::rounded_cylinder(p, a[0], a[1], a[2]),
    )
}

pub(crate) fn cone(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(to, "sd_cone", &[("r", Scalar), ("h", Scalar)], |p, a| {
        sdf::cone(p, a[0], a[1])
    })
}

pub(crate) fn infinite_cylinder(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(to, "sd_infinite_cylinder", &[("r", Scalar)], |p, a| {
        sdf::infinite_cylinder(p, a[0])
    })
}

pub(crate) fn infinite_cone(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(to, "sd_infinite_cone", &[("angle", Scalar)], |p, a| {
        sdf::infinite_cone(p, a[0])
    })
}

pub(crate) fn cut_hollow_sphere(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_cut_hollow_sphere",
        &[("r", Scalar), ("h", Scalar), ("t", Scalar)],
        |p, a| sdf::cut_hollow_sphere(p, a[0], a[1], a[2]),
    )
}

pub(crate) fn death_star(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_death_star",
        &[("ra", Scalar), ("rb", Scalar), ("d", Scalar)],
        |p, a| sdf::death_star(p, a[0], a[1], a[2]),
    )
}

pub(crate) fn box_frame(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(to, "sd_box_frame", &[("b", Vec3), ("t", Scalar)], |p, a| {
        sdf::box_frame(p, vector(a, 0), a[3])
    })
}

pub(crate) fn cylinder_between(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_cylinder_between",
        &[("a", Vec3), ("b", Vec3), ("r", Scalar)],
        |p, a| sdf::cylinder_between(p, vector(a, 0), vector(a, 3), a[6]),
    )
}

pub(crate) fn cone_between(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_cone_between",
        &[("a", Vec3), ("b", Vec3), ("ra", Scalar), ("rb", Scalar)],
        |p, a| sdf::cone_between(p, vector(a, 0), vector(a, 3), a[6], a[7]),
    )
}

pub(crate) fn round_cone_between(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(
        to,
        "sd_round_cone_between",
        &[("a", Vec3), ("b", Vec3), ("ra", Scalar), ("rb", Scalar)],
        |p, a| sdf::round_cone_between(p, vector(a, 0), vector(a, 3), a[6], a[7]),
    )
}

pub(crate) fn ellipsoid(to: &dyn Printer) -> Result<String, Unprintable> {
    distance(to, "sd_ellipsoid", &[("r", Vec3)], |p, a| {
        sdf::ellipsoid(p, vector(a, 0))
    })
}

/// The suffix of a fractal helper's trapped form (see [`fractal`]).
pub(crate) const TRAP_SUFFIX: &str = "_trap";

/// The name of a fractal helper's form, trapped or not.
pub(crate) fn fractal_name(name: &str, trap: bool) -> String {
    if trap {
        format!("{name}{TRAP_SUFFIX}")
    } else {
        name.to_string()
    }
}

/// Prints a fractal's helper, which returns the pair (distance, trap).
/// With `trap`, the form named with [`TRAP_SUFFIX`] that takes a trap
/// shape after the fractal's own parameters (the ten numbers of
/// [`TrapShape::values`]) and returns the shape's value of the orbit as
/// the trap.
fn fractal(
    to: &dyn Printer,
    name: &str,
    params: &[(&str, Shape)],
    trap: bool,
    formula: impl FnOnce(&[Var], Option<&TrapShape<Var>>) -> Estimate<Var>,
) -> Result<String, Unprintable> {
    let mut all = params.to_vec();
    if trap {
        all.extend([
            ("trap_centre", Vec3),
            ("trap_axis", Vec3),
            ("trap_across", Scalar),
            ("trap_along", Scalar),
            ("trap_radius", Scalar),
            ("trap_count", Scalar),
        ]);
    }
    print(to, &fractal_name(name, trap), &all, Pair, |a| {
        let shape = trap.then(|| {
            let values = a[a.len() - 10..].try_into().expect("ten trap numbers");
            TrapShape::from_values(values)
        });
        let e = formula(a, shape.as_ref());
        vec![e.distance, e.trap]
    })
}

/// The Mandelbulb of any real power, with `acos`/`atan2`/`sin`/`cos`.
pub(crate) fn mandelbulb(to: &dyn Printer, trap: bool) -> Result<String, Unprintable> {
    fractal(
        to,
        "mandelbulb",
        &[
            ("p", Vec3),
            ("power", Scalar),
            ("iterations", Scalar),
            ("escape", Scalar),
            ("ball", Scalar),
        ],
        trap,
        |a, t| sdf::mandelbulb_estimate(vector(a, 0), a[3], a[4], a[5], a[6], None, t),
    )
}

/// The name of the Mandelbulb's helper for the baked integer power `n`.
pub(crate) fn power_helper_name(n: u32) -> String {
    format!("mandelbulb_p{n}")
}

/// Structure specialisation: for a baked integer power `n`, a helper
/// `mandelbulb_pN` printed from the one Mandelbulb formula
/// ([`cpu::sdf::mandelbulb_estimate`](crate::cpu::sdf::mandelbulb_estimate))
/// traced with the power fixed: its binary exponentiation and angle powers
/// unroll into straight-line multiplications (no loop over the bits of
/// `n`, no trigonometry).
pub(crate) fn mandelbulb_power(
    to: &dyn Printer,
    n: u32,
    trap: bool,
) -> Result<String, Unprintable> {
    fractal(
        to,
        &power_helper_name(n),
        &[
            ("p", Vec3),
            ("iterations", Scalar),
            ("escape", Scalar),
            ("ball", Scalar),
        ],
        trap,
        |a, t| {
            let power = Var::of(f64::from(n));
            sdf::mandelbulb_estimate(vector(a, 0), power, a[3], a[4], a[5], Some(n), t)
        },
    )
}

/// The Menger sponge.
pub(crate) fn menger(to: &dyn Printer, trap: bool) -> Result<String, Unprintable> {
    fractal(
        to,
        "menger",
        &[("p", Vec3), ("iterations", Scalar), ("scale", Scalar)],
        trap,
        |a, t| sdf::menger_estimate(vector(a, 0), a[3], a[4], t),
    )
}

/// The Sierpinski tetrahedron.
pub(crate) fn sierpinski(to: &dyn Printer, trap: bool) -> Result<String, Unprintable> {
    fractal(
        to,
        "sierpinski",
        &[("p", Vec3), ("iterations", Scalar), ("scale", Scalar)],
        trap,
        |a, t| sdf::sierpinski_estimate(vector(a, 0), a[3], a[4], t),
    )
}

/// The Mandelbox, in Mandelbrot mode or (`julia`) with a constant.
pub(crate) fn mandelbox(to: &dyn Printer, julia: bool, trap: bool) -> Result<String, Unprintable> {
    let mut params = vec![
        ("p", Vec3),
        ("iterations", Scalar),
        ("scale", Scalar),
        ("min_radius", Scalar),
        ("fixed_radius", Scalar),
        ("fold_limit", Scalar),
    ];
    if julia {
        params.push(("c", Vec3));
    }
    let name = if julia {
        "mandelbox_julia"
    } else {
        "mandelbox"
    };
    fractal(to, name, &params, trap, |a, t| {
        let m = sdf::MandelboxParams::new(a[4], a[5], a[6], a[7], julia.then(|| vector(a, 8)));
        sdf::mandelbox_estimate(vector(a, 0), a[3], &m, t)
    })
}

/// Knighty's pseudo-Kleinian fractal.
pub(crate) fn pseudo_kleinian(to: &dyn Printer, trap: bool) -> Result<String, Unprintable> {
    fractal(
        to,
        "pseudo_kleinian",
        &[
            ("p", Vec3),
            ("iterations", Scalar),
            ("fold_size", Vec3),
            ("inversion", Scalar),
            ("offset", Vec3),
            ("thickness", Scalar),
        ],
        trap,
        |a, t| {
            let k = PseudoKleinian {
                fold_size: [a[4], a[5], a[6]],
                inversion: a[7],
                offset: [a[8], a[9], a[10]],
                thickness: a[11],
                iterations: 0,
            };
            sdf::pseudo_kleinian_estimate(vector(a, 0), a[3], &k, t)
        },
    )
}

/// A kaleidoscopic IFS of `fold`; with `turned`, the turns before and
/// after the fold as two vectors of angles (zeros for a turn the node
/// leaves out: no turn, exactly).
pub(crate) fn kifs(
    to: &dyn Printer,
    fold: KifsFold,
    turned: bool,
    name: &str,
    trap: bool,
) -> Result<String, Unprintable> {
    let mut params = vec![
        ("p", Vec3),
        ("iterations", Scalar),
        ("scale", Scalar),
        ("offset", Vec3),
    ];
    if turned {
        params.extend([("before", Vec3), ("after", Vec3)]);
    }
    fractal(to, name, &params, trap, |a, t| {
        let k = sdf::KifsParams::new(fold, a[4], vector(a, 5));
        let k = if turned {
            k.with_turns(Some(vector(a, 8)), Some(vector(a, 11)))
        } else {
            k
        };
        sdf::kifs_estimate(vector(a, 0), a[3], &k, t)
    })
}

/// A hybrid of the structure `shape` (its operations, their parameters
/// the helper's inputs in the order [`Hybrid`]'s parameters are listed),
/// with the baked integer powers `integer_powers`.
pub(crate) fn hybrid(
    to: &dyn Printer,
    name: &str,
    shape: &Hybrid<()>,
    integer_powers: &[Option<u32>],
    trap: bool,
) -> Result<String, Unprintable> {
    let mut names = vec!["p".to_string(), "iterations".to_string()];
    let mut collect = |_: &(), spec: ParamSpec<'_>| -> Result<(), Unprintable> {
        // `stages[0].ops[1].limit` → `s0_1_limit`.
        let short = spec
            .name
            .replace("stages[", "s")
            .replace("].ops[", "_")
            .replace("].", "_")
            .replace('.', "_");
        names.push(short);
        Ok(())
    };
    shape.try_map(&mut collect)?;
    let params: Vec<(&str, Shape)> = names
        .iter()
        .enumerate()
        .map(|(i, n)| (n.as_str(), if i == 0 { Vec3 } else { Scalar }))
        .collect();
    fractal(to, name, &params, trap, |a, t| {
        let mut next = 4;
        let h = shape.map(|()| {
            next += 1;
            a[next - 1]
        });
        sdf::hybrid_estimate(vector(a, 0), a[3], &h, integer_powers, t)
    })
}

/// The quaternion Julia set, `c` as four numbers.
pub(crate) fn julia(to: &dyn Printer, trap: bool) -> Result<String, Unprintable> {
    fractal(
        to,
        "julia",
        &[
            ("p", Vec3),
            ("cx", Scalar),
            ("cy", Scalar),
            ("cz", Scalar),
            ("cw", Scalar),
            ("w", Scalar),
            ("iterations", Scalar),
            ("bailout", Scalar),
        ],
        trap,
        |a, t| {
            let c = [a[3], a[4], a[5], a[6]];
            sdf::julia_estimate(vector(a, 0), c, a[7], a[8], a[9], t)
        },
    )
}

#[cfg(test)]
mod power_tests {
    use super::*;
    use crate::expr::OpenCl;

    #[test]
    fn power_eight_needs_no_trigonometry_and_three_squarings() {
        let src = mandelbulb_power(&OpenCl, 8, false).unwrap();
        assert!(src.contains("real2 mandelbulb_p8("), "{src}");
        for f in ["sin(", "cos(", "acos(", "atan2(", "pow("] {
            assert!(!src.contains(f), "{f} in {src}");
        }
        // r^7 = r * r^2 * r^4: r is squared, and squared again.
        assert!(src.contains("R(2.0) *"), "{src}");
    }

    #[test]
    fn a_real_power_uses_the_trigonometric_form() {
        let src = mandelbulb(&OpenCl, false).unwrap();
        for f in ["acos(", "atan2(", "pow("] {
            assert!(src.contains(f), "{f} missing from {src}");
        }
    }
}
