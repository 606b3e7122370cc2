//! A fast path for evaluating a root (variable, output channel or standalone
//! expression): the compiled tree flattened into register code with every user
//! function inlined, constants folded after inlining, and variables and function
//! arguments computed at their first use on the path taken (so `if`/`select` stay
//! lazy).
//!
//! The fast code follows the exact evaluator only while nothing observable happens:
//! any event the exact evaluator would react to (division by zero, `select` out of
//! range, an error, a `:` constant not yet cached) makes it give up, and the caller
//! evaluates the root with the exact evaluator instead. Without events an evaluation
//! is a pure function of the host variables, the channels and the cached `:`
//! constants, so both paths give the same value. Programs the inliner cannot flatten
//! (recursion, host functions, very large expansions) have no fast code.
//!
//! One file on purpose (about 1 800 lines): the lowering, the relocation, the peephole
//! pass and the run loop all match on every variant of [`Op`]; a new op is added in one
//! place with its four cases side by side, and the run loop's `unsafe` register indexing
//! relies on `build`'s check right above it.

use std::collections::HashMap;

use crate::builtins::{self, Builtin, Math1};
use crate::eval::{Compiled, VarSlot};
use crate::node::{FnTarget, Node};

/// Registers with this bit set are constants (index into the constant pool) while
/// compiling; they are relocated in front of the temporaries at the end.
const KBIT: u32 = 1 << 31;
/// Largest number of instructions of one root's fast code.
const MAX_OPS: usize = 20_000;
/// Deepest nesting of inlined calls and variables.
const MAX_NEST: u32 = 64;

#[derive(Debug, Clone, Copy)]
pub(crate) enum Op {
    Host {
        d: u32,
        v: u32,
    },
    Chan {
        d: u32,
        c: u32,
    },
    /// A `:` constant that depends on the input: its cached value, or give up.
    Cached {
        d: u32,
        v: u32,
    },
    Copy {
        d: u32,
        a: u32,
    },
    Neg {
        d: u32,
        a: u32,
    },
    Add {
        d: u32,
        a: u32,
        b: u32,
    },
    Sub {
        d: u32,
        a: u32,
        b: u32,
    },
    Mul {
        d: u32,
        a: u32,
        b: u32,
    },
    Div {
        d: u32,
        a: u32,
        b: u32,
    },
    Pow {
        d: u32,
        a: u32,
        b: u32,
    },
    Atan2 {
        d: u32,
        y: u32,
        x: u32,
    },
    Floor {
        d: u32,
        a: u32,
    },
    Asin {
        d: u32,
        a: u32,
    },
    Acos {
        d: u32,
        a: u32,
    },
    Sqrt {
        d: u32,
        a: u32,
    },
    Math {
        d: u32,
        a: u32,
        m: Math1,
    },
    /// `max`/`min` of registers `lists[l..l+n]`.
    Max {
        d: u32,
        l: u32,
        n: u32,
    },
    Min {
        d: u32,
        l: u32,
        n: u32,
    },
    Rand {
        d: u32,
        a: u32,
    },
    Jn {
        d: u32,
        n: u32,
        x: u32,
    },
    Yn {
        d: u32,
        n: u32,
        x: u32,
    },
    In {
        d: u32,
        a: u32,
    },
    Arg {
        d: u32,
        a: u32,
    },
    /// Jump to `to` unless `c > 0`.
    JumpNotPos {
        c: u32,
        to: u32,
    },
    /// Jump to `to` unless `a > b`.
    JumpNotGt {
        a: u32,
        b: u32,
        to: u32,
    },
    /// `d = c > 0 ? x : y`.
    Pick {
        d: u32,
        c: u32,
        x: u32,
        y: u32,
    },
    /// `d = a > b ? x : y`.
    PickGt {
        d: u32,
        a: u32,
        b: u32,
        x: u32,
        y: u32,
    },
    Jump {
        to: u32,
    },
    /// `select` with lazy arguments: jump to `lists[l + k - 1]` for index `k` in 1..=n;
    /// for index 0, `d = n` and jump to `lists[l + n]`.
    Select {
        d: u32,
        i: u32,
        l: u32,
        n: u32,
    },
    /// `select` of constants `table[t..t+n]`.
    SelectK {
        d: u32,
        i: u32,
        t: u32,
        n: u32,
    },
    Abort,
    /// Made by the peephole pass: `d = a` and jump to `to`.
    CopyJump {
        d: u32,
        a: u32,
        to: u32,
    },
    /// `d = floor(a op b)` with the op's own semantics (`DivFloor` gives up on a zero
    /// divisor like `Div`).
    AddFloor {
        d: u32,
        a: u32,
        b: u32,
    },
    SubFloor {
        d: u32,
        a: u32,
        b: u32,
    },
    MulFloor {
        d: u32,
        a: u32,
        b: u32,
    },
    DivFloor {
        d: u32,
        a: u32,
        b: u32,
    },
    /// `d = k * asin(a)`, `k * acos(a)`, `k * atan2(y, x)`.
    AsinMul {
        d: u32,
        a: u32,
        k: u32,
    },
    AcosMul {
        d: u32,
        a: u32,
        k: u32,
    },
    Atan2Mul {
        d: u32,
        y: u32,
        x: u32,
        k: u32,
    },
    /// `d = x + a*b`, `d = a*b + x`, `d = x - a*b` (two roundings, as the pair).
    AddMul {
        d: u32,
        x: u32,
        a: u32,
        b: u32,
    },
    MulAdd {
        d: u32,
        a: u32,
        b: u32,
        x: u32,
    },
    SubMul {
        d: u32,
        x: u32,
        a: u32,
        b: u32,
    },
    /// `d = (a + b) + c`.
    AddAdd {
        d: u32,
        a: u32,
        b: u32,
        c: u32,
    },
}

/// The fast code of one root.
#[derive(Debug, Clone)]
pub(crate) struct Fast {
    ops: Vec<Op>,
    lists: Vec<u32>,
    table: Vec<f64>,
    /// Initial register file: constants first, then zeroed temporaries.
    pub(crate) regs: Vec<f64>,
    out: u32,
}

/// Why a root gets no fast code.
struct GiveUp;

struct Frame<'a> {
    args: &'a [Node],
    parent: usize,
    cache: Vec<Option<u32>>,
}

enum Undo {
    Var(u32),
    Param(usize, usize),
    Cse(Key),
}

/// What a pure op computes (kind, operands), for common subexpressions.
type Key = (u8, u32, u32, u32);

fn key(op: &Op) -> Option<Key> {
    Some(match *op {
        Op::Host { v, .. } => (0, v, 0, 0),
        Op::Chan { c, .. } => (1, c, 0, 0),
        Op::Neg { a, .. } => (2, a, 0, 0),
        Op::Add { a, b, .. } => (3, a, b, 0),
        Op::Sub { a, b, .. } => (4, a, b, 0),
        Op::Mul { a, b, .. } => (5, a, b, 0),
        Op::Div { a, b, .. } => (6, a, b, 0),
        Op::Pow { a, b, .. } => (7, a, b, 0),
        Op::Atan2 { y, x, .. } => (8, y, x, 0),
        Op::Floor { a, .. } => (9, a, 0, 0),
        Op::Asin { a, .. } => (14, a, 0, 0),
        Op::Acos { a, .. } => (15, a, 0, 0),
        Op::Sqrt { a, .. } => (16, a, 0, 0),
        Op::Math { a, m, .. } => (10, a, m as u32, 0),
        Op::Rand { a, .. } => (11, a, 0, 0),
        Op::In { a, .. } => (12, a, 0, 0),
        Op::SelectK { i, t, n, .. } => (13, i, t, n),
        _ => return None,
    })
}

