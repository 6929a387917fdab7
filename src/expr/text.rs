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
//! NAME in A..B { ... }` with integer bounds (at most
//! [`MAX_ITERATIONS`] in all), whose body may `break if COND;`. Values are
//! numbers, 3-vectors (`p`, `vec3(x, y, z)`, `.x .y .z`) and truth values
//! (comparisons, `&&`, `||`, `!`). The names are `p`, the parameters, `pi`
//! and the `let`s; the functions are listed in [`FUNCTIONS`]. There is no
//! recursion and no unbounded loop, so every formula terminates; loops
//! are unrolled and branches become `select`s, so a printer writes only the
//! IR's operations. Errors give the line and column (from 1) and what was
//! expected.

use std::collections::HashMap;
use std::fmt;

use super::num::Num;
use super::program::{Program, Var, trace};
use crate::math::{V3, v3};

/// The most loop iterations a formula may run, counting every loop and
/// every nesting: loops are unrolled, so this bounds the program's size.
pub const MAX_ITERATIONS: u64 = 256;

/// The longest formula text accepted, in bytes.
pub const MAX_LENGTH: usize = 16 * 1024;

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

#[derive(Debug, Clone, Copy, PartialEq)]
enum Tok {
    Num(f64),
    Ident,
    Sym(&'static str),
    End,
}

#[derive(Debug, Clone, Copy)]
struct Token {
    tok: Tok,
    start: usize,
    end: usize,
}

const SYMBOLS: &[&str] = &[
    "<=", ">=", "==", "!=", "&&", "||", "..", "+", "-", "*", "/", "(", ")", "{", "}", ",", ";",
    "=", "<", ">", "!", ".",
];

fn lex(text: &str) -> Result<Vec<Token>, (usize, String)> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if text[i..].starts_with("//") {
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
        } else if c.is_ascii_digit() {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                // `0..4`: a range, not a number's point.
                if bytes[i] == b'.' && bytes.get(i + 1) == Some(&b'.') {
                    break;
                }
                i += 1;
            }
            if i < bytes.len() && (bytes[i] == b'e' || bytes[i] == b'E') {
                let mut j = i + 1;
                if j < bytes.len() && (bytes[j] == b'+' || bytes[j] == b'-') {
                    j += 1;
                }
                if j < bytes.len() && bytes[j].is_ascii_digit() {
                    i = j;
                    while i < bytes.len() && bytes[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let v: f64 = text[start..i]
                .parse()
                .map_err(|_| (start, format!("`{}` is not a number", &text[start..i])))?;
            if !v.is_finite() {
                return Err((start, format!("`{}` is too large", &text[start..i])));
            }
            out.push(Token {
                tok: Tok::Num(v),
                start,
                end: i,
            });
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            out.push(Token {
                tok: Tok::Ident,
                start,
                end: i,
            });
        } else if let Some(s) = SYMBOLS.iter().find(|s| text[i..].starts_with(**s)) {
            out.push(Token {
                tok: Tok::Sym(s),
                start: i,
                end: i + s.len(),
            });
            i += s.len();
        } else {
            let ch = text[i..].chars().next().unwrap_or('?');
            return Err((i, format!("unexpected character `{ch}`")));
        }
    }
    out.push(Token {
        tok: Tok::End,
        start: text.len(),
        end: text.len(),
    });
    Ok(out)
}

/// An expression, with the byte offset it starts at.
#[derive(Debug, Clone)]
enum Expr {
    Num(f64),
    Name(String, usize),
    Neg(Box<Expr>),
    Not(Box<Expr>),
    Binary(&'static str, Box<Expr>, Box<Expr>, usize),
    Call(String, Vec<Expr>, usize),
    Field(Box<Expr>, usize, usize),
    If(Box<Expr>, Box<Block>, Box<Block>, usize),
}

#[derive(Debug, Clone)]
enum Stmt {
    Let(String, Expr, usize),
    Assign(String, Expr, usize),
    If(Expr, Block, Block),
    For(String, i64, i64, Block, usize),
    BreakIf(Expr, usize),
}

/// Statements, then an optional value.
#[derive(Debug, Clone)]
struct Block {
    stmts: Vec<Stmt>,
    value: Option<Expr>,
}

struct Parser<'t> {
    text: &'t str,
    tokens: Vec<Token>,
    at: usize,
}

type Parse<T> = Result<T, (usize, String)>;

const KEYWORDS: &[&str] = &["let", "if", "else", "for", "in", "break"];

impl Parser<'_> {
    fn peek(&self) -> Token {
        self.tokens[self.at]
    }

