//! The WebGPU shading language: `real`, `real2` and `real3` are aliases
//! of `f32` and its vectors ([`Wgsl::PRELUDE`]), literals are abstract
//! floats that take the type they meet, and the two operations WGSL does
//! not have as OpenCL does (a finiteness test, rounding halves away from
//! zero) are functions of the prelude.

use super::{
    Binary, Inline, Printer, Program, Shape, Signature, Syntax, Unary, Unprintable, print_function,
    print_inline, unwrap,
};

/// The WGSL printer. Every module of printed functions starts with
/// [`Wgsl::PRELUDE`]. WGSL has single precision only: a literal beyond
/// it is [`Unprintable::Literal`].
///
/// WGSL lets an implementation assume no value is NaN or infinite, and
/// leaves `min`, `max` and `clamp` of a NaN, `pow` of a negative base and
/// the integer of a NaN unspecified, where OpenCL C and the CPU reference
/// define them; and an operation of literals alone that overflows (such
/// as `1e30 * 1e30` in a formula's text) is an error when the shader is
/// created, where OpenCL computes an infinity. Formulas whose values stay
/// finite (every built-in one) print alike in both.
///
/// ```
/// use fractal_sdf::expr::{Num, Printer, Shape, Signature, Wgsl, trace};
/// let program = trace(2, |a| vec![(a[0] * a[0] + a[1] * a[1]).sqrt()]);
/// let signature = Signature::new("hyp", &[("x", Shape::Scalar), ("y", Shape::Scalar)], Shape::Scalar);
/// let function = Wgsl.function(&signature, &program).unwrap();
/// assert!(function.starts_with("fn hyp(x: real, y: real) -> real {"));
/// ```
#[derive(Debug, Clone, Copy, Default)]
pub struct Wgsl;

impl Wgsl {
    /// What every module of printed functions starts with: the number
    /// types, and the functions the printer calls that WGSL lacks.
    pub const PRELUDE: &'static str = "\
alias real = f32;
alias real2 = vec2<f32>;
alias real3 = vec3<f32>;
alias real4 = vec4<f32>;
alias uint = u32;
alias int = i32;

// Whether x is neither infinite nor NaN (under IEEE arithmetic, NaN fails
// the comparison).
fn fsdf_is_finite(x: real) -> bool {
    return abs(x) <= 3.4028234663852886e38;
}

// The nearest integer, halves away from zero (WGSL's round takes halves
// to even).
fn fsdf_round(x: real) -> real {
    let t = trunc(x);
    return select(t, t + sign(x), abs(x - t) >= 0.5);
}
";
}

/// The words WGSL keeps for itself (its keywords and reserved words) and
/// the built-in names the printer calls: a parameter named one of these
/// is written with a `_` after it.
const RESERVED: &[&str] = &[
    // Keywords.
    "alias",
    "break",
    "case",
    "const",
    "const_assert",
    "continue",
    "continuing",
    "default",
    "diagnostic",
    "discard",
    "else",
    "enable",
    "false",
    "fn",
    "for",
    "if",
    "let",
    "loop",
    "override",
    "requires",
    "return",
    "struct",
    "switch",
    "true",
    "var",
    "while",
    // Reserved words.
    "NULL",
    "Self",
    "abstract",
    "active",
    "alignas",
    "alignof",
    "as",
    "asm",
    "asm_fragment",
    "async",
    "attribute",
    "auto",
    "await",
    "become",
    "binding_array",
    "cast",
    "catch",
    "class",
    "co_await",
    "co_return",
    "co_yield",
    "coherent",
    "column_major",
    "common",
    "compile",
    "compile_fragment",
    "concept",
    "const_cast",
    "consteval",
    "constexpr",
    "constinit",
    "crate",
    "debugger",
    "decltype",
    "delete",
    "demote",
    "demote_to_helper",
    "do",
    "dynamic_cast",
    "enum",
    "explicit",
    "export",
    "extends",
    "extern",
    "external",
    "fallthrough",
    "filter",
    "final",
    "finally",
    "friend",
    "from",
    "fxgroup",
    "get",
    "goto",
    "groupshared",
    "highp",
    "impl",
    "implements",
    "import",
    "inline",
    "instanceof",
    "interface",
    "layout",
    "lowp",
    "macro",
    "macro_rules",
    "match",
    "mediump",
    "meta",
    "mod",
    "module",
    "move",
    "mut",
    "mutable",
    "namespace",
    "new",
    "nil",
    "noexcept",
    "noinline",
    "nointerpolation",
    "noperspective",
    "null",
    "nullptr",
    "of",
    "operator",
    "package",
    "packoffset",
    "partition",
    "pass",
    "patch",
    "pixelfragment",
    "precise",
    "precision",
    "premerge",
    "priv",
    "protected",
    "pub",
    "public",
    "readonly",
    "ref",
    "regardless",
    "register",
    "reinterpret_cast",
    "require",
    "resource",
    "restrict",
    "self",
    "set",
    "shared",
    "sizeof",
    "smooth",
    "snorm",
    "static",
    "static_assert",
    "static_cast",
    "std",
    "subroutine",
    "super",
    "target",
    "template",
    "this",
    "thread_local",
    "throw",
    "trait",
    "try",
    "type",
    "typedef",
    "typeid",
    "typename",
    "typeof",
    "union",
    "unless",
    "unorm",
    "unsafe",
    "unsized",
    "use",
    "using",
    "varying",
    "virtual",
    "volatile",
    "wgsl",
    "where",
    "with",
    "writeonly",
    "yield",
    // Names the printed code calls or declares with.
    "abs",
    "acos",
    "atan2",
    "bool",
    "ceil",
    "clamp",
    "cos",
    "exp",
    "f32",
    "floor",
    "i32",
    "length",
    "log",
    "max",
    "min",
    "pow",
    "real",
    "real2",
    "real3",
    "select",
    "sign",
    "sin",
    "sqrt",
    "trunc",
    "vec2",
    "vec3",
    // Names the prelude and the scene's modules declare.
    "real4",
    "uint",
    "int",
    "u32",
    "fsdf_is_finite",
    "fsdf_round",
    "params",
    "FSDF_INFINITY",
    "DEFAULT_COLOR",
    "SCENE_ORIGIN",
];

