//! The identifiers a custom shape may not take, because the OpenCL C
//! language, its built-ins or the generated program already give them a
//! meaning.
//!
//! A custom shape's parameters become the parameter names of its function,
//! and its name becomes a function name (`custom_NAME`). A parameter named
//! like a macro of the generated header (`DETAIL`), one of its types
//! (`real`) or a built-in (`sin`) would be replaced, shadow it or fail to
//! parse. The rules, in the order they are applied:
//!
//! 1. OpenCL C keywords, qualifiers and type names (every vector width of
//!    every scalar type, `real` included) and the built-in functions of the
//!    OpenCL C 1.2 library (by name, and by the prefixes of its families:
//!    `convert_`, `as_TYPE`, `vload`, `native_`, ...);
//! 2. names reserved for the implementation: a leading `__`, or `_` and a
//!    capital;
//! 3. names written in capitals (no lower-case letter), the convention of
//!    every macro of the generated program and of OpenCL (`DETAIL`, `R`,
//!    `M_PI`, `FLT_MAX`, `CLK_LOCAL_MEM_FENCE`);
//! 4. `params`, the generated functions' name for the buffer of dynamic
//!    parameter values, and the prefixes of names code generation writes:
//!    `custom_` (custom shapes), `sd_` (the helper library), `march_` (the
//!    marcher), `cl_` (extensions), and `mandelbulb_pN` (specialised
//!    Mandelbulbs);
//! 5. every name the generated program itself defines or calls, read from
//!    the program: its macros, typedefs and file-scope functions, collected
//!    from the header (both precisions, both targets, every effect on), the
//!    whole helper library and both kernels. This rule cannot go stale: a
//!    new `#define` or helper is reserved as soon as it is emitted.

use std::collections::BTreeSet;
use std::sync::OnceLock;

use glam::DVec3;

use super::{Options, Target, header, helpers::Helper, power, writer::Writer};
use crate::quality::{Effects, Glow, Precision, Quality};

/// Keywords and reserved words of OpenCL C (C99's, OpenCL's address-space,
/// access and function qualifiers, and the words the specification
/// reserves). This and the lists below are words separated by
/// whitespace.
const KEYWORDS: &str = "\
    auto break case char const continue default do double else enum extern float for goto if \
    inline int long register restrict return short signed sizeof static struct switch typedef \
    union unsigned void volatile while _Bool _Complex _Imaginary \
    global local constant private generic kernel read_only write_only read_write uniform pipe \
    vec_step true false complex imaginary defined asm main \
";

/// Scalar and opaque type names. Vector types (`float3`, `real16`,
/// `double4x4`) are recognised by shape in [`is_type_name`].
const TYPES: &str = "\
    bool uchar ushort uint ulong half quad real size_t ptrdiff_t intptr_t uintptr_t image1d_t \
    image1d_array_t image1d_buffer_t image2d_t image2d_array_t image2d_depth_t \
    image2d_array_depth_t image3d_t sampler_t event_t queue_t clk_event_t reserve_id_t \
    ndrange_t memory_order memory_scope \
";

/// The element types vector types are made of.
const VECTOR_ELEMENTS: &str = "\
    char uchar short ushort int uint long ulong float double half bool quad real \
";

/// Built-in functions of OpenCL C 1.2 (math, integer, common, geometric,
/// relational, synchronisation, work-item and miscellaneous functions).
const BUILTINS: &str = "\
    acos acosh acospi asin asinh asinpi atan atan2 atanh atanpi atan2pi cbrt ceil copysign cos \
    cosh cospi erfc erf exp exp2 exp10 expm1 fabs fdim floor fma fmax fmin fmod fract frexp \
    hypot ilogb ldexp lgamma lgamma_r log log2 log10 log1p logb mad maxmag minmag modf nan \
    nextafter pow pown powr remainder remquo rint rootn round rsqrt sin sincos sinh sinpi sqrt \
    tan tanh tanpi tgamma trunc \
    abs abs_diff add_sat hadd rhadd clz ctz mad_hi mad_sat mul_hi rotate sub_sat upsample \
    popcount mad24 mul24 \
    clamp degrees max min mix radians step smoothstep sign \
    cross dot distance length normalize fast_distance fast_length fast_normalize \
    isequal isnotequal isgreater isgreaterequal isless islessequal islessgreater isfinite \
    isinf isnan isnormal isordered isunordered signbit any all bitselect select \
    barrier mem_fence read_mem_fence write_mem_fence wait_group_events prefetch \
    get_work_dim get_global_size get_global_id get_local_size get_local_id get_num_groups \
    get_group_id get_global_offset get_enqueued_local_size get_global_linear_id \
    get_local_linear_id \
    shuffle shuffle2 printf nanf \
    half_cos half_divide half_exp half_exp2 half_exp10 half_log half_log2 half_log10 half_powr \
    half_recip half_rsqrt half_sin half_sqrt half_tan \
";