    fn describe(&self, t: Token) -> String {
        match t.tok {
            Tok::End => "the end of the formula".into(),
            _ => format!("`{}`", &self.text[t.start..t.end]),
        }
    }

    fn is_sym(&self, s: &str) -> bool {
        self.peek().tok == Tok::Sym(symbol(s))
    }

    fn is_word(&self, w: &str) -> bool {
        let t = self.peek();
        t.tok == Tok::Ident && &self.text[t.start..t.end] == w
    }

    fn expect_sym(&mut self, s: &str, what: &str) -> Parse<usize> {
        let t = self.peek();
        if self.is_sym(s) {
            self.at += 1;
            Ok(t.start)
        } else {
            Err((
                t.start,
                format!("expected {what}, found {}", self.describe(t)),
            ))
        }
    }

    fn expect_word(&mut self, w: &str) -> Parse<()> {
        let t = self.peek();
        if self.is_word(w) {
            self.at += 1;
            Ok(())
        } else {
            Err((
                t.start,
                format!("expected `{w}`, found {}", self.describe(t)),
            ))
        }
    }

    fn name(&mut self, what: &str) -> Parse<(String, usize)> {
        let t = self.peek();
        let text = &self.text[t.start..t.end];
        if t.tok == Tok::Ident && !KEYWORDS.contains(&text) {
            self.at += 1;
            Ok((text.to_string(), t.start))
        } else {
            Err((
                t.start,
                format!("expected {what}, found {}", self.describe(t)),
            ))
        }
    }

    fn integer(&mut self) -> Parse<i64> {
        let t = self.peek();
        let negative = self.is_sym("-");
        if negative {
            self.at += 1;
        }
        let t2 = self.peek();
        match t2.tok {
            #[allow(clippy::cast_possible_truncation)]
            Tok::Num(v) if v.fract() == 0.0 && v.abs() <= 1e6 => {
                self.at += 1;
                Ok(if negative { -(v as i64) } else { v as i64 })
            }
            _ => Err((
                t.start,
                format!(
                    "expected an integer loop bound, found {}",
                    self.describe(t2)
                ),
            )),
        }
    }

    /// Statements and a final value, up to `}` or the end.
    fn block(&mut self) -> Parse<Block> {
        let mut stmts = Vec::new();
        loop {
            if self.is_sym("}") || self.peek().tok == Tok::End {
                return Ok(Block { stmts, value: None });
            }
            let t = self.peek();
            if self.is_word("let") {
                self.at += 1;
                let (name, at) = self.name("a name after `let`")?;
                self.expect_sym("=", "`=`")?;
                let e = self.expr()?;
                self.expect_sym(";", "`;` after the `let`")?;
                stmts.push(Stmt::Let(name, e, at));
            } else if self.is_word("for") {
                self.at += 1;
                let (name, at) = self.name("a loop variable after `for`")?;
                self.expect_word("in")?;
                let from = self.integer()?;
                self.expect_sym("..", "`..` in the loop's range")?;
                let to = self.integer()?;
                self.expect_sym("{", "`{` to open the loop's body")?;
                let body = self.block()?;
                if let Some(v) = &body.value {
                    return Err((
                        start(v),
                        "a loop's body ends with a statement, not a value".into(),
                    ));
                }
                self.expect_sym("}", "`}` to close the loop's body")?;
                stmts.push(Stmt::For(name, from, to, body, at));
            } else if self.is_word("break") {
                self.at += 1;
                self.expect_word("if")?;
                let e = self.expr()?;
                self.expect_sym(";", "`;` after `break if`")?;
                stmts.push(Stmt::BreakIf(e, t.start));
            } else if self.is_word("if") {
                let e = self.if_expr()?;
                let Expr::If(c, a, b, at) = e else {
                    unreachable!("if_expr returns an if")
                };
                if a.value.is_some() && b.value.is_some() {
                    // An `if` with values is the formula's value (or an
                    // error if more follows).
                    let value = Expr::If(c, a, b, at);
                    if self.is_sym("}") || self.peek().tok == Tok::End {
                        return Ok(Block {
                            stmts,
                            value: Some(value),
                        });
                    }
                    let n = self.peek();
                    return Err((
                        n.start,
                        format!(
                            "expected the end after the value, found {}",
                            self.describe(n)
                        ),
                    ));
                }
                if let Some(v) = a.value.as_ref().or(b.value.as_ref()) {
                    return Err((
                        start(v),
                        "an `if` gives a value in both branches or in neither".into(),
                    ));
                }
                stmts.push(Stmt::If(*c, *a, *b));
            } else if t.tok == Tok::Ident
                && self.tokens.get(self.at + 1).map(|n| n.tok) == Some(Tok::Sym("="))
            {
                let (name, at) = self.name("a name")?;
                self.at += 1;
                let e = self.expr()?;
                self.expect_sym(";", "`;` after the assignment")?;
                stmts.push(Stmt::Assign(name, e, at));
            } else {
                let e = self.expr()?;
                if self.is_sym("}") || self.peek().tok == Tok::End {
                    return Ok(Block {
                        stmts,
                        value: Some(e),
                    });
                }
                let n = self.peek();
                return Err((
                    n.start,
                    format!(
                        "expected an operator or the end of the value, found {}",
                        self.describe(n)
                    ),
                ));
            }
        }
    }

