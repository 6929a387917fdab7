//! The formula language's lexer and parser: text to statements and
//! expressions, each with the byte offset it starts at.

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Tok {
    Num(f64),
    Ident,
    Sym(&'static str),
    End,
}

#[derive(Debug, Clone, Copy)]
pub(super) struct Token {
    pub(super) tok: Tok,
    pub(super) start: usize,
    pub(super) end: usize,
}

const SYMBOLS: &[&str] = &[
    "<=", ">=", "==", "!=", "&&", "||", "..", "+", "-", "*", "/", "(", ")", "{", "}", ",", ";",
    "=", "<", ">", "!", ".",
];

pub(super) fn lex(text: &str) -> Result<Vec<Token>, (usize, String)> {
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
pub(super) enum Expr {
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
pub(super) enum Stmt {
    Let(String, Expr, usize),
    Assign(String, Expr, usize),
    If(Expr, Block, Block),
    For(String, i64, i64, Block, usize),
    BreakIf(Expr, usize),
}

/// Statements, then an optional value.
#[derive(Debug, Clone)]
pub(super) struct Block {
    pub(super) stmts: Vec<Stmt>,
    pub(super) value: Option<Expr>,
}

pub(super) struct Parser<'t> {
    pub(super) text: &'t str,
    pub(super) tokens: Vec<Token>,
    pub(super) at: usize,
    /// How deep the parser is in parentheses, blocks and prefixes.
    pub(super) nesting: usize,
}

/// The error of an expression deeper than [`MAX_DEPTH`](super::MAX_DEPTH).
fn too_deep(at: usize) -> (usize, String) {
    (
        at,
        format!(
            "an expression more than {} operations deep; split it with `let`",
            super::MAX_DEPTH
        ),
    )
}

/// How deep an expression's operations stack, blocks included.
fn depth(e: &Expr) -> usize {
    1 + match e {
        Expr::Num(_) | Expr::Name(..) => 0,
        Expr::Neg(a) | Expr::Not(a) | Expr::Field(a, ..) => depth(a),
        Expr::Binary(_, a, b, _) => depth(a).max(depth(b)),
        Expr::Call(_, args, _) => args.iter().map(depth).max().unwrap_or(0),
        Expr::If(c, a, b, _) => depth(c).max(block_depth(a)).max(block_depth(b)),
    }
}

fn block_depth(b: &Block) -> usize {
    let stmt = |s: &Stmt| match s {
        Stmt::Let(_, e, _) | Stmt::Assign(_, e, _) | Stmt::BreakIf(e, _) => depth(e),
        Stmt::If(c, a, b) => depth(c).max(block_depth(a)).max(block_depth(b)),
        Stmt::For(_, _, _, body, _) => block_depth(body),
    };
    let value = b.value.as_ref().map_or(0, depth);
    1 + b.stmts.iter().map(stmt).max().unwrap_or(0).max(value)
}

pub(super) type Parse<T> = Result<T, (usize, String)>;

pub(super) const KEYWORDS: &[&str] = &["let", "if", "else", "for", "in", "break"];

impl Parser<'_> {
    pub(super) fn peek(&self) -> Token {
        self.tokens[self.at]
    }

    pub(super) fn describe(&self, t: Token) -> String {
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
    pub(super) fn block(&mut self) -> Parse<Block> {
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
        let b = self.nested(Self::block)?;
        self.expect_sym("}", &format!("`}}` to close {what}"))?;
        Ok(b)
    }

    /// Runs `parse` one level deeper, refusing more than
    /// [`MAX_NESTING`](super::MAX_NESTING) levels.
    fn nested<T>(&mut self, parse: impl FnOnce(&mut Self) -> Parse<T>) -> Parse<T> {
        if self.nesting >= super::MAX_NESTING {
            return Err((
                self.peek().start,
                format!(
                    "parentheses, blocks and signs nested more than {} deep",
                    super::MAX_NESTING
                ),
            ));
        }
        self.nesting += 1;
        let result = parse(self);
        self.nesting -= 1;
        result
    }

    /// Refuses an expression whose operations stack more than
    /// [`MAX_DEPTH`](super::MAX_DEPTH) deep.
    fn shallow(e: Expr, at: usize) -> Parse<Expr> {
        if depth(&e) > super::MAX_DEPTH {
            return Err(too_deep(at));
        }
        Ok(e)
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
        let at = self.peek().start;
        let e = self.nested(|p| p.binary(0))?;
        Self::shallow(e, at)
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
        // The chain's depth so far: each operator stacks on the last.
        let mut deep = depth(&left);
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
            deep = deep.max(depth(&right)) + 1;
            if deep > super::MAX_DEPTH {
                return Err(too_deep(t.start));
            }
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
            return self.nested(|p| Ok(Expr::Neg(Box::new(p.unary()?))));
        }
        if self.is_sym("!") {
            self.at += 1;
            return self.nested(|p| Ok(Expr::Not(Box::new(p.unary()?))));
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

pub(super) fn start(e: &Expr) -> usize {
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
