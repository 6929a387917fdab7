//! Printers: a [`Program`] as a function in a kernel language.
//!
//! A printer writes only what the program holds — operations, inputs
//! named by the signature, and literals — so nothing a user writes (a
//! formula in a scene file) can reach the source as text. Values read once
//! are written inline; values read more often get a name. [`OpenCl`]
//! writes OpenCL C and [`Wgsl`] the WebGPU shading language: one writer
//! decides what to name, where loops and early returns go, and each
//! backend's `Syntax` spells it.

mod opencl;
mod wgsl;

use std::collections::HashMap;

use super::num::MAX_LOOP_STEPS;
use super::ops::{Binary, Unary};
use super::program::{Loop, Op, Program, ValueId};

pub use opencl::OpenCl;
pub use wgsl::Wgsl;

/// The shape of a parameter or result: how many scalar inputs or outputs
/// it stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
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
#[non_exhaustive]
pub struct Signature<'a> {
    /// The function's name (an identifier the caller chose).
    pub name: &'a str,
    /// Each parameter's name and shape.
    pub params: &'a [(&'a str, Shape)],
    /// The result's shape.
    pub result: Shape,
}

impl<'a> Signature<'a> {
    /// A function `name(params) -> result`.
    #[must_use]
    pub fn new(name: &'a str, params: &'a [(&'a str, Shape)], result: Shape) -> Self {
        Signature {
            name,
            params,
            result,
        }
    }

    /// How many scalar inputs the parameters stand for.
    #[must_use]
    pub fn inputs(&self) -> u32 {
        self.params.iter().map(|(_, s)| s.width()).sum()
    }
}

/// A program a printer cannot write.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Unprintable {
    /// A literal that is NaN or infinite, or beyond the backend's
    /// precision.
    #[error("the literal {0} cannot be written")]
    Literal(f64),
    /// A comparison of 3-vectors (the IR compares numbers only).
    #[error("a comparison of 3-vectors cannot be written")]
    Vector,
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
    /// [`Unprintable`] for a literal it cannot write or a program whose inputs
    /// or outputs do not match the signature.
    fn function(&self, signature: &Signature<'_>, program: &Program)
    -> Result<String, Unprintable>;

    /// Statements computing `program` in the caller's function: its inputs
    /// are read as `inputs` (each an expression of the caller, such as a
    /// point's name or a parameter's slot, with its shape), temporaries
    /// are named `{prefix}0`, `{prefix}1`, … and the outputs are grouped
    /// into `results`, each as an expression.
    ///
    /// # Errors
    /// As [`Printer::function`].
    fn inline(
        &self,
        inputs: &[(&str, Shape)],
        results: &[Shape],
        program: &Program,
        prefix: &str,
    ) -> Result<Inline, Unprintable>;
}

/// A program written inside another function (see [`Printer::inline`]).
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct Inline {
    /// The statements, one per line, to write before the results are read.
    pub statements: String,
    /// Each result's expression (without enclosing parentheses).
    pub results: Vec<String>,
}

impl Inline {
    /// Statements and the expressions of the results they compute: what a
    /// [`Printer::inline`] returns.
    #[must_use]
    pub fn new(statements: String, results: Vec<String>) -> Self {
        Inline {
            statements,
            results,
        }
    }
}

/// How a backend's language spells what the writer decides. The types
/// are named `real`, `real2`, `real3` and `bool` in every backend (the
/// precision's number, its pairs and 3-vectors, and truth values).
trait Syntax {
    /// A literal; an error for NaN, an infinity or a value beyond the
    /// backend's precision.
    fn literal(&self, v: f64) -> Result<String, Unprintable>;
    /// Whether `text` is a literal as [`Syntax::literal`] writes it.
    fn is_literal(&self, text: &str) -> bool;
    /// The function that computes `u` (every [`Unary`] but `Neg` and
    /// `Not`, which are operators).
    fn unary_function(&self, u: Unary) -> &'static str;
    /// The function that computes `b` (`Min`, `Max`, `Atan2` and `Pow`;
    /// the others are operators, and `Hypot` the length of a pair).
    fn binary_function(&self, b: Binary) -> &'static str;
    /// Whether a vector operation `b` takes a number as its second
    /// operand (for every component).
    fn scalar_operand(&self, b: Binary) -> bool;
    /// A 3-vector of three components, or of one repeated.
    fn vector(&self, parts: &[&str]) -> String;
    /// A pair.
    fn pair(&self, parts: &[&str]) -> String;
    /// `a` where `c` holds, else `b`.
    fn select(&self, c: &str, a: &str, b: &str) -> String;
    /// An immutable variable `name` of type `ty` (`real`, `real3`, `bool`).
    fn constant(&self, ty: &str, name: &str, value: &str) -> String;
    /// A mutable variable.
    fn variable(&self, ty: &str, name: &str, value: &str) -> String;
    /// The integer `name`: a loop's step count, `count` clamped to `[0,
    /// max]` and rounded up.
    fn steps(&self, name: &str, count: &str, max: u32) -> String;
    /// The header of a loop whose integer `index` counts from 0 to
    /// `steps`, opening its block.
    fn for_header(&self, index: &str, steps: &str) -> String;
    /// A loop's integer index as a number.
    fn index_value(&self, index: &str) -> String;
    /// A parameter's name in the function's body (a backend renames the
    /// names its language reserves).
    fn parameter(&self, name: &str) -> String {
        name.to_string()
    }
    /// A whole function: its name, parameters, result type, statements and
    /// the returned expression.
    fn function(
        &self,
        name: &str,
        params: &[(String, &str)],
        result: &str,
        body: &str,
        returned: &str,
    ) -> String;
}

/// `u(a)` in `syn`'s language: `a` as an operand, `inner` as a call's
/// argument.
fn unary(syn: &dyn Syntax, u: Unary, a: &str, inner: &str) -> String {
    match u {
        Unary::Neg => format!("(-{a})"),
        Unary::Not => format!("(!{a})"),
        _ => format!("{}({inner})", syn.unary_function(u)),
    }
}

/// `x b y` in `syn`'s language, for numbers or (the arithmetic and
/// functions) vectors.
fn binary(syn: &dyn Syntax, b: Binary, x: &str, y: &str) -> String {
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
        // The length of a 2-vector, as the plain types compute it (see
        // `Num::hypot`).
        Binary::Hypot => format!("length({})", unwrap(&syn.pair(&[ax, ay]))),
        Binary::Min | Binary::Max | Binary::Atan2 | Binary::Pow => {
            format!("{}({ax}, {ay})", syn.binary_function(b))
        }
    }
}

/// The type of values of shape `shape`.
fn type_of(shape: Shape) -> &'static str {
    match shape {
        Shape::Scalar => "real",
        Shape::Pair => "real2",
        Shape::Vec3 => "real3",
    }
}