    fn braced(&mut self, what: &str) -> Parse<Block> {
        self.expect_sym("{", &format!("`{{` to open {what}"))?;
        let b = self.block()?;
        self.expect_sym("}", &format!("`}}` to close {what}"))?;
        Ok(b)
    }

    fn if_expr(&mut self) -> Parse<Expr> {
        let at = self.peek().start;
        self.expect_word("if")?;
        let c = self.expr()?;
        let a = self.braced("the `if` branch")?;
        let b = if self.is_word("else") {
            self.at += 1;
            if self.is_word("if") {
                let e = self.if_expr()?;
                let value = matches!(&e, Expr::If(_, a, _, _) if a.value.is_some());
                if value {
                    Block {
                        stmts: Vec::new(),
                        value: Some(e),
                    }
                } else {
                    let Expr::If(c, a, b, _) = e else {
                        unreachable!("if_expr returns an if")
                    };
                    Block {
                        stmts: vec![Stmt::If(*c, *a, *b)],
                        value: None,
                    }
                }
            } else {
                self.braced("the `else` branch")?
            }
        } else {
            Block {
                stmts: Vec::new(),
                value: None,
            }
        };
        Ok(Expr::If(Box::new(c), Box::new(a), Box::new(b), at))
    }

    fn expr(&mut self) -> Parse<Expr> {
        self.binary(0)
    }

    fn binary(&mut self, level: usize) -> Parse<Expr> {
        const LEVELS: &[&[&str]] = &[
            &["||"],
            &["&&"],
            &["<", "<=", ">", ">=", "==", "!="],
            &["+", "-"],
            &["*", "/"],
        ];
        if level == LEVELS.len() {
            return self.unary();
        }
        let mut left = self.binary(level + 1)?;
        loop {
            let t = self.peek();
            let Tok::Sym(s) = t.tok else {
                return Ok(left);
            };
            if !LEVELS[level].contains(&s) {
                return Ok(left);
            }
            self.at += 1;
            let right = self.binary(level + 1)?;
            left = Expr::Binary(s, Box::new(left), Box::new(right), t.start);
            // Comparisons do not chain.
            if level == 2 {
                return Ok(left);
            }
        }
    }

