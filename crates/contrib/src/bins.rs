//! The `.cal` context of the contribution tracer: definitions from `-e`, `-f` and `-p` in
//! command-line order (rayinit.cal first), bin-count expressions evaluated at parse time,
//! and the compiled bin expressions evaluated for every tracked ray.

use std::path::PathBuf;

use fenestra_cli::raypath::Resolver;

use anyhow::{anyhow, bail, Context, Result};
use fenestra_calc::{Compiled, ExprId, Program, State, VarId};

/// Host variables set from the ray that reached a tracked surface, in this order.
pub const RAY_VARS: [&str; 31] = [
    "Dx", "Dy", "Dz", "Nx", "Ny", "Nz", "Px", "Py", "Pz", "T", "Ts", "Rdot", "S", "Tx", "Ty", "Tz",
    "Ix", "Iy", "Iz", "Jx", "Jy", "Jz", "Kx", "Ky", "Kz", "Lu", "Lv", "NxP", "NyP", "NzP", "RdotP",
];

use crate::native::{self, NativeBin};

/// One definition source, in command-line order.
#[derive(Debug, Clone)]
enum Def {
    Expr(String),
    File(PathBuf),
    Param(String, f64),
}

/// Definitions collected while the command line is parsed.
#[derive(Debug, Clone, Default)]
pub struct CalcDefs {
    rayinit: Option<PathBuf>,
    defs: Vec<Def>,
    /// Where `rayinit.cal` and `-f` files are found.
    resolver: Resolver,
}

/// Parses `-p` assignments (`a=1,b=2`; separators `,` `;` `:` or blanks).
pub fn parse_params(text: &str) -> Result<Vec<(String, f64)>> {
    let mut out = Vec::new();
    for item in text
        .split(|c: char| c == ',' || c == ';' || c == ':' || c.is_whitespace())
        .filter(|s| !s.is_empty())
    {
        let (name, val) = item
            .split_once('=')
            .with_context(|| format!("-p '{text}': expected name=value, found '{item}'"))?;
        let name = name.trim();
        if name.is_empty()
            || !name
                .chars()
                .next()
                .is_some_and(|c| c.is_alphabetic() || c == '_')
        {
            bail!("-p '{text}': bad variable name '{name}'");
        }
        let v = fenestra_cli::opts::parse_real(val.trim())
            .with_context(|| format!("-p '{text}': '{val}' is not a number"))?;
        out.push((name.to_string(), v));
    }
    Ok(out)
}

impl CalcDefs {
    /// Starts with `rayinit.cal` preloaded when it is found on RAYPATH or in fenestra's lib
    /// (the environment's [`Resolver`]).
    pub fn new() -> Self {
        Self::with_resolver(Resolver::from_env())
    }

    /// Starts with `rayinit.cal` preloaded when `resolver` finds it; `-f` files are found
    /// through it too.
    pub fn with_resolver(resolver: Resolver) -> Self {
        CalcDefs {
            rayinit: resolver.find("rayinit.cal"),
            defs: Vec::new(),
            resolver,
        }
    }

    /// Adds `-e` definitions (checked for syntax now).
    pub fn push_expr(&mut self, text: &str) -> Result<()> {
        let mut p = Program::for_renderer();
        p.load_str("-e", text).map_err(|e| anyhow!("{e}"))?;
        self.defs.push(Def::Expr(text.to_string()));
        Ok(())
    }

    /// Adds a `-f` file, found through the resolver (checked for syntax now).
    pub fn push_file(&mut self, name: &str) -> Result<()> {
        let path = self.resolver.find_or_err(name)?;
        let mut p = Program::for_renderer();
        p.load_file(&path).map_err(|e| anyhow!("{e}"))?;
        self.defs.push(Def::File(path));
        Ok(())
    }

    /// Applies `-p` assignments now (they are applied again before each bin evaluation).
    pub fn push_params(&mut self, params: &[(String, f64)]) {
        for (n, v) in params {
            self.defs.push(Def::Param(n.clone(), *v));
        }
    }

    /// The program with every definition so far.
    pub fn program(&self) -> Result<Program> {
        let mut p = Program::for_renderer();
        if let Some(r) = &self.rayinit {
            p.load_file(r).map_err(|e| anyhow!("{e}"))?;
        }
        for d in &self.defs {
            match d {
                Def::Expr(t) => p.load_str("-e", t).map_err(|e| anyhow!("{e}"))?,
                Def::File(f) => p.load_file(f).map_err(|e| anyhow!("{e}"))?,
                Def::Param(n, v) => p.set_number(n, *v),
            }
        }
        Ok(p)
    }

