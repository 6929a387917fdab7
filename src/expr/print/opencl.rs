//! OpenCL C: `real` is the precision's type (the kernel header's
//! typedef), literals are `R(...)` (its literal macro).

use super::{
    Binary, Inline, Printer, Program, Shape, Signature, Syntax, Unary, Unprintable, print_function,
    print_inline,
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

    fn unary_function(&self, u: Unary) -> &'static str {
        match u {
            Unary::Sqrt => "sqrt",
            Unary::Abs => "fabs",
            Unary::Sin => "sin",
            Unary::Cos => "cos",
            Unary::Acos => "acos",
            Unary::Exp => "exp",
            Unary::Ln => "log",
            Unary::Floor => "floor",
            Unary::Round => "round",
            Unary::Finite => "isfinite",
            Unary::Neg | Unary::Not => unreachable!("operators"),
        }
    }

    fn binary_function(&self, b: Binary) -> &'static str {
        match b {
            Binary::Min => "fmin",
            Binary::Max => "fmax",
            Binary::Atan2 => "atan2",
            Binary::Pow => "pow",
            _ => unreachable!("operators"),
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