fn dst(op: &mut Op) -> Option<&mut u32> {
    match op {
        Op::Host { d, .. }
        | Op::Chan { d, .. }
        | Op::Cached { d, .. }
        | Op::Copy { d, .. }
        | Op::Neg { d, .. }
        | Op::Add { d, .. }
        | Op::Sub { d, .. }
        | Op::Mul { d, .. }
        | Op::Div { d, .. }
        | Op::Pow { d, .. }
        | Op::Atan2 { d, .. }
        | Op::Floor { d, .. }
        | Op::Asin { d, .. }
        | Op::Acos { d, .. }
        | Op::Sqrt { d, .. }
        | Op::Math { d, .. }
        | Op::Max { d, .. }
        | Op::Min { d, .. }
        | Op::Rand { d, .. }
        | Op::Jn { d, .. }
        | Op::Yn { d, .. }
        | Op::In { d, .. }
        | Op::Arg { d, .. }
        | Op::Select { d, .. }
        | Op::SelectK { d, .. }
        | Op::Pick { d, .. }
        | Op::PickGt { d, .. }
        | Op::CopyJump { d, .. }
        | Op::AddFloor { d, .. }
        | Op::SubFloor { d, .. }
        | Op::MulFloor { d, .. }
        | Op::DivFloor { d, .. }
        | Op::AsinMul { d, .. }
        | Op::AcosMul { d, .. }
        | Op::Atan2Mul { d, .. }
        | Op::AddMul { d, .. }
        | Op::MulAdd { d, .. }
        | Op::SubMul { d, .. }
        | Op::AddAdd { d, .. } => Some(d),
        Op::JumpNotPos { .. } | Op::JumpNotGt { .. } | Op::Jump { .. } | Op::Abort => None,
    }
}

struct Fc<'a> {
    c: &'a Compiled,
    ops: Vec<Op>,
    consts: Vec<f64>,
    const_ids: HashMap<u64, u32>,
    ntemp: u32,
    lists: Vec<u32>,
    table: Vec<f64>,
    frames: Vec<Frame<'a>>,
    vars: Vec<Option<u32>>,
    undo: Vec<Undo>,
    cse: HashMap<Key, u32>,
    nest: u32,
    /// Temporaries written by a sum or a `floor` (never -0).
    no_neg_zero: Vec<bool>,
    /// While set, emitting an op fails (finding out whether expressions fold to
    /// constants).
    probing: bool,
}

fn is_k(r: u32) -> bool {
    r & KBIT != 0
}

impl<'a> Fc<'a> {
    fn new(c: &'a Compiled) -> Self {
        Fc {
            c,
            ops: Vec::new(),
            consts: Vec::new(),
            const_ids: HashMap::new(),
            ntemp: 0,
            lists: Vec::new(),
            table: Vec::new(),
            frames: vec![Frame {
                args: &[],
                parent: 0,
                cache: Vec::new(),
            }],
            vars: vec![None; c.vars.len()],
            undo: Vec::new(),
            cse: HashMap::new(),
            nest: 0,
            no_neg_zero: Vec::new(),
            probing: false,
        }
    }

    fn k(&mut self, v: f64) -> u32 {
        let n = self.consts.len() as u32;
        let id = *self.const_ids.entry(v.to_bits()).or_insert(n);
        if id == n {
            self.consts.push(v);
        }
        id | KBIT
    }

    fn kval(&self, r: u32) -> Option<f64> {
        is_k(r).then(|| self.consts[(r & !KBIT) as usize])
    }

    fn temp(&mut self) -> u32 {
        self.ntemp += 1;
        self.ntemp - 1
    }

    fn emit(&mut self, op: Op) -> Result<(), GiveUp> {
        if self.ops.len() >= MAX_OPS || self.probing {
            return Err(GiveUp);
        }
        self.ops.push(op);
        Ok(())
    }

    /// Emits an op writing a new temporary (or finds the same pure op emitted
    /// earlier on the path).
    fn op(&mut self, f: impl FnOnce(u32) -> Op) -> Result<u32, GiveUp> {
        let probe = f(u32::MAX);
        let k = key(&probe);
        if let Some(r) = k.and_then(|k| self.cse.get(&k)) {
            return Ok(*r);
        }
        let d = self.temp();
        let mut op = probe;
        if let Some(x) = dst(&mut op) {
            *x = d;
        }
        self.emit(op)?;
        if let Some(k) = k {
            self.cse.insert(k, d);
            self.undo.push(Undo::Cse(k));
        }
        if matches!(op, Op::Add { .. } | Op::Floor { .. }) {
            let i = d as usize;
            if self.no_neg_zero.len() <= i {
                self.no_neg_zero.resize(i + 1, false);
            }
            self.no_neg_zero[i] = true;
        }
        Ok(d)
    }

    fn abort(&mut self) -> Result<u32, GiveUp> {
        self.emit(Op::Abort)?;
        Ok(self.k(0.0))
    }

    fn rollback(&mut self, mark: usize) {
        while self.undo.len() > mark {
            match self.undo.pop() {
                Some(Undo::Var(v)) => self.vars[v as usize] = None,
                Some(Undo::Param(f, i)) => self.frames[f].cache[i] = None,
                Some(Undo::Cse(k)) => {
                    self.cse.remove(&k);
                }
                None => {}
            }
        }
    }

    /// Removes the `Add` (`mul` false) or `Mul` op just written to the newest temporary
    /// `r` when one operand is the identity (`x + 0`, `x * 1`: `identity`) and the other
    /// may stand for the result (`stands`; the right operand is tried first), and returns
    /// that other operand; otherwise returns `r` unchanged.
    fn elide_identity(
        &mut self,
        r: u32,
        mul: bool,
        identity: impl Fn(&Self, u32) -> bool,
        stands: impl Fn(&Self, u32) -> bool,
    ) -> u32 {
        let (d, a, b) = match (self.ops.last().copied(), mul) {
            (Some(Op::Add { d, a, b }), false) | (Some(Op::Mul { d, a, b }), true) => (d, a, b),
            _ => return r,
        };
        if d != r || r + 1 != self.ntemp {
            return r;
        }
        let k = if identity(self, b) && stands(self, a) {
            a
        } else if identity(self, a) && stands(self, b) {
            b
        } else {
            return r;
        };
        self.ops.pop();
        self.rollback_cse_of(d);
        self.ntemp -= 1;
        if let Some(f) = self.no_neg_zero.get_mut(d as usize) {
            *f = false;
        }
        k
    }

    /// Forgets the common-subexpression entry of the op just removed.
    fn rollback_cse_of(&mut self, d: u32) {
        if let Some(Undo::Cse(k)) = self.undo.last() {
            if self.cse.get(k) == Some(&d) {
                let k = *k;
                self.cse.remove(&k);
                self.undo.pop();
            }
        }
    }

    fn here(&self) -> u32 {
        self.ops.len() as u32
    }

    fn patch(&mut self, at: usize, to: u32) {
        match &mut self.ops[at] {
            Op::JumpNotPos { to: t, .. } | Op::JumpNotGt { to: t, .. } | Op::Jump { to: t } => {
                *t = to
            }
            _ => {}
        }
    }

    /// Compiles `n` in a lazy branch: its result is copied into `d`, and what it
    /// computed is forgotten afterwards.
    fn branch(&mut self, n: &'a Node, fr: usize, d: u32) -> Result<(), GiveUp> {
        let mark = self.undo.len();
        self.node_into(n, fr, d)?;
        self.rollback(mark);
        Ok(())
    }

    /// Compiles `n` with its value in `d` (nested `if`s write `d` directly).
    fn node_into(&mut self, n: &'a Node, fr: usize, d: u32) -> Result<(), GiveUp> {
        let r = match n {
            Node::Lib(_, a) => return self.node_into(a, fr, d),
            Node::If(t) => return self.cond(&t.0, &t.1, &t.2, fr, Some(d)).map(|_| ()),
            Node::CallUser(f, args) => return self.call_user(*f, args, fr, Some(d)).map(|_| ()),
            Node::Builtin(Builtin::Select, args) if args.len() > 1 => {
                let r = self.select(args, fr, Some(d))?;
                if r == d {
                    return Ok(());
                }
                r
            }
            _ => self.node(n, fr)?,
        };
        // the op just emitted writes the value: let it write `d` instead
        let last = self
            .ops
            .last_mut()
            .filter(|o| !matches!(o, Op::Copy { .. }));
        match last.and_then(dst) {
            Some(x) if !is_k(r) && *x == r && r + 1 == self.ntemp => *x = d,
            _ => self.emit(Op::Copy { d, a: r })?,
        }
        Ok(())
    }

