//! Evaluation of a compiled program: per-thread [`State`] (host variable values, caches
//! of `=` variables per evaluation, input channels), lazy cached function arguments
//! as Radiance has them, and a depth limit that turns runaway recursion into an error.
#![allow(clippy::borrow_interior_mutable_const)]

use std::cell::Cell;
use std::sync::OnceLock;

use crate::builtins::{self, Builtin};
use crate::error::{CalcError, ErrorKind};
use crate::fast::{Fast, Inputs};
use crate::node::{FnTarget, Node};
use crate::program::{ExprId, FuncId, HostFn, VarId};

/// Maximum nesting of function calls and variable evaluations.
pub const MAX_DEPTH: u32 = 1000;

/// Arguments cached per call (the rest are re-evaluated at each use).
const NCACHE: usize = 12;

/// How a variable gets its value.
#[derive(Debug, Clone)]
pub(crate) enum VarSlot {
    /// Set by the host.
    Host,
    /// Defined by an expression (`true` for `:` constants).
    Def(Node, bool),
    /// Folded to a constant.
    Const(f64),
    /// An `=` variable folded to a constant whose evaluation makes library calls: its
    /// first use in an evaluation leaves the error flag cleared, as evaluating it would.
    ConstClr(f64),
}

/// A compiled user function.
#[derive(Debug, Clone)]
pub(crate) struct FuncBody {
    pub nparams: u32,
    pub body: Node,
    pub name: String,
}

/// A compiled program: immutable, shareable between threads; each thread evaluates with
/// its own [`State`].
#[derive(Clone)]
pub struct Compiled {
    pub(crate) vars: Vec<VarSlot>,
    pub(crate) var_names: Vec<String>,
    pub(crate) funcs: Vec<FuncBody>,
    pub(crate) hosts: Vec<HostFn>,
    pub(crate) host_names: Vec<String>,
    pub(crate) chans: Vec<(u32, Node)>,
    pub(crate) exprs: Vec<Node>,
    pub(crate) errors: Vec<CalcError>,
    /// Fast code per root (see `crate::fast`): variables, then channels (in the order
    /// of `chans`), then standalone expressions; `None` where a root has none.
    /// Each is built at the root's first evaluation.
    pub(crate) fast: Vec<OnceLock<Option<Fast>>>,
}

/// Warnings Radiance prints while evaluating (counted; the host reports them).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Warnings {
    /// `x/0` evaluated (result 0).
    pub division_by_zero: u32,
    /// `select` index out of range (result 0).
    pub select_domain: u32,
    /// Built-in calls that returned 0 because an error flag was raised while they were
    /// evaluated (Radiance's `NAME(): range error` / `NAME(): domain error`), in order.
    pub library: Vec<(&'static str, ErrFlag)>,
}

/// The error flag a built-in call checks (C's `errno` in Radiance): raised by a
/// division by zero (range) or an out-of-range `select` (domain).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum ErrFlag {
    /// No error.
    #[default]
    None,
    /// Division by zero.
    Range,
    /// `select` index out of range.
    Domain,
}

impl Warnings {
    /// Whether any warning happened.
    pub fn any(&self) -> bool {
        self.division_by_zero > 0 || self.select_domain > 0 || !self.library.is_empty()
    }

    /// The warning messages Radiance prints (grouped by kind).
    pub fn messages(&self) -> Vec<String> {
        let mut v = vec!["Division by zero".to_string(); self.division_by_zero as usize];
        for (name, f) in &self.library {
            if *name == "^" {
                v.push("Illegal power".to_string());
                continue;
            }
            let what = if *f == ErrFlag::Domain {
                "domain"
            } else {
                "range"
            };
            v.push(format!("{name}(): {what} error"));
        }
        v
    }
}

#[derive(Debug, Clone)]
enum Failure {
    Table(u32),
    Dynamic(ErrorKind, String),
}

