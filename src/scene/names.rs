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
//!    `custom_` (custom shapes), `inside_` (inside shapes' tests), `sd_`
//!    (the helper library), `march_` (the
//!    marcher), `cl_` (extensions), and `mandelbulb_pN` (specialised
//!    Mandelbulbs);
//! 5. every name the generated program itself defines or calls: code
//!    generation reads those from the program it writes and refuses a
//!    shape that uses one when it emits the shape (`codegen::names`), so
//!    the rule cannot go stale and this module needs no code generation.
//!
//! [`CustomShape::new`](super::CustomShape::new) applies rules 1 to 4.

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
    custom_ inside_ sd_ march_ cl_ \
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
    None
}

/// `source` with its `/* */` and `//` comments blanked (newlines kept, so
/// lines keep their numbers).
pub(crate) fn strip_comments(source: &str) -> String {
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
