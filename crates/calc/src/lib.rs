//! fenestra-calc: Radiance's `.cal` expression language — parser, compiler to a
//! slot-resolved tree, evaluator with Radiance's semantics, and the built-in library.
//!
//! ```
//! use fenestra_calc::Program;
//! let mut p = Program::new();
//! p.load_str("-e", "r = sqrt(Dx*Dx + Dy*Dy); f(a, b) = a*b + r;").unwrap();
//! let d = p.bind_vars(&["Dx", "Dy"]);
//! let c = p.compile().unwrap();
//! let (r, f) = (c.var("r").unwrap(), c.func("f").unwrap());
//! let mut st = c.state();
//! st.set_all(&d, &[3.0, 4.0]);
//! assert_eq!(c.eval_var(&mut st, r).unwrap(), 5.0);
//! assert_eq!(c.call(&mut st, f, &[2.0, 3.0]).unwrap(), 11.0);
//! ```

pub mod ast;
pub mod builtins;
mod compile;
pub mod error;
mod eval;
mod fast;
mod fold;
pub mod format;
mod lit;
mod node;
pub mod parse;
mod program;

pub use builtins::Extras;
pub use error::{CalcError, ErrorKind, Location};
pub use eval::{Compiled, ErrFlag, State, Warnings, MAX_DEPTH};
pub use program::{ExprId, FuncId, HostFn, Program, VarId};