/// Per-thread evaluation state.
#[derive(Debug, Clone)]
pub struct State {
    vals: Vec<f64>,
    stamps: Vec<u64>,
    epoch: u64,
    chans: Vec<f64>,
    fargs: Vec<f64>,
    depth: u32,
    fail: Option<Failure>,
    /// Warnings since the last [`State::take_warnings`].
    warnings: Warnings,
    /// The error flag built-in calls check (see [`ErrFlag`]).
    errno: ErrFlag,
    /// Counts writes of the error flag (to know whether an evaluation touched it).
    errno_writes: u64,
    /// Register files of the fast code, one per root.
    fast_regs: Vec<Vec<f64>>,
    /// The epoch in which the roots of `fast_roots` were evaluated by fast code.
    fast_epoch: u64,
    /// Roots evaluated by fast code in `fast_epoch` and not yet replayed exactly.
    fast_roots: Vec<u32>,
    /// The last epoch with an exact evaluation: no fast code for the rest of it (the
    /// exact evaluator may have cached values that a recomputation would not give).
    exact_epoch: u64,
    /// Evaluations done by fast code (for tests).
    #[cfg(test)]
    pub(crate) fast_hits: u64,
}

pub(crate) struct Frame<'a> {
    args: &'a [Node],
    parent: Option<&'a Frame<'a>>,
    cache: [Cell<f64>; NCACHE],
    have: Cell<u32>,
}

impl<'a> Frame<'a> {
    fn new(args: &'a [Node], parent: Option<&'a Frame<'a>>) -> Self {
        Frame {
            args,
            parent,
            cache: Default::default(),
            have: Cell::new(0),
        }
    }

    fn with_values(vals: &[f64]) -> Frame<'static> {
        let f = Frame::new(&[], None);
        for (i, v) in vals.iter().enumerate().take(NCACHE) {
            f.cache[i].set(*v);
        }
        f.have.set((1u32 << vals.len().min(NCACHE)) - 1);
        f
    }
}

/// The frame of top-level expressions (no parameters). Each use is a fresh temporary,
/// which is what we want: nothing is ever cached in it.
#[allow(clippy::declare_interior_mutable_const)]
const ROOT: Frame<'static> = Frame {
    args: &[],
    parent: None,
    cache: [const { Cell::new(0.0) }; NCACHE],
    have: Cell::new(0),
};

impl State {
    /// Sets a host variable (see [`crate::Program::bind_vars`]); cached `=` variables
    /// are recomputed at the next evaluation.
    #[inline]
    pub fn set(&mut self, v: VarId, value: f64) {
        self.vals[v.0 as usize] = value;
        self.epoch += 1;
    }

    /// Sets several host variables at once.
    #[inline]
    pub fn set_all(&mut self, vars: &[VarId], values: &[f64]) {
        for (v, x) in vars.iter().zip(values) {
            self.vals[v.0 as usize] = *x;
        }
        self.epoch += 1;
    }

    /// Sets the input channels `$1…$N` (rcalc's columns; a renderer's ray values).
    pub fn set_chans(&mut self, vals: &[f64]) {
        self.chans.clear();
        self.chans.extend_from_slice(vals);
        self.epoch += 1;
    }

    /// Mutable access to the channel values (call [`State::touch`] after changing them).
    pub fn chans_mut(&mut self) -> &mut Vec<f64> {
        &mut self.chans
    }

    /// Sets the primitive's real arguments seen by `arg(n)`.
    pub fn set_fargs(&mut self, vals: &[f64]) {
        self.fargs.clear();
        self.fargs.extend_from_slice(vals);
        self.epoch += 1;
    }

    /// Starts a new evaluation: forgets cached `=` variable values.
    #[inline]
    pub fn touch(&mut self) {
        self.epoch += 1;
    }

    #[inline]
    fn set_errno(&mut self, e: ErrFlag) {
        self.errno = e;
        self.errno_writes += 1;
    }

    /// Whether the error flag was written since `writes` was read from `errno_writes`.
    pub(crate) fn errno_written_since(&self, writes: u64) -> bool {
        self.errno_writes != writes
    }

    /// Whether warnings were counted since the last [`State::take_warnings`].
    #[inline]
    pub fn has_warnings(&self) -> bool {
        self.warnings.any()
    }

    /// Returns and clears the warnings counted so far.
    pub fn take_warnings(&mut self) -> Warnings {
        std::mem::take(&mut self.warnings)
    }
}