    fn unary(&mut self) -> Parse<Expr> {
        if self.is_sym("-") {
            self.at += 1;
            return Ok(Expr::Neg(Box::new(self.unary()?)));
        }
        if self.is_sym("!") {
            self.at += 1;
            return Ok(Expr::Not(Box::new(self.unary()?)));
        }
        let mut e = self.primary()?;
        while self.is_sym(".") {
            self.at += 1;
            let t = self.peek();
            let field = &self.text[t.start..t.end];
            let i = match (t.tok, field) {
                (Tok::Ident, "x") => 0,
                (Tok::Ident, "y") => 1,
                (Tok::Ident, "z") => 2,
                _ => {
                    return Err((
                        t.start,
                        format!(
                            "expected a component `x`, `y` or `z`, found {}",
                            self.describe(t)
                        ),
                    ));
                }
            };
            self.at += 1;
            e = Expr::Field(Box::new(e), i, t.start);
        }
        Ok(e)
    }

    fn primary(&mut self) -> Parse<Expr> {
        let t = self.peek();
        match t.tok {
            Tok::Num(v) => {
                self.at += 1;
                Ok(Expr::Num(v))
            }
            Tok::Sym("(") => {
                self.at += 1;
                let e = self.expr()?;
                self.expect_sym(")", "`)`")?;
                Ok(e)
            }
            Tok::Ident if self.is_word("if") => self.if_expr(),
            Tok::Ident => {
                let (name, at) = self.name("a value")?;
                if self.is_sym("(") {
                    self.at += 1;
                    let mut args = Vec::new();
                    if !self.is_sym(")") {
                        loop {
                            args.push(self.expr()?);
                            if self.is_sym(",") {
                                self.at += 1;
                            } else {
                                break;
                            }
                        }
                    }
                    self.expect_sym(")", "`,` or `)` in the call")?;
                    Ok(Expr::Call(name, args, at))
                } else {
                    Ok(Expr::Name(name, at))
                }
            }
            _ => Err((
                t.start,
                format!(
                    "expected a number, a name, a call or `(`, found {}",
                    self.describe(t)
                ),
            )),
        }
    }
}

/// The `'static` spelling of a symbol.
fn symbol(s: &str) -> &'static str {
    SYMBOLS.iter().find(|x| **x == s).copied().unwrap_or("")
}

fn start(e: &Expr) -> usize {
    match e {
        Expr::Num(_) => 0,
        Expr::Neg(e) | Expr::Not(e) => start(e),
        Expr::Name(_, at)
        | Expr::Binary(_, _, _, at)
        | Expr::Call(_, _, at)
        | Expr::Field(_, _, at)
        | Expr::If(_, _, _, at) => *at,
    }
}

/// A value while a formula runs.
#[derive(Debug, Clone, Copy)]
enum Value<N: Num> {
    Number(N),
    Vector(V3<N>),
    Truth(N::Bool),
}

impl<N: Num> Value<N> {
    fn kind(&self) -> &'static str {
        match self {
            Value::Number(_) => "a number",
            Value::Vector(_) => "a vector",
            Value::Truth(_) => "a truth value",
        }
    }

    fn select(c: N::Bool, a: Self, b: Self) -> Option<Self> {
        Some(match (a, b) {
            (Value::Number(x), Value::Number(y)) => Value::Number(N::select(c, x, y)),
            (Value::Vector(x), Value::Vector(y)) => Value::Vector(V3::select(c, x, y)),
            (Value::Truth(x), Value::Truth(y)) => Value::Truth((c & x) | (!c & y)),
            _ => return None,
        })
    }
}

/// A parsed text formula: a distance of `p` and named parameters.
#[derive(Debug, Clone)]
pub struct Formula {
    text: String,
    params: Vec<String>,
    body: Block,
    lines: Vec<usize>,
}

struct Run<'f, N: Num> {
    formula: &'f Formula,
    vars: Vec<HashMap<String, Value<N>>>,
    /// Where assignments take effect: everywhere (`None`), or where the
    /// truth value holds (inside an `if` or a loop that may have broken).
    mask: Option<N::Bool>,
    iterations: u64,
}

type Eval<T> = Result<T, (usize, String)>;

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
        // One run in plain numbers checks names, calls and types.
        formula
            .run::<f64>(v3(0.0, 0.0, 0.0), &vec![0.0; params.len()])
            .map_err(|(at, m)| formula.locate(at, m))?;
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

