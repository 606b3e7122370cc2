//! pcomb's expressions (`-e`, `-f`): output channels `ro go bo` (or `lo` for all three),
//! inputs `ri(n) gi(n) bi(n) li(n)` with optional pixel offsets `ri(n, dx, dy)`
//! (`n = 0` gives the number of inputs), `le(n)` input exposure, `pa(n)` pixel aspect,
//! position `x y` (y up from the bottom), sizes `xres yres` (output) and `xmax ymax`
//! (inputs), `nfiles` (the number of inputs), `WE` (179 lm/W) and `PI`, as Radiance's pcomb
//! defines them.

use std::cell::Cell;
use std::sync::Arc;

use anyhow::{anyhow, Result};
use fenestra_calc::{Compiled, Program, State, VarId};

/// One input as the expression functions see it: stored scanlines (top first), the
/// coefficients of `-s`/`-c`/`-o` already applied.
pub struct ExprInput {
    /// Width.
    pub width: usize,
    /// Height.
    pub height: usize,
    /// Pixels, top row first.
    pub pixels: Vec<[f32; 3]>,
    /// `EXPOSURE` product of its header.
    pub exposure: f64,
    /// `PIXASPECT` of its header.
    pub aspect: f64,
}

impl ExprInput {
    fn exposure_of(&self) -> f64 {
        self.exposure
    }

    fn aspect_of(&self) -> f64 {
        self.aspect
    }
}

thread_local! {
    /// The output pixel being computed (x, y from the bottom) and the output size.
    static PIXEL: Cell<(f64, f64, f64, f64)> = const { Cell::new((0.0, 0.0, 1.0, 1.0)) };
}

/// A compiled set of pcomb expressions.
pub struct Exprs {
    exe: Compiled,
    st: State,
    xy: Vec<VarId>,
    chans: [Option<VarId>; 3],
    lo: Option<VarId>,
}

/// Radiance's luminance weights (`bright()`).
const LUM: [f64; 3] = [0.265_074_126, 0.670_114_631, 0.064_811_243];

fn input_value(inputs: &[ExprInput], a: &[f64], chan: Option<usize>) -> f64 {
    let n = a.first().copied().unwrap_or(0.0);
    let k = (n + 0.5).floor();
    if k <= 0.0 {
        return inputs.len() as f64;
    }
    let Some(inp) = inputs.get(k as usize - 1) else {
        return 0.0;
    };
    let (x, y, xres, yres) = PIXEL.with(Cell::get);
    let dx = a.get(1).copied().unwrap_or(0.0).round();
    let dy = a.get(2).copied().unwrap_or(0.0).round();
    // Output position to input pixel (as pcomb resamples), then the offset, clamped.
    let xin = ((x + 0.5) * inp.width as f64 / xres).floor() + dx;
    let yin = ((y + 0.5) * inp.height as f64 / yres).floor() + dy;
    let xi = xin.clamp(0.0, inp.width as f64 - 1.0) as usize;
    let yi = yin.clamp(0.0, inp.height as f64 - 1.0) as usize;
    let p = inp.pixels[(inp.height - 1 - yi) * inp.width + xi];
    match chan {
        Some(c) => f64::from(p[c]),
        None => (0..3).map(|c| LUM[c] * f64::from(p[c])).sum(),
    }
}

impl Exprs {
    /// Compiles the definitions `load` adds (the `-e`/`-f` sources, in order) for these
    /// inputs and output size.
    pub fn new(
        load: &dyn Fn(&mut Program) -> Result<()>,
        inputs: Arc<Vec<ExprInput>>,
        xres: usize,
        yres: usize,
    ) -> Result<Exprs> {
        let mut p = Program::new();
        let (xmax, ymax) = inputs
            .first()
            .map(|i| (i.width as f64, i.height as f64))
            .unwrap_or((xres as f64, yres as f64));
        p.set_number("xmax", xmax);
        p.set_number("ymax", ymax);
        p.set_number("xres", xres as f64);
        p.set_number("yres", yres as f64);
        p.set_number("nfiles", inputs.len() as f64);
        p.set_number("WE", 179.0);
        p.set_number("PI", std::f64::consts::PI);
        for (name, chan) in [
            ("ri", Some(0)),
            ("gi", Some(1)),
            ("bi", Some(2)),
            ("li", None),
        ] {
            let inp = inputs.clone();
            p.define_host_fn(
                name,
                1,
                Arc::new(move |a: &[f64]| input_value(&inp, a, chan)),
            );
        }
        for (name, field) in [
            ("le", ExprInput::exposure_of as fn(&ExprInput) -> f64),
            ("pa", ExprInput::aspect_of),
        ] {
            let inp = inputs.clone();
            p.define_host_fn(
                name,
                1,
                Arc::new(move |a: &[f64]| {
                    let k = (a[0] + 0.5).floor();
                    if k <= 0.0 {
                        return inp.len() as f64;
                    }
                    inp.get(k as usize - 1).map_or(0.0, field)
                }),
            );
        }
        load(&mut p)?;
        let xy = p.bind_vars(&["x", "y"]);
        let exe = p.compile().map_err(|e| anyhow!("{e}"))?;
        let chans = [exe.var("ro"), exe.var("go"), exe.var("bo")];
        let lo = exe.var("lo");
        let st = exe.state();
        PIXEL.with(|c| c.set((0.0, 0.0, xres as f64, yres as f64)));
        Ok(Exprs {
            exe,
            st,
            xy,
            chans,
            lo,
        })
    }

    /// The output pixel at (x, y from the bottom), given the default (the scaled sum).
    pub fn pixel(&mut self, x: usize, y: usize, default: [f64; 3]) -> Result<[f64; 3]> {
        PIXEL.with(|c| {
            let (_, _, xr, yr) = c.get();
            c.set((x as f64, y as f64, xr, yr));
        });
        self.st.set_all(&self.xy, &[x as f64, y as f64]);
        if let Some(lo) = self.lo {
            let v = self
                .exe
                .eval_var(&mut self.st, lo)
                .map_err(|e| anyhow!("{e}"))?;
            return Ok([v; 3]);
        }
        let mut out = default;
        for (k, c) in self.chans.iter().enumerate() {
            if let Some(v) = c {
                out[k] = self
                    .exe
                    .eval_var(&mut self.st, *v)
                    .map_err(|e| anyhow!("{e}"))?;
            }
        }
        Ok(out)
    }
}
