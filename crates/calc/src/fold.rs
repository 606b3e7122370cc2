//! Constant folding: variables whose definitions depend on nothing the host or the
//! input can change are evaluated once at compile time, and operations on constants
//! are replaced by their values (only when evaluating raised no warning or error, so
//! messages stay as Radiance gives them).

use crate::builtins::Builtin;
use crate::eval::{Compiled, VarSlot};
use crate::node::Node;

#[derive(Clone, Copy, PartialEq)]
enum Mark {
    Unknown,
    Busy,
    Pure,
    Impure,
}

struct Purity {
    vars: Vec<Mark>,
    funcs: Vec<Mark>,
}

impl Purity {
    fn node(&mut self, c: &Compiled, n: &Node) -> bool {
        match n {
            Node::Num(_) | Node::NumClr(_) | Node::Param(_) | Node::FuncRef(_) => true,
            Node::Lib(_, a) => self.node(c, a),
            Node::Chan(_) | Node::CallHost(..) | Node::CallParam(..) | Node::Fail(_) => false,
            Node::Var(i) => self.var(c, *i as usize),
            Node::Neg(a) | Node::Math1(_, a) => self.node(c, a),
            Node::Add(p) | Node::Sub(p) | Node::Mul(p) | Node::Div(p) | Node::Pow(p) => {
                self.node(c, &p.0) && self.node(c, &p.1)
            }
            Node::Atan2(p) => self.node(c, &p.0) && self.node(c, &p.1),
            Node::If(t) => self.node(c, &t.0) && self.node(c, &t.1) && self.node(c, &t.2),
            Node::Builtin(b, args) => {
                !matches!(b, Builtin::In | Builtin::Arg) && args.iter().all(|a| self.node(c, a))
            }
            Node::CallUser(f, args) => {
                self.func(c, *f as usize) && args.iter().all(|a| self.node(c, a))
            }
        }
    }

    fn var(&mut self, c: &Compiled, i: usize) -> bool {
        match self.vars[i] {
            Mark::Pure => return true,
            Mark::Impure | Mark::Busy => return false,
            Mark::Unknown => {}
        }
        let pure = match &c.vars[i] {
            VarSlot::Host => false,
            VarSlot::Const(_) | VarSlot::ConstClr(_) => true,
            VarSlot::Def(n, _) => {
                self.vars[i] = Mark::Busy;
                self.node(c, n)
            }
        };
        self.vars[i] = if pure { Mark::Pure } else { Mark::Impure };
        pure
    }

    fn func(&mut self, c: &Compiled, f: usize) -> bool {
        match self.funcs[f] {
            Mark::Pure | Mark::Busy => return true,
            Mark::Impure => return false,
            Mark::Unknown => {}
        }
        self.funcs[f] = Mark::Busy;
        let pure = self.node(c, &c.funcs[f].body);
        self.funcs[f] = if pure { Mark::Pure } else { Mark::Impure };
        pure
    }
}

/// Evaluates a node that has no free parameters, if it does so cleanly; with whether
/// the evaluation made library calls (wrote the error flag).
fn try_eval(c: &Compiled, n: &Node) -> Option<(f64, bool)> {
    let mut st = c.state();
    let id = crate::eval::probe(c, n, &mut st)?;
    if st.take_warnings().any() {
        return None;
    }
    Some((id, st.errno_written_since(0)))
}

