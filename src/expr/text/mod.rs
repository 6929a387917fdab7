//! Text formulas: a distance written as text (in a scene file or on the
//! command line), parsed into a [`Formula`] that runs like any formula
//! written in Rust — as numbers, intervals or a traced [`Program`].
//!
//! ```text
//! // A sphere of radius r, its surface rippled by `amp`.
//! let d = length(p) - r;
//! let q = p;
//! for i in 0..4 {
//!     q = abs(q) - vec3(0.5, 0.5, 0.5);
//!     break if dot(q, q) > 4.0;
//! }
//! if d > 1.0 { d } else { d + amp * sin(8.0 * q.x) }
//! ```
//!
//! A formula is statements then the value: `let NAME = EXPR;`, `NAME =
//! EXPR;` (to a name `let` made), `if COND { ... } else { ... }` and `for
//! NAME in A..B { ... }` with integer bounds (at most [`MAX_ITERATIONS`]
//! steps, counting the loops around it), whose body may `break if COND;`. Values are
//! numbers, 3-vectors (`p`, `vec3(x, y, z)`, `.x .y .z`) and truth values
//! (comparisons, `&&`, `||`, `!`). The names are `p`, the parameters, `pi`
//! and the `let`s; the functions are listed in [`FUNCTIONS`]. There is no
//! recursion and no unbounded loop, so every formula terminates; a loop
//! is one loop of the program (its state is what its body assigns) and
//! branches become `select`s, so a printer writes only the IR's
//! operations. Errors give the line and column (from 1) and what was
//! expected.

mod eval;
mod parse;

use std::collections::HashMap;
use std::fmt;

use super::num::Num;
use super::program::Program;
use super::trace::{Var, trace};
use crate::expr::{V3, v3};
use eval::{Eval, Run, Value};
use parse::{Block, KEYWORDS, Parser, Tok, lex, start};

/// The most steps a loop may take, times the steps of the loops around it:
/// a bound on the work of one evaluation.
pub const MAX_ITERATIONS: u64 = 4096;

/// The longest formula text accepted, in bytes.
pub const MAX_LENGTH: usize = 16 * 1024;

/// How deep parentheses, blocks and prefix operators may nest in a formula.
pub const MAX_NESTING: usize = 64;

/// How deep one expression's operations may stack (a chain `a + b + c`
/// is as deep as it is long); a longer one is split with `let`.
pub const MAX_DEPTH: usize = 256;

/// The functions a formula may call, with their argument counts.
pub const FUNCTIONS: &[(&str, usize)] = &[
    ("sqrt", 1),
    ("abs", 1),
    ("sin", 1),
    ("cos", 1),
    ("acos", 1),
    ("exp", 1),
    ("log", 1),
    ("floor", 1),
    ("round", 1),
    ("fract", 1),
    ("min", 2),
    ("max", 2),
    ("atan2", 2),
    ("pow", 2),
    ("hypot", 2),
    ("clamp", 3),
    ("mix", 3),
    ("length", 1),
    ("dot", 2),
    ("cross", 2),
    ("normalize", 1),
    ("vec3", 3),
];

/// A formula's syntax or meaning error, located.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub struct FormulaError {
    /// The line, from 1.
    pub line: usize,
    /// The column, in characters from 1.
    pub column: usize,
    /// What is wrong, and what was expected.
    pub message: String,
}

impl fmt::Display for FormulaError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "line {}, column {}: {}",
            self.line, self.column, self.message
        )
    }
}

impl std::error::Error for FormulaError {}

/// A parsed text formula: a distance of `p` and named parameters.
#[derive(Debug, Clone)]
pub struct Formula {
    text: String,
    params: Vec<String>,
    body: Block,
    lines: Vec<usize>,
}

