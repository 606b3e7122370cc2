//! Patterns: `brightfunc` and `colorfunc` evaluated with fenestra's .cal engine
//! (`lib/rayinit.cal` preloaded, as Radiance's renderers do), with the ray variables
//! `Dx Dy Dz Nx Ny Nz Px Py Pz T Ts Rdot …` bound per evaluation and `arg(n)` the
//! primitive's real arguments. gensky's `skybr skybright.cal` and gendaylit's
//! `skybright perezlum.cal` — the sky functions every daylight run evaluates for each
//! sky ray — take a native fast path (fenestra-sky's models of the same files; the
//! two agree to 1e-12, see tests/sky_cal_files.rs).

use std::sync::Arc;

use anyhow::{anyhow, bail, Result};
use fenestra_calc::{Compiled, ExprId, FuncId, Program, VarId};

use crate::datafile::DataGrid;
use crate::options::CalSource;
use fenestra_io::raypath::Resolver;
use fenestra_scene::Scene;
use fenestra_sky::cie::SkyBright;
use fenestra_sky::skyvec::PerezLum;
use glam::DVec3;

/// Where a pattern is evaluated: the ray and the surface point it reached.
#[derive(Debug, Clone, Copy)]
pub struct PatternInput {
    /// Unit ray direction (`Dx Dy Dz`).
    pub dir: DVec3,
    /// Hit point (`Px Py Pz`); the ray origin for a distant source.
    pub point: DVec3,
    /// Unit surface normal (`Nx Ny Nz`); `-dir` for a distant source.
    pub normal: DVec3,
    /// Distance along the ray (`T`, `Ts`).
    pub dist: f64,
}

/// The names the host sets before each evaluation, in this order.
const HOST_VARS: [&str; 29] = [
    "Dx", "Dy", "Dz", "Nx", "Ny", "Nz", "Px", "Py", "Pz", "T", "Ts", "Rdot", "NxP", "NyP", "NzP",
    "RdotP", "S", "Ix", "Iy", "Iz", "Jx", "Jy", "Jz", "Kx", "Ky", "Kz", "Tx", "Ty", "Tz",
];

/// The coordinate frame of a pattern given transform arguments (`-rz 30 -t 1 2 3 …`
/// after its strings), as Radiance's renderers set it: points go through the inverse
/// transform `b`; directions and normals through its linear part divided by the scale
/// `s = |1/sca|` (so they stay unit); distances are multiplied by `s`; `S` is `s`,
/// `Tx Ty Tz` the inverse's translation and `I J K` its rows over `s` (checked against
/// the reference rtrace in tests/patterns.rs).
#[derive(Debug, Clone, Copy)]
pub struct PatternFrame {
    b: fenestra_scene::transform::Transform,
    s: f64,
}

impl PatternFrame {
    /// The frame of transform words `args` (`None` for none); an error names a bad word or
    /// a singular transform.
    pub fn parse(args: &[String]) -> Result<Option<PatternFrame>> {
        if args.is_empty() {
            return Ok(None);
        }
        let f = fenestra_scene::transform::Transform::parse_all(args)?;
        let b = f
            .inverse()
            .ok_or_else(|| anyhow!("the transform '{}' is singular", args.join(" ")))?;
        Ok(Some(PatternFrame { b, s: b.sca.abs() }))
    }

    fn vector(&self, v: DVec3) -> DVec3 {
        DVec3::from_array(self.b.vector(v.to_array())) / self.s
    }
}

/// A trial ray evaluated when a pattern is compiled, so undefined names and wrong
/// argument counts are reported at load time instead of as silent zeros later.
const TRIAL: PatternInput = PatternInput {
    dir: DVec3::new(0.3, 0.4, 0.866_025_403_784_438_6),
    point: DVec3::ZERO,
    normal: DVec3::new(0.0, 0.0, -1.0),
    dist: 1.0,
};

