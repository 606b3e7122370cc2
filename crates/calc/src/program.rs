//! Collecting definitions from files and strings, in order, with Radiance's
//! redefinition rule (a later definition of a name replaces the earlier one).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::sync::Arc;

use crate::ast::{Def, Expr, Lhs, Pos};
use crate::builtins::Extras;
use crate::error::{CalcError, ErrorKind, Location};
use crate::parse::{parse_defs, parse_expr};

/// A function provided by the host tool: receives its evaluated arguments.
pub type HostFn = Arc<dyn Fn(&[f64]) -> f64 + Send + Sync>;

/// A loaded source (for error messages).
#[derive(Debug, Clone)]
pub(crate) struct Source {
    pub name: String,
    pub lines: Vec<String>,
}

/// A definition of a name (variable or function).
#[derive(Debug, Clone)]
pub(crate) struct NameDef {
    /// Parameter names for a function; `None` for a variable.
    pub params: Option<Vec<String>>,
    pub constant: bool,
    pub body: Expr,
}

/// A host-provided function.
#[derive(Clone)]
pub(crate) struct HostFunc {
    pub name: String,
    pub min_args: usize,
    pub f: HostFn,
}

/// Identifies a variable of a compiled program (returned by [`Program::bind_vars`] and
/// [`crate::Compiled::var`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct VarId(pub(crate) u32);

/// Identifies a function of a compiled program ([`crate::Compiled::func`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FuncId(pub(crate) u32);

/// Identifies a standalone expression compiled with the program ([`Program::add_expr`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ExprId(pub(crate) u32);

/// A .cal program being assembled: load sources in order, bind host variables and
/// functions, then [`Program::compile`].
#[derive(Clone, Default)]
pub struct Program {
    pub(crate) sources: Vec<Source>,
    pub(crate) defs: HashMap<String, NameDef>,
    pub(crate) order: Vec<String>,
    pub(crate) chans: BTreeMap<u32, (Expr, Pos)>,
    pub(crate) bound: Vec<String>,
    pub(crate) hosts: Vec<HostFunc>,
    pub(crate) exprs: Vec<Expr>,
    pub(crate) extras: Extras,
    /// Radiance's parse-time constant handling is off (see [`Program::set_parse_constants`]).
    pub(crate) no_parse_constants: bool,
}

impl Program {
    /// An empty program with the core library only.
    pub fn new() -> Self {
        Program::default()
    }

    /// An empty program with rcalc's extras (`in`, `PI`, Bessel and error functions).
    pub fn for_rcalc() -> Self {
        let mut p = Program::new();
        p.extras.rcalc = true;
        p.load_str("(rcalc)", "PI : 3.14159265358979323846;")
            .expect("built-in definition");
        p
    }

    /// An empty program with the renderers' extras (`arg`, `erf`, `erfc`).
    pub fn for_renderer() -> Self {
        let mut p = Program::new();
        p.extras.render = true;
        p
    }

    /// Turns Radiance's parse-time constant handling on (the default) or off for the
    /// definitions loaded afterwards (rcalc's `-n` turns it off): literal
    /// sub-expressions folded, `x - c` read as `x + (-c)`, `x / c` as `x * (1/c)`,
    /// and a literal expression that divides by zero refused.
    pub fn set_parse_constants(&mut self, on: bool) {
        self.no_parse_constants = !on;
    }

    /// Enables or disables optional built-in groups.
    pub fn set_extras(&mut self, extras: Extras) {
        self.extras = extras;
    }

    fn add_source(&mut self, name: &str, text: &str) -> u32 {
        self.sources.push(Source {
            name: name.to_string(),
            lines: text.lines().map(str::to_string).collect(),
        });
        (self.sources.len() - 1) as u32
    }

    /// The location of a position, with the text of its line.
    pub(crate) fn location(sources: &[Source], pos: Pos) -> Location {
        let Some(s) = sources.get(pos.src as usize) else {
            return Location::default();
        };
        Location {
            source: s.name.clone(),
            line: pos.line as usize,
            column: pos.col as usize,
            text: s
                .lines
                .get((pos.line as usize).saturating_sub(1))
                .cloned()
                .unwrap_or_default(),
        }
    }

    /// A syntax error with `message` at `pos`.
    fn syntax_error(&self, message: String, pos: Pos) -> CalcError {
        CalcError::at(
            ErrorKind::Syntax,
            message,
            Self::location(&self.sources, pos),
        )
    }