impl<N: Num> Run<'_, N> {
    fn lookup(&self, name: &str) -> Option<Value<N>> {
        self.vars.iter().rev().find_map(|s| s.get(name).copied())
    }

    fn block(&mut self, b: &Block) -> Eval<Option<Value<N>>> {
        self.vars.push(HashMap::new());
        let result = self.block_in_scope(b);
        self.vars.pop();
        result
    }

    fn block_in_scope(&mut self, b: &Block) -> Eval<Option<Value<N>>> {
        for s in &b.stmts {
            self.stmt(s)?;
        }
        b.value.as_ref().map(|e| self.expr(e)).transpose()
    }

    fn assign(&mut self, name: &str, v: Value<N>, at: usize) -> Eval<()> {
        let old = self.lookup(name).ok_or_else(|| {
            (
                at,
                format!("`{name}` is not defined; define it first with `let {name} = ...;`"),
            )
        })?;
        let frame = self
            .vars
            .iter()
            .rposition(|s| s.contains_key(name))
            .unwrap_or(0);
        if frame == 0 {
            return Err((at, format!("`{name}` is an input and cannot be assigned")));
        }
        let new = match self.mask {
            None => match (old, v) {
                (Value::Number(_), Value::Number(_))
                | (Value::Vector(_), Value::Vector(_))
                | (Value::Truth(_), Value::Truth(_)) => v,
                _ => return Err(mismatch(at, name, old, v)),
            },
            Some(m) => Value::select(m, v, old).ok_or_else(|| mismatch(at, name, old, v))?,
        };
        self.vars[frame].insert(name.to_string(), new);
        Ok(())
    }

    fn stmt(&mut self, s: &Stmt) -> Eval<()> {
        match s {
            Stmt::Let(name, e, at) => {
                if matches!(name.as_str(), "p" | "pi") || self.formula.params.contains(name) {
                    return Err((*at, format!("`{name}` is an input; choose another name")));
                }
                let v = self.expr(e)?;
                self.vars
                    .last_mut()
                    .expect("a block has a scope")
                    .insert(name.clone(), v);
            }
            Stmt::Assign(name, e, at) => {
                let v = self.expr(e)?;
                self.assign(name, v, *at)?;
            }
            Stmt::If(c, a, b) => {
                let c = self.truth(c)?;
                let outer = self.mask;
                self.mask = Some(outer.map_or(c, |m| m & c));
                self.block(a)?;
                self.mask = Some(outer.map_or(!c, |m| m & !c));
                self.block(b)?;
                self.mask = outer;
            }
            Stmt::For(name, from, to, body, at) => {
                let count = u64::try_from((to - from).max(0)).unwrap_or(0);
                self.iterations += count;
                if self.iterations > MAX_ITERATIONS {
                    return Err((
                        *at,
                        format!(
                            "the loops run {} iterations in all; the most is {MAX_ITERATIONS}",
                            self.iterations
                        ),
                    ));
                }
                let outer = self.mask;
                for i in *from..*to {
                    self.vars.push(HashMap::new());
                    #[allow(clippy::cast_precision_loss)] // |i| <= 1e6
                    self.vars
                        .last_mut()
                        .expect("pushed")
                        .insert(name.clone(), Value::Number(N::of(i as f64)));
                    let r = self.block(body);
                    self.vars.pop();
                    r?;
                }
                self.mask = outer;
            }
            Stmt::BreakIf(c, at) => {
                if !self.in_loop(*at) {
                    return Err((
                        *at,
                        "`break if` is only allowed directly in a loop's body".into(),
                    ));
                }
                let c = self.truth(c)?;
                self.mask = Some(self.mask.map_or(!c, |m| m & !c));
            }
        }
        Ok(())
    }

    /// Whether `at` lies directly within a loop's body.
    fn in_loop(&self, at: usize) -> bool {
        fn within(stmts: &[Stmt], at: usize, looped: bool) -> Option<bool> {
            for s in stmts {
                match s {
                    Stmt::BreakIf(_, a) if *a == at => return Some(looped),
                    Stmt::For(_, _, _, b, _) => {
                        if let Some(r) = within(&b.stmts, at, true) {
                            return Some(r);
                        }
                    }
                    // A break inside an `if` is refused: the loop's body
                    // breaks where it says so, unconditionally placed.
                    Stmt::If(_, a, b) => {
                        if let Some(r) =
                            within(&a.stmts, at, false).or_else(|| within(&b.stmts, at, false))
                        {
                            return Some(r);
                        }
                    }
                    _ => {}
                }
            }
            None
        }
        within(&self.formula.body.stmts, at, false).unwrap_or(false)
    }

    fn truth(&mut self, e: &Expr) -> Eval<N::Bool> {
        match self.expr(e)? {
            Value::Truth(b) => Ok(b),
            v => Err((
                start(e),
                format!("expected a truth value (a comparison), found {}", v.kind()),
            )),
        }
    }

    fn expr(&mut self, e: &Expr) -> Eval<Value<N>> {
        Ok(match e {
            Expr::Num(v) => Value::Number(N::of(*v)),
            Expr::Name(name, at) => self.lookup(name).ok_or_else(|| {
                let mut known: Vec<String> = vec!["p".into()];
                known.extend(self.formula.params.iter().cloned());
                known.push("pi".into());
                for s in self.vars.iter().skip(1) {
                    known.extend(s.keys().cloned());
                }
                (
                    *at,
                    format!(
                        "unknown variable `{name}`; expected one of {}",
                        known.join(", ")
                    ),
                )
            })?,
            Expr::Neg(a) => match self.expr(a)? {
                Value::Number(n) => Value::Number(-n),
                Value::Vector(v) => Value::Vector(-v),
                Value::Truth(_) => {
                    return Err((start(a), "cannot negate a truth value; use `!`".into()));
                }
            },
            Expr::Not(a) => Value::Truth(!self.truth(a)?),
            Expr::Field(a, i, _) => match self.expr(a)? {
                Value::Vector(v) => Value::Number(v.get(*i)),
                v => {
                    return Err((
                        start(a),
                        format!("`.x`, `.y`, `.z` need a vector, found {}", v.kind()),
                    ));
                }
            },
            Expr::Binary(op, a, b, at) => {
                let (x, y) = (self.expr(a)?, self.expr(b)?);
                binary(op, x, y).ok_or_else(|| {
                    (
                        *at,
                        format!("`{op}` cannot combine {} and {}", x.kind(), y.kind()),
                    )
                })?
            }
            Expr::If(c, a, b, at) => {
                let c = self.truth(c)?;
                let outer = self.mask;
                self.mask = Some(outer.map_or(c, |m| m & c));
                let x = self.block(a);
                self.mask = Some(outer.map_or(!c, |m| m & !c));
                let y = self.block(b);
                self.mask = outer;
                let (x, y) = (x?, y?);
                match (x, y) {
                    (Some(x), Some(y)) => Value::select(c, x, y).ok_or_else(|| {
                        (
                            *at,
                            format!("the branches give {} and {}", x.kind(), y.kind()),
                        )
                    })?,
                    _ => {
                        return Err((
                            *at,
                            "an `if` used as a value needs a value in both branches".into(),
                        ));
                    }
                }
            }
            Expr::Call(name, args, at) => {
                let Some(&(_, arity)) = FUNCTIONS.iter().find(|(f, _)| f == name) else {
                    let names: Vec<&str> = FUNCTIONS.iter().map(|(f, _)| *f).collect();
                    return Err((
                        *at,
                        format!(
                            "unknown function `{name}`; expected one of {}",
                            names.join(", ")
                        ),
                    ));
                };
                if args.len() != arity {
                    return Err((
                        *at,
                        format!("`{name}` takes {arity} argument(s), got {}", args.len()),
                    ));
                }
                let values: Vec<Value<N>> =
                    args.iter().map(|a| self.expr(a)).collect::<Eval<_>>()?;
                call(name, &values).ok_or_else(|| {
                    let kinds: Vec<&str> = values.iter().map(Value::kind).collect();
                    (*at, format!("`{name}` cannot take {}", kinds.join(", ")))
                })?
            }
        })
    }
}