/// A program with what every pattern sees first: `rayinit.cal`, then the command
/// line's `-e`/`-f` sources, then the pattern's own file (`.` for none).
fn program(user: &[CalSource], cal: &str, resolver: &Resolver) -> Result<Program> {
    let mut p = Program::for_renderer();
    let init = resolver.find_or_err("rayinit.cal")?;
    p.load_file(&init).map_err(|e| anyhow!("{e}"))?;
    for c in user {
        c.load(&mut p, resolver)?;
    }
    if cal != "." {
        let path = resolver.find_or_err(cal)?;
        p.load_file(&path).map_err(|e| anyhow!("{e}"))?;
    }
    Ok(p)
}

/// Identifies a compiled pattern for the per-thread evaluation states.
static NEXT_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

thread_local! {
    /// Each thread's evaluation state per pattern (by id): a pattern evaluation takes no
    /// lock and allocates nothing once its thread has made the state.
    static STATES: std::cell::RefCell<Vec<(u64, fenestra_calc::State)>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// Runs `f` with this thread's evaluation state for pattern `id` of program `exe`.
fn with_state<R>(id: u64, exe: &Compiled, f: impl FnOnce(&mut fenestra_calc::State) -> R) -> R {
    STATES.with(|s| {
        let mut s = s.borrow_mut();
        let k = match s.iter().position(|e| e.0 == id) {
            Some(k) => k,
            None => {
                // States of patterns from earlier scenes are dropped now and then.
                if s.len() >= 64 {
                    s.clear();
                }
                s.push((id, exe.state()));
                s.len() - 1
            }
        };
        f(&mut s[k].1)
    })
}

/// What a pattern evaluated by the .cal engine evaluates with: its program, the id of its
/// per-thread states, its frame, the host variables and `arg(n)`.
struct CalCore {
    exe: Compiled,
    id: u64,
    frame: Option<PatternFrame>,
    vars: Vec<VarId>,
    fargs: Vec<f64>,
}

impl CalCore {
    /// The core of program `exe` (host variables `vars`), with a new state id.
    fn new(exe: Compiled, frame: Option<PatternFrame>, vars: Vec<VarId>, fargs: &[f64]) -> CalCore {
        CalCore {
            exe,
            id: NEXT_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
            frame,
            vars,
            fargs: fargs.to_vec(),
        }
    }

    /// Runs `f` with this thread's evaluation state, its variables set for ray `q`.
    #[inline]
    fn with_ray<R>(
        &self,
        q: &PatternInput,
        f: impl FnOnce(&mut fenestra_calc::State) -> Result<R>,
    ) -> Result<R> {
        with_state(self.id, &self.exe, |st| {
            st.set_all(&self.vars, &CalPattern::values(q, self.frame.as_ref()));
            st.set_fargs(&self.fargs);
            f(st)
        })
    }

    /// Evaluates `exprs` in state `st` into the start of `out`.
    #[inline]
    fn eval_exprs(
        &self,
        st: &mut fenestra_calc::State,
        exprs: &[ExprId],
        out: &mut [f64],
    ) -> Result<()> {
        for (k, e) in exprs.iter().enumerate() {
            out[k] = self.exe.eval_expr(st, *e).map_err(|e| anyhow!("{e}"))?;
        }
        Ok(())
    }

    /// The debug form of pattern `name` over this core, with its number of `what`.
    fn debug(
        &self,
        f: &mut std::fmt::Formatter<'_>,
        name: &str,
        what: &str,
        count: usize,
    ) -> std::fmt::Result {
        f.debug_struct(name)
            .field(what, &count)
            .field("fargs", &self.fargs)
            .finish()
    }
}

/// A pattern compiled from a .cal file.
pub struct CalPattern {
    core: CalCore,
    exprs: Vec<ExprId>,
}

impl std::fmt::Debug for CalPattern {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.core.debug(f, "CalPattern", "exprs", self.exprs.len())
    }
}