    fn binary(
        &mut self,
        a: &'a Node,
        b: &'a Node,
        fr: usize,
        fold: fn(f64, f64) -> Option<f64>,
        op: fn(u32, u32, u32) -> Op,
    ) -> Result<u32, GiveUp> {
        let ra = self.node(a, fr)?;
        let rb = self.node(b, fr)?;
        if let (Some(x), Some(y)) = (self.kval(ra), self.kval(rb)) {
            if let Some(v) = fold(x, y) {
                return Ok(self.k(v));
            }
        }
        self.op(|d| op(d, ra, rb))
    }

    fn unary(
        &mut self,
        a: u32,
        fold: impl Fn(f64) -> f64,
        op: impl FnOnce(u32, u32) -> Op,
    ) -> Result<u32, GiveUp> {
        if let Some(x) = self.kval(a) {
            return Ok(self.k(fold(x)));
        }
        self.op(|d| op(d, a))
    }

    fn cond(
        &mut self,
        c: &'a Node,
        t: &'a Node,
        e: &'a Node,
        fr: usize,
        into: Option<u32>,
    ) -> Result<u32, GiveUp> {
        let rc = self.node(c, fr)?;
        if let Some(x) = self.kval(rc) {
            let chosen = if x > 0.0 { t } else { e };
            return match into {
                Some(d) => self.node_into(chosen, fr, d).map(|_| d),
                None => self.node(chosen, fr),
            };
        }
        let d = match into {
            Some(d) => d,
            None => self.temp(),
        };
        let j1 = self.ops.len();
        self.emit(Op::JumpNotPos { c: rc, to: 0 })?;
        self.branch(t, fr, d)?;
        let j2 = self.ops.len();
        self.emit(Op::Jump { to: 0 })?;
        let h = self.here();
        self.patch(j1, h);
        self.branch(e, fr, d)?;
        let h = self.here();
        self.patch(j2, h);
        Ok(d)
    }

    /// `select`; a jump table writes its cases into `into` when given (the value is in
    /// the register returned).
    fn select(&mut self, args: &'a [Node], fr: usize, into: Option<u32>) -> Result<u32, GiveUp> {
        let ri = self.node(&args[0], fr)?;
        let count = args.len() - 1;
        if let Some(x) = self.kval(ri) {
            let Some(i) = builtins::select_index(x) else {
                return self.abort();
            };
            if i == 0 {
                return Ok(self.k(count as f64));
            }
            if i > count {
                return self.abort();
            }
            return self.node(&args[i], fr);
        }
        // cases that are all constants (literals, or folded after inlining): a table
        if let Some(vals) = self.constants(&args[1..], fr) {
            let t = self.table.len() as u32;
            self.table.extend(vals);
            return self.op(|d| Op::SelectK {
                d,
                i: ri,
                t,
                n: count as u32,
            });
        }
        let d = match into {
            Some(d) => d,
            None => self.temp(),
        };
        let l = self.lists.len() as u32;
        // case k at lists[l + k - 1], the end (where index 0 goes) at lists[l + count]
        self.lists.extend(std::iter::repeat_n(0, count + 1));
        self.emit(Op::Select {
            d,
            i: ri,
            l,
            n: count as u32,
        })?;
        let mut ends = Vec::with_capacity(count);
        for (k, a) in args[1..].iter().enumerate() {
            self.lists[l as usize + k] = self.here();
            self.branch(a, fr, d)?;
            ends.push(self.ops.len());
            self.emit(Op::Jump { to: 0 })?;
        }
        let h = self.here();
        for j in ends {
            self.patch(j, h);
        }
        self.lists[l as usize + count] = h;
        Ok(d)
    }

    /// The values of `args` when each folds to a constant without emitting an op;
    /// otherwise `None`, with everything the attempt compiled forgotten.
    fn constants(&mut self, args: &'a [Node], fr: usize) -> Option<Vec<f64>> {
        if let Some(v) = args.iter().map(|a| a.num()).collect::<Option<Vec<f64>>>() {
            return Some(v);
        }
        let (undo, ntemp) = (self.undo.len(), self.ntemp);
        let (lists, table) = (self.lists.len(), self.table.len());
        let was = std::mem::replace(&mut self.probing, true);
        let mut vals = Vec::with_capacity(args.len());
        for a in args {
            match self.node(a, fr).ok().and_then(|r| self.kval(r)) {
                Some(v) => vals.push(v),
                None => break,
            }
        }
        self.probing = was;
        if vals.len() == args.len() {
            return Some(vals);
        }
        // no op was emitted; forget the temporaries, cached values and lists
        self.rollback(undo);
        self.ntemp = ntemp;
        self.no_neg_zero.truncate(ntemp as usize);
        self.lists.truncate(lists);
        self.table.truncate(table);
        None
    }

    fn builtin(&mut self, b: Builtin, args: &'a [Node], fr: usize) -> Result<u32, GiveUp> {
        let need = b.min_args();
        if args.len() < need {
            return self.abort();
        }
        match b {
            Builtin::If => self.cond(&args[0], &args[1], &args[2], fr, None),
            Builtin::Select => self.select(args, fr, None),
            Builtin::Math1(m) => self.math1(m, &args[0], fr),
            Builtin::Atan2 => self.atan2(&args[0], &args[1], fr),
            Builtin::Max | Builtin::Min => {
                let mut regs = Vec::with_capacity(args.len());
                for a in args {
                    regs.push(self.node(a, fr)?);
                }
                let l = self.lists.len() as u32;
                self.lists.extend_from_slice(&regs);
                let n = regs.len() as u32;
                if b == Builtin::Max {
                    self.op(|d| Op::Max { d, l, n })
                } else {
                    self.op(|d| Op::Min { d, l, n })
                }
            }
            Builtin::Rand => {
                let a = self.node(&args[0], fr)?;
                self.unary(a, builtins::rand_hash, |d, a| Op::Rand { d, a })
            }
            Builtin::Jn | Builtin::Yn => {
                let x = self.node(&args[1], fr)?;
                let n = self.node(&args[0], fr)?;
                if b == Builtin::Jn {
                    self.op(|d| Op::Jn { d, n, x })
                } else {
                    self.op(|d| Op::Yn { d, n, x })
                }
            }
            Builtin::In => {
                let a = self.node(&args[0], fr)?;
                self.op(|d| Op::In { d, a })
            }
            Builtin::Arg => {
                let a = self.node(&args[0], fr)?;
                self.op(|d| Op::Arg { d, a })
            }
        }
    }

    fn math1(&mut self, m: Math1, a: &'a Node, fr: usize) -> Result<u32, GiveUp> {
        let a = self.node(a, fr)?;
        match m {
            Math1::Floor => self.unary(a, |x| m.apply(x), |d, a| Op::Floor { d, a }),
            Math1::Asin => self.unary(a, |x| m.apply(x), |d, a| Op::Asin { d, a }),
            Math1::Acos => self.unary(a, |x| m.apply(x), |d, a| Op::Acos { d, a }),
            Math1::Sqrt => self.unary(a, |x| m.apply(x), |d, a| Op::Sqrt { d, a }),
            _ => self.unary(a, |x| m.apply(x), |d, a| Op::Math { d, a, m }),
        }
    }