/// Checks a program's inputs and outputs against the counts its caller
/// gives.
fn check_arity(program: &Program, inputs: u32, outputs: usize) -> Result<(), Unprintable> {
    if program.inputs != inputs {
        return Err(Unprintable::Arity {
            what: "inputs",
            program: program.inputs as usize,
            signature: inputs as usize,
        });
    }
    if program.outputs.len() != outputs {
        return Err(Unprintable::Arity {
            what: "outputs",
            program: program.outputs.len(),
            signature: outputs,
        });
    }
    Ok(())
}

/// The name of each scalar input (a scalar parameter's name, or a vector
/// parameter's component, `p.x`), and the vector parameter whose
/// components start at each input.
fn input_names(params: &[(String, Shape)]) -> (Vec<String>, Vec<Option<String>>) {
    let mut names = Vec::new();
    let mut vectors = Vec::new();
    for (name, shape) in params {
        match shape {
            Shape::Scalar => names.push(name.clone()),
            Shape::Pair => names.extend(["x", "y"].map(|c| format!("{name}.{c}"))),
            Shape::Vec3 => names.extend(["x", "y", "z"].map(|c| format!("{name}.{c}"))),
        }
        vectors.push((*shape == Shape::Vec3).then(|| name.clone()));
        for _ in 1..shape.width() {
            vectors.push(None);
        }
    }
    (names, vectors)
}

/// Writes a program's statements, and the text each value is read as.
struct Writer<'s> {
    syn: &'s dyn Syntax,
    /// The statements so far.
    out: String,
    /// The temporaries' prefix: `t` unless a parameter could be one.
    prefix: String,
    /// Temporaries and loops named so far (names are unique in the
    /// function, so nested blocks never shadow).
    temps: u32,
    loops: u32,
}