impl CalPattern {
    /// Compiles expressions `exprs` (1 for brightfunc, 3 for colorfunc) over .cal file
    /// `cal` (`.` for none, found through RAYPATH), with `rayinit.cal` loaded first and
    /// `fargs` as `arg(n)`. A trial evaluation reports undefined names now.
    pub fn new(
        exprs: &[String],
        cal: &str,
        fargs: &[f64],
        frame: Option<PatternFrame>,
        label: &str,
        user: &[CalSource],
        resolver: &Resolver,
    ) -> Result<CalPattern> {
        let mut p = program(user, cal, resolver)?;
        let vars = p.bind_vars(&HOST_VARS);
        let mut ids = Vec::new();
        for e in exprs {
            ids.push(p.add_expr(label, e).map_err(|e| anyhow!("{e}"))?);
        }
        let exe = p.compile().map_err(|e| anyhow!("{e}"))?;
        let cp = CalPattern {
            core: CalCore::new(exe, frame, vars, fargs),
            exprs: ids,
        };
        cp.eval(&TRIAL)?;
        Ok(cp)
    }

    /// The value (RGB; a brightfunc gives three equal channels) for a ray.
    pub fn value(&self, q: &PatternInput) -> Result<DVec3> {
        self.eval(q)
    }

    fn values(q: &PatternInput, frame: Option<&PatternFrame>) -> [f64; 29] {
        let rdot = -q.dir.dot(q.normal);
        let Some(f) = frame else {
            let (d, p, n) = (q.dir, q.point, q.normal);
            return [
                d.x, d.y, d.z, n.x, n.y, n.z, p.x, p.y, p.z, q.dist, q.dist, rdot, n.x, n.y, n.z,
                rdot, 1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0,
            ];
        };
        let (d, n) = (f.vector(q.dir), f.vector(q.normal));
        let p = f.b.point(q.point.to_array());
        let m = &f.b.m;
        let t = q.dist * f.s;
        let ax = |r: usize, c: usize| m[r][c] / f.s;
        [
            d.x,
            d.y,
            d.z,
            n.x,
            n.y,
            n.z,
            p[0],
            p[1],
            p[2],
            t,
            t,
            rdot,
            n.x,
            n.y,
            n.z,
            rdot,
            f.s,
            ax(0, 0),
            ax(0, 1),
            ax(0, 2),
            ax(1, 0),
            ax(1, 1),
            ax(1, 2),
            ax(2, 0),
            ax(2, 1),
            ax(2, 2),
            m[3][0],
            m[3][1],
            m[3][2],
        ]
    }

    fn eval(&self, q: &PatternInput) -> Result<DVec3> {
        self.core.with_ray(q, |st| {
            let mut out = [0.0; 3];
            self.core.eval_exprs(st, &self.exprs, &mut out)?;
            if self.exprs.len() == 1 {
                out = [out[0]; 3];
            }
            Ok(DVec3::from_array(out))
        })
    }
}

/// A compiled pattern.
#[derive(Debug, Clone)]
pub enum Pattern {
    /// gensky's CIE sky (`skybright.cal`), evaluated natively.
    Cie(SkyBright),
    /// gendaylit's Perez sky (`perezlum.cal`), evaluated natively.
    Perez(PerezLum),
    /// Any other `brightfunc`/`colorfunc`, through the .cal engine.
    Cal(Arc<CalPattern>),
    /// `brightdata`/`colordata`: interpolated data files.
    Data(Arc<DataPattern>),
    /// An mkillum distribution over fenestra's `illum.cal`, evaluated natively.
    Illum(Arc<crate::illum_pattern::IllumPattern>),
}