/// Prefixes of built-in families: conversions, vector loads and stores,
/// atomics, native maths, images, work-group and sub-group functions.
/// (Reinterpretations, `as_TYPE`, are recognised by their type.)
const BUILTIN_PREFIXES: &str = "\
    convert_ vload vstore atomic_ atom_ native_ read_image write_image get_image_ \
    async_work_group_ work_group_ sub_group_ \
";

/// Prefixes of names code generation writes (or an OpenCL extension
/// defines).
const GENERATED_PREFIXES: &str = "\
    custom_ sd_ march_ cl_ \
";

/// Whether `name` is one of the words of `list`.
fn listed(list: &str, name: &str) -> bool {
    list.split_whitespace().any(|w| w == name)
}

/// Whether `name` is a type name of OpenCL C or of the generated header:
/// a scalar or opaque type, or a vector (`float3`, `real16`) or reserved
/// matrix (`double4x4`) type.
fn is_type_name(name: &str) -> bool {
    if listed(TYPES, name) {
        return true;
    }
    let widths = ["2", "3", "4", "8", "16"];
    VECTOR_ELEMENTS.split_whitespace().any(|base| {
        name.strip_prefix(base).is_some_and(|rest| {
            let (n, m) = rest
                .split_once('x')
                .map_or((rest, None), |(n, m)| (n, Some(m)));
            widths.contains(&n) && m.is_none_or(|m| widths.contains(&m))
        })
    })
}

/// Why `name` cannot be a parameter of a custom shape's OpenCL function
/// (see the module documentation), or `None` if it can. `name` must
/// already be an identifier.
pub(crate) fn reserved(name: &str) -> Option<String> {
    if listed(KEYWORDS, name) {
        return Some("is an OpenCL C keyword".into());
    }
    if is_type_name(name) {
        return Some("is an OpenCL C type name".into());
    }
    if listed(BUILTINS, name) || name.strip_prefix("as_").is_some_and(is_type_name) {
        return Some("is an OpenCL C built-in function".into());
    }
    if let Some(prefix) = BUILTIN_PREFIXES
        .split_whitespace()
        .find(|p| name.starts_with(p))
    {
        return Some(format!(
            "starts with `{prefix}`, the prefix of OpenCL C built-in functions"
        ));
    }
    if name.starts_with("__")
        || (name.starts_with('_') && name[1..].starts_with(char::is_uppercase))
    {
        return Some("starts with `__` or `_` and a capital, reserved for the compiler".into());
    }
    if name.chars().any(|c| c.is_ascii_uppercase()) && !name.chars().any(|c| c.is_ascii_lowercase())
    {
        return Some(
            "is written in capitals, reserved for macros (of the generated program and of \
             OpenCL C)"
                .into(),
        );
    }
    if name == "params" {
        return Some(
            "names the buffer of dynamic parameter values in the generated program".into(),
        );
    }
    if let Some(prefix) = GENERATED_PREFIXES
        .split_whitespace()
        .find(|p| name.starts_with(p))
    {
        return Some(format!(
            "starts with `{prefix}`, a prefix of names the generated program uses"
        ));
    }
    generated(name)
}

/// Why the file-scope name `name` (a custom shape's function) would
/// collide with the generated program, or `None`.
pub(crate) fn generated(name: &str) -> Option<String> {
    let specialised = name
        .strip_prefix("mandelbulb_p")
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()));
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
/// precision and target with every effect on, the helper library, a
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
                    ..Effects::default()
                },
                target,
            };
            let mut w = Writer::new(precision);
            header(&mut w, &options);
            texts.push(w.finish());
        }
    }
    texts.extend(Helper::ALL.iter().map(|h| h.source().to_string()));
    texts.push(power::mandelbulb_helper(8));
    texts.push(include_str!("../../kernels/march.cl").into());
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

/// `source` with its `/* */` and `//` comments blanked (newlines kept, so
/// lines keep their numbers).
fn strip_comments(source: &str) -> String {
    let mut out = String::with_capacity(source.len());
    let mut rest = source;
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix("/*") {
            let end = after.find("*/").map_or(after.len(), |e| e + 2);
            out.extend(after[..end].chars().filter(|&c| c == '\n'));
            out.push(' ');
            rest = &after[end..];
        } else if let Some(after) = rest.strip_prefix("//") {
            let end = after.find('\n').unwrap_or(after.len());
            rest = &after[end..];
        } else {
            let c = rest.chars().next().expect("not empty");
            out.push(c);
            rest = &rest[c.len_utf8()..];
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
            "twist_bound",
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
            ("twist_bound", "generated program"),
            ("mandelbulb_p12", "generated program"),
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