impl Formula {
    /// Parses `text` with the parameters `params` (their names, in the
    /// order their values are given), checking every name, call and type
    /// by running it once.
    ///
    /// # Errors
    /// A [`FormulaError`] at the first problem: a syntax error, an unknown
    /// name or function, a wrong argument count or type, a loop beyond
    /// [`MAX_ITERATIONS`], or no value at the end.
    pub fn parse(text: &str, params: &[&str]) -> Result<Self, FormulaError> {
        let lines: Vec<usize> = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        let mut formula = Formula {
            text: text.to_string(),
            params: params.iter().map(|s| (*s).to_string()).collect(),
            body: Block {
                stmts: Vec::new(),
                value: None,
            },
            lines,
        };
        if text.len() > MAX_LENGTH {
            return Err(formula.locate(
                0,
                format!(
                    "the formula is {} bytes long; the most is {MAX_LENGTH}",
                    text.len()
                ),
            ));
        }
        for p in params {
            if matches!(*p, "p" | "pi") || KEYWORDS.contains(p) {
                return Err(formula.locate(0, format!("a parameter may not be called `{p}`")));
            }
        }
        let tokens = lex(text).map_err(|(at, m)| formula.locate(at, m))?;
        let mut parser = Parser {
            text,
            tokens,
            at: 0,
            nesting: 0,
        };
        let body = parser.block().map_err(|(at, m)| formula.locate(at, m))?;
        if parser.peek().tok != Tok::End {
            let t = parser.peek();
            return Err(formula.locate(
                t.start,
                format!(
                    "expected the end of the formula, found {}",
                    parser.describe(t)
                ),
            ));
        }
        if body.value.is_none() {
            return Err(formula.locate(
                text.len(),
                "expected the formula's value (a number) at its end".into(),
            ));
        }
        formula.body = body;
        // One run in plain numbers and one traced (which runs every loop's
        // body once, whatever its count) check names, calls and types.
        formula
            .run::<f64>(v3(0.0, 0.0, 0.0), &vec![0.0; params.len()])
            .map_err(|(at, m)| formula.locate(at, m))?;
        let mut traced = Ok(());
        let n = u32::try_from(params.len() + 3).unwrap_or(u32::MAX);
        trace(n, |a: &[Var]| {
            match formula.run(v3(a[0], a[1], a[2]), &a[3..]) {
                Ok(v) => vec![v],
                Err(e) => {
                    traced = Err(e);
                    vec![a[0]]
                }
            }
        });
        traced.map_err(|(at, m)| formula.locate(at, m))?;
        Ok(formula)
    }

    /// The formula's text.
    #[must_use]
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The parameters' names, in order.
    #[must_use]
    pub fn params(&self) -> &[String] {
        &self.params
    }

    fn locate(&self, at: usize, message: String) -> FormulaError {
        let line = self.lines.partition_point(|&l| l <= at).max(1);
        let from = self.lines[line - 1];
        let column = self.text[from..at.min(self.text.len())].chars().count() + 1;
        FormulaError {
            line,
            column,
            message,
        }
    }

    /// The distance at `p` with parameter values `args`, in any number
    /// type. A parsed formula always runs (parsing ran it once); the value
    /// is NaN should it not.
    #[must_use]
    pub fn distance<N: Num>(&self, p: V3<N>, args: &[N]) -> N {
        self.run(p, args).unwrap_or_else(|_| N::of(f64::NAN))
    }

    /// The formula traced into a program with inputs `p.x, p.y, p.z` and
    /// then the parameters.
    #[must_use]
    pub fn program(&self) -> Program {
        let n = u32::try_from(self.params.len() + 3).unwrap_or(u32::MAX);
        trace(n, |a: &[Var]| {
            vec![self.distance(v3(a[0], a[1], a[2]), &a[3..])]
        })
    }