/// A `brightdata` (one grid) or `colordata` (three grids) pattern: coordinate
/// expressions locate the ray in the grids, then the function(s) map the interpolated
/// values (brightdata: `func(v)`; colordata: `rfunc(r,g,b)`, `gfunc(…)`, `bfunc(…)`).
pub struct DataPattern {
    core: CalCore,
    coords: Vec<ExprId>,
    funcs: Vec<FuncId>,
    grids: Vec<DataGrid>,
}

impl std::fmt::Debug for DataPattern {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.core.debug(f, "DataPattern", "grids", self.grids.len())
    }
}

impl DataPattern {
    fn eval(&self, q: &PatternInput) -> Result<DVec3> {
        self.core.with_ray(q, |st| {
            let mut x = [0.0f64; 16];
            self.core.eval_exprs(st, &self.coords, &mut x)?;
            let x = &x[..self.coords.len()];
            let mut v = [0.0f64; 3];
            for (k, g) in self.grids.iter().enumerate() {
                v[k] = g.value(x);
            }
            let v = &v[..self.grids.len()];
            let mut out = [0.0; 3];
            for (k, f) in self.funcs.iter().enumerate() {
                out[k] = self.core.exe.call(st, *f, v).map_err(|e| anyhow!("{e}"))?;
            }
            if self.funcs.len() == 1 {
                out = [out[0]; 3];
            }
            Ok(DVec3::from_array(out))
        })
    }
}

impl Pattern {
    /// Value for a ray (grey patterns give equal channels). A .cal evaluation error
    /// (caught at scene load on a trial ray, so rare here) gives zero.
    pub fn eval(&self, q: &PatternInput) -> DVec3 {
        match self {
            Pattern::Cie(s) => DVec3::splat(s.radiance(q.dir.to_array())),
            Pattern::Perez(p) => DVec3::splat(p.radiance(q.dir.to_array())),
            Pattern::Cal(c) => c.eval(q).unwrap_or(DVec3::ZERO),
            Pattern::Data(d) => d.eval(q).unwrap_or(DVec3::ZERO),
            Pattern::Illum(p) => p.eval(q),
        }
    }
}

/// Compiles pattern primitive `k` (used by material `user` for messages).
/// `cal` holds the command line's `-e`/`-f` definitions; files are found through `resolver`.
pub fn compile(
    scene: &Scene,
    k: usize,
    user: &str,
    cal: &[CalSource],
    resolver: &Resolver,
) -> Result<Pattern> {
    let q = &scene.prims[k];
    let file = |s: &str| s.rsplit('/').next().unwrap_or(s).to_string();
    if q.ptype == "brightfunc" && q.sargs.len() == 2 {
        let (func, cal) = (q.sargs[0].as_str(), file(&q.sargs[1]));
        if func == "skybr" && cal == "skybright.cal" {
            if let Some(s) = SkyBright::from_args(&q.rargs) {
                return Ok(Pattern::Cie(s));
            }
        }
        if func == "skybright" && cal == "perezlum.cal" {
            if let Some(p) = PerezLum::from_args(&q.rargs) {
                return Ok(Pattern::Perez(p));
            }
        }
    }
    let what = format!("{}: {} '{}' (modifying '{user}')", q.loc, q.ptype, q.name);
    if q.ptype == "brightdata" || q.ptype == "colordata" {
        return compile_data(q, &what, cal, resolver);
    }
    let nexpr = match q.ptype.as_str() {
        "brightfunc" => 1,
        "colorfunc" => 3,
        other => bail!(
            "{what}: fenestra's ray tracer evaluates brightfunc, colorfunc, brightdata and colordata patterns; '{other}' is not supported yet"
        ),
    };
    if q.sargs.len() < nexpr + 1 {
        bail!(
            "{what}: needs {} string arguments (function{} and .cal file)",
            nexpr + 1,
            if nexpr > 1 { "s" } else { "" }
        );
    }
    let frame = PatternFrame::parse(&q.sargs[nexpr + 1..]).map_err(|e| anyhow!("{what}: {e:#}"))?;
    let cp = CalPattern::new(
        &q.sargs[..nexpr],
        &q.sargs[nexpr],
        &q.rargs,
        frame,
        &q.name,
        cal,
        resolver,
    )
    .map_err(|e| anyhow!("{what}: {e:#}"))?;
    Ok(Pattern::Cal(Arc::new(cp)))
}