impl Printer for Wgsl {
    fn function(
        &self,
        signature: &Signature<'_>,
        program: &Program,
    ) -> Result<String, Unprintable> {
        print_function(self, signature, program)
    }

    fn inline(
        &self,
        inputs: &[(&str, Shape)],
        results: &[Shape],
        program: &Program,
        prefix: &str,
    ) -> Result<Inline, Unprintable> {
        print_inline(self, inputs, results, program, prefix)
    }
}

impl Syntax for Wgsl {
    fn literal(&self, v: f64) -> Result<String, Unprintable> {
        // A literal beyond single precision is an error when the shader
        // is created.
        #[allow(clippy::cast_possible_truncation)]
        if !v.is_finite() || (v as f32).is_infinite() {
            return Err(Unprintable::Literal(v));
        }
        // Debug formatting has a `.` or an exponent: an abstract float.
        Ok(if v.is_sign_negative() {
            format!("(-{:?})", -v)
        } else {
            format!("{v:?}")
        })
    }

    fn is_literal(&self, text: &str) -> bool {
        let inner = unwrap(text);
        inner
            .strip_prefix('-')
            .unwrap_or(inner)
            .parse::<f64>()
            .is_ok()
            && !inner.contains(['i', 'I', 'n', 'N'])
    }

    fn unary_function(&self, u: Unary) -> &'static str {
        match u {
            Unary::Sqrt => "sqrt",
            Unary::Abs => "abs",
            Unary::Sin => "sin",
            Unary::Cos => "cos",
            Unary::Acos => "acos",
            Unary::Exp => "exp",
            Unary::Ln => "log",
            Unary::Floor => "floor",
            Unary::Round => "fsdf_round",
            Unary::Finite => "fsdf_is_finite",
            Unary::Neg | Unary::Not => unreachable!("operators"),
        }
    }

    fn binary_function(&self, b: Binary) -> &'static str {
        match b {
            Binary::Min => "min",
            Binary::Max => "max",
            Binary::Atan2 => "atan2",
            Binary::Pow => "pow",
            _ => unreachable!("operators"),
        }
    }

    fn scalar_operand(&self, b: Binary) -> bool {
        // WGSL's arithmetic takes a scalar beside a vector; its `min` and
        // `max` do not.
        matches!(b, Binary::Add | Binary::Sub | Binary::Mul | Binary::Div)
    }

    fn vector(&self, parts: &[&str]) -> String {
        format!("real3({})", parts.join(", "))
    }

    fn pair(&self, parts: &[&str]) -> String {
        format!("real2({})", parts.join(", "))
    }

    fn select(&self, c: &str, a: &str, b: &str) -> String {
        format!("select({}, {}, {})", unwrap(b), unwrap(a), unwrap(c))
    }

    fn constant(&self, ty: &str, name: &str, value: &str) -> String {
        format!("let {name}: {ty} = {value};")
    }

    fn variable(&self, ty: &str, name: &str, value: &str) -> String {
        format!("var {name}: {ty} = {value};")
    }

    fn steps(&self, name: &str, count: &str, max: u32) -> String {
        format!("let {name}: i32 = i32(clamp(ceil(real({count})), 0.0, {max}.0));")
    }

    fn for_header(&self, index: &str, steps: &str) -> String {
        format!("for (var {index}: i32 = 0; {index} < {steps}; {index}++) {{")
    }

    fn index_value(&self, index: &str) -> String {
        format!("real({index})")
    }

    fn parameter(&self, name: &str) -> String {
        if RESERVED.contains(&name) {
            format!("{name}_")
        } else {
            name.to_string()
        }
    }

    fn function(
        &self,
        name: &str,
        params: &[(String, &str)],
        result: &str,
        body: &str,
        returned: &str,
    ) -> String {
        let params: Vec<String> = params.iter().map(|(n, ty)| format!("{n}: {ty}")).collect();
        format!(
            "fn {name}({}) -> {result} {{\n{body}    return {returned};\n}}\n",
            params.join(", ")
        )
    }
}