/// One program being written: the text each input and each value so far
/// is read as, and the enclosing programs' values (innermost last).
struct Block<'b> {
    syn: &'b dyn Syntax,
    program: &'b Program,
    inputs: &'b [String],
    /// The vector parameter whose three components start at each input.
    vectors: &'b [Option<String>],
    outer: &'b [&'b [String]],
    text: Vec<String>,
    /// The state of each loop written so far, by the loop's value.
    states: HashMap<usize, LoopState>,
    indent: usize,
}

/// A loop's state as written: each element's text (a variable, or a
/// component of one), and the vectors that hold three elements, by the
/// first element's index.
struct LoopState {
    elements: Vec<String>,
    vectors: Vec<(u32, String)>,
}

impl Block<'_> {
    /// The expression of a result of shape `shape` whose components are
    /// `outputs`: a vector the program computed whole where it did.
    fn result(&self, shape: Shape, outputs: &[ValueId]) -> String {
        let texts: Vec<&str> = outputs.iter().map(|v| self.atom(*v)).collect();
        let parts: Vec<&str> = texts.iter().map(|t| unwrap(t)).collect();
        match shape {
            Shape::Scalar => texts[0].to_string(),
            Shape::Pair => self.syn.pair(&parts),
            Shape::Vec3 => match self.whole_vector(outputs[0], outputs[1], outputs[2]) {
                Some(v) => v.to_string(),
                None => self.syn.vector(&parts),
            },
        }
    }

    fn atom(&self, v: ValueId) -> &str {
        &self.text[v.index()]
    }

    /// A value as a call's argument: no enclosing parentheses needed.
    fn arg(&self, v: ValueId) -> &str {
        unwrap(self.atom(v))
    }

    /// A vector parameter or value, when `x, y, z` are its components in
    /// order.
    fn whole_vector(&self, x: ValueId, y: ValueId, z: ValueId) -> Option<&str> {
        let ops = &self.program.ops;
        match (ops[x.index()], ops[y.index()], ops[z.index()]) {
            (Op::Input(a), Op::Input(b), Op::Input(c)) if b == a + 1 && c == a + 2 => {
                self.vectors.get(a as usize)?.as_deref()
            }
            (Op::Component(a, 0), Op::Component(b, 1), Op::Component(c, 2)) if a == b && b == c => {
                Some(self.arg(a))
            }
            (Op::Element(l, a), Op::Element(m, b), Op::Element(n, c))
                if l == m && m == n && b == a + 1 && c == a + 2 =>
            {
                let state = self.states.get(&l.index())?;
                state
                    .vectors
                    .iter()
                    .find(|(first, _)| *first == a)
                    .map(|(_, name)| name.as_str())
            }
            _ => None,
        }
    }

    /// The scalar a vector value repeats, if it is a splat.
    fn splat(&self, v: ValueId) -> Option<ValueId> {
        match self.program.ops[v.index()] {
            Op::Make3(x, y, z) if x == y && y == z => Some(x),
            _ => None,
        }
    }

    /// A vector operand: a splat (`(real3)(s)`) as the scalar `s` where
    /// `scalar` allows it.
    fn vector_operand(&self, v: ValueId, scalar: bool) -> &str {
        match self.splat(v) {
            Some(s) if scalar => self.atom(s),
            _ => self.atom(v),
        }
    }

    /// The expression of `op`, parenthesised unless it is a call; `None`
    /// for a loop (written as statements).
    fn expression(&self, op: Op) -> Result<Option<String>, Unprintable> {
        let syn = self.syn;
        Ok(Some(match op {
            Op::Const(v) => syn.literal(v)?,
            Op::Input(i) => self.inputs[i as usize].clone(),
            Op::Capture(up, v) => {
                let at = self.outer.len() - up as usize;
                self.outer[at][v.index()].clone()
            }
            Op::Loop(_) => return Ok(None),
            Op::Element(l, k) => self.states[&l.index()].elements[k as usize].clone(),
            Op::Unary(u, a) => unary(syn, u, self.atom(a), self.arg(a)),
            Op::Binary(b, x, y) => binary(syn, b, self.atom(x), self.atom(y)),
            Op::Make3(x, y, z) => match self.whole_vector(x, y, z) {
                Some(v) => v.to_string(),
                None if x == y && y == z => syn.vector(&[self.arg(x)]),
                None => syn.vector(&[self.arg(x), self.arg(y), self.arg(z)]),
            },
            Op::Component(v, i) => format!("{}.{}", self.atom(v), ["x", "y", "z"][i as usize]),
            Op::Unary3(u, a) => return self.expression(Op::Unary(u, a)),
            Op::Binary3(b, x, y) => {
                let scalar_ok = syn.scalar_operand(b);
                // One operand stays a vector, so the result is one.
                let y_splat = scalar_ok && self.splat(y).is_some();
                let x_splat = !y_splat && matches!(b, Binary::Add | Binary::Mul);
                let x = self.vector_operand(x, x_splat);
                let y = self.vector_operand(y, y_splat);
                if b.is_logic() {
                    return Err(Unprintable::Vector);
                }
                binary(syn, b, x, y)
            }
            Op::Select3(c, a, b) | Op::Select(c, a, b) => {
                syn.select(self.atom(c), self.atom(a), self.atom(b))
            }
            Op::Length3(x, y, z) => match self.whole_vector(x, y, z) {
                Some(v) => format!("length({v})"),
                None => format!(
                    "length({})",
                    unwrap(&syn.vector(&[self.arg(x), self.arg(y), self.arg(z)]))
                ),
            },
        }))
    }
}