    fn run<N: Num>(&self, p: V3<N>, args: &[N]) -> Eval<N> {
        let mut globals = HashMap::new();
        globals.insert("p".to_string(), Value::Vector(p));
        globals.insert("pi".to_string(), Value::Number(N::of(std::f64::consts::PI)));
        for (name, v) in self.params.iter().zip(args) {
            globals.insert(name.clone(), Value::Number(*v));
        }
        let mut run = Run {
            formula: self,
            vars: vec![globals],
            mask: None,
            iterations: 0,
        };
        let value = run.block(&self.body)?;
        match value {
            Some(Value::Number(n)) => Ok(n),
            Some(v) => Err((
                self.body.value.as_ref().map_or(0, start),
                format!("the formula's value is {}; expected a number", v.kind()),
            )),
            None => Err((self.text.len(), "expected the formula's value".into())),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(text: &str, params: &[&str], p: [f64; 3], args: &[f64]) -> f64 {
        Formula::parse(text, params)
            .unwrap()
            .distance(v3(p[0], p[1], p[2]), args)
    }

    #[test]
    fn formulas_compute_what_they_say() {
        assert_eq!(at("length(p) - r", &["r"], [3.0, 4.0, 0.0], &[1.0]), 4.0);
        assert_eq!(at("let a = 2; a * a + p.x", &[], [1.0, 0.0, 0.0], &[]), 5.0);
        let sum = "let s = 0; for i in 0..10 { s = s + i; break if s > 9; } s";
        assert_eq!(at(sum, &[], [0.0; 3], &[]), 10.0);
        let branch = "let d = 0; if p.x > 0 { d = 1; } else { d = 2; } d";
        assert_eq!(at(branch, &[], [1.0, 0.0, 0.0], &[]), 1.0);
        assert_eq!(at(branch, &[], [-1.0, 0.0, 0.0], &[]), 2.0);
        let value = "if p.y < 0 { -1 } else if p.y > 0 { 1 } else { 0 }";
        assert_eq!(at(value, &[], [0.0, -3.0, 0.0], &[]), -1.0);
        assert_eq!(at(value, &[], [0.0, 3.0, 0.0], &[]), 1.0);
        assert_eq!(at(value, &[], [0.0, 0.0, 0.0], &[]), 0.0);
    }

    #[test]
    fn the_traced_program_agrees_with_the_text() {
        let f = Formula::parse(
            "let q = p; for i in 0..3 { q = abs(q) - vec3(0.3, 0.2, 0.1) * r; break if length(q) > 2; } length(q) - 0.1",
            &["r"],
        )
        .unwrap();
        let program = f.program();
        for k in 0..50 {
            let t = f64::from(k) * 0.37;
            let p = v3(t.sin() * 2.0, t.cos(), (t * 0.7).sin() * 3.0);
            let direct = f.distance(p, &[1.5]);
            let run = program.run(&[p.x, p.y, p.z, 1.5])[0];
            assert_eq!(direct.to_bits(), run.to_bits());
        }
    }

    #[test]
    fn errors_say_where_and_what_was_expected() {
        let e = Formula::parse("length(p) -", &[]).unwrap_err();
        assert_eq!((e.line, e.column), (1, 12));
        assert!(e.message.contains("expected a number"), "{e}");
        let e = Formula::parse("let a = 1;\nlength(p) - q", &["r"]).unwrap_err();
        assert_eq!((e.line, e.column), (2, 13), "{e}");
        assert!(
            e.message.contains("unknown variable `q`") && e.message.contains("r"),
            "{e}"
        );
        let e = Formula::parse("for i in 0..100 { for j in 0..100 { } } 1", &[]).unwrap_err();
        assert!(e.message.contains("10000 steps"), "{e}");
        let e = Formula::parse("let x = 0; for i in 0..0 { x = q; } x", &[]).unwrap_err();
        assert!(e.message.contains("unknown variable `q`"), "{e}");
        let e = Formula::parse("p", &[]).unwrap_err();
        assert!(e.message.contains("a vector"), "{e}");
        let e = Formula::parse("sqrt(1, 2)", &[]).unwrap_err();
        assert!(e.message.contains("takes 1"), "{e}");
        let e = Formula::parse("break if 1 > 0; 1", &[]).unwrap_err();
        assert!(e.message.contains("loop"), "{e}");
    }
}
