//! Resolving names to slots and building the compiled program, with constant folding
//! of definitions that depend on nothing the host or the input can change.

use std::collections::HashMap;

use crate::ast::{BinOp, Expr, Pos};
use crate::builtins::{self, Builtin};
use crate::error::{CalcError, ErrorKind};
use crate::eval::{Compiled, FuncBody, VarSlot};
use crate::node::{FnTarget, Node};
use crate::program::{NameDef, Program};

struct Compiler<'p> {
    prog: &'p Program,
    var_ids: HashMap<String, u32>,
    func_ids: HashMap<String, u32>,
    host_ids: HashMap<String, u32>,
    errors: Vec<CalcError>,
}

impl Program {
    /// Compiles the program: every name resolved, constants folded. References to
    /// undefined names compile to errors raised when (and only when) evaluated.
    pub fn compile(&self) -> Result<Compiled, CalcError> {
        let mut c = Compiler {
            prog: self,
            var_ids: HashMap::new(),
            func_ids: HashMap::new(),
            host_ids: HashMap::new(),
            errors: Vec::new(),
        };
        let mut var_names: Vec<String> = self.bound.clone();
        for (i, n) in self.bound.iter().enumerate() {
            c.var_ids.insert(n.clone(), i as u32);
        }
        let mut func_names = Vec::new();
        for name in &self.order {
            let d = &self.defs[name];
            if c.var_ids.contains_key(name) {
                continue; // host binding wins
            }
            if d.params.is_some() {
                c.func_ids.insert(name.clone(), func_names.len() as u32);
                func_names.push(name.clone());
            } else {
                c.var_ids.insert(name.clone(), var_names.len() as u32);
                var_names.push(name.clone());
            }
        }
        for (i, h) in self.hosts.iter().enumerate() {
            c.host_ids.insert(h.name.clone(), i as u32);
        }
        let mut vars = Vec::with_capacity(var_names.len());
        for (i, n) in var_names.iter().enumerate() {
            if i < self.bound.len() {
                vars.push(VarSlot::Host);
            } else {
                let d = &self.defs[n];
                let node = c.expr(&d.body, None);
                vars.push(VarSlot::Def(node, d.constant));
            }
        }
        let mut funcs = Vec::with_capacity(func_names.len());
        for n in &func_names {
            let d: &NameDef = &self.defs[n];
            let params = d.params.as_deref().unwrap_or(&[]);
            let body = c.expr(&d.body, Some(params));
            funcs.push(FuncBody {
                nparams: params.len() as u32,
                body,
                name: n.clone(),
            });
        }
        let chans = self
            .chans
            .iter()
            .map(|(n, (e, _))| (*n, c.expr(e, None)))
            .collect();
        let exprs = self.exprs.iter().map(|e| c.expr(e, None)).collect();
        let mut out = Compiled {
            vars,
            var_names,
            funcs,
            hosts: self.hosts.iter().map(|h| h.f.clone()).collect(),
            host_names: self.hosts.iter().map(|h| h.name.clone()).collect(),
            chans,
            exprs,
            errors: c.errors,
            fast: Vec::new(),
        };
        let bad = crate::fold::fold(&mut out);
        if let Some(&i) = bad.first() {
            if !self.no_parse_constants {
                return Err(CalcError::new(
                    ErrorKind::Syntax,
                    format!("{}: bad constant expression", out.var_names[i]),
                ));
            }
        }
        // FENESTRA_CALC_EXACT=1 leaves out the fast code (for comparisons and timing)
        if std::env::var_os("FENESTRA_CALC_EXACT").is_none_or(|v| v.is_empty() || v == "0") {
            out.enable_fast();
        }
        Ok(out)
    }
}