fn fold_node(c: &Compiled, p: &mut Purity, n: &mut Node, in_func: bool) {
    // children first
    match n {
        Node::Neg(a) | Node::Math1(_, a) | Node::Lib(_, a) => fold_node(c, p, a, in_func),
        Node::Add(q)
        | Node::Sub(q)
        | Node::Mul(q)
        | Node::Div(q)
        | Node::Pow(q)
        | Node::Atan2(q) => {
            fold_node(c, p, &mut q.0, in_func);
            fold_node(c, p, &mut q.1, in_func);
        }
        Node::If(t) => {
            fold_node(c, p, &mut t.0, in_func);
            fold_node(c, p, &mut t.1, in_func);
            fold_node(c, p, &mut t.2, in_func);
        }
        Node::Builtin(_, args)
        | Node::CallUser(_, args)
        | Node::CallHost(_, args)
        | Node::CallParam(_, args) => {
            for a in args.iter_mut() {
                fold_node(c, p, a, in_func);
            }
        }
        _ => {}
    }
    let foldable = match n {
        // a `ConstClr` variable stays: only its first use clears the error flag
        Node::Var(i) => matches!(c.vars[*i as usize], VarSlot::Const(_)),
        Node::Neg(a) | Node::Math1(_, a) => a.num().is_some(),
        Node::Add(q)
        | Node::Sub(q)
        | Node::Mul(q)
        | Node::Div(q)
        | Node::Pow(q)
        | Node::Atan2(q) => q.0.num().is_some() && q.1.num().is_some(),
        Node::If(t) => t.0.num().is_some(),
        Node::Builtin(b, args) => {
            !matches!(b, Builtin::In | Builtin::Arg)
                && args.first().is_some_and(|a| a.num().is_some())
                && (matches!(b, Builtin::Select) || args.iter().all(|a| a.num().is_some()))
        }
        Node::CallUser(f, args) => {
            args.iter()
                .all(|a| a.num().is_some() || matches!(a, Node::FuncRef(_)))
                && p.func(c, *f as usize)
        }
        _ => false,
    };
    if !foldable {
        return;
    }
    // `if`/`select` with a constant selector reduce to the chosen branch.
    if let Node::If(t) = n {
        let cond = t.0.num().unwrap_or(0.0);
        let chosen = if cond > 0.0 { t.1.clone() } else { t.2.clone() };
        *n = lib_reduced("if", chosen);
        return;
    }
    if let Node::Builtin(Builtin::Select, args) = n {
        let v = args[0].num().unwrap_or(0.0);
        let count = args.len() - 1;
        if v >= -0.5 {
            let i = (v + 0.5) as i64 as usize;
            if i == 0 {
                *n = Node::NumClr(count as f64);
            } else if i <= count {
                *n = lib_reduced("select", args[i].clone());
                return;
            }
        }
        return;
    }
    if in_func && contains_param(n) {
        return;
    }
    if let Some((v, touched)) = try_eval(c, n) {
        *n = if touched {
            Node::NumClr(v)
        } else {
            Node::Num(v)
        };
    }
}

/// A library call (`if`, `select`) reduced to the argument it returns: a number when
/// the argument is one (the call clears the error flag), else the argument wrapped so
/// that it still behaves as the call (flag cleared first, an error inside reported).
fn lib_reduced(name: &'static str, arg: Node) -> Node {
    match arg.num() {
        Some(v) => Node::NumClr(v),
        None => Node::Lib(name, Box::new(arg)),
    }
}

/// Whether `n` uses a parameter of the enclosing function (or calls one).
fn contains_param(n: &Node) -> bool {
    n.any(&|n| matches!(n, Node::Param(_) | Node::CallParam(..)))
}

/// Folds constants in place; returns the `:` constants whose value raised an error
/// (Radiance refuses them: "bad constant expression").
pub(crate) fn fold(c: &mut Compiled) -> Vec<usize> {
    let mut bad = Vec::new();
    let mut p = Purity {
        vars: vec![Mark::Unknown; c.vars.len()],
        funcs: vec![Mark::Unknown; c.funcs.len()],
    };
    // 1. pure variables become constants
    for i in 0..c.vars.len() {
        if !matches!(c.vars[i], VarSlot::Def(..)) || !p.var(c, i) {
            continue;
        }
        let node = Node::Var(i as u32);
        if let Some((v, touched)) = try_eval(c, &node) {
            let constant = matches!(c.vars[i], VarSlot::Def(_, true));
            c.vars[i] = if touched && !constant {
                VarSlot::ConstClr(v)
            } else {
                VarSlot::Const(v)
            };
        } else if matches!(c.vars[i], VarSlot::Def(_, true)) {
            let mut st = c.state();
            if crate::eval::probe(c, &node, &mut st).is_some() && st.take_warnings().any() {
                bad.push(i);
            }
        }
    }
    // 2. fold inside every body (working on copies, as evaluation reads the program)
    for i in 0..c.vars.len() {
        if let VarSlot::Def(node, k) = &c.vars[i] {
            let (mut node, k) = (node.clone(), *k);
            fold_node(c, &mut p, &mut node, false);
            c.vars[i] = VarSlot::Def(node, k);
        }
    }
    for f in 0..c.funcs.len() {
        let mut body = c.funcs[f].body.clone();
        fold_node(c, &mut p, &mut body, true);
        c.funcs[f].body = body;
    }
    for k in 0..c.chans.len() {
        let mut node = c.chans[k].1.clone();
        fold_node(c, &mut p, &mut node, false);
        c.chans[k].1 = node;
    }
    for k in 0..c.exprs.len() {
        let mut node = c.exprs[k].clone();
        fold_node(c, &mut p, &mut node, false);
        c.exprs[k] = node;
    }
    bad
}