    fn atan2(&mut self, y: &'a Node, x: &'a Node, fr: usize) -> Result<u32, GiveUp> {
        let rx = self.node(x, fr)?;
        let ry = self.node(y, fr)?;
        if let (Some(a), Some(b)) = (self.kval(ry), self.kval(rx)) {
            return Ok(self.k(a.atan2(b)));
        }
        self.op(|d| Op::Atan2 { d, y: ry, x: rx })
    }

    fn call_user(
        &mut self,
        f: u32,
        args: &'a [Node],
        fr: usize,
        into: Option<u32>,
    ) -> Result<u32, GiveUp> {
        let c = self.c;
        let fb = &c.funcs[f as usize];
        if self.nest >= MAX_NEST {
            return Err(GiveUp);
        }
        self.nest += 1;
        self.frames.push(Frame {
            args,
            parent: fr,
            cache: vec![None; args.len()],
        });
        let id = self.frames.len() - 1;
        let r = match into {
            Some(d) => self.node_into(&fb.body, id, d).map(|_| d),
            None => self.node(&fb.body, id),
        };
        self.nest -= 1;
        r
    }

    fn node(&mut self, n: &'a Node, fr: usize) -> Result<u32, GiveUp> {
        let c = self.c;
        match n {
            Node::Num(v) | Node::NumClr(v) => Ok(self.k(*v)),
            Node::Lib(_, a) => self.node(a, fr),
            Node::Var(i) => {
                if let Some(r) = self.vars[*i as usize] {
                    return Ok(r);
                }
                let iu = *i as usize;
                let r = match &c.vars[iu] {
                    VarSlot::Const(x) | VarSlot::ConstClr(x) => return Ok(self.k(*x)),
                    VarSlot::Host => self.op(|d| Op::Host { d, v: *i })?,
                    VarSlot::Def(_, true) => self.op(|d| Op::Cached { d, v: *i })?,
                    VarSlot::Def(body, false) => {
                        if self.nest >= MAX_NEST {
                            return Err(GiveUp);
                        }
                        self.nest += 1;
                        let r = self.node(body, 0);
                        self.nest -= 1;
                        r?
                    }
                };
                self.vars[iu] = Some(r);
                self.undo.push(Undo::Var(*i));
                Ok(r)
            }
            Node::Chan(ch) => self.op(|d| Op::Chan { d, c: *ch }),
            Node::Param(i) => {
                let iu = *i as usize;
                if fr == 0 || iu >= self.frames[fr].args.len() {
                    return self.abort();
                }
                if let Some(r) = self.frames[fr].cache[iu] {
                    return Ok(r);
                }
                let (arg, parent) = (&self.frames[fr].args[iu], self.frames[fr].parent);
                let r = self.node(arg, parent)?;
                self.frames[fr].cache[iu] = Some(r);
                self.undo.push(Undo::Param(fr, iu));
                Ok(r)
            }
            Node::Neg(a) => {
                let a = self.node(a, fr)?;
                self.unary(a, |x| -x, |d, a| Op::Neg { d, a })
            }
            Node::Add(p) => {
                let r = self.binary(
                    &p.0,
                    &p.1,
                    fr,
                    |x, y| Some(x + y + 0.0),
                    |d, a, b| Op::Add { d, a, b },
                )?;
                // x + ±0 is x when x is itself a sum or a floor (never -0)
                Ok(self.elide_identity(
                    r,
                    false,
                    |s, q| s.kval(q) == Some(0.0),
                    |s, q| !is_k(q) && s.no_neg_zero.get(q as usize) == Some(&true),
                ))
            }
            Node::Sub(p) => self.binary(
                &p.0,
                &p.1,
                fr,
                |x, y| Some(x - y),
                |d, a, b| Op::Sub { d, a, b },
            ),
            Node::Mul(p) => {
                let r = self.binary(
                    &p.0,
                    &p.1,
                    fr,
                    |x, y| Some(x * y),
                    |d, a, b| Op::Mul { d, a, b },
                )?;
                // x*1 is x (also for infinities, NaNs and signed zeros)
                Ok(self.elide_identity(r, true, |s, q| s.kval(q) == Some(1.0), |_, _| true))
            }
            Node::Div(p) => self.binary(
                &p.0,
                &p.1,
                fr,
                |x, y| (y != 0.0).then(|| x / y),
                |d, a, b| Op::Div { d, a, b },
            ),
            Node::Pow(p) => self.binary(
                &p.0,
                &p.1,
                fr,
                |x, y| Some(x.powf(y)),
                |d, a, b| Op::Pow { d, a, b },
            ),
            Node::If(t) => self.cond(&t.0, &t.1, &t.2, fr, None),
            Node::Math1(m, a) => self.math1(*m, a, fr),
            Node::Atan2(p) => self.atan2(&p.0, &p.1, fr),
            Node::Builtin(b, args) => self.builtin(*b, args, fr),
            Node::CallUser(f, args) => self.call_user(*f, args, fr, None),
            Node::CallHost(..) => Err(GiveUp),
            Node::CallParam(i, args) => {
                // what the parameter names, following parameters passed through
                // (the root frame has no parent)
                let parent = |f: usize, fs: &[Frame]| (f != 0).then(|| fs[f].parent);
                let mut node = self.frames[fr].args.get(*i as usize);
                let mut pf = parent(fr, &self.frames);
                loop {
                    match node {
                        Some(Node::FuncRef(t)) => {
                            return match *t {
                                FnTarget::User(f) => {
                                    if args.len() < c.funcs[f as usize].nparams as usize {
                                        return self.abort();
                                    }
                                    self.call_user(f, args, fr, None)
                                }
                                FnTarget::Host(_) => Err(GiveUp),
                                FnTarget::Builtin(b) => self.builtin(b, args, fr),
                            };
                        }
                        Some(Node::Param(j)) => {
                            let Some(p) = pf else { break };
                            node = self.frames[p].args.get(*j as usize);
                            pf = parent(p, &self.frames);
                        }
                        _ => break,
                    }
                }
                self.abort()
            }
            Node::FuncRef(_) | Node::Fail(_) => self.abort(),
        }
    }
}

/// Builds the fast code of a root, if it can be flattened.
pub(crate) fn build(c: &Compiled, root: &Node) -> Option<Fast> {
    let mut fc = Fc::new(c);
    let out = fc.node(root, 0).ok()?;
    let nk = fc.consts.len() as u32;
    let map = |r: u32| if is_k(r) { r & !KBIT } else { r + nk };
    for op in &mut fc.ops {
        match op {
            Op::Host { d, .. }
            | Op::Chan { d, .. }
            | Op::Cached { d, .. }
            | Op::Max { d, .. }
            | Op::Min { d, .. } => *d = map(*d),
            Op::Copy { d, a }
            | Op::Neg { d, a }
            | Op::Floor { d, a }
            | Op::Asin { d, a }
            | Op::Acos { d, a }
            | Op::Sqrt { d, a }
            | Op::Math { d, a, .. }
            | Op::Rand { d, a }
            | Op::In { d, a }
            | Op::Arg { d, a } => {
                *d = map(*d);
                *a = map(*a);
            }
            Op::Add { d, a, b }
            | Op::Sub { d, a, b }
            | Op::Mul { d, a, b }
            | Op::Div { d, a, b }
            | Op::Pow { d, a, b } => {
                *d = map(*d);
                *a = map(*a);
                *b = map(*b);
            }
            Op::Atan2 { d, y, x } => {
                *d = map(*d);
                *y = map(*y);
                *x = map(*x);
            }
            Op::Jn { d, n, x } | Op::Yn { d, n, x } => {
                *d = map(*d);
                *n = map(*n);
                *x = map(*x);
            }
            Op::JumpNotPos { c, .. } => *c = map(*c),
            // made by the peephole pass, after relocation
            Op::JumpNotGt { .. }
            | Op::Pick { .. }
            | Op::PickGt { .. }
            | Op::CopyJump { .. }
            | Op::AddFloor { .. }
            | Op::SubFloor { .. }
            | Op::MulFloor { .. }
            | Op::DivFloor { .. }
            | Op::AsinMul { .. }
            | Op::AcosMul { .. }
            | Op::Atan2Mul { .. }
            | Op::AddMul { .. }
            | Op::MulAdd { .. }
            | Op::SubMul { .. }
            | Op::AddAdd { .. } => {}
            Op::Select { d, i, .. } | Op::SelectK { d, i, .. } => {
                *d = map(*d);
                *i = map(*i);
            }
            Op::Jump { .. } | Op::Abort => {}
        }
    }
    // register lists of max/min (jump tables of `select` hold op indices)
    let mut lists = fc.lists.clone();
    for op in &fc.ops {
        if let Op::Max { l, n, .. } | Op::Min { l, n, .. } = op {
            for r in &mut lists[*l as usize..(*l + *n) as usize] {
                *r = map(*r);
            }
        }
    }
    let mut regs = fc.consts.clone();
    regs.resize((nk + fc.ntemp) as usize, 0.0);
    let nk = fc.consts.len();
    let mut f = Fast {
        ops: fc.ops,
        lists,
        table: fc.table,
        regs,
        out: map(out),
    };
    peephole(&mut f, nk);
    // every register named must exist (`Fast::run` indexes without checks)
    let n = f.regs.len() as u32;
    let mut valid = f.out < n;
    for op in &f.ops {
        let mut o = *op;
        valid &= dst(&mut o).is_none_or(|d| *d < n);
        if let Op::Max { l, n: k, .. } | Op::Min { l, n: k, .. } = *op {
            valid &= k > 0 && ((l + k) as usize) <= f.lists.len();
        }
        reads(op, &f.lists, |r| valid &= r < n);
    }
    valid.then_some(f)
}