impl Writer<'_> {
    fn line(&mut self, indent: usize, text: &str) {
        for _ in 0..indent {
            self.out.push_str("    ");
        }
        self.out.push_str(text);
        self.out.push('\n');
    }

    fn temp(&mut self) -> String {
        let name = format!("{}{}", self.prefix, self.temps);
        self.temps += 1;
        name
    }

    /// Names `text` as a temporary of type `ty`, unless it is already a
    /// plain name or literal.
    fn name(&mut self, indent: usize, ty: &str, text: &str) -> String {
        if is_simple(self.syn, text) {
            return text.to_string();
        }
        let name = self.temp();
        let line = self.syn.constant(ty, &name, unwrap(text));
        self.line(indent, &line);
        name
    }

    /// Writes the statements of the block's live values; with `split`,
    /// first those `split` needs, then `if (split) break;`, then the rest.
    fn block(&mut self, b: &mut Block<'_>, split: Option<ValueId>) -> Result<(), Unprintable> {
        self.split_block(b, split.map(|v| (v, Exit::Break)))
    }

    /// [`Writer::block`] with the way out at the split: a loop's
    /// `break`, or a function's early `return` of the values where the
    /// split holds (which the first statements compute too).
    fn split_block(
        &mut self,
        b: &mut Block<'_>,
        split: Option<(ValueId, Exit)>,
    ) -> Result<(), Unprintable> {
        let (split, exit) = match split {
            Some((v, exit)) => (Some(v), Some(exit)),
            None => (None, None),
        };
        let program = b.program;
        let uses = printed_uses(program);
        let live = program.live();
        // Values a loop reads are named: a loop body never recomputes an
        // expression of the program around it.
        let mut named = vec![false; program.ops.len()];
        for op in &program.ops {
            if let Op::Loop(_) = op {
                for v in op.operands(&program.loops) {
                    named[v.index()] = true;
                }
            }
        }
        let first: Vec<bool> = match split {
            Some(v) => {
                let mut need = vec![false; program.ops.len()];
                need[v.index()] = true;
                if let Some(Exit::Return(_, early)) = &exit {
                    for e in early {
                        need[e.index()] = true;
                    }
                }
                for i in (0..program.ops.len()).rev() {
                    if need[i] {
                        for o in program.ops[i].operands(&program.loops) {
                            need[o.index()] = true;
                        }
                    }
                }
                need
            }
            None => vec![true; program.ops.len()],
        };
        b.text = vec![String::new(); program.ops.len()];
        let passes: &[bool] = if split.is_some() {
            &[true, false]
        } else {
            &[true]
        };
        for &pass in passes {
            for (i, op) in program.ops.iter().enumerate() {
                if !live[i] || first[i] != pass {
                    continue;
                }
                self.op(b, i, *op, uses[i] > 1 || named[i])?;
            }
            if pass && let Some(v) = split {
                let cond = unwrap(b.atom(v)).to_string();
                let leave = match &exit {
                    Some(Exit::Return(shape, early)) => {
                        format!("return {};", unwrap(&b.result(*shape, early)))
                    }
                    _ => "break;".to_string(),
                };
                self.line(b.indent, &format!("if ({cond}) {{"));
                self.line(b.indent + 1, &leave);
                self.line(b.indent, "}");
            }
        }
        Ok(())
    }

    /// Writes value `i` of the block: inline, named, or a loop.
    fn op(&mut self, b: &mut Block<'_>, i: usize, op: Op, name: bool) -> Result<(), Unprintable> {
        if let Op::Loop(n) = op {
            let (text, state) = self.write_loop(b, &b.program.loops[n as usize])?;
            b.text[i] = text;
            b.states.insert(i, state);
            return Ok(());
        }
        let text = b.expression(op)?.unwrap_or_default();
        let trivial = matches!(
            op,
            Op::Const(_) | Op::Input(_) | Op::Capture(..) | Op::Element(..)
        ) || is_simple(self.syn, &text);
        b.text[i] = if name && !trivial {
            let ty = if op.is_logic() {
                "bool"
            } else if op.is_vector() {
                "real3"
            } else {
                "real"
            };
            let t = self.temp();
            let line = self.syn.constant(ty, &t, unwrap(&text));
            self.line(b.indent, &line);
            t
        } else {
            text
        };
        Ok(())
    }

    /// Writes a loop; its text is the prefix of its state's names. Three
    /// consecutive elements that start as a vector and are always replaced
    /// by one (or kept) are one vector variable, as a hand-written loop
    /// keeps its point.
    fn write_loop(&mut self, b: &Block<'_>, l: &Loop) -> Result<(String, LoopState), Unprintable> {
        let id = self.loops;
        self.loops += 1;
        let state = format!("{}s{id}", self.prefix);
        let index = format!("{}i{id}", self.prefix);
        let indent = b.indent;
        let k = l.init.len();
        // Each element's vector (by its first element) and component.
        let mut group: Vec<Option<(usize, usize)>> = vec![None; k];
        let mut vectors = Vec::new();
        let mut j = 0;
        while j + 3 <= k {
            let init = b.whole_vector(l.init[j], l.init[j + 1], l.init[j + 2]);
            match init {
                Some(text) if next_vector(&l.body, j).is_some() => {
                    vectors.push((j, text.to_string()));
                    for c in 0..3 {
                        group[j + c] = Some((j, c));
                    }
                    j += 3;
                }
                _ => j += 1,
            }
        }
        let elements: Vec<String> = (0..k)
            .map(|j| match group[j] {
                Some((first, c)) => format!("{state}_{first}.{}", ["x", "y", "z"][c]),
                None => format!("{state}_{j}"),
            })
            .collect();
        for (j, v) in l.init.iter().enumerate() {
            match group[j] {
                Some((_, 0)) => {
                    let init = &vectors.iter().find(|(f, _)| *f == j).expect("grouped").1;
                    let line = self
                        .syn
                        .variable("real3", &format!("{state}_{j}"), unwrap(init));
                    self.line(indent, &line);
                }
                Some(_) => {}
                None => {
                    let init = unwrap(b.atom(*v)).to_string();
                    let line = self.syn.variable("real", &format!("{state}_{j}"), &init);
                    self.line(indent, &line);
                }
            }
        }
        // The step count as an integer, once: `i < ceil(count)` is `i <
        // count` for every integer `i`, NaN and negative counts make no
        // step, and the count is capped as `Num::iterate` caps it.
        let count = unwrap(b.atom(l.count)).to_string();
        let steps = format!("{}n{id}", self.prefix);
        let line = self.syn.steps(&steps, &count, MAX_LOOP_STEPS);
        self.line(indent, &line);
        let line = self.syn.for_header(&index, &steps);
        self.line(indent, &line);
        let mut inputs = vec![self.syn.index_value(&index)];
        inputs.extend(elements.iter().cloned());
        let mut input_vectors = vec![None; k + 1];
        for (first, _) in &vectors {
            input_vectors[first + 1] = Some(format!("{state}_{first}"));
        }
        let mut outer: Vec<&[String]> = b.outer.to_vec();
        outer.push(&b.text);
        let mut body = Block {
            syn: self.syn,
            program: &l.body,
            inputs: &inputs,
            vectors: &input_vectors,
            outer: &outer,
            text: Vec::new(),
            states: HashMap::new(),
            indent: indent + 1,
        };
        self.block(&mut body, l.stop_before_output())?;
        // The next state and the stop are read before the state changes.
        let mut next = Vec::with_capacity(k);
        for (j, v) in l.body.outputs[..k].iter().enumerate() {
            next.push(match group[j] {
                Some((_, 0)) => match next_vector(&l.body, j) {
                    Some(Some(w)) => Some(self.name(indent + 1, "real3", body.atom(w))),
                    _ => None,
                },
                Some(_) => None,
                None => {
                    let text = body.atom(*v).to_string();
                    if text == elements[j] {
                        None
                    } else {
                        Some(self.name(indent + 1, "real", &text))
                    }
                }
            });
        }
        let stop = match l.stop_after_output() {
            Some(v) => {
                let text = body.atom(v).to_string();
                Some(self.name(indent + 1, "bool", &text))
            }
            None => None,
        };
        for (j, n) in next.iter().enumerate() {
            if let Some(n) = n {
                self.line(indent + 1, &format!("{state}_{j} = {n};"));
            }
        }
        if let Some(stop) = stop {
            self.line(indent + 1, &format!("if ({stop}) {{"));
            self.line(indent + 2, "break;");
            self.line(indent + 1, "}");
        }
        self.line(indent, "}");
        let vectors = vectors
            .into_iter()
            .map(|(first, _)| {
                let first = u32::try_from(first).expect("a loop's state is small");
                (first, format!("{state}_{first}"))
            })
            .collect();
        Ok((state, LoopState { elements, vectors }))
    }
}

