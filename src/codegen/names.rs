//! The names a custom shape may not take because the generated program
//! gives them a meaning (rule 5 of [`crate::scene`]'s name rules, which
//! `CustomShape::new` applies for rules 1 to 4): read from the program
//! itself, so a new `#define` or helper is reserved as soon as it is
//! emitted. Code generation refuses a shape that uses one.
use std::collections::BTreeSet;
use std::sync::OnceLock;

use glam::DVec3;

use super::{Options, Target, formulas, header, helpers::Helper, writer::Writer};
use crate::error::{Error, Result};
use crate::expr::OpenCl;
use crate::quality::{Effects, Glow, Precision, Quality};
use crate::scene::CustomShape;
use crate::scene::names::strip_comments;

/// Why `name` cannot be a custom shape's parameter: rules 1 to 4 (see
/// `scene::names`) or a name the generated program gives a meaning.
#[cfg(test)]
fn reserved(name: &str) -> Option<String> {
    crate::scene::names::reserved(name).or_else(|| generated(name))
}

/// Refuses a custom shape whose function or parameter names the generated
/// program already uses.
pub(crate) fn check_custom(shape: &CustomShape) -> Result<()> {
    let bad = |reason: String| Error::CustomShape {
        name: shape.name().into(),
        reason,
    };
    for function in std::iter::once(shape.function_name()).chain(shape.test_name()) {
        if let Some(why) = generated(&function) {
            return Err(bad(format!("its OpenCL function `{function}` {why}")));
        }
    }
    for (param, _) in shape.params() {
        if let Some(why) = generated(param) {
            return Err(bad(format!("parameter `{param}` {why}")));
        }
    }
    if let Some(why) = body_directive_problem(shape.opencl_body()) {
        return Err(bad(why));
    }
    Ok(())
}

/// Why a custom shape's OpenCL body would change the program around it,
/// or `None`: a `#define` or `#undef` of a name the generated program
/// uses (a macro reaches past the body). Lines are counted from 1, the
/// body's first line.
pub(crate) fn body_directive_problem(body: &str) -> Option<String> {
    let code = strip_comments(body);
    let mut continued = false;
    for (i, line) in code.lines().enumerate() {
        let directive = !continued && line.trim_start().starts_with('#');
        continued = line.trim_end().ends_with('\\');
        let Some(rest) = directive.then(|| line.trim_start()[1..].trim_start()) else {
            continue;
        };
        for word in ["define", "undef"] {
            let Some(after) = rest.strip_prefix(word) else {
                continue;
            };
            let Some((name, _)) = identifiers(after).first().copied() else {
                continue;
            };
            let taken = generated(name).is_some()
                || name.starts_with("custom_")
                || name.starts_with("inside_");
            if taken {
                return Some(format!(
                    "the OpenCL body's `#{word} {name}` (line {} of the body) would change \
                     a name the generated program uses",
                    i + 1
                ));
            }
        }
    }
    None
}

/// Why the file-scope name `name` (a custom shape's function) would
/// collide with the generated program, or `None`.
pub(crate) fn generated(name: &str) -> Option<String> {
    // The numbered helpers (`mandelbulb_p8`, `hybrid_0`), and their
    // trapped forms.
    let base = name.strip_suffix(formulas::TRAP_SUFFIX).unwrap_or(name);
    let numbered = |prefix: &str| {
        base.strip_prefix(prefix)
            .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
    };
    let specialised = numbered("mandelbulb_p") || numbered("hybrid_");
    if specialised || program_names().contains(name) {
        return Some("is a name the generated program defines or calls".into());
    }
    None
}

/// The names every generated program may define or call (rule 5 of the
/// module documentation), collected once.
pub(crate) fn program_names() -> &'static BTreeSet<String> {
    static NAMES: OnceLock<BTreeSet<String>> = OnceLock::new();
    NAMES.get_or_init(|| {
        let mut names = BTreeSet::new();
        for text in library_texts() {
            collect(&text, &mut names);
        }
        names
    })
}

