//! Printers: a [`Program`] as a function in a kernel language.
//!
//! A printer writes only what the program holds — operations, inputs
//! named by the signature, and literals — so nothing a user writes (a
//! formula in a scene file) can reach the source as text. Values read once
//! are written inline; values read more often get a name. [`OpenCl`]
//! writes OpenCL C; a second backend is a second [`Printer`].

use std::fmt::Write as _;

use super::program::{Binary, Op, Program, Unary, ValueId};

/// The shape of a parameter or result: how many scalar inputs or outputs
/// it stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// One number.
    Scalar,
    /// Two numbers (OpenCL `real2`).
    Pair,
    /// A 3-vector (OpenCL `real3`).
    Vec3,
}

impl Shape {
    /// How many scalars it holds.
    #[must_use]
    pub fn width(self) -> u32 {
        match self {
            Shape::Scalar => 1,
            Shape::Pair => 2,
            Shape::Vec3 => 3,
        }
    }
}

/// A function's name, parameters and result: the program's inputs are the
/// parameters' components in order, and its outputs the result's.
#[derive(Debug, Clone, Copy)]
pub struct Signature<'a> {
    /// The function's name (an identifier the caller chose).
    pub name: &'a str,
    /// Each parameter's name and shape.
    pub params: &'a [(&'a str, Shape)],
    /// The result's shape.
    pub result: Shape,
}

impl Signature<'_> {
    /// How many scalar inputs the parameters stand for.
    #[must_use]
    pub fn inputs(&self) -> u32 {
        self.params.iter().map(|(_, s)| s.width()).sum()
    }
}

/// A program a printer cannot write.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Unprintable {
    /// A literal that is NaN or infinite.
    #[error("the non-finite literal {0} cannot be written")]
    Literal(f64),
    /// The program's inputs or outputs do not match the signature.
    #[error("the program has {program} {what}, the signature {signature}")]
    Arity {
        /// `inputs` or `outputs`.
        what: &'static str,
        /// The program's count.
        program: usize,
        /// The signature's count.
        signature: usize,
    },
}

/// Writes a [`Program`] as a function of one backend's language.
pub trait Printer {
    /// The function `signature` computing `program`.
    ///
    /// # Errors
    /// [`Unprintable`] for a non-finite literal or a program whose inputs
    /// or outputs do not match the signature.
    fn function(&self, signature: &Signature<'_>, program: &Program)
    -> Result<String, Unprintable>;
}

/// The OpenCL C printer: `real` is the precision's type, literals are
/// `R(...)` (the kernel header's literal macro).
#[derive(Debug, Clone, Copy, Default)]
pub struct OpenCl;

/// Checks a program's inputs and outputs against a signature.
fn check_arity(signature: &Signature<'_>, program: &Program) -> Result<(), Unprintable> {
    if program.inputs != signature.inputs() {
        return Err(Unprintable::Arity {
            what: "inputs",
            program: program.inputs as usize,
            signature: signature.inputs() as usize,
        });
    }
    let outputs = signature.result.width() as usize;
    if program.outputs.len() != outputs {
        return Err(Unprintable::Arity {
            what: "outputs",
            program: program.outputs.len(),
            signature: outputs,
        });
    }
    Ok(())
}

/// The name of each scalar input: a scalar parameter's name, or a vector
/// parameter's component (`p.x`).
fn input_names(signature: &Signature<'_>) -> Vec<String> {
    let mut names = Vec::new();
    for (name, shape) in signature.params {
        match shape {
            Shape::Scalar => names.push((*name).to_string()),
            Shape::Pair => names.extend(["x", "y"].map(|c| format!("{name}.{c}"))),
            Shape::Vec3 => names.extend(["x", "y", "z"].map(|c| format!("{name}.{c}"))),
        }
    }
    names
}

/// An OpenCL C literal of the precision the header chose.
fn literal(v: f64) -> Result<String, Unprintable> {
    if !v.is_finite() {
        return Err(Unprintable::Literal(v));
    }
    // Debug formatting is the shortest text that reads back as `v`, with a
    // `.` or an exponent: a valid C floating constant once suffixed.
    Ok(if v.is_sign_negative() {
        format!("(-R({:?}))", -v)
    } else {
        format!("R({v:?})")
    })
}

struct OpenClWriter<'p> {
    program: &'p Program,
    inputs: Vec<String>,
    /// Each value's text where it is read: a name, or its inlined
    /// expression.
    text: Vec<String>,
    /// The vector parameter whose three components start at each input.
    vectors: Vec<Option<String>>,
}