/// Calls `f` with each register `op` reads.
fn reads(op: &Op, lists: &[u32], mut f: impl FnMut(u32)) {
    match *op {
        Op::Copy { a, .. }
        | Op::CopyJump { a, .. }
        | Op::Neg { a, .. }
        | Op::Floor { a, .. }
        | Op::Asin { a, .. }
        | Op::Acos { a, .. }
        | Op::Sqrt { a, .. }
        | Op::Math { a, .. }
        | Op::Rand { a, .. }
        | Op::In { a, .. }
        | Op::Arg { a, .. }
        | Op::JumpNotPos { c: a, .. }
        | Op::Select { i: a, .. }
        | Op::SelectK { i: a, .. } => f(a),
        Op::Add { a, b, .. }
        | Op::Sub { a, b, .. }
        | Op::Mul { a, b, .. }
        | Op::Div { a, b, .. }
        | Op::Pow { a, b, .. }
        | Op::AddFloor { a, b, .. }
        | Op::SubFloor { a, b, .. }
        | Op::MulFloor { a, b, .. }
        | Op::DivFloor { a, b, .. }
        | Op::AsinMul { a, k: b, .. }
        | Op::AcosMul { a, k: b, .. }
        | Op::Atan2 { y: a, x: b, .. }
        | Op::Jn { n: a, x: b, .. }
        | Op::Yn { n: a, x: b, .. }
        | Op::JumpNotGt { a, b, .. } => {
            f(a);
            f(b);
        }
        Op::Atan2Mul {
            y: a, x: b, k: c, ..
        }
        | Op::AddMul {
            x: a, a: b, b: c, ..
        }
        | Op::MulAdd { a, b, x: c, .. }
        | Op::SubMul {
            x: a, a: b, b: c, ..
        }
        | Op::AddAdd { a, b, c, .. } => {
            f(a);
            f(b);
            f(c);
        }
        Op::Pick { c, x, y, .. } => {
            f(c);
            f(x);
            f(y);
        }
        Op::PickGt { a, b, x, y, .. } => {
            f(a);
            f(b);
            f(x);
            f(y);
        }
        Op::Max { l, n, .. } | Op::Min { l, n, .. } => {
            for &r in lists.get(l as usize..(l + n) as usize).unwrap_or(&[]) {
                f(r);
            }
        }
        Op::Host { .. } | Op::Chan { .. } | Op::Cached { .. } | Op::Jump { .. } | Op::Abort => {}
    }
}

/// Calls `f` with each op index `op` may jump to (besides the next op).
fn targets(op: &Op, lists: &[u32], mut f: impl FnMut(u32)) {
    match *op {
        Op::JumpNotPos { to, .. }
        | Op::JumpNotGt { to, .. }
        | Op::Jump { to }
        | Op::CopyJump { to, .. } => f(to),
        Op::Select { l, n, .. } => {
            for &t in lists.get(l as usize..=(l + n) as usize).unwrap_or(&[]) {
                f(t);
            }
        }
        _ => {}
    }
}