impl Compiler<'_> {
    fn fail(&mut self, kind: ErrorKind, msg: String, pos: Pos) -> Node {
        let loc = Program::location(&self.prog.sources, pos);
        self.errors.push(CalcError::at(kind, msg, loc));
        Node::Fail((self.errors.len() - 1) as u32)
    }

    fn fn_target(&self, name: &str) -> Option<(FnTarget, usize)> {
        if let Some(&f) = self.func_ids.get(name) {
            let n = self.prog.defs[name].params.as_ref().map_or(0, Vec::len);
            return Some((FnTarget::User(f), n));
        }
        if let Some(&h) = self.host_ids.get(name) {
            return Some((FnTarget::Host(h), self.prog.hosts[h as usize].min_args));
        }
        builtins::lookup(name, self.prog.extras).map(|(b, n)| (FnTarget::Builtin(b), n))
    }

    fn expr(&mut self, e: &Expr, params: Option<&[String]>) -> Node {
        match e {
            Expr::Num(v) => Node::Num(*v),
            Expr::Chan(n, _) => Node::Chan(*n),
            Expr::Name(n, pos) => {
                if let Some(i) = params.and_then(|p| p.iter().position(|x| x == n)) {
                    return Node::Param(i as u32);
                }
                if let Some(&v) = self.var_ids.get(n) {
                    return Node::Var(v);
                }
                if let Some((t, _)) = self.fn_target(n) {
                    return Node::FuncRef(t);
                }
                self.fail(
                    ErrorKind::UndefinedVariable,
                    format!("{n}: undefined variable"),
                    *pos,
                )
            }
            Expr::Neg(a) => {
                let a = self.expr(a, params);
                Node::Neg(Box::new(a))
            }
            Expr::Bin(op, a, b) => {
                let a = self.expr(a, params);
                let b = self.expr(b, params);
                let pair = Box::new((a, b));
                match op {
                    BinOp::Add => Node::Add(pair),
                    BinOp::Sub => Node::Sub(pair),
                    BinOp::Mul => Node::Mul(pair),
                    BinOp::Div => Node::Div(pair),
                    BinOp::Pow => Node::Pow(pair),
                }
            }
            Expr::Call(name, args, pos) => {
                let mut cargs: Vec<Node> = args.iter().map(|a| self.expr(a, params)).collect();
                if let Some(i) = params.and_then(|p| p.iter().position(|x| x == name)) {
                    return Node::CallParam(i as u32, cargs.into_boxed_slice());
                }
                let Some((target, min)) = self.fn_target(name) else {
                    return self.fail(
                        ErrorKind::UndefinedFunction,
                        format!("{name}(): undefined function"),
                        *pos,
                    );
                };
                if cargs.len() < min {
                    return self.fail(
                        ErrorKind::TooFewArguments,
                        format!(
                            "{name}(): too few arguments ({} given, {min} needed)",
                            cargs.len()
                        ),
                        *pos,
                    );
                }
                match target {
                    FnTarget::User(f) => Node::CallUser(f, cargs.into_boxed_slice()),
                    FnTarget::Host(h) => Node::CallHost(h, cargs.into_boxed_slice()),
                    FnTarget::Builtin(b) => match b {
                        Builtin::If => {
                            cargs.truncate(3);
                            let c = cargs.pop().unwrap_or(Node::Num(0.0));
                            let bb = cargs.pop().unwrap_or(Node::Num(0.0));
                            let a = cargs.pop().unwrap_or(Node::Num(0.0));
                            Node::If(Box::new((a, bb, c)))
                        }
                        Builtin::Math1(m) => {
                            cargs.truncate(1);
                            Node::Math1(m, Box::new(cargs.pop().unwrap_or(Node::Num(0.0))))
                        }
                        Builtin::Atan2 => {
                            cargs.truncate(2);
                            let x = cargs.pop().unwrap_or(Node::Num(0.0));
                            let y = cargs.pop().unwrap_or(Node::Num(0.0));
                            Node::Atan2(Box::new((y, x)))
                        }
                        b => Node::Builtin(b, cargs.into_boxed_slice()),
                    },
                }
            }
        }
    }
}