/// Whether a loop body's next state at elements `j..j + 3` is one vector:
/// `Some(Some(w))` for the components of the body's vector `w`,
/// `Some(None)` for the three elements unchanged, `None` otherwise.
fn next_vector(body: &Program, j: usize) -> Option<Option<ValueId>> {
    let out = body.outputs.get(j..j + 3)?;
    let ops = &body.ops;
    match (
        ops[out[0].index()],
        ops[out[1].index()],
        ops[out[2].index()],
    ) {
        (Op::Component(a, 0), Op::Component(b, 1), Op::Component(c, 2)) if a == b && b == c => {
            Some(Some(a))
        }
        (Op::Input(a), Op::Input(b), Op::Input(c))
            if a as usize == j + 1 && b == a + 1 && c == a + 2 =>
        {
            Some(None)
        }
        _ => None,
    }
}

/// How many times each value's text is written, as the printer writes
/// them: a vector read whole (three components made into a vector, or its
/// length) counts once, and a component's reads count as its vector's.
/// A value written more than once is named.
fn printed_uses(program: &Program) -> Vec<u32> {
    let ops = &program.ops;
    let live = program.live();
    let mut uses = vec![0u32; ops.len()];
    let whole =
        |x: ValueId, y: ValueId, z: ValueId| match (ops[x.index()], ops[y.index()], ops[z.index()])
        {
            (Op::Component(a, 0), Op::Component(b, 1), Op::Component(c, 2)) if a == b && b == c => {
                Some(a)
            }
            _ => None,
        };
    let result = |outputs: &[ValueId]| match outputs {
        [x, y, z] => whole(*x, *y, *z),
        _ => None,
    };
    match result(&program.outputs) {
        Some(v) => uses[v.index()] += 1,
        None => program.outputs.iter().for_each(|v| uses[v.index()] += 1),
    }
    for i in (0..ops.len()).rev() {
        if !live[i] {
            continue;
        }
        match ops[i] {
            Op::Make3(x, y, z) | Op::Length3(x, y, z) if uses[i] > 0 => match whole(x, y, z) {
                Some(v) => uses[v.index()] += 1,
                None => [x, y, z].iter().for_each(|o| uses[o.index()] += 1),
            },
            Op::Component(v, _) => uses[v.index()] += uses[i],
            Op::Loop(_) => {
                for o in ops[i].operands(&program.loops) {
                    uses[o.index()] += 1;
                }
            }
            op if uses[i] > 0 => {
                for o in op.operands(&program.loops) {
                    uses[o.index()] += 1;
                }
            }
            _ => {}
        }
    }
    uses
}