impl Compiled {
    /// A fresh evaluation state (host variables 0, no channels).
    pub fn state(&self) -> State {
        let n = self.vars.len();
        State {
            vals: vec![0.0; n],
            stamps: vec![0; n],
            epoch: 1,
            chans: Vec::new(),
            fargs: Vec::new(),
            depth: 0,
            fail: None,
            warnings: Warnings::default(),
            errno: ErrFlag::None,
            errno_writes: 0,
            fast_regs: vec![Vec::new(); self.fast.len()],
            fast_epoch: 0,
            fast_roots: Vec::new(),
            exact_epoch: 0,
            #[cfg(test)]
            fast_hits: 0,
        }
    }

    /// Whether any definition, function or channel refers to variable `v` (e.g. to
    /// know whether a host must keep setting a counter such as rcalc's `recno`).
    pub fn references_var(&self, v: VarId) -> bool {
        let walk = |n: &Node| n.any(&|n| matches!(n, Node::Var(i) if *i == v.0));
        self.vars
            .iter()
            .any(|s| matches!(s, VarSlot::Def(n, _) if walk(n)))
            || self.funcs.iter().any(|f| walk(&f.body))
            || self.chans.iter().any(|(_, n)| walk(n))
            || self.exprs.iter().any(walk)
    }

    /// Whether a `:` constant was left to be computed at its first evaluation (it
    /// depends on the input or the host, and keeps its first value afterwards).
    pub fn has_late_constants(&self) -> bool {
        self.vars.iter().any(|s| matches!(s, VarSlot::Def(_, true)))
    }

    /// Whether expression `e` has fast code (built now if not yet); false when the
    /// compiler gave up on it or fast code is switched off (`FENESTRA_CALC_EXACT`).
    pub fn has_fast_code(&self, e: ExprId) -> bool {
        let id = self.vars.len() + self.chans.len() + e.0 as usize;
        self.fast
            .get(id)
            .is_some_and(|f| f.get_or_init(|| self.build_fast(id)).is_some())
    }

    /// Makes room for the fast code of every root (built at first use).
    pub(crate) fn enable_fast(&mut self) {
        let n = self.vars.len() + self.chans.len() + self.exprs.len();
        self.fast = (0..n).map(|_| OnceLock::new()).collect();
    }

    /// Builds the fast code of root `id`.
    fn build_fast(&self, id: usize) -> Option<Fast> {
        let (nv, nc) = (self.vars.len(), self.chans.len());
        let node = if id < nv {
            match &self.vars[id] {
                // a `:` variable keeps its first value: always exact (it is cached)
                VarSlot::Def(n, false) => n,
                _ => return None,
            }
        } else if id < nv + nc {
            &self.chans[id - nv].1
        } else {
            &self.exprs[id - nv - nc]
        };
        crate::fast::build(self, node)
    }

    /// Tries the fast code of root `id`; `None` when there is none or it gave up.
    #[inline]
    fn try_fast(&self, st: &mut State, id: usize) -> Option<f64> {
        if st.exact_epoch == st.epoch {
            return None;
        }
        let f = self
            .fast
            .get(id)?
            .get_or_init(|| self.build_fast(id))
            .as_ref()?;
        let regs = st.fast_regs.get_mut(id)?;
        if regs.len() != f.regs.len() {
            regs.clone_from(&f.regs);
        }
        let inp = Inputs {
            vals: &st.vals,
            stamps: &st.stamps,
            chans: &st.chans,
            fargs: &st.fargs,
        };
        let x = f.run(&mut st.fast_regs[id], &inp)?;
        if st.fast_epoch != st.epoch {
            st.fast_epoch = st.epoch;
            st.fast_roots.clear();
        }
        st.fast_roots.push(id as u32);
        #[cfg(test)]
        {
            st.fast_hits += 1;
        }
        Some(x)
    }