/// Fuses ops (registers below `nk` are constants). A sign test of a difference, of a
/// sum with a constant or of a negation becomes a comparison: `a - b > 0` exactly
/// when `a > b`, `a + k > 0` when `a > -k`, `-a > 0` when `0 > a` (an IEEE sum or
/// difference is zero only when it is exactly zero, rounding keeps the sign, and
/// NaNs compare false either way). An `if` choosing between two values already in
/// registers becomes one op.
fn peephole(f: &mut Fast, nk: usize) {
    let n = f.ops.len();
    let mut uses = vec![0u32; f.regs.len()];
    let mut landing = vec![0u32; n + 1];
    for op in &f.ops {
        reads(op, &f.lists, |r| {
            if let Some(u) = uses.get_mut(r as usize) {
                *u += 1
            }
        });
        targets(op, &f.lists, |t| {
            if let Some(l) = landing.get_mut(t as usize) {
                *l += 1
            }
        });
    }
    if let Some(u) = uses.get_mut(f.out as usize) {
        *u += 1;
    }
    // a constant register holding `v` (new ones are added after the temporaries)
    let base = f.regs.len();
    let konst = |regs: &mut Vec<f64>, v: f64| -> u32 {
        let same = |i: &usize| regs[*i].to_bits() == v.to_bits();
        match (0..nk).chain(base..regs.len()).find(same) {
            Some(i) => i as u32,
            None => {
                regs.push(v);
                (regs.len() - 1) as u32
            }
        }
    };
    let mut keep = vec![true; n];
    // 1. sign tests of differences, sums and negations
    for i in 0..n.saturating_sub(1) {
        let Op::JumpNotPos { c, to } = f.ops[i + 1] else {
            continue;
        };
        if landing[i + 1] != 0 || uses.get(c as usize) != Some(&1) {
            continue;
        }
        let fused = match f.ops[i] {
            Op::Sub { d, a, b } if d == c => Some((a, b)),
            Op::Add { d, a, b } if d == c && (b as usize) < nk => {
                let negk = -f.regs[b as usize];
                let k = konst(&mut f.regs, negk);
                Some((a, k))
            }
            Op::Add { d, a, b } if d == c && (a as usize) < nk => {
                let negk = -f.regs[a as usize];
                let k = konst(&mut f.regs, negk);
                Some((b, k))
            }
            Op::Neg { d, a } if d == c => Some((konst(&mut f.regs, 0.0), a)),
            _ => None,
        };
        if let Some((a, b)) = fused {
            f.ops[i] = Op::JumpNotGt { a, b, to };
            keep[i + 1] = false;
        }
    }
    // 2. `if` between two registers: test, copy, jump over, copy
    let next = |i: usize, keep: &[bool]| (i + 1..n).find(|&j| keep[j]);
    for i in 0..n {
        if !keep[i] {
            continue;
        }
        let (c, ab, to) = match f.ops[i] {
            Op::JumpNotPos { c, to } => (Some(c), None, to),
            Op::JumpNotGt { a, b, to } => (None, Some((a, b)), to),
            _ => continue,
        };
        let Some(j1) = next(i, &keep) else { continue };
        let Some(j2) = next(j1, &keep) else { continue };
        let Some(j3) = next(j2, &keep) else { continue };
        let (Op::Copy { d, a: x }, Op::Jump { to: end }, Op::Copy { d: d2, a: y }) =
            (f.ops[j1], f.ops[j2], f.ops[j3])
        else {
            continue;
        };
        let after = next(j3, &keep).unwrap_or(n);
        if d != d2
            || to as usize != j3
            || end as usize != after
            || landing[j1] != 0
            || landing[j2] != 0
            || landing[j3] != 1
        {
            continue;
        }
        f.ops[i] = match (c, ab) {
            (Some(c), _) => Op::Pick { d, c, x, y },
            (_, Some((a, b))) => Op::PickGt { d, a, b, x, y },
            _ => continue,
        };
        keep[j1] = false;
        keep[j2] = false;
        keep[j3] = false;
        landing[after] -= 1;
    }
    // 3. pairs of ops as one: a copy and the jump after it; `floor` of a sum,
    // difference, product or quotient; a product with `asin`, `acos`, `atan2` (the
    // intermediate value read by nothing else, the second op not a jump target)
    for i in 0..n {
        if !keep[i] {
            continue;
        }
        let Some(j) = next(i, &keep) else { continue };
        if landing[j] != 0 {
            continue;
        }
        let once = |t: u32| uses.get(t as usize) == Some(&1);
        let fused = match (f.ops[i], f.ops[j]) {
            (Op::Copy { d, a }, Op::Jump { to }) => Some(Op::CopyJump { d, a, to }),
            (Op::Add { d: t, a, b }, Op::Floor { d, a: u }) if t == u && once(t) => {
                Some(Op::AddFloor { d, a, b })
            }
            (Op::Sub { d: t, a, b }, Op::Floor { d, a: u }) if t == u && once(t) => {
                Some(Op::SubFloor { d, a, b })
            }
            (Op::Mul { d: t, a, b }, Op::Floor { d, a: u }) if t == u && once(t) => {
                Some(Op::MulFloor { d, a, b })
            }
            (Op::Div { d: t, a, b }, Op::Floor { d, a: u }) if t == u && once(t) => {
                Some(Op::DivFloor { d, a, b })
            }
            (Op::Asin { d: t, a }, Op::Mul { d, a: k, b: u }) if t == u && k != t && once(t) => {
                Some(Op::AsinMul { d, a, k })
            }
            (Op::Acos { d: t, a }, Op::Mul { d, a: k, b: u }) if t == u && k != t && once(t) => {
                Some(Op::AcosMul { d, a, k })
            }
            (Op::Atan2 { d: t, y, x }, Op::Mul { d, a: k, b: u })
                if t == u && k != t && once(t) =>
            {
                Some(Op::Atan2Mul { d, y, x, k })
            }
            (Op::Mul { d: t, a, b }, Op::Add { d, a: x, b: u }) if t == u && x != t && once(t) => {
                Some(Op::AddMul { d, x, a, b })
            }
            (Op::Mul { d: t, a, b }, Op::Add { d, a: u, b: x }) if t == u && x != t && once(t) => {
                Some(Op::MulAdd { d, a, b, x })
            }
            (Op::Mul { d: t, a, b }, Op::Sub { d, a: x, b: u }) if t == u && x != t && once(t) => {
                Some(Op::SubMul { d, x, a, b })
            }
            (Op::Add { d: t, a, b }, Op::Add { d, a: u, b: c }) if t == u && c != t && once(t) => {
                Some(Op::AddAdd { d, a, b, c })
            }
            _ => None,
        };
        if let Some(op) = fused {
            f.ops[i] = op;
            keep[j] = false;
        }
    }
    // 4. the ops kept, jump targets renumbered
    let mut newidx = vec![0u32; n + 1];
    let mut k = 0u32;
    for (i, x) in newidx.iter_mut().enumerate() {
        *x = k;
        if i < n && keep[i] {
            k += 1;
        }
    }
    let old = std::mem::take(&mut f.ops);
    for (i, mut op) in old.into_iter().enumerate() {
        if !keep[i] {
            continue;
        }
        match &mut op {
            Op::JumpNotPos { to, .. }
            | Op::JumpNotGt { to, .. }
            | Op::Jump { to }
            | Op::CopyJump { to, .. } => *to = newidx[*to as usize],
            Op::Select { l, n, .. } => {
                for t in &mut f.lists[*l as usize..=(*l + *n) as usize] {
                    *t = newidx[*t as usize];
                }
            }
            _ => {}
        }
        f.ops.push(op);
    }
    // 5. a jump to a jump goes straight to the latter's target
    let ops = f.ops.clone();
    let hop = |mut t: u32| {
        for _ in 0..8 {
            match ops.get(t as usize) {
                Some(Op::Jump { to }) => t = *to,
                _ => break,
            }
        }
        t
    };
    for op in &mut f.ops {
        match op {
            Op::JumpNotPos { to, .. }
            | Op::JumpNotGt { to, .. }
            | Op::Jump { to }
            | Op::CopyJump { to, .. } => *to = hop(*to),
            _ => {}
        }
    }
}

/// What the fast code reads besides its registers.
pub(crate) struct Inputs<'s> {
    pub vals: &'s [f64],
    pub stamps: &'s [u64],
    pub chans: &'s [f64],
    pub fargs: &'s [f64],
}

/// The register file, indexed without bounds checks: [`build`] checked that every
/// register an op names is below `Fast::regs.len()`, and [`Fast::run`] that the file
/// has that length.
struct Regs<'r>(&'r mut [f64]);

impl std::ops::Index<usize> for Regs<'_> {
    type Output = f64;
    #[inline(always)]
    fn index(&self, i: usize) -> &f64 {
        debug_assert!(i < self.0.len());
        // SAFETY: see the type's comment.
        unsafe { self.0.get_unchecked(i) }
    }
}

impl std::ops::IndexMut<usize> for Regs<'_> {
    #[inline(always)]
    fn index_mut(&mut self, i: usize) -> &mut f64 {
        debug_assert!(i < self.0.len());
        // SAFETY: see the type's comment.
        unsafe { self.0.get_unchecked_mut(i) }
    }
}

#[inline]
fn floor0(x: f64) -> f64 {
    // floor without a libm call for |x| < 2^52 (the oracle's floor never returns -0)
    if x.abs() < 4_503_599_627_370_496.0 {
        let t = x as i64 as f64;
        (if t > x { t - 1.0 } else { t }) + 0.0
    } else {
        x.floor() + 0.0
    }
}