/// Whether `text` is a name or a literal, cheap to read twice.
fn is_simple(syn: &dyn Syntax, text: &str) -> bool {
    text.chars()
        .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '.')
        || syn.is_literal(text)
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

/// How a split block leaves at its split.
enum Exit {
    /// A loop's `break`.
    Break,
    /// A function's `return` of these values, of this shape.
    Return(Shape, Vec<ValueId>),
}

/// Where every output of `program` is `select(c, a, b)` with one condition
/// `c` that needs no loop (so it is cheap to know first): `c`, the `a`s and
/// the `b`s. A function then returns the `a`s early where `c` holds.
fn early_return(program: &Program) -> Option<(ValueId, Vec<ValueId>, Vec<ValueId>)> {
    let mut cond = None;
    let (mut first, mut late) = (Vec::new(), Vec::new());
    for &out in &program.outputs {
        let (Op::Select(c, a, b) | Op::Select3(c, a, b)) = program.ops[out.index()] else {
            return None;
        };
        if cond.is_some_and(|k| k != c) {
            return None;
        }
        cond = Some(c);
        first.push(a);
        late.push(b);
    }
    let c = cond?;
    // The condition and the early values must not wait for a loop.
    let mut need = vec![false; program.ops.len()];
    need[c.index()] = true;
    for a in &first {
        need[a.index()] = true;
    }
    for i in (0..program.ops.len()).rev() {
        if need[i] {
            if let Op::Loop(_) = program.ops[i] {
                return None;
            }
            for o in program.ops[i].operands(&program.loops) {
                need[o.index()] = true;
            }
        }
    }
    Some((c, first, late))
}