    /// Before an exact evaluation: the roots evaluated by fast code in this epoch are
    /// evaluated again exactly (they raised nothing, so this only leaves the caches of
    /// `=` variables and the error flag as the exact evaluator would have them).
    fn replay(&self, st: &mut State) {
        st.exact_epoch = st.epoch;
        if st.fast_epoch != st.epoch || st.fast_roots.is_empty() {
            return;
        }
        let roots = std::mem::take(&mut st.fast_roots);
        let (nv, nc) = (self.vars.len(), self.chans.len());
        for &id in &roots {
            let id = id as usize;
            if id < nv {
                self.var_value(id as u32, st);
            } else if id < nv + nc {
                self.eval(&self.chans[id - nv].1, st, &ROOT);
            } else {
                self.eval(&self.exprs[id - nv - nc], st, &ROOT);
            }
            st.depth = 0;
        }
        st.fast_roots = roots;
        st.fast_roots.clear();
    }

    /// The id of a variable (host-bound or defined), if it exists.
    pub fn var(&self, name: &str) -> Option<VarId> {
        self.var_names
            .iter()
            .position(|n| n == name)
            .map(|i| VarId(i as u32))
    }

    /// The id of a user-defined function, if it exists.
    pub fn func(&self, name: &str) -> Option<FuncId> {
        self.funcs
            .iter()
            .position(|f| f.name == name)
            .map(|i| FuncId(i as u32))
    }

    /// Number of parameters of a user function.
    pub fn func_params(&self, f: FuncId) -> usize {
        self.funcs[f.0 as usize].nparams as usize
    }

    /// The output channels defined (`$N = …`), in increasing order.
    pub fn channels(&self) -> Vec<u32> {
        self.chans.iter().map(|(n, _)| *n).collect()
    }

    /// The value of a folded constant variable, if it is one.
    pub fn constant_value(&self, v: VarId) -> Option<f64> {
        match self.vars[v.0 as usize] {
            VarSlot::Const(x) | VarSlot::ConstClr(x) => Some(x),
            _ => None,
        }
    }

    fn finish(&self, st: &mut State, v: f64) -> Result<f64, CalcError> {
        st.depth = 0;
        match st.fail.take() {
            None => Ok(v),
            Some(Failure::Table(i)) => Err(self.errors[i as usize].clone()),
            Some(Failure::Dynamic(k, m)) => Err(CalcError::new(k, m)),
        }
    }

    /// Evaluates a variable.
    #[inline]
    pub fn eval_var(&self, st: &mut State, v: VarId) -> Result<f64, CalcError> {
        if let Some(x) = self.try_fast(st, v.0 as usize) {
            return Ok(x);
        }
        self.replay(st);
        let x = self.var_value(v.0, st);
        if st.fail.is_none() {
            return Ok(x);
        }
        self.finish(st, x)
    }

    /// Calls a user function with numeric arguments (at most 12).
    #[inline]
    pub fn call(&self, st: &mut State, f: FuncId, args: &[f64]) -> Result<f64, CalcError> {
        let fb = &self.funcs[f.0 as usize];
        if args.len() < fb.nparams as usize || args.len() > NCACHE {
            return Err(CalcError::new(
                ErrorKind::TooFewArguments,
                format!(
                    "{}(): called with {} arguments, needs {}",
                    fb.name,
                    args.len(),
                    fb.nparams
                ),
            ));
        }
        self.replay(st);
        let fr = Frame::with_values(args);
        let x = self.eval(&fb.body, st, &fr);
        if st.fail.is_none() {
            return Ok(x);
        }
        self.finish(st, x)
    }

    /// Evaluates output channel `$n` (0 when it is not defined).
    pub fn eval_chan(&self, st: &mut State, n: u32) -> Result<f64, CalcError> {
        let Some(k) = self.chans.iter().position(|(c, _)| *c == n) else {
            return Ok(0.0);
        };
        if let Some(x) = self.try_fast(st, self.vars.len() + k) {
            return Ok(x);
        }
        self.replay(st);
        let x = self.eval(&self.chans[k].1, st, &ROOT);
        self.finish(st, x)
    }

    /// Evaluates a standalone expression added with [`crate::Program::add_expr`].
    #[inline]
    pub fn eval_expr(&self, st: &mut State, e: ExprId) -> Result<f64, CalcError> {
        let id = self.vars.len() + self.chans.len() + e.0 as usize;
        if let Some(x) = self.try_fast(st, id) {
            return Ok(x);
        }
        self.replay(st);
        let x = self.eval(&self.exprs[e.0 as usize], st, &ROOT);
        if st.fail.is_none() {
            return Ok(x);
        }
        self.finish(st, x)
    }