fn mismatch<N: Num>(at: usize, name: &str, old: Value<N>, new: Value<N>) -> (usize, String) {
    (
        at,
        format!(
            "`{name}` holds {}; it cannot be given {}",
            old.kind(),
            new.kind()
        ),
    )
}

fn binary<N: Num>(op: &str, x: Value<N>, y: Value<N>) -> Option<Value<N>> {
    use Value::{Number as S, Truth as B, Vector as V};
    Some(match (op, x, y) {
        ("+", S(a), S(b)) => S(a + b),
        ("-", S(a), S(b)) => S(a - b),
        ("*", S(a), S(b)) => S(a * b),
        ("/", S(a), S(b)) => S(a / b),
        ("+", V(a), V(b)) => V(a + b),
        ("-", V(a), V(b)) => V(a - b),
        ("*", V(a), V(b)) => V(a * b),
        ("/", V(a), V(b)) => V(a / b),
        ("*", V(a), S(b)) => V(a * b),
        ("*", S(a), V(b)) => V(b * a),
        ("/", V(a), S(b)) => V(a / b),
        ("<", S(a), S(b)) => B(a.lt(b)),
        ("<=", S(a), S(b)) => B(a.le(b)),
        (">", S(a), S(b)) => B(a.gt(b)),
        (">=", S(a), S(b)) => B(a.ge(b)),
        ("==", S(a), S(b)) => B(a.le(b) & b.le(a)),
        ("!=", S(a), S(b)) => B(a.lt(b) | b.lt(a)),
        ("&&", B(a), B(b)) => B(a & b),
        ("||", B(a), B(b)) => B(a | b),
        _ => return None,
    })
}