/// [`Printer::function`] in the language `syn` spells.
fn print_function(
    syn: &dyn Syntax,
    signature: &Signature<'_>,
    program: &Program,
) -> Result<String, Unprintable> {
    check_arity(
        program,
        signature.inputs(),
        signature.result.width() as usize,
    )?;
    let params: Vec<(String, Shape)> = signature
        .params
        .iter()
        .map(|(name, shape)| (syn.parameter(name), *shape))
        .collect();
    let (inputs, vectors) = input_names(&params);
    // Temporaries are `t0`, `t1`, ..., loops' states `ts0_0` and
    // indices `ti0`: with more underscores while a parameter's name
    // starts with the prefix.
    let mut prefix = String::from("t");
    while params.iter().any(|(n, _)| n.starts_with(prefix.as_str())) {
        prefix.push('_');
    }
    let mut w = Writer {
        syn,
        out: String::new(),
        prefix,
        temps: 0,
        loops: 0,
    };
    let mut block = Block {
        syn,
        program,
        inputs: &inputs,
        vectors: &vectors,
        outer: &[],
        text: Vec::new(),
        states: HashMap::new(),
        indent: 1,
    };
    // A result that is one value where a condition holds and another
    // elsewhere, for every output (a fractal's far field), returns
    // early: the other values are computed only where they count.
    let early = early_return(program);
    let outputs = match &early {
        Some((_, _, late)) => late.clone(),
        None => program.outputs.clone(),
    };
    w.split_block(
        &mut block,
        early.map(|(c, first, _)| (c, Exit::Return(signature.result, first))),
    )?;
    let result = unwrap(&block.result(signature.result, &outputs)).to_string();
    let params: Vec<(String, &str)> = params
        .into_iter()
        .map(|(name, shape)| (name, type_of(shape)))
        .collect();
    Ok(syn.function(
        signature.name,
        &params,
        type_of(signature.result),
        &w.out,
        &result,
    ))
}

/// [`Printer::inline`] in the language `syn` spells.
fn print_inline(
    syn: &dyn Syntax,
    inputs: &[(&str, Shape)],
    results: &[Shape],
    program: &Program,
    prefix: &str,
) -> Result<Inline, Unprintable> {
    let width = |shapes: &mut dyn Iterator<Item = Shape>| shapes.map(Shape::width).sum::<u32>();
    let outputs = width(&mut results.iter().copied()) as usize;
    check_arity(program, width(&mut inputs.iter().map(|(_, s)| *s)), outputs)?;
    let inputs: Vec<(String, Shape)> = inputs.iter().map(|(n, s)| ((*n).to_string(), *s)).collect();
    let (names, vectors) = input_names(&inputs);
    let mut w = Writer {
        syn,
        out: String::new(),
        prefix: prefix.to_string(),
        temps: 0,
        loops: 0,
    };
    let mut block = Block {
        syn,
        program,
        inputs: &names,
        vectors: &vectors,
        outer: &[],
        text: Vec::new(),
        states: HashMap::new(),
        indent: 0,
    };
    w.block(&mut block, None)?;
    let mut at = 0;
    let results = results
        .iter()
        .map(|shape| {
            let width = shape.width() as usize;
            let text = block.result(*shape, &program.outputs[at..at + width]);
            at += width;
            unwrap(&text).to_string()
        })
        .collect();
    Ok(Inline {
        statements: w.out,
        results,
    })
}
