//! The operations of the expression IR: plain data that the numbers
//! ([`Num`](super::Num)) and the program both name.

/// An operation of one operand.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Unary {
    /// `-x`
    Neg,
    /// `sqrt(x)`
    Sqrt,
    /// `|x|`
    Abs,
    /// `sin(x)`
    Sin,
    /// `cos(x)`
    Cos,
    /// `acos(x)`
    Acos,
    /// `e^x`
    Exp,
    /// `ln(x)`
    Ln,
    /// `floor(x)`
    Floor,
    /// The nearest integer, halves away from zero (`round(x)`).
    Round,
    /// Whether `x` is finite (a truth value).
    Finite,
    /// Logical not of a truth value.
    Not,
}

/// An operation of two operands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Binary {
    /// `a + b`
    Add,
    /// `a - b`
    Sub,
    /// `a * b`
    Mul,
    /// `a / b`
    Div,
    /// The smaller (the other where one is NaN).
    Min,
    /// The larger (the other where one is NaN).
    Max,
    /// `atan2(a, b)`: the angle of `(b, a)`.
    Atan2,
    /// `a^b`
    Pow,
    /// `sqrt(a^2 + b^2)`
    Hypot,
    /// `a < b` (a truth value).
    Lt,
    /// `a <= b` (a truth value).
    Le,
    /// Both truth values.
    And,
    /// Either truth value.
    Or,
}

impl Binary {
    /// Whether the result is a truth value.
    #[must_use]
    pub fn is_logic(self) -> bool {
        matches!(self, Binary::Lt | Binary::Le | Binary::And | Binary::Or)
    }
}