/// Every text a generated program is assembled from: the header for each
/// precision and target with every effect and materials on, the helper library, a
/// specialised Mandelbulb and both kernels with all their effect blocks.
fn library_texts() -> Vec<String> {
    let mut texts = Vec::new();
    for precision in [Precision::F32, Precision::F64] {
        for target in [Target::Render, Target::Evaluate] {
            let options = Options {
                quality: Quality {
                    precision,
                    ao_samples: 1,
                    shadow_steps: 1,
                    ..Quality::default()
                },
                effects: Effects {
                    ambient_occlusion: true,
                    shadows: true,
                    glow: Some(Glow::new(DVec3::ONE, 1.0)),
                    fog_density: 1.0,
                    volumetric: Some(crate::quality::Volumetric::default()),
                    global_illumination: Some(crate::quality::GlobalIllumination::default()),
                    ..Effects::default()
                },
                target,
                environment: true,
            };
            let mut w = Writer::new(precision);
            let features = super::Features {
                materials: true,
                inside: true,
                brute: Some(crate::ir::Bound {
                    centre: DVec3::ZERO,
                    radius: 1.0,
                    slope: 1.0,
                }),
                glow: Some(crate::ir::Bound {
                    centre: DVec3::ZERO,
                    radius: 1.0,
                    slope: 1.0,
                }),
                origin: DVec3::ZERO,
                node_glow: Some((1, 1.0)),
                emitters: vec![crate::ir::Bound {
                    centre: DVec3::ZERO,
                    radius: 1.0,
                    slope: 1.0,
                }],
            };
            header(&mut w, &options, &features);
            texts.push(w.finish());
        }
    }
    texts.extend(Helper::ALL.iter().filter_map(|h| h.source(&OpenCl).ok()));
    texts.extend(
        Helper::ALL
            .iter()
            .filter_map(|h| h.fractal_source(&OpenCl, true).and_then(Result::ok)),
    );
    texts.extend(formulas::mandelbulb_power(&OpenCl, 8, false).ok());
    texts.push(super::RENDER_KERNEL.into());
    texts.push(include_str!("../../kernels/eval.cl").into());
    texts
}

/// Adds to `names` the identifiers `source` gives a meaning to everywhere:
/// the names of its macros (defined or tested), every identifier at file
/// scope outside parentheses (types, typedefs, functions, globals) and
/// every identifier that is called (followed by `(`).
pub(crate) fn collect(source: &str, names: &mut BTreeSet<String>) {
    let code = strip_comments(source);
    let (mut braces, mut parens) = (0usize, 0usize);
    let mut continued = false;
    for line in code.lines() {
        let directive = continued || line.trim_start().starts_with('#');
        continued = directive && line.trim_end().ends_with('\\');
        if directive {
            if let Some(rest) = line.trim_start().strip_prefix('#') {
                let rest = rest.trim_start();
                let word: String = rest.chars().take_while(char::is_ascii_alphabetic).collect();
                if matches!(
                    word.as_str(),
                    "define" | "undef" | "ifdef" | "ifndef" | "if" | "elif"
                ) {
                    for (ident, _) in identifiers(&rest[word.len()..]) {
                        if ident != "defined" {
                            names.insert(ident.to_string());
                        }
                        if word == "define" || word == "undef" {
                            break; // only the macro's own name
                        }
                    }
                }
            }
            continue;
        }
        let bytes = line.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            let c = bytes[i];
            if c.is_ascii_alphabetic() || c == b'_' {
                let start = i;
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                    i += 1;
                }
                let ident = &line[start..i];
                let called = line[i..].trim_start().starts_with('(');
                if (braces == 0 && parens == 0) || called {
                    names.insert(ident.to_string());
                }
                continue;
            }
            if c.is_ascii_digit() {
                // A number, with its suffix or exponent letters.
                while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'.') {
                    i += 1;
                }
                continue;
            }
            match c {
                b'{' => braces += 1,
                b'}' => braces = braces.saturating_sub(1),
                b'(' => parens += 1,
                b')' => parens = parens.saturating_sub(1),
                _ => {}
            }
            i += 1;
        }
    }
}