    #[inline]
    fn var_value(&self, i: u32, st: &mut State) -> f64 {
        let iu = i as usize;
        match &self.vars[iu] {
            VarSlot::Const(x) => *x,
            VarSlot::ConstClr(x) => {
                // evaluated (its library calls made) once per evaluation, as Radiance
                // caches `=` variables
                if st.stamps[iu] != st.epoch {
                    st.stamps[iu] = st.epoch;
                    st.set_errno(ErrFlag::None);
                }
                *x
            }
            VarSlot::Host => st.vals[iu],
            VarSlot::Def(node, constant) => {
                let want = if *constant { u64::MAX } else { st.epoch };
                if st.stamps[iu] == want {
                    return st.vals[iu];
                }
                if !self.enter(st, &self.var_names[iu]) {
                    return 0.0;
                }
                let x = self.eval(node, st, &ROOT);
                st.depth -= 1;
                if st.fail.is_none() {
                    st.vals[iu] = x;
                    st.stamps[iu] = want;
                }
                x
            }
        }
    }

    #[inline]
    fn enter(&self, st: &mut State, name: &str) -> bool {
        if st.fail.is_some() {
            return false;
        }
        st.depth += 1;
        if st.depth > MAX_DEPTH {
            st.depth -= 1;
            st.fail = Some(Failure::Dynamic(
                ErrorKind::Recursion,
                format!(
                    "{name}: definitions nested more than {MAX_DEPTH} deep (recursion without a base case?)"
                ),
            ));
            return false;
        }
        true
    }

    fn param(&self, i: u32, st: &mut State, fr: &Frame) -> f64 {
        let iu = i as usize;
        if iu < NCACHE && fr.have.get() & (1 << iu) != 0 {
            return fr.cache[iu].get();
        }
        let Some(a) = fr.args.get(iu) else {
            if st.fail.is_none() {
                st.fail = Some(Failure::Dynamic(
                    ErrorKind::TooFewArguments,
                    "too few arguments in function call".into(),
                ));
            }
            return 0.0;
        };
        let x = self.eval(a, st, fr.parent.unwrap_or(&ROOT));
        if iu < NCACHE {
            fr.cache[iu].set(x);
            fr.have.set(fr.have.get() | (1 << iu));
        }
        x
    }

    fn call_user(&self, f: u32, args: &[Node], st: &mut State, fr: &Frame) -> f64 {
        let fb = &self.funcs[f as usize];
        if !self.enter(st, &fb.name) {
            return 0.0;
        }
        let nf = Frame::new(args, Some(fr));
        let x = self.eval(&fb.body, st, &nf);
        st.depth -= 1;
        x
    }

    fn call_host(&self, h: u32, args: &[Node], st: &mut State, fr: &Frame) -> f64 {
        let mut buf = [0.0f64; NCACHE];
        let n = args.len().min(NCACHE);
        for (i, a) in args.iter().take(n).enumerate() {
            buf[i] = self.eval(a, st, fr);
        }
        (self.hosts[h as usize])(&buf[..n])
    }

    fn call_target(&self, t: FnTarget, args: &[Node], st: &mut State, fr: &Frame) -> f64 {
        match t {
            FnTarget::User(f) => {
                if args.len() < self.funcs[f as usize].nparams as usize {
                    return self.dyn_fail(
                        st,
                        ErrorKind::TooFewArguments,
                        format!("{}(): too few arguments", self.funcs[f as usize].name),
                    );
                }
                self.call_user(f, args, st, fr)
            }
            FnTarget::Host(h) => self.call_host(h, args, st, fr),
            FnTarget::Builtin(b) => self.call_builtin(b, args, st, fr),
        }
    }

    fn dyn_fail(&self, st: &mut State, k: ErrorKind, msg: String) -> f64 {
        if st.fail.is_none() {
            st.fail = Some(Failure::Dynamic(k, msg));
        }
        0.0
    }