impl Fast {
    /// Runs the code; `None` when the exact evaluator must take over.
    #[inline]
    pub(crate) fn run(&self, regs: &mut [f64], inp: &Inputs) -> Option<f64> {
        if regs.len() != self.regs.len() {
            return None; // a state made for another program
        }
        let mut r = Regs(regs);
        let ops = &self.ops[..];
        let mut pc = 0usize;
        while let Some(op) = ops.get(pc) {
            pc += 1;
            match *op {
                Op::Host { d, v } => r[d as usize] = inp.vals[v as usize],
                Op::Chan { d, c } => {
                    r[d as usize] = inp
                        .chans
                        .get((c as usize).wrapping_sub(1))
                        .copied()
                        .unwrap_or(0.0)
                }
                Op::Cached { d, v } => {
                    if inp.stamps[v as usize] != u64::MAX {
                        return None;
                    }
                    r[d as usize] = inp.vals[v as usize];
                }
                Op::Copy { d, a } => r[d as usize] = r[a as usize],
                Op::Neg { d, a } => r[d as usize] = -r[a as usize],
                Op::Add { d, a, b } => r[d as usize] = r[a as usize] + r[b as usize] + 0.0,
                Op::Sub { d, a, b } => r[d as usize] = r[a as usize] - r[b as usize],
                Op::Mul { d, a, b } => r[d as usize] = r[a as usize] * r[b as usize],
                Op::Div { d, a, b } => {
                    let y = r[b as usize];
                    if y == 0.0 {
                        return None;
                    }
                    r[d as usize] = r[a as usize] / y;
                }
                Op::Pow { d, a, b } => r[d as usize] = r[a as usize].powf(r[b as usize]),
                Op::Atan2 { d, y, x } => r[d as usize] = r[y as usize].atan2(r[x as usize]),
                Op::Floor { d, a } => r[d as usize] = floor0(r[a as usize]),
                Op::Asin { d, a } => r[d as usize] = Math1::Asin.apply(r[a as usize]),
                Op::Acos { d, a } => r[d as usize] = Math1::Acos.apply(r[a as usize]),
                Op::Sqrt { d, a } => r[d as usize] = Math1::Sqrt.apply(r[a as usize]),
                Op::Math { d, a, m } => r[d as usize] = m.apply(r[a as usize]),
                Op::Max { d, l, n } | Op::Min { d, l, n } => {
                    let is_max = matches!(op, Op::Max { .. });
                    let list = &self.lists[l as usize..(l + n) as usize];
                    let mut m = r[list[0] as usize];
                    for &a in list[1..].iter().rev() {
                        let v = r[a as usize];
                        if (is_max && v > m) || (!is_max && v < m) {
                            m = v;
                        }
                    }
                    r[d as usize] = m;
                }
                Op::Rand { d, a } => r[d as usize] = builtins::rand_hash(r[a as usize]),
                Op::Jn { d, n, x } => r[d as usize] = builtins::jn(r[n as usize], r[x as usize]),
                Op::Yn { d, n, x } => r[d as usize] = builtins::yn(r[n as usize], r[x as usize]),
                Op::In { d, a } => {
                    r[d as usize] = builtins::in_arg_index(r[a as usize], inp.chans).unwrap_or(0.0);
                }
                Op::Arg { d, a } => {
                    r[d as usize] = builtins::in_arg_index(r[a as usize], inp.fargs).ok()?;
                }
                Op::JumpNotPos { c, to } => {
                    if r[c as usize] <= 0.0 || r[c as usize].is_nan() {
                        pc = to as usize;
                    }
                }
                Op::Jump { to } => pc = to as usize,
                Op::JumpNotGt { a, b, to } => {
                    if r[a as usize] <= r[b as usize]
                        || r[a as usize].is_nan()
                        || r[b as usize].is_nan()
                    {
                        pc = to as usize;
                    }
                }
                Op::Pick { d, c, x, y } => {
                    r[d as usize] = if r[c as usize] > 0.0 {
                        r[x as usize]
                    } else {
                        r[y as usize]
                    };
                }
                Op::PickGt { d, a, b, x, y } => {
                    r[d as usize] = if r[a as usize] > r[b as usize] {
                        r[x as usize]
                    } else {
                        r[y as usize]
                    };
                }
                Op::Select { d, i, l, n } => {
                    let x = r[i as usize];
                    let k = builtins::select_index(x)?;
                    if k > n as usize {
                        return None;
                    }
                    if k == 0 {
                        r[d as usize] = n as f64;
                        pc = self.lists[l as usize + n as usize] as usize;
                    } else {
                        pc = self.lists[l as usize + k - 1] as usize;
                    }
                }
                Op::SelectK { d, i, t, n } => {
                    let x = r[i as usize];
                    let k = builtins::select_index(x)?;
                    if k == 0 {
                        r[d as usize] = n as f64;
                    } else if k > n as usize {
                        return None;
                    } else {
                        r[d as usize] = self.table[t as usize + k - 1];
                    }
                }
                Op::Abort => return None,
                Op::CopyJump { d, a, to } => {
                    r[d as usize] = r[a as usize];
                    pc = to as usize;
                }
                Op::AddFloor { d, a, b } => {
                    r[d as usize] = floor0(r[a as usize] + r[b as usize] + 0.0)
                }
                Op::SubFloor { d, a, b } => r[d as usize] = floor0(r[a as usize] - r[b as usize]),
                Op::MulFloor { d, a, b } => r[d as usize] = floor0(r[a as usize] * r[b as usize]),
                Op::DivFloor { d, a, b } => {
                    let y = r[b as usize];
                    if y == 0.0 {
                        return None;
                    }
                    r[d as usize] = floor0(r[a as usize] / y);
                }
                Op::AsinMul { d, a, k } => {
                    r[d as usize] = r[k as usize] * Math1::Asin.apply(r[a as usize])
                }
                Op::AcosMul { d, a, k } => {
                    r[d as usize] = r[k as usize] * Math1::Acos.apply(r[a as usize])
                }
                Op::Atan2Mul { d, y, x, k } => {
                    r[d as usize] = r[k as usize] * r[y as usize].atan2(r[x as usize])
                }
                Op::AddMul { d, x, a, b } => {
                    r[d as usize] = r[x as usize] + r[a as usize] * r[b as usize] + 0.0
                }
                Op::MulAdd { d, a, b, x } => {
                    r[d as usize] = r[a as usize] * r[b as usize] + r[x as usize] + 0.0
                }
                Op::SubMul { d, x, a, b } => {
                    r[d as usize] = r[x as usize] - r[a as usize] * r[b as usize]
                }
                Op::AddAdd { d, a, b, c } => {
                    r[d as usize] = (r[a as usize] + r[b as usize] + 0.0) + r[c as usize] + 0.0
                }
            }
        }
        Some(r[self.out as usize])
    }
}

#[cfg(test)]
mod tests {
    use super::Op;
    use crate::{Compiled, Program};

    /// A small deterministic generator (64-bit LCG); `.1` says which of `f1`, `f2`
    /// (bits 0, 1) an expression may call.
    struct Gen(u64, u8);

    impl Gen {
        fn next(&mut self, n: usize) -> usize {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((self.0 >> 33) % n as u64) as usize
        }

        /// An expression over the names allowed at this place.
        fn expr(&mut self, depth: u32, names: &[&str]) -> String {
            let leaf = depth == 0 || self.next(4) == 0;
            if leaf {
                return match self.next(3) {
                    0 => ["0", "1", "-1", "0.5", "2.5", "3", "1e-3"][self.next(7)].to_string(),
                    1 => format!("${}", 1 + self.next(3)),
                    _ => names[self.next(names.len())].to_string(),
                };
            }
            let d = depth - 1;
            let e = |g: &mut Self| g.expr(d, names);
            match self.next(19) {
                0 => format!("({} + {})", e(self), e(self)),
                1 => format!("({} - {})", e(self), e(self)),
                2 => format!("({} * {})", e(self), e(self)),
                3 => format!("({} / {})", e(self), e(self)),
                4 => format!("({} ^ {})", e(self), e(self)),
                5 => format!("if({}, {}, {})", e(self), e(self), e(self)),
                6 => format!("select({}, {}, {}, {})", e(self), e(self), e(self), e(self)),
                7 => format!("select({}, 4, 5, 6)", e(self)),
                8 => format!("max({}, {}, {})", e(self), e(self), e(self)),
                9 => format!("min({}, {})", e(self), e(self)),
                10 => format!("floor({})", e(self)),
                11 => format!("{}({})", ["sqrt", "acos"][self.next(2)], e(self)),
                12 => format!("asin({})", e(self)),
                13 => format!("atan2({}, {})", e(self), e(self)),
                14 if self.1 & 1 != 0 => format!("f1({})", e(self)),
                15 if self.1 & 2 != 0 => format!("f2({}, {})", e(self), e(self)),
                14 | 15 => format!("(-{} - 1)", e(self)),
                16 => format!("g({}, {})", ["sin", "f1", "floor"][self.next(3)], e(self)),
                17 => format!("in({})", e(self)),
                _ => format!("-{}", e(self)),
            }
        }
    }

    fn outcome(c: &Compiled, st: &mut crate::State, rec: &[f64]) -> Vec<String> {
        st.set_chans(rec);
        let mut v = Vec::new();
        for n in c.channels() {
            v.push(match c.eval_chan(st, n) {
                // the sign of a NaN from two NaN operands depends on the operand order
                // the compiler picks (as between Radiance and either evaluator)
                Ok(x) if x.is_nan() => "nan".to_string(),
                Ok(x) => format!("{:x}", x.to_bits()),
                Err(e) => format!("error {:?}", e.kind),
            });
            v.push(format!("{:?}", st.take_warnings().messages()));
        }
        v
    }

