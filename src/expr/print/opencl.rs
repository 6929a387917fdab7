//! OpenCL C: `real` is the precision's type (the kernel header's
//! typedef), literals are `R(...)` (its literal macro).

use super::{
    Binary, Inline, Printer, Program, Shape, Signature, Syntax, Unary, Unprintable, print_function,
    print_inline, unwrap,
};

/// The OpenCL C printer: `real` is the precision's type, literals are
/// `R(...)` (the kernel header's literal macro).
#[derive(Debug, Clone, Copy, Default)]
pub struct OpenCl;

impl Printer for OpenCl {
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

impl Syntax for OpenCl {
    fn literal(&self, v: f64) -> Result<String, Unprintable> {
        if !v.is_finite() {
            return Err(Unprintable::Literal(v));
        }
        // Debug formatting is the shortest text that reads back as `v`,
        // with a `.` or an exponent: a valid C floating constant once
        // suffixed.
        Ok(if v.is_sign_negative() {
            format!("(-R({:?}))", -v)
        } else {
            format!("R({v:?})")
        })
    }

    fn is_literal(&self, text: &str) -> bool {
        text.starts_with("R(") && text.ends_with(')') && !text[2..].contains('(')
    }

    fn unary(&self, u: Unary, a: &str, inner: &str) -> String {
        match u {
            Unary::Neg => format!("(-{a})"),
            Unary::Not => format!("(!{a})"),
            Unary::Sqrt => format!("sqrt({inner})"),
            Unary::Abs => format!("fabs({inner})"),
            Unary::Sin => format!("sin({inner})"),
            Unary::Cos => format!("cos({inner})"),
            Unary::Acos => format!("acos({inner})"),
            Unary::Exp => format!("exp({inner})"),
            Unary::Ln => format!("log({inner})"),
            Unary::Floor => format!("floor({inner})"),
            Unary::Round => format!("round({inner})"),
            Unary::Finite => format!("isfinite({inner})"),
        }
    }

    fn binary(&self, b: Binary, x: &str, y: &str) -> String {
        let (ax, ay) = (unwrap(x), unwrap(y));
        match b {
            Binary::Add => format!("({x} + {y})"),
            Binary::Sub => format!("({x} - {y})"),
            Binary::Mul => format!("({x} * {y})"),
            Binary::Div => format!("({x} / {y})"),
            Binary::Lt => format!("({x} < {y})"),
            Binary::Le => format!("({x} <= {y})"),
            Binary::And => format!("({x} && {y})"),
            Binary::Or => format!("({x} || {y})"),
            Binary::Min => format!("fmin({ax}, {ay})"),
            Binary::Max => format!("fmax({ax}, {ay})"),
            Binary::Atan2 => format!("atan2({ax}, {ay})"),
            Binary::Pow => format!("pow({ax}, {ay})"),
            // The length of a 2-vector, as the plain types compute it (see
            // `Num::hypot`).
            Binary::Hypot => format!("length((real2)({ax}, {ay}))"),
        }
    }

    fn scalar_operand(&self, b: Binary) -> bool {
        // OpenCL C takes a scalar second operand for a vector in
        // arithmetic, `fmin` and `fmax`.
        matches!(
            b,
            Binary::Add | Binary::Sub | Binary::Mul | Binary::Div | Binary::Min | Binary::Max
        )
    }

    fn vector(&self, parts: &[&str]) -> String {
        format!("((real3)({}))", parts.join(", "))
    }

    fn pair(&self, parts: &[&str]) -> String {
        format!("((real2)({}))", parts.join(", "))
    }

    fn select(&self, c: &str, a: &str, b: &str) -> String {
        format!("({c} ? {a} : {b})")
    }

    fn constant(&self, ty: &str, name: &str, value: &str) -> String {
        format!("{ty} {name} = {value};")
    }

    fn variable(&self, ty: &str, name: &str, value: &str) -> String {
        self.constant(ty, name, value)
    }

    fn steps(&self, name: &str, count: &str, max: u32) -> String {
        format!("int {name} = (int)clamp(ceil({count}), R(0.0), R({max}.0));")
    }

    fn for_header(&self, index: &str, steps: &str) -> String {
        format!("for (int {index} = 0; {index} < {steps}; {index}++) {{")
    }

    fn index_value(&self, index: &str) -> String {
        format!("(real){index}")
    }

    fn function(
        &self,
        name: &str,
        params: &[(String, &str)],
        result: &str,
        body: &str,
        returned: &str,
    ) -> String {
        let params: Vec<String> = params.iter().map(|(n, ty)| format!("{ty} {n}")).collect();
        format!(
            "{result} {name}({}) {{\n{body}    return {returned};\n}}\n",
            params.join(", ")
        )
    }
}