    /// A built-in call as Radiance makes it: the error flag is cleared, the function
    /// runs (evaluating its arguments), and if the flag was raised meanwhile the call
    /// reports `NAME(): range/domain error` and returns 0 (the flag stays raised).
    #[inline]
    fn lib_call(
        &self,
        st: &mut State,
        name: &'static str,
        f: impl FnOnce(&Self, &mut State) -> f64,
    ) -> f64 {
        st.set_errno(ErrFlag::None);
        let v = f(self, st);
        if st.errno != ErrFlag::None {
            self.lib_error(st, name)
        } else {
            v
        }
    }

    #[cold]
    fn lib_error(&self, st: &mut State, name: &'static str) -> f64 {
        if name == "select" && st.errno == ErrFlag::Domain {
            st.warnings.select_domain += 1;
        }
        if st.warnings.library.len() < 64 {
            st.warnings.library.push((name, st.errno));
        }
        0.0
    }

    fn call_builtin(&self, b: Builtin, args: &[Node], st: &mut State, fr: &Frame) -> f64 {
        self.lib_call(st, b.name(), |c, st| c.builtin_body(b, args, st, fr))
    }

    fn builtin_body(&self, b: Builtin, args: &[Node], st: &mut State, fr: &Frame) -> f64 {
        let need = b.min_args();
        if args.len() < need {
            return self.dyn_fail(
                st,
                ErrorKind::TooFewArguments,
                format!("{b:?}(): too few arguments").to_lowercase(),
            );
        }
        match b {
            Builtin::If => {
                if self.eval(&args[0], st, fr) > 0.0 {
                    self.eval(&args[1], st, fr)
                } else {
                    self.eval(&args[2], st, fr)
                }
            }
            Builtin::Math1(m) => m.apply(self.eval(&args[0], st, fr)),
            Builtin::Atan2 => {
                // Radiance's build evaluates the second argument first
                let x = self.eval(&args[1], st, fr);
                self.eval(&args[0], st, fr).atan2(x)
            }
            Builtin::Select => {
                let n = self.eval(&args[0], st, fr);
                let count = args.len() - 1;
                if n.is_nan() || n < -0.5 {
                    st.set_errno(ErrFlag::Domain);
                    return 0.0;
                }
                if n + 0.5 >= 2147483648.0 {
                    // Radiance converts the index to a C int and fails outright
                    return self.dyn_fail(
                        st,
                        ErrorKind::Other,
                        "select(): bad call to argument (index beyond the integer range)".into(),
                    );
                }
                let i = (n + 0.5) as i64;
                if i == 0 {
                    return count as f64;
                }
                if i as usize > count {
                    st.set_errno(ErrFlag::Domain);
                    return 0.0;
                }
                self.eval(&args[i as usize], st, fr)
            }
            Builtin::Max | Builtin::Min => {
                // Radiance's build evaluates the first argument, then the others
                // from the last backwards (observable through the error flag)
                let mut m = self.eval(&args[0], st, fr);
                for a in args[1..].iter().rev() {
                    let v = self.eval(a, st, fr);
                    if (b == Builtin::Max && v > m) || (b == Builtin::Min && v < m) {
                        m = v;
                    }
                }
                m
            }
            Builtin::Rand => builtins::rand_hash(self.eval(&args[0], st, fr)),
            Builtin::Jn => {
                let x = self.eval(&args[1], st, fr);
                builtins::jn(self.eval(&args[0], st, fr), x)
            }
            Builtin::Yn => {
                let x = self.eval(&args[1], st, fr);
                builtins::yn(self.eval(&args[0], st, fr), x)
            }
            Builtin::In => {
                let n = self.eval(&args[0], st, fr);
                builtins::in_arg_index(n, &st.chans).unwrap_or(0.0)
            }
            Builtin::Arg => {
                let n = self.eval(&args[0], st, fr);
                match builtins::in_arg_index(n, &st.fargs) {
                    Ok(v) => v,
                    Err(i) => self.dyn_fail(
                        st,
                        ErrorKind::Other,
                        format!("arg({i}): the primitive has {} arguments", st.fargs.len()),
                    ),
                }
            }
        }
    }