    /// Whether `expr` may be evaluated natively: it is a Klems `kbin…` or `rbin` expression,
    /// the matching file loaded is fenestra's own (byte-identical), and no other definition
    /// (or `-p` name) defines any name the file uses.
    fn native_allowed(&self, expr: &str, params: &[(String, f64)]) -> bool {
        if std::env::var_os("FENESTRA_NO_NATIVE_BINS").is_some() {
            return false;
        }
        let (text, names): (&str, &[&str]) = if native::klems_frame(expr).is_some() {
            (native::KLEMS_FULL_CAL, &native::KLEMS_NAMES)
        } else if expr.trim() == "rbin" {
            (native::REINHART_CAL, &native::REINHART_NAMES)
        } else {
            return false;
        };
        let is_ours = |p: &PathBuf| std::fs::read_to_string(p).is_ok_and(|t| t == text);
        let Some(k) = self
            .defs
            .iter()
            .rposition(|d| matches!(d, Def::File(f) if is_ours(f)))
        else {
            return false;
        };
        let bad = |name: &str| names.contains(&name) || native::BUILTINS_USED.contains(&name);
        if params.iter().any(|(n, _)| bad(n)) {
            return false;
        }
        let others = self
            .defs
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != k)
            .map(|(_, d)| d.clone())
            .chain(self.rayinit.iter().map(|r| Def::File(r.clone())));
        for d in others {
            let mut p = Program::new();
            let ok = match &d {
                Def::Expr(t) => p.load_str("-e", t).is_ok(),
                Def::File(f) => p.load_file(f).is_ok(),
                Def::Param(n, _) => {
                    if bad(n) {
                        return false;
                    }
                    continue;
                }
            };
            if !ok
                || names
                    .iter()
                    .chain(native::BUILTINS_USED.iter())
                    .any(|n| p.is_defined(n))
            {
                return false;
            }
        }
        true
    }

    /// Evaluates an expression with the definitions seen so far (rcontrib's `-bn`).
    pub fn eval_now(&self, expr: &str) -> Result<f64> {
        let mut p = self.program()?;
        let vars = p.bind_vars(&RAY_VARS);
        let id = p.add_expr("-bn", expr).map_err(|e| anyhow!("{e}"))?;
        let exe = p.compile().map_err(|e| anyhow!("{e}"))?;
        let mut st = exe.state();
        st.set_all(&vars, &ray_values_default());
        exe.eval_expr(&mut st, id)
            .map_err(|e| anyhow!("bin count '{expr}': {e}"))
    }
}

fn ray_values_default() -> [f64; 31] {
    let mut v = [0.0; 31];
    v[12] = 1.0; // S
    v[16] = 1.0; // Ix
    v[20] = 1.0; // Jy
    v[24] = 1.0; // Kz
    v
}

/// Values of [`RAY_VARS`] for a ray.
pub fn ray_values(c: &fenestra_trace::Contribution) -> [f64; 31] {
    let mut v = ray_values_default();
    v[0..3].copy_from_slice(&c.dir.to_array());
    v[3..6].copy_from_slice(&c.normal.to_array());
    v[6..9].copy_from_slice(&c.hit.to_array());
    v[9] = c.total_dist;
    v[10] = c.dist;
    v[11] = (-c.dir.dot(c.normal)).clamp(-1.0, 1.0);
    // no perturbed normals (textures) in bin evaluation: NxP.. = Nx.., RdotP = Rdot
    v[27..30].copy_from_slice(&c.normal.to_array());
    v[30] = v[11];
    v
}

/// Compiled bin expressions: one program per distinct `-p` parameter set.
pub struct Bins {
    groups: Vec<(Compiled, Vec<VarId>)>,
    /// Per modifier: the native evaluation of its bin expression, when allowed.
    natives: Vec<Option<NativeBin>>,
    /// Per modifier: `None` for the constant bin 0, else (group, expression).
    exprs: Vec<Option<(usize, ExprId)>>,
}

/// What a modifier needs from the calc context.
pub struct BinRequest<'a> {
    /// The `-b` expression text.
    pub expr: &'a str,
    /// The `-p` assignments in effect for the modifier.
    pub params: &'a [(String, f64)],
}

/// Whether a bin expression is a number that Radiance takes as bin 0 (its value v with
/// (int)(v + 1.5) = 1, i.e. −0.5 ≤ v < 0.5): one bin, nothing to evaluate.
pub fn is_constant_bin(expr: &str) -> bool {
    fenestra_cli::opts::parse_real(expr.trim()).is_some_and(|v| (v + 1.5).trunc() == 1.0)
}