/// The identifiers of `text` with their byte offsets (numbers skipped).
fn identifiers(text: &str) -> Vec<(&str, usize)> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_alphanumeric() || c == b'_' {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            if !c.is_ascii_digit() {
                out.push((&text[start..i], start));
            }
        } else {
            i += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_collector_reads_macros_typedefs_functions_and_calls() {
        let mut names = BTreeSet::new();
        collect(
            "#define ONE R(1.0) // one\n#define ARGS \\\n    __global const real* hidden\n\
             typedef float real;\n/* comment_name() */\n\
             typedef struct {\n    real field;\n} Pair;\n\
             real helper(real k, real h) {\n    real local = fabs(k) + 1e-30f;\n\
             return local;\n}\n\
             #ifdef ENABLE_X\n__constant real table[2] = {R(1.0), R(2.0)};\n#endif\n",
            &mut names,
        );
        let got: Vec<&str> = names.iter().map(String::as_str).collect();
        assert_eq!(
            got,
            [
                "ARGS",
                "ENABLE_X",
                "ONE",
                "Pair",
                "R",
                "__constant",
                "fabs",
                "float",
                "helper",
                "real",
                "struct",
                "table",
                "typedef"
            ]
        );
    }

    #[test]
    fn the_program_names_hold_the_header_library_and_kernels() {
        let names = program_names();
        for name in [
            "R",
            "DETAIL",
            "GAMMA",
            "REAL_TINY",
            "CAMERA_ORIGIN",
            "LIGHT_STRIDE",
            "RENDER_TILE_ARGS",
            "EVAL_POINTS_ARGS",
            "ENABLE_FOG",
            "FOG_DENSITY",
            "DE",
            "DE_shade",
            "sd_sphere",
            "menger",
            "march_ray",
            "render_tile",
            "eval_points",
            "real3",
        ] {
            assert!(names.contains(name), "{name} is not collected");
        }
        for free in ["radius", "thickness", "k", "h", "x", "color"] {
            assert!(!names.contains(free), "{free} is collected");
        }
    }

    #[test]
    fn reserved_names_say_why() {
        for (name, why) in [
            ("return", "keyword"),
            ("kernel", "keyword"),
            ("float3", "type name"),
            ("real", "type name"),
            ("real16", "type name"),
            ("double4x4", "type name"),
            ("sin", "built-in"),
            ("length", "built-in"),
            ("convert_float4", "built-in"),
            ("as_uint4", "built-in"),
            ("half_sqrt", "built-in"),
            ("__x", "compiler"),
            ("_Foo", "compiler"),
            ("M_PI", "capitals"),
            ("DETAIL", "capitals"),
            ("custom_gyroid", "prefix"),
            ("sd_anything", "prefix"),
            ("cl_khr_fp64", "prefix"),
            ("DE_shade", "generated program"),
            ("menger", "generated program"),
            ("mandelbulb_p12", "generated program"),
            ("mandelbulb_p5_trap", "generated program"),
            ("menger_trap", "generated program"),
            ("hybrid_3", "generated program"),
            ("params", "buffer"),
        ] {
            let reason = reserved(name).unwrap_or_else(|| panic!("{name} is allowed"));
            assert!(reason.contains(why), "{name}: {reason}");
        }
        for name in [
            "radius",
            "thickness",
            "half_length",
            "as_given",
            "k",
            "x",
            "Radius",
            "r2",
            "float_like",
            "m_pi",
            "p2",
        ] {
            assert_eq!(reserved(name), None, "{name}");
        }
    }
}