    /// Loads definitions from text; `name` labels it in messages (a file name, or `-e`).
    pub fn load_str(&mut self, name: &str, text: &str) -> Result<(), CalcError> {
        let src = self.add_source(name, text);
        let defs = parse_defs(text, src).map_err(|e| self.syntax_error(e.message, e.pos))?;
        for mut d in defs {
            if !self.no_parse_constants {
                if let Err(r) = crate::lit::fold(&mut d.body, self.extras, &self.defs) {
                    let msg = match r {
                        crate::lit::Refused::BadConstant => "bad constant expression",
                        crate::lit::Refused::DivideByZero => "divide by zero constant",
                    };
                    return Err(self.syntax_error(msg.to_string(), d.pos));
                }
            }
            self.define(d);
        }
        Ok(())
    }

    /// Loads definitions from a file.
    pub fn load_file(&mut self, path: &Path) -> Result<(), CalcError> {
        let bytes = std::fs::read(path).map_err(|e| {
            CalcError::new(
                ErrorKind::Io,
                format!("cannot read file '{}': {e}", path.display()),
            )
        })?;
        // bytes as Radiance reads them: text that is not UTF-8 is taken one byte per
        // character (names and numbers are ASCII; comments may be Latin-1)
        let text = String::from_utf8(bytes)
            .unwrap_or_else(|e| e.into_bytes().iter().map(|&b| char::from(b)).collect());
        self.load_str(&path.display().to_string(), &text)
    }

    fn define(&mut self, d: Def) {
        match d.lhs {
            Lhs::Chan(n) => {
                self.chans.insert(n, (d.body, d.pos));
            }
            Lhs::Var(name) => self.insert(name, None, d.constant, d.body),
            Lhs::Func(name, params) => self.insert(name, Some(params), d.constant, d.body),
        }
    }

    fn insert(&mut self, name: String, params: Option<Vec<String>>, constant: bool, body: Expr) {
        if !self.defs.contains_key(&name) {
            self.order.push(name.clone());
        }
        self.defs.insert(
            name,
            NameDef {
                params,
                constant,
                body,
            },
        );
    }

    /// Sets a variable to a number as a `=` definition (like rcontrib's `-p a=1`).
    pub fn set_number(&mut self, name: &str, value: f64) {
        self.insert(name.to_string(), None, false, Expr::Num(value));
    }

    /// Whether a name has a definition (variable or function) from the loaded sources.
    pub fn is_defined(&self, name: &str) -> bool {
        self.defs.contains_key(name)
    }

    /// Whether a name is defined as a function.
    pub fn is_function(&self, name: &str) -> bool {
        self.defs.get(name).is_some_and(|d| d.params.is_some())
    }

    /// Output channels defined (`$N = …`), in increasing order.
    pub fn channels(&self) -> Vec<u32> {
        self.chans.keys().copied().collect()
    }

    /// Declares variables the host sets before each evaluation (e.g. `Dx Dy Dz`). They
    /// take precedence over definitions of the same name. Returns their ids in order.
    pub fn bind_vars(&mut self, names: &[&str]) -> Vec<VarId> {
        names
            .iter()
            .map(|n| {
                let i = match self.bound.iter().position(|b| b == n) {
                    Some(i) => i,
                    None => {
                        self.bound.push(n.to_string());
                        self.bound.len() - 1
                    }
                };
                VarId(i as u32)
            })
            .collect()
    }

    /// Declares a function implemented by the host, taking at least `min_args` arguments.
    /// Definitions of the same name in the sources take precedence, as for built-ins.
    pub fn define_host_fn(&mut self, name: &str, min_args: usize, f: HostFn) {
        self.hosts.retain(|h| h.name != name);
        self.hosts.push(HostFunc {
            name: name.to_string(),
            min_args,
            f,
        });
    }

    /// Parses a standalone expression (e.g. rcontrib's `-b` bin expression) to be
    /// compiled with the program; evaluate it with [`crate::Compiled::eval_expr`].
    pub fn add_expr(&mut self, label: &str, text: &str) -> Result<ExprId, CalcError> {
        let src = self.add_source(label, text);
        let e = parse_expr(text, src).map_err(|e| self.syntax_error(e.message, e.pos))?;
        self.exprs.push(e);
        Ok(ExprId((self.exprs.len() - 1) as u32))
    }
}
