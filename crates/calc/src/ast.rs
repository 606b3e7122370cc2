//! Syntax tree of .cal definitions, as parsed (names not yet resolved).

/// A position in a loaded source: source index, line and column (from 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Pos {
    /// Index of the source in the program's source table.
    pub src: u32,
    /// Line, from 1.
    pub line: u32,
    /// Column, from 1.
    pub col: u32,
}

/// Binary operators.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BinOp {
    /// `+`
    Add,
    /// `-`
    Sub,
    /// `*`
    Mul,
    /// `/`
    Div,
    /// `^`
    Pow,
}

/// An expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A numeric literal.
    Num(f64),
    /// A name used as a value (variable, parameter, or a function passed as argument).
    Name(String, Pos),
    /// `$N`.
    Chan(u32, Pos),
    /// `name(args…)`.
    Call(String, Vec<Expr>, Pos),
    /// Unary minus.
    Neg(Box<Expr>),
    /// A binary operation.
    Bin(BinOp, Box<Expr>, Box<Expr>),
}

/// The left-hand side of a definition.
#[derive(Debug, Clone, PartialEq)]
pub enum Lhs {
    /// `name = …`
    Var(String),
    /// `name(p1, p2, …) = …`
    Func(String, Vec<String>),
    /// `$N = …` (an output channel, rcalc).
    Chan(u32),
}

/// One definition statement.
#[derive(Debug, Clone, PartialEq)]
pub struct Def {
    /// What is defined.
    pub lhs: Lhs,
    /// True for `:` (constant) definitions.
    pub constant: bool,
    /// The defining expression.
    pub body: Expr,
    /// Where the definition starts.
    pub pos: Pos,
}