    /// Compiles `src` for rcalc and checks that its fast code gives the exact evaluator's
    /// outcome on every pair (`$1`, `$2`) of `special` values; returns the fast program and
    /// how many evaluations its fast code completed.
    fn agree_on_pairs(src: &str, special: &[f64]) -> (Compiled, u64) {
        let mut p = Program::for_rcalc();
        p.load_str("-e", src).unwrap();
        let fast = p.compile().unwrap();
        let mut exact = fast.clone();
        exact.fast.clear();
        let (mut sf, mut se) = (fast.state(), exact.state());
        for &a in special {
            for &b in special {
                let r = [a, b, 0.25];
                assert_eq!(
                    outcome(&fast, &mut sf, &r),
                    outcome(&exact, &mut se, &r),
                    "{r:?}"
                );
            }
        }
        let hits = sf.fast_hits;
        (fast, hits)
    }

    /// The fused comparisons and picks on NaNs, infinities, signed zeros and
    /// subnormals: the values of the exact evaluator.
    #[test]
    fn fused_tests_agree_on_special_values() {
        let src = "$1 = if($1 - $2, 1, 2); $2 = if($1 + 3, 5, $2); $3 = if(-$1, $3, 7);\n\
                   $4 = if($1 - $2, $1 - 1, $2 + 1); $5 = if(3 + $2, $1, $2);\n\
                   $6 = if($1 - 5e-324, -0, 0) + if($1 + -5e-324, 1, 0)*10;";
        let special = [
            f64::NAN,
            -f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.0,
            -0.0,
            1.0,
            -3.0,
            5e-324,
            -5e-324,
            1e308,
            -1e308,
        ];
        let (_, hits) = agree_on_pairs(src, &special);
        assert_eq!(hits, (special.len() * special.len() * 6) as u64);
    }

    /// The fused op pairs on special values (NaNs, infinities, signed zeros, subnormals,
    /// values beyond 2^52): the exact evaluator's outcomes; every pair is formed.
    #[test]
    fn fused_pairs_agree_on_special_values() {
        let src = "$1 = floor($1 + $2); $2 = floor($1 - $2); $3 = floor($1 * $2);\n\
                   $4 = floor($1 / $2); $5 = 3*asin($1); $6 = $2*acos($1);\n\
                   $7 = -2*atan2($1, $2); $8 = if($1, 1, $2*$2) + 1;\n\
                   $9 = $1 + $2*3; $10 = $1*$2 + 3; $11 = 2 - $1*$2; $12 = ($1 + $2) + $2;\n\
                   $13 = ($1 + $2) + -0; $14 = 0 + floor($1); $15 = $1 + 0; $16 = $1*$2 + 0;";
        let special = [
            f64::NAN,
            -f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            0.0,
            -0.0,
            0.5,
            -1.0,
            2.5,
            -3.75,
            5e-324,
            -5e-324,
            4.5e15,
            -4.5e15,
            1e308,
            -1e308,
        ];
        let (fast, hits) = agree_on_pairs(src, &special);
        // every fused pair was made, and the fast code ran (a zero divisor gives up)
        let mut seen = [false; 12];
        for f in fast.fast.iter().filter_map(|f| f.get()).flatten() {
            for op in &f.ops {
                let k = match op {
                    Op::AddFloor { .. } => 0,
                    Op::SubFloor { .. } => 1,
                    Op::MulFloor { .. } => 2,
                    Op::DivFloor { .. } => 3,
                    Op::AsinMul { .. } => 4,
                    Op::AcosMul { .. } => 5,
                    Op::Atan2Mul { .. } => 6,
                    Op::CopyJump { .. } => 7,
                    Op::AddMul { .. } => 8,
                    Op::MulAdd { .. } => 9,
                    Op::SubMul { .. } => 10,
                    Op::AddAdd { .. } => 11,
                    _ => continue,
                };
                seen[k] = true;
            }
        }
        assert_eq!(seen, [true; 12]);
        assert!(hits > (special.len() * special.len() * 7) as u64);
    }

    /// A `select` whose cases fold to constants after inlining is a table lookup (no
    /// jump table), with the exact evaluator's outcomes (index 0, out of range, NaN).
    #[test]
    fn select_of_folded_constants_is_a_table() {
        let src = "k : 3; f(r) = if(r - 1, 2*r + k, -0);\n\
                   $1 = select($1, f(0), f(1), f(2), 360/f(3)); $2 = select($2 + 1, f(1), $1, 4);";
        let special = [
            f64::NAN,
            -1.0,
            0.0,
            0.4,
            1.0,
            2.0,
            3.0,
            3.6,
            4.0,
            5.0,
            1e300,
        ];
        let (fast, hits) = agree_on_pairs(src, &special);
        let ops: Vec<Op> = fast
            .fast
            .iter()
            .filter_map(|f| f.get())
            .flatten()
            .flat_map(|f| f.ops.clone())
            .collect();
        let tables = ops
            .iter()
            .filter(|o| matches!(o, Op::SelectK { .. }))
            .count();
        let jumps = ops
            .iter()
            .filter(|o| matches!(o, Op::Select { .. }))
            .count();
        // $1 is a table; $2 has a case that is not a constant (a jump table)
        assert_eq!((tables, jumps), (1, 1), "{ops:?}");
        assert!(hits > 0);
    }

    #[test]
    fn fast_code_agrees_with_the_exact_evaluator() {
        let mut g = Gen(12345, 3);
        let recs: [&[f64]; 8] = [
            &[0.5, 2.0, -3.0],
            &[0.0, 1e-3, 7.25],
            &[-1.5, 0.0, 100.0],
            &[3.0, -0.25, 0.125],
            &[1.0, 1.0],
            &[0.0, 0.0, 0.0],
            // infinities and subnormals
            &[1e300, -1e308, 5e-324],
            &[-0.0, 1.7e308, -1e-310],
        ];
        let (mut hits, mut evals) = (0, 0);
        for _ in 0..2000 {
            let mut src = String::new();
            src += &format!("k1 : {};\n", g.expr(2, &["1", "PI"]));
            src += &format!("v1 = {};\n", g.expr(3, &["k1", "$2"]));
            src += &format!("v2 = {};\n", g.expr(3, &["k1", "v1"]));
            // one program in 8 may recurse (no fast code); the others call downwards
            let rec = g.next(8) == 0;
            g.1 = if rec { 3 } else { 2 };
            src += &format!("f1(a) = {};\n", g.expr(3, &["a", "v1", "k1"]));
            g.1 = if rec { 3 } else { 0 };
            src += &format!("f2(a, b) = {};\n", g.expr(3, &["a", "b", "v2"]));
            g.1 = 3;
            src += "g(f, x) = f(x) + f(x + 1);\n";
            for n in 1..=3 {
                src += &format!("${n} = {};\n", g.expr(4, &["v1", "v2", "k1"]));
            }
            let mut p = Program::for_rcalc();
            if p.load_str("-e", &src).is_err() {
                continue;
            }
            let Ok(fast) = p.compile() else { continue };
            let mut exact = fast.clone();
            exact.fast.clear();
            let (mut sf, mut se) = (fast.state(), exact.state());
            for r in recs {
                evals += fast.channels().len() as u64;
                assert_eq!(
                    outcome(&fast, &mut sf, r),
                    outcome(&exact, &mut se, r),
                    "program:\n{src}record {r:?}"
                );
            }
            hits += sf.fast_hits;
        }
        // most evaluations must have gone through fast code for this to test it
        eprintln!("{hits} of {evals} evaluations by fast code");
        assert!(
            hits * 2 > evals,
            "{hits} of {evals} evaluations by fast code"
        );
    }
}