/// `brightdata func data funcfile x1…xn` / `colordata rf gf bf rdata gdata bdata funcfile x1…xn`.
fn compile_data(
    q: &fenestra_scene::Primitive,
    what: &str,
    user: &[CalSource],
    resolver: &Resolver,
) -> Result<Pattern> {
    let nf = if q.ptype == "brightdata" { 1 } else { 3 };
    if q.sargs.len() < 2 * nf + 1 {
        bail!("{what}: needs at least {} string arguments", 2 * nf + 1);
    }
    let mut grids = Vec::new();
    for name in &q.sargs[nf..2 * nf] {
        let path = resolver
            .find_or_err(name)
            .map_err(|e| anyhow!("{what}: {e:#}"))?;
        grids.push(DataGrid::read(&path).map_err(|e| anyhow!("{what}: {e:#}"))?);
    }
    let dims = grids[0].dims();
    if grids.iter().any(|g| g.dims() != dims) {
        bail!("{what}: the data files have different numbers of dimensions");
    }
    let cal = &q.sargs[2 * nf];
    let coords = &q.sargs[2 * nf + 1..];
    if coords.len() < dims {
        bail!(
            "{what}: the data has {dims} dimension(s) but {} coordinate expression(s) follow the function file",
            coords.len()
        );
    }
    let (coords, xf) = coords.split_at(dims);
    if xf.is_empty() && user.is_empty() {
        let text = |name: &str| {
            resolver
                .find(name)
                .and_then(|p| std::fs::read_to_string(p).ok())
        };
        if let (Some(c), Some(r)) = (text(cal), text("rayinit.cal")) {
            let nf = q.sargs[..nf].to_vec();
            let coords = coords.to_vec();
            if crate::illum_pattern::IllumPattern::recognise(&nf, &c, &r, &coords, &q.rargs, &grids)
                .is_some()
            {
                let r = &q.rargs;
                let frame = (coords[0] == "il_alth").then(|| {
                    [
                        DVec3::new(r[0], r[1], r[2]),
                        DVec3::new(r[3], r[4], r[5]),
                        DVec3::new(r[6], r[7], r[8]),
                    ]
                });
                let shared = grids.iter().all(|g| g.same_axes(&grids[0]));
                return Ok(Pattern::Illum(Arc::new(
                    crate::illum_pattern::IllumPattern {
                        grids,
                        frame,
                        shared,
                    },
                )));
            }
        }
    }
    let frame = PatternFrame::parse(xf).map_err(|e| anyhow!("{what}: {e:#}"))?;
    let mut p = program(user, cal, resolver).map_err(|e| anyhow!("{what}: {e:#}"))?;
    let vars = p.bind_vars(&HOST_VARS);
    let mut ids = Vec::new();
    for e in coords {
        ids.push(p.add_expr(&q.name, e).map_err(|e| anyhow!("{what}: {e}"))?);
    }
    let exe = p.compile().map_err(|e| anyhow!("{what}: {e}"))?;
    let mut funcs = Vec::new();
    for f in &q.sargs[..nf] {
        funcs.push(exe.func(f).ok_or_else(|| {
            anyhow!("{what}: '{f}' is not a function defined in rayinit.cal or {cal}")
        })?);
    }
    let dp = DataPattern {
        core: CalCore::new(exe, frame, vars, &q.rargs),
        coords: ids,
        funcs,
        grids,
    };
    dp.eval(&TRIAL).map_err(|e| anyhow!("{what}: {e}"))?;
    Ok(Pattern::Data(Arc::new(dp)))
}