impl OpenClWriter<'_> {
    fn atom(&self, v: ValueId) -> &str {
        &self.text[v.index()]
    }

    /// A value as a call's argument: no enclosing parentheses needed.
    fn arg(&self, v: ValueId) -> &str {
        unwrap(self.atom(v))
    }

    /// A vector parameter, when `x, y, z` are its components in order.
    fn whole_vector(&self, x: ValueId, y: ValueId, z: ValueId) -> Option<&str> {
        let ops = &self.program.ops;
        if let (Op::Input(a), Op::Input(b), Op::Input(c)) =
            (ops[x.index()], ops[y.index()], ops[z.index()])
            && b == a + 1
            && c == a + 2
        {
            return self.vectors.get(a as usize)?.as_deref();
        }
        None
    }

    /// The expression of `op`, parenthesised unless it is a call.
    fn expression(&self, op: Op) -> Result<String, Unprintable> {
        Ok(match op {
            Op::Const(v) => literal(v)?,
            Op::Input(i) => self.inputs[i as usize].clone(),
            Op::Unary(u, a) => {
                let (a, inner) = (self.atom(a), self.arg(a));
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
                    Unary::Finite => format!("isfinite({inner})"),
                }
            }
            Op::Binary(b, x, y) => {
                let (ax, ay) = (self.arg(x), self.arg(y));
                let (x, y) = (self.atom(x), self.atom(y));
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
                    Binary::Hypot => format!("hypot({ax}, {ay})"),
                }
            }
            Op::Length3(x, y, z) => match self.whole_vector(x, y, z) {
                Some(v) => format!("length({v})"),
                None => format!(
                    "length((real3)({}, {}, {}))",
                    self.arg(x),
                    self.arg(y),
                    self.arg(z)
                ),
            },
            Op::Select(c, a, b) => {
                format!("({} ? {} : {})", self.atom(c), self.atom(a), self.atom(b))
            }
        })
    }
}

/// Values as a call's arguments.
fn args(values: &[&str]) -> String {
    values
        .iter()
        .map(|v| unwrap(v))
        .collect::<Vec<_>>()
        .join(", ")
}

/// `text` without one pair of enclosing parentheses, when they enclose it
/// all.
fn unwrap(text: &str) -> &str {
    let Some(inner) = text.strip_prefix('(').and_then(|t| t.strip_suffix(')')) else {
        return text;
    };
    let mut depth = 0i32;
    for c in inner.chars() {
        match c {
            '(' => depth += 1,
            ')' => {
                depth -= 1;
                if depth < 0 {
                    return text;
                }
            }
            _ => {}
        }
    }
    inner
}

impl Printer for OpenCl {
    fn function(
        &self,
        signature: &Signature<'_>,
        program: &Program,
    ) -> Result<String, Unprintable> {
        check_arity(signature, program)?;
        let inputs = input_names(signature);
        let mut vectors = Vec::new();
        for (name, shape) in signature.params {
            vectors.push((*shape == Shape::Vec3).then(|| (*name).to_string()));
            for _ in 1..shape.width() {
                vectors.push(None);
            }
        }
        let mut w = OpenClWriter {
            program,
            inputs,
            text: Vec::with_capacity(program.ops.len()),
            vectors,
        };
        let uses = program.uses();
        let live = program.live();
        let mut body = String::new();
        let mut named = 0;
        // Temporaries are `t0`, `t1`, ...: with more underscores while a
        // parameter could be one of them.
        let mut prefix = String::from("t");
        while signature.params.iter().any(|(n, _)| {
            n.strip_prefix(prefix.as_str())
                .is_some_and(|rest| rest.chars().all(|c| c.is_ascii_digit()))
        }) {
            prefix.push('_');
        }
        for (i, op) in program.ops.iter().enumerate() {
            let text = w.expression(*op)?;
            let inline = matches!(op, Op::Const(_) | Op::Input(_)) || uses[i] <= 1 || !live[i];
            if inline {
                w.text.push(text);
            } else {
                let ty = if op.is_logic() { "bool" } else { "real" };
                writeln!(body, "    {ty} {prefix}{named} = {};", unwrap(&text)).ok();
                w.text.push(format!("{prefix}{named}"));
                named += 1;
            }
        }
        let outputs: Vec<&str> = program.outputs.iter().map(|v| w.atom(*v)).collect();
        let (ty, result) = match signature.result {
            Shape::Scalar => ("real", unwrap(outputs[0]).to_string()),
            Shape::Pair => ("real2", format!("(real2)({})", args(&outputs))),
            Shape::Vec3 => ("real3", format!("(real3)({})", args(&outputs))),
        };
        let params: Vec<String> = signature
            .params
            .iter()
            .map(|(name, shape)| {
                let ty = match shape {
                    Shape::Scalar => "real",
                    Shape::Pair => "real2",
                    Shape::Vec3 => "real3",
                };
                format!("{ty} {name}")
            })
            .collect();
        Ok(format!(
            "{ty} {}({}) {{\n{body}    return {result};\n}}\n",
            signature.name,
            params.join(", ")
        ))
    }
}