    /// Evaluates a node in a frame.
    pub(crate) fn eval(&self, n: &Node, st: &mut State, fr: &Frame) -> f64 {
        match n {
            Node::Num(v) => *v,
            Node::NumClr(v) => {
                st.set_errno(ErrFlag::None);
                *v
            }
            Node::Lib(name, a) => self.lib_call(st, name, |c, st| c.eval(a, st, fr)),
            Node::Var(i) => self.var_value(*i, st),
            Node::Chan(c) => st
                .chans
                .get((*c as usize).wrapping_sub(1))
                .copied()
                .unwrap_or(0.0),
            Node::Param(i) => self.param(*i, st, fr),
            Node::Neg(a) => -self.eval(a, st, fr),
            // Radiance sums from 0, so a sum of negative zeros is +0.
            Node::Add(p) => self.eval(&p.0, st, fr) + self.eval(&p.1, st, fr) + 0.0,
            Node::Sub(p) => self.eval(&p.0, st, fr) - self.eval(&p.1, st, fr),
            Node::Mul(p) => self.eval(&p.0, st, fr) * self.eval(&p.1, st, fr),
            Node::Div(p) => {
                let a = self.eval(&p.0, st, fr);
                let b = self.eval(&p.1, st, fr);
                if b == 0.0 {
                    st.warnings.division_by_zero += 1;
                    st.set_errno(ErrFlag::Range);
                    // Radiance's result is the (signed) zero divisor: 1/-0 gives -0
                    b
                } else {
                    a / b
                }
            }
            // `^` checks the error flag like a built-in call ("Illegal power", result 0)
            Node::Pow(p) => self.lib_call(st, "^", |c, st| {
                let a = c.eval(&p.0, st, fr);
                a.powf(c.eval(&p.1, st, fr))
            }),
            Node::If(t) => self.lib_call(st, "if", |c, st| {
                if c.eval(&t.0, st, fr) > 0.0 {
                    c.eval(&t.1, st, fr)
                } else {
                    c.eval(&t.2, st, fr)
                }
            }),
            Node::Math1(m, a) => self.lib_call(st, m.name(), |c, st| m.apply(c.eval(a, st, fr))),
            Node::Atan2(p) => self.lib_call(st, "atan2", |c, st| {
                // Radiance's build evaluates the second argument first
                let x = c.eval(&p.1, st, fr);
                c.eval(&p.0, st, fr).atan2(x)
            }),
            Node::Builtin(b, args) => self.call_builtin(*b, args, st, fr),
            Node::CallUser(f, args) => self.call_user(*f, args, st, fr),
            Node::CallHost(h, args) => self.call_host(*h, args, st, fr),
            Node::CallParam(i, args) => {
                // Find what the parameter names, following parameters passed through.
                let mut node = fr.args.get(*i as usize);
                let mut pf = fr.parent;
                loop {
                    match node {
                        Some(Node::FuncRef(t)) => return self.call_target(*t, args, st, fr),
                        Some(Node::Param(j)) => {
                            let Some(p) = pf else { break };
                            node = p.args.get(*j as usize);
                            pf = p.parent;
                        }
                        _ => break,
                    }
                }
                self.dyn_fail(
                    st,
                    ErrorKind::UndefinedFunction,
                    "a parameter called as a function is not a function name".into(),
                )
            }
            Node::FuncRef(t) => {
                let name = match t {
                    FnTarget::User(f) => self.funcs[*f as usize].name.clone(),
                    FnTarget::Host(h) => self.host_names[*h as usize].clone(),
                    FnTarget::Builtin(b) => format!("{b:?}").to_lowercase(),
                };
                self.dyn_fail(
                    st,
                    ErrorKind::UndefinedVariable,
                    format!("{name}: undefined variable (it is a function)"),
                )
            }
            Node::Fail(i) => {
                if st.fail.is_none() {
                    st.fail = Some(Failure::Table(*i));
                }
                0.0
            }
        }
    }
}

/// Evaluates a parameter-free node at compile time; `None` if it failed.
pub(crate) fn probe(c: &Compiled, n: &Node, st: &mut State) -> Option<f64> {
    let x = c.eval(n, st, &ROOT);
    if st.fail.is_some() {
        return None;
    }
    Some(x)
}
