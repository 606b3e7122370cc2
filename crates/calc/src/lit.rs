//! What Radiance's parser does with constants while it reads a definition (unless
//! disabled, as rcalc's `-n` does for the definitions that follow it): sub-expressions
//! made only of literals (and built-in calls on them) are replaced by their values,
//! `x - c` becomes `x + (-c)` and `x / c` becomes `x * (1/c)`; a literal zero times, over or
//! to the power of anything is that zero (`0*x`, `x*0`, `0/x`, `0^x`; checked against the
//! oracle's rcalc, signed zeros included). An error while folding
//! (division by zero, `select` out of range) is fatal: "bad constant expression";
//! dividing by a literal zero is fatal too: "divide by zero constant".

use std::collections::HashMap;

use crate::ast::{BinOp, Expr};
use crate::builtins::{self, Builtin, Extras};
use crate::program::NameDef;

/// Why a definition was refused.
pub(crate) enum Refused {
    /// A literal sub-expression raised an error.
    BadConstant,
    /// Division by a literal zero.
    DivideByZero,
}

enum Lit {
    Not,
    Value(f64),
}

/// Folds an expression in place; `Err` when Radiance's parser refuses it.
/// `defs` are the definitions read so far: a `:` constant whose value is known counts
/// as a literal.
pub(crate) fn fold(
    e: &mut Expr,
    extras: Extras,
    defs: &HashMap<String, NameDef>,
) -> Result<(), Refused> {
    let cx = Cx { extras, defs };
    match cx.fold_inner(e)? {
        Lit::Value(v) => *e = Expr::Num(v),
        Lit::Not => {}
    }
    Ok(())
}

struct Cx<'a> {
    extras: Extras,
    defs: &'a HashMap<String, NameDef>,
}

impl Cx<'_> {
    fn fold_inner(&self, e: &mut Expr) -> Result<Lit, Refused> {
        let extras = self.extras;
        match e {
            Expr::Num(v) => Ok(Lit::Value(*v)),
            Expr::Name(n, _) => Ok(match self.defs.get(n.as_str()) {
                Some(d) if d.constant && d.params.is_none() => match d.body {
                    Expr::Num(v) => Lit::Value(v),
                    _ => Lit::Not,
                },
                _ => Lit::Not,
            }),
            Expr::Chan(..) => Ok(Lit::Not),
            Expr::Neg(a) => Ok(match self.fold_inner(a)? {
                Lit::Value(v) => Lit::Value(-v),
                Lit::Not => Lit::Not,
            }),
            Expr::Bin(op, a, b) => {
                let la = self.fold_inner(a)?;
                let lb = self.fold_inner(b)?;
                match (la, lb) {
                    (Lit::Value(x), Lit::Value(y)) => Ok(Lit::Value(match op {
                        BinOp::Add => x + y + 0.0,
                        BinOp::Sub => x - y,
                        BinOp::Mul => x * y,
                        BinOp::Div if y == 0.0 => return Err(Refused::BadConstant),
                        BinOp::Div => x / y,
                        BinOp::Pow => x.powf(y),
                    })),
                    // A literal zero times, over or to the power of anything is that zero
                    // (the other side is never evaluated), as Radiance's parser folds it.
                    (Lit::Value(x), Lit::Not)
                        if x == 0.0 && matches!(op, BinOp::Mul | BinOp::Div | BinOp::Pow) =>
                    {
                        Ok(Lit::Value(x))
                    }
                    (Lit::Value(x), Lit::Not) => {
                        **a = Expr::Num(x);
                        Ok(Lit::Not)
                    }
                    (Lit::Not, Lit::Value(y)) if y == 0.0 && *op == BinOp::Mul => Ok(Lit::Value(y)),
                    (Lit::Not, Lit::Value(y)) => {
                        match op {
                            BinOp::Sub => {
                                *op = BinOp::Add;
                                **b = Expr::Num(-y);
                            }
                            BinOp::Div if y == 0.0 || y.is_nan() => {
                                return Err(Refused::DivideByZero)
                            }
                            BinOp::Div => {
                                *op = BinOp::Mul;
                                **b = Expr::Num(1.0 / y);
                            }
                            // `x^0` is 1 without evaluating x; `x^1` is x (no power
                            // computed, so no error-flag check): `x*1` is exactly x
                            BinOp::Pow if y == 0.0 => return Ok(Lit::Value(1.0)),
                            BinOp::Pow if y == 1.0 => {
                                *op = BinOp::Mul;
                                **b = Expr::Num(1.0);
                            }
                            _ => **b = Expr::Num(y),
                        }
                        Ok(Lit::Not)
                    }
                    (Lit::Not, Lit::Not) => Ok(Lit::Not),
                }
            }
            Expr::Call(name, args, _) => {
                let mut vals = Vec::with_capacity(args.len());
                let mut all = true;
                for a in args.iter_mut() {
                    match self.fold_inner(a)? {
                        Lit::Value(v) => {
                            *a = Expr::Num(v);
                            vals.push(v);
                        }
                        Lit::Not => all = false,
                    }
                }
                if !all {
                    return Ok(Lit::Not);
                }
                let Some((b, min)) = builtins::lookup(name, extras) else {
                    return Ok(Lit::Not);
                };
                if vals.len() < min {
                    return Ok(Lit::Not); // reported when compiled
                }
                Ok(match b {
                    Builtin::Math1(m) => Lit::Value(m.apply(vals[0])),
                    Builtin::Atan2 => Lit::Value(vals[0].atan2(vals[1])),
                    Builtin::If => Lit::Value(if vals[0] > 0.0 { vals[1] } else { vals[2] }),
                    Builtin::Max => {
                        Lit::Value(
                            vals[1..]
                                .iter()
                                .fold(vals[0], |m, &v| if v > m { v } else { m }),
                        )
                    }
                    Builtin::Min => {
                        Lit::Value(
                            vals[1..]
                                .iter()
                                .fold(vals[0], |m, &v| if v < m { v } else { m }),
                        )
                    }
                    Builtin::Rand => Lit::Value(builtins::rand_hash(vals[0])),
                    Builtin::Select => {
                        let i = builtins::select_index(vals[0]).ok_or(Refused::BadConstant)?;
                        if i == 0 {
                            Lit::Value((vals.len() - 1) as f64)
                        } else if i < vals.len() {
                            Lit::Value(vals[i])
                        } else {
                            return Err(Refused::BadConstant);
                        }
                    }
                    _ => Lit::Not,
                })
            }
        }
    }
}
