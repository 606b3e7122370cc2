//! Rendering options shared by rtrace and rcontrib (`-ab -ad -lw -lr -ds -dj …`).

use fenestra_io::raypath::Resolver;

/// Options of the integrator (Radiance names in the field docs).
#[derive(Debug, Clone, PartialEq)]
pub struct TraceOptions {
    /// `-ab`: ambient bounces.
    pub ab: u32,
    /// `-ad`: ambient divisions.
    pub ad: u32,
    /// `-lw`: minimum ray weight.
    pub lw: f64,
    /// `-lr`: maximum reflections (negative: Russian roulette with that hard limit).
    pub lr: i32,
    /// `-ds`: source subdivision ratio (0 = none).
    pub ds: f64,
    /// `-dj`: source jitter (0..1).
    pub dj: f64,
    /// `-dc`: source certainty: with thresholding, the next ⌊n^dc + ½⌋ of n source samples
    /// are weighed against the threshold (1: all the rest, 0: one at a time).
    pub dc: f64,
    /// `-dr`: relays (accepted; virtual sources are not modelled).
    pub dr: i32,
    /// `-dt`: direct threshold: source samples whose potential is below this fraction of
    /// what the ray has gathered are not shadow-tested (0: every sample is tested).
    pub dt: f64,
    /// `-st`: specular sampling threshold.
    pub st: f64,
    /// `-ss`: specular sampling (0 = no rough-specular indirect samples).
    pub ss: f64,
    /// `-bv`: back faces of emitters visible.
    pub bv: bool,
    /// `-av`: ambient value beyond the last bounce.
    pub av: [f64; 3],
    /// `-as`: ambient super-samples (extra hemisphere samples where strata vary most;
    /// rtrace 512, rcontrib always 0 as Radiance's).
    pub asamp: u32,
    /// Seed of the random streams (each input ray gets its own stream).
    pub seed: u64,
    /// Disable effect selection (run the full integrator; for tests and benchmarks).
    pub full: bool,
    /// `-e expr` and `-f file.cal` in command-line order: loaded after `rayinit.cal` and
    /// before each pattern's own file, as Radiance's global calcomp context.
    pub cal: Vec<CalSource>,
    /// Where the scene's auxiliary files (.cal, data, BSDF XML) and `-f` files are found
    /// (by default `RAYPATH` and fenestra's library, read when the options are made).
    pub resolver: Resolver,
}

/// A command-line .cal source (`-e` or `-f`).
#[derive(Debug, Clone, PartialEq)]
pub enum CalSource {
    /// `-e expr`.
    Expr(String),
    /// `-f file` (found through RAYPATH).
    File(String),
}

impl CalSource {
    /// Loads this source into a program (a file found through `resolver`).
    pub fn load(&self, p: &mut fenestra_calc::Program, resolver: &Resolver) -> anyhow::Result<()> {
        match self {
            CalSource::Expr(e) => p.load_str("-e", e).map_err(|e| anyhow::anyhow!("{e}")),
            CalSource::File(f) => {
                let path = resolver.find_or_err(f)?;
                p.load_file(&path).map_err(|e| anyhow::anyhow!("{e}"))
            }
        }
    }
}

impl TraceOptions {
    /// rtrace's defaults (`-ab 0 -ad 1024 -as 512 -lw 1e-4 -lr -10 -dt .03 -dj 0 -st .15`).
    pub fn rtrace() -> Self {
        TraceOptions {
            ab: 0,
            ad: 1024,
            lw: 1e-4,
            lr: -10,
            ds: 0.2,
            dj: 0.0,
            dc: 0.75,
            dr: 2,
            dt: 0.03,
            st: 0.15,
            ss: 1.0,
            bv: true,
            av: [0.0; 3],
            asamp: 512,
            seed: 0,
            full: false,
            cal: Vec::new(),
            resolver: Resolver::from_env(),
        }
    }

    /// rcontrib's defaults (`-ab 1 -ad 350 -lw 2e-3 -dj .9 -dr 3 -st .02`, `-dt 0`, `-as 0`).
    pub fn rcontrib() -> Self {
        TraceOptions {
            ab: 1,
            ad: 350,
            lw: 2e-3,
            dj: 0.9,
            dr: 3,
            dt: 0.0,
            st: 0.02,
            asamp: 0,
            ..Self::rtrace()
        }
    }
}

impl TraceOptions {
    /// The one-number integrator options both rtrace and rcontrib take, by Radiance name.
    pub const NUMBER_OPTIONS: [&'static str; 11] = [
        "ab", "ad", "lw", "lr", "ds", "dj", "dc", "dr", "st", "ss", "seed",
    ];

    /// Whether `name` is one of [`Self::NUMBER_OPTIONS`].
    pub fn is_number_option(name: &str) -> bool {
        Self::NUMBER_OPTIONS.contains(&name)
    }

    /// Sets one of [`Self::NUMBER_OPTIONS`] from its value (`-ab` at least 0, `-ad` at
    /// least 1, integers truncated as Radiance's `atoi`); false for any other name.
    pub fn set_number(&mut self, name: &str, v: f64) -> bool {
        match name {
            "ab" => self.ab = v.max(0.0) as u32,
            "ad" => self.ad = v.max(1.0) as u32,
            "lw" => self.lw = v,
            "lr" => self.lr = v as i32,
            "ds" => self.ds = v,
            "dj" => self.dj = v,
            "dc" => self.dc = v,
            "dr" => self.dr = v as i32,
            "st" => self.st = v,
            "ss" => self.ss = v,
            "seed" => self.seed = v as u64,
            _ => return false,
        }
        true
    }
}

impl Default for TraceOptions {
    fn default() -> Self {
        Self::rtrace()
    }
}