fn call<N: Num>(name: &str, a: &[Value<N>]) -> Option<Value<N>> {
    use Value::{Number as S, Vector as V};
    let map = |v: V3<N>, f: fn(N) -> N| V(v.map(f));
    Some(match (name, a) {
        ("sqrt", [S(x)]) => S(x.sqrt()),
        ("abs", [S(x)]) => S(x.abs()),
        ("abs", [V(v)]) => V(v.abs()),
        ("sin", [S(x)]) => S(x.sin()),
        ("cos", [S(x)]) => S(x.cos()),
        ("acos", [S(x)]) => S(x.acos()),
        ("exp", [S(x)]) => S(x.exp()),
        ("log", [S(x)]) => S(x.ln()),
        ("floor", [S(x)]) => S(x.floor()),
        ("floor", [V(v)]) => map(*v, N::floor),
        ("fract", [S(x)]) => S(x.fract()),
        ("fract", [V(v)]) => map(*v, N::fract),
        ("min", [S(x), S(y)]) => S(x.min(*y)),
        ("max", [S(x), S(y)]) => S(x.max(*y)),
        ("min", [V(x), V(y)]) => V(x.zip(*y, N::min)),
        ("max", [V(x), V(y)]) => V(x.zip(*y, N::max)),
        ("max", [V(x), S(y)]) => V(x.max_s(*y)),
        ("atan2", [S(y), S(x)]) => S(y.atan2(*x)),
        ("pow", [S(x), S(y)]) => S(x.powf(*y)),
        ("hypot", [S(x), S(y)]) => S(x.hypot(*y)),
        ("clamp", [S(x), S(lo), S(hi)]) => S(x.clamp(*lo, *hi)),
        ("mix", [S(x), S(y), S(t)]) => S(x.mix(*y, *t)),
        ("mix", [V(x), V(y), S(t)]) => V(*x + (*y - *x) * *t),
        ("length", [V(v)]) => S(v.length()),
        ("dot", [V(x), V(y)]) => S(x.dot(*y)),
        ("cross", [V(x), V(y)]) => V(x.cross(*y)),
        ("normalize", [V(v)]) => V(*v / v.length()),
        ("vec3", [S(x), S(y), S(z)]) => V(v3(*x, *y, *z)),
        _ => return None,
    })
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
        let e = Formula::parse("for i in 0..1000 { } 1", &[]).unwrap_err();
        assert!(e.message.contains("256"), "{e}");
        let e = Formula::parse("p", &[]).unwrap_err();
        assert!(e.message.contains("a vector"), "{e}");
        let e = Formula::parse("sqrt(1, 2)", &[]).unwrap_err();
        assert!(e.message.contains("takes 1"), "{e}");
        let e = Formula::parse("break if 1 > 0; 1", &[]).unwrap_err();
        assert!(e.message.contains("loop"), "{e}");
    }
}
