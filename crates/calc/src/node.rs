//! The compiled form: expression trees with names resolved to slots.

use crate::builtins::{Builtin, Math1};

/// A function an argument may name (`d1(sin, x)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum FnTarget {
    User(u32),
    Host(u32),
    Builtin(Builtin),
}

/// A compiled expression node.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Node {
    Num(f64),
    /// A folded library call's value: also clears the error flag, as the call would.
    NumClr(f64),
    /// A library call reduced to the argument it returns (a folded `if`/`select`): it
    /// still clears the error flag first and reports an error raised inside.
    Lib(&'static str, Box<Node>),
    /// A global variable (host-bound or defined).
    Var(u32),
    /// `$N` (1-based).
    Chan(u32),
    /// The `i`th parameter of the enclosing function.
    Param(u32),
    Neg(Box<Node>),
    Add(Box<(Node, Node)>),
    Sub(Box<(Node, Node)>),
    Mul(Box<(Node, Node)>),
    Div(Box<(Node, Node)>),
    Pow(Box<(Node, Node)>),
    If(Box<(Node, Node, Node)>),
    Math1(Math1, Box<Node>),
    Atan2(Box<(Node, Node)>),
    /// Any other built-in (select, min, max, rand, jn, yn, in, arg).
    Builtin(Builtin, Box<[Node]>),
    CallUser(u32, Box<[Node]>),
    CallHost(u32, Box<[Node]>),
    /// Calling a parameter that names a function.
    CallParam(u32, Box<[Node]>),
    /// A function name used as an argument.
    FuncRef(FnTarget),
    /// An error found at compile time, raised if evaluated (index in the error table).
    Fail(u32),
}

impl Node {
    /// The constant value, if this is a number.
    pub(crate) fn num(&self) -> Option<f64> {
        match self {
            Node::Num(v) | Node::NumClr(v) => Some(*v),
            _ => None,
        }
    }

    /// Whether `f` holds for this node or any node below it (checked before its
    /// operands, left to right, stopping at the first hit).
    pub(crate) fn any(&self, f: &impl Fn(&Node) -> bool) -> bool {
        if f(self) {
            return true;
        }
        match self {
            Node::Lib(_, a) | Node::Neg(a) | Node::Math1(_, a) => a.any(f),
            Node::Add(p)
            | Node::Sub(p)
            | Node::Mul(p)
            | Node::Div(p)
            | Node::Pow(p)
            | Node::Atan2(p) => p.0.any(f) || p.1.any(f),
            Node::If(t) => t.0.any(f) || t.1.any(f) || t.2.any(f),
            Node::Builtin(_, a)
            | Node::CallUser(_, a)
            | Node::CallHost(_, a)
            | Node::CallParam(_, a) => a.iter().any(|a| a.any(f)),
            Node::Num(_)
            | Node::NumClr(_)
            | Node::Var(_)
            | Node::Chan(_)
            | Node::Param(_)
            | Node::FuncRef(_)
            | Node::Fail(_) => false,
        }
    }
}