impl Bins {
    /// Compiles the bin expressions of all modifiers with the complete definitions.
    pub fn compile(defs: &CalcDefs, reqs: &[BinRequest]) -> Result<Bins> {
        let mut keys: Vec<String> = Vec::new();
        let mut progs: Vec<(Program, Vec<VarId>)> = Vec::new();
        let mut placed: Vec<Option<(usize, ExprId)>> = Vec::new();
        for r in reqs {
            if is_constant_bin(r.expr) {
                placed.push(None);
                continue;
            }
            let key = format!("{:?}", r.params);
            let g = match keys.iter().position(|k| *k == key) {
                Some(g) => g,
                None => {
                    let mut p = defs.program()?;
                    for (n, v) in r.params {
                        p.set_number(n, *v);
                    }
                    let vars = p.bind_vars(&RAY_VARS);
                    keys.push(key);
                    progs.push((p, vars));
                    progs.len() - 1
                }
            };
            let id = progs[g]
                .0
                .add_expr("-b", r.expr)
                .map_err(|e| anyhow!("bin expression '{}': {e}", r.expr))?;
            placed.push(Some((g, id)));
        }
        let mut groups = Vec::new();
        for (p, vars) in progs {
            groups.push((p.compile().map_err(|e| anyhow!("{e}"))?, vars));
        }
        let mut natives = Vec::new();
        for (r, pl) in reqs.iter().zip(&placed) {
            let nb = match pl {
                Some((g, _)) if defs.native_allowed(r.expr, r.params) => {
                    let (exe, vars) = &groups[*g];
                    // a constant of the program: the same for any ray values
                    let konst = |name: &str| -> Option<f64> {
                        let v = exe.var(name)?;
                        let mut out = None;
                        for fill in [f64::NAN, 0.3, -0.7] {
                            let mut st = exe.state();
                            st.set_all(vars, &[fill; 31]);
                            let x = exe.eval_var(&mut st, v).ok()?;
                            if !x.is_finite() || out.is_some_and(|o| o != x) {
                                return None;
                            }
                            out = Some(x);
                        }
                        out
                    };
                    if let Some((n, u)) = native::klems_frame(r.expr) {
                        konst("RHS").map(|rhs| NativeBin::Klems { n, u, rhs })
                    } else {
                        konst("MF")
                            .filter(|m| *m >= 1.0 && m.fract() == 0.0)
                            .map(|mf| NativeBin::Reinhart { mf })
                    }
                }
                _ => None,
            };
            natives.push(nb);
        }
        Ok(Bins {
            groups,
            natives,
            exprs: placed,
        })
    }

    /// Fresh evaluation states, one per group (one set per thread).
    pub fn states(&self) -> Vec<State> {
        self.groups.iter().map(|(c, _)| c.state()).collect()
    }

    /// The bin value of modifier `m` for a contribution (not yet rounded).
    pub fn eval_for(
        &self,
        m: usize,
        c: &fenestra_trace::Contribution,
        states: &mut [State],
    ) -> Result<f64> {
        if let Some(nb) = &self.natives[m] {
            return Ok(nb.eval(c.dir));
        }
        self.eval(m, &ray_values(c), states)
    }

    /// The bin value of modifier `m` for a ray (not yet rounded).
    pub fn eval(&self, m: usize, vals: &[f64; 31], states: &mut [State]) -> Result<f64> {
        let Some((g, id)) = self.exprs[m] else {
            return Ok(0.0);
        };
        let (exe, vars) = &self.groups[g];
        let st = &mut states[g];
        st.set_all(vars, vals);
        exe.eval_expr(st, id).map_err(|e| anyhow!("{e}"))
    }

    /// Whether modifier `m` has a non-constant bin expression.
    pub fn varies(&self, m: usize) -> bool {
        self.exprs[m].is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn definitions_are_found_through_the_given_resolver() {
        let dir = std::env::temp_dir().join(format!("fenestra-calcdefs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("mine.cal"), "twice(x) = 2*x;\n").unwrap();
        let mut defs = CalcDefs::with_resolver(Resolver::new(vec![dir.clone()]));
        // no rayinit.cal in that folder: none preloaded
        assert!(defs.rayinit.is_none());
        defs.push_file("mine.cal").unwrap();
        let e = defs.push_file("absent.cal").unwrap_err().to_string();
        assert!(
            e.contains("absent.cal") && e.contains(&dir.display().to_string()),
            "{e}"
        );
        let mut p = defs.program().unwrap();
        let id = p.add_expr("t", "twice(21)").unwrap();
        let exe = p.compile().unwrap();
        assert_eq!(exe.eval_expr(&mut exe.state(), id).unwrap(), 42.0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
