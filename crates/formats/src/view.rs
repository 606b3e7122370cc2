//! Radiance view parameters: parsing (`-vt? -vp -vd -vu -vh -vv -vo -va -vs -vl`, `VIEW=`
//! lines, view files), checking and deriving the image plane (`setview`), mapping image
//! locations to rays (`viewray`) and printing them back as a `VIEW=` line.
// Component-wise vector arithmetic reads most clearly with explicit indices.
#![allow(clippy::needless_range_loop)]

use std::f64::consts::PI;

use crate::view_print::fmt_g;

/// The numeric tolerance Radiance's double-precision build uses.
pub const FTINY: f64 = 1e-6;

/// Projection types.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewType {
    /// `-vtv` perspective.
    Perspective,
    /// `-vtl` parallel.
    Parallel,
    /// `-vta` angular fisheye.
    Angular,
    /// `-vth` hemispherical fisheye.
    Hemispherical,
    /// `-vts` planisphere (stereographic).
    Planisphere,
    /// `-vtc` cylindrical panorama.
    Cylindrical,
}

impl ViewType {
    /// The type letter (`v l a h s c`).
    pub fn letter(self) -> char {
        match self {
            ViewType::Perspective => 'v',
            ViewType::Parallel => 'l',
            ViewType::Angular => 'a',
            ViewType::Hemispherical => 'h',
            ViewType::Planisphere => 's',
            ViewType::Cylindrical => 'c',
        }
    }

    /// The type for a letter.
    pub fn from_letter(c: char) -> Option<Self> {
        Some(match c {
            'v' => ViewType::Perspective,
            'l' => ViewType::Parallel,
            'a' => ViewType::Angular,
            'h' => ViewType::Hemispherical,
            's' => ViewType::Planisphere,
            'c' => ViewType::Cylindrical,
            _ => return None,
        })
    }
}

/// A view as given by its options, plus the derived image-plane vectors after [`View::setup`].
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    /// Projection type.
    pub vtype: ViewType,
    /// View point.
    pub vp: [f64; 3],
    /// View direction (unit after setup).
    pub vdir: [f64; 3],
    /// Up vector (unit after setup).
    pub vup: [f64; 3],
    /// Focal distance (the length of `-vd`).
    pub vdist: f64,
    /// Horizontal size (degrees, or world units for parallel views).
    pub horiz: f64,
    /// Vertical size.
    pub vert: f64,
    /// Horizontal shift (image fractions).
    pub hoff: f64,
    /// Vertical lift.
    pub voff: f64,
    /// Fore clipping distance.
    pub vfore: f64,
    /// Aft clipping distance (0: none).
    pub vaft: f64,
    /// Derived horizontal image vector.
    pub hvec: [f64; 3],
    /// Derived vertical image vector.
    pub vvec: [f64; 3],
    /// Squared horizontal image-plane scale.
    pub hn2: f64,
    /// Squared vertical image-plane scale.
    pub vn2: f64,
}

impl Default for View {
    fn default() -> Self {
        View {
            vtype: ViewType::Perspective,
            vp: [0.0; 3],
            vdir: [0.0, 1.0, 0.0],
            vup: [0.0, 0.0, 1.0],
            vdist: 1.0,
            horiz: 45.0,
            vert: 45.0,
            hoff: 0.0,
            voff: 0.0,
            vfore: 0.0,
            vaft: 0.0,
            hvec: [0.0; 3],
            vvec: [0.0; 3],
            hn2: 0.0,
            vn2: 0.0,
        }
    }
}

/// Radiance's `normalize`: unit length in place (with its first-order shortcut for
/// nearly unit vectors, so results agree to the last bit); returns the old length.
pub fn normalize(v: &mut [f64; 3]) -> f64 {
    // Summed in the order the reference build evaluates it.
    let mut d = v[0] * v[0] + (v[1] * v[1] + v[2] * v[2]);
    if d == 0.0 {
        return 0.0;
    }
    let len;
    if (1.0 - FTINY..=1.0 + FTINY).contains(&d) {
        len = 0.5 + 0.5 * d;
        d = 2.0 - len;
    } else {
        len = d.sqrt();
        d = 1.0 / len;
    }
    v[0] *= d;
    v[1] *= d;
    v[2] *= d;
    len
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// How many words a view option consumed, or why it was refused.
pub type OptResult = Result<usize, String>;

impl View {
    /// Applies one view option at `args[0]` (`-vtv`, `-vp x y z`, …); returns the
    /// number of value words consumed after the option itself. `-vf` is not handled here.
    pub fn apply_option(&mut self, args: &[String]) -> OptResult {
        let opt = args.first().ok_or("missing view option")?;
        let rest = opt
            .strip_prefix("-v")
            .ok_or_else(|| format!("'{opt}' is not a view option"))?;
        let num = |k: usize| -> Result<f64, String> {
            let w = args
                .get(k)
                .ok_or_else(|| format!("option {opt} needs more values"))?;
            parse_num(w).ok_or_else(|| format!("option {opt}: expected a number, got '{w}'"))
        };
        let vec3 = || -> Result<[f64; 3], String> { Ok([num(1)?, num(2)?, num(3)?]) };
        let mut chars = rest.chars();
        let c = chars
            .next()
            .ok_or_else(|| format!("unknown view option '{opt}'"))?;
        let tail: String = chars.collect();
        if c == 't' {
            let mut t = tail.chars();
            let letter = t
                .next()
                .ok_or_else(|| format!("option {opt} needs a type letter"))?;
            if t.next().is_some() {
                return Err(format!("unknown view type '{opt}'"));
            }
            self.vtype = ViewType::from_letter(letter)
                .ok_or_else(|| format!("unknown view type '{letter}' in {opt}"))?;
            return Ok(0);
        }
        if !tail.is_empty() {
            return Err(format!("unknown view option '{opt}'"));
        }
        let vector = match c {
            'p' => Some(&mut self.vp),
            'd' => Some(&mut self.vdir),
            'u' => Some(&mut self.vup),
            _ => None,
        };
        if let Some(v) = vector {
            *v = vec3()?;
            if c == 'd' {
                self.vdist = 1.0;
            }
            return Ok(3);
        }
        let scalar = match c {
            'h' => &mut self.horiz,
            'v' => &mut self.vert,
            'o' => &mut self.vfore,
            'a' => &mut self.vaft,
            's' => &mut self.hoff,
            'l' => &mut self.voff,
            _ => return Err(format!("unknown view option '{opt}'")),
        };
        *scalar = num(1)?;
        Ok(1)
    }

    /// Applies every view option found in a line (a `VIEW=` line, or a command line such
    /// as `rview -vtv -vp …`); words that are not view options are skipped, as Radiance
    /// does. Returns how many options were applied.
    pub fn scan_line(&mut self, line: &str) -> usize {
        let words: Vec<String> = line.split_whitespace().map(str::to_string).collect();
        let mut n = 0;
        let mut i = 0;
        while i < words.len() {
            if words[i].starts_with("-v") {
                let mut trial = self.clone();
                if let Ok(k) = trial.apply_option(&words[i..]) {
                    *self = trial;
                    n += 1;
                    i += k + 1;
                    continue;
                }
            }
            i += 1;
        }
        n
    }

    /// Whether a header line carries view options (`VIEW=` or a renderer's command line).
    pub fn is_view_line(line: &str, prog: &str) -> bool {
        let first = line.split(' ').next().unwrap_or("");
        let base = first.rsplit('/').next().unwrap_or(first);
        let starts = |p: &str| !p.is_empty() && base.starts_with(p);
        line.starts_with("VIEW=")
            || ["rpict", "rview", "rvu", "rpiece", "pinterp"]
                .iter()
                .any(|p| starts(p))
            || starts(prog)
    }

    /// Reads a view file (a `VIEW=` line, or `rview -vtv …` lines, possibly a picture
    /// header); every view line found applies in turn. `Ok(false)` when none was found.
    pub fn apply_file_text(&mut self, text: &str, prog: &str) -> bool {
        let mut found = false;
        for line in text.lines() {
            if line.is_empty() {
                break;
            }
            if Self::is_view_line(line, prog) && self.scan_line(line) > 0 {
                found = true;
            }
        }
        found
    }

    /// Checks the view and derives the image-plane vectors (Radiance's `setview`).
    pub fn setup(&mut self) -> Result<(), String> {
        const ILL_H: &str = "illegal horizontal view size";
        const ILL_V: &str = "illegal vertical view size";
        if self.vfore < -FTINY
            || self.vaft < -FTINY
            || (self.vaft > FTINY && self.vaft <= self.vfore)
        {
            return Err("illegal fore/aft clipping plane".into());
        }
        if self.vdist <= FTINY {
            return Err("illegal view distance".into());
        }
        self.vdist *= normalize(&mut self.vdir);
        if self.vdist == 0.0 {
            return Err("zero view direction".into());
        }
        if normalize(&mut self.vup) == 0.0 {
            return Err("zero view up vector".into());
        }
        self.hvec = cross(&self.vdir, &self.vup);
        if normalize(&mut self.hvec) == 0.0 {
            return Err("view up parallel to view direction".into());
        }
        self.vvec = cross(&self.hvec, &self.vdir);
        if self.horiz <= FTINY {
            return Err(ILL_H.into());
        }
        if self.vert <= FTINY {
            return Err(ILL_V.into());
        }
        let (h, v) = (self.horiz, self.vert);
        let half = PI / 180.0 / 2.0;
        match self.vtype {
            ViewType::Parallel => {
                self.hn2 = h;
                self.vn2 = v;
            }
            ViewType::Perspective => {
                if h >= 180.0 - FTINY {
                    return Err(ILL_H.into());
                }
                if v >= 180.0 - FTINY {
                    return Err(ILL_V.into());
                }
                self.hn2 = 2.0 * (h * half).tan();
                self.vn2 = 2.0 * (v * half).tan();
            }
            ViewType::Cylindrical => {
                if h > 360.0 + FTINY {
                    return Err(ILL_H.into());
                }
                if v >= 180.0 - FTINY {
                    return Err(ILL_V.into());
                }
                self.hn2 = h * (PI / 180.0);
                self.vn2 = 2.0 * (v * half).tan();
            }
            ViewType::Angular => {
                if h > 360.0 + FTINY {
                    return Err(ILL_H.into());
                }
                if v > 360.0 + FTINY {
                    return Err(ILL_V.into());
                }
                self.hn2 = h * (PI / 180.0);
                self.vn2 = v * (PI / 180.0);
            }
            ViewType::Hemispherical => {
                if h > 180.0 + FTINY {
                    return Err(ILL_H.into());
                }
                if v > 180.0 + FTINY {
                    return Err(ILL_V.into());
                }
                self.hn2 = 2.0 * (h * half).sin();
                self.vn2 = 2.0 * (v * half).sin();
            }
            ViewType::Planisphere => {
                if h >= 360.0 - FTINY {
                    return Err(ILL_H.into());
                }
                if v >= 360.0 - FTINY {
                    return Err(ILL_V.into());
                }
                self.hn2 = 2.0 * (h * half).sin() / (1.0 + (h * half).cos());
                self.vn2 = 2.0 * (v * half).sin() / (1.0 + (v * half).cos());
            }
        }
        if !matches!(self.vtype, ViewType::Angular | ViewType::Planisphere) {
            if self.vtype != ViewType::Cylindrical {
                for k in 0..3 {
                    self.hvec[k] *= self.hn2;
                }
            }
            for k in 0..3 {
                self.vvec[k] *= self.vn2;
            }
        }
        self.hn2 *= self.hn2;
        self.vn2 *= self.vn2;
        Ok(())
    }

    /// Pixel height over width for a square-pixel image of this view.
    pub fn aspect(&self) -> f64 {
        (self.vn2 / self.hn2).sqrt()
    }

    /// The ray through image location (x, y) ∈ [0,1]² (x right, y up) of a set-up view:
    /// `Some((origin, direction, maximum distance or 0))`, `None` outside the view.
    ///
    /// Sums are grouped as the reference Radiance 6.0a build evaluates them, so results
    /// agree to the last bit. As there, perspective and cylindrical directions are
    /// normalised explicitly; fisheye directions are unit by construction (to rounding).
    pub fn ray(&self, x: f64, y: f64) -> Option<([f64; 3], [f64; 3], f64)> {
        let x = (x + -0.5) + self.hoff;
        let y = (y + -0.5) + self.voff;
        let aft = self.vaft > FTINY;
        let span = if aft { self.vaft - self.vfore } else { 0.0 };
        // (x·h + y·v) + z·vdir
        let comb = |z: f64, x: f64, y: f64| -> [f64; 3] {
            let mut d = [0.0; 3];
            for k in 0..3 {
                d[k] = (x * self.hvec[k] + y * self.vvec[k]) + z * self.vdir[k];
            }
            d
        };
        let orig_from = |d: &[f64; 3]| -> [f64; 3] {
            let mut o = [0.0; 3];
            for k in 0..3 {
                o[k] = d[k] * self.vfore + self.vp[k];
            }
            o
        };
        let normalised = |mut d: [f64; 3]| {
            let o = orig_from(&d);
            let len = normalize(&mut d);
            Some((o, d, if aft { span * len } else { 0.0 }))
        };
        let unnormalised = |d: [f64; 3]| Some((orig_from(&d), d, span));
        match self.vtype {
            ViewType::Parallel => {
                let mut o = [0.0; 3];
                for k in 0..3 {
                    o[k] = (self.vfore * self.vdir[k] + self.vp[k])
                        + (x * self.hvec[k] + y * self.vvec[k]);
                }
                Some((o, self.vdir, span))
            }
            ViewType::Perspective => {
                let mut d = [0.0; 3];
                for k in 0..3 {
                    d[k] = (x * self.hvec[k] + y * self.vvec[k]) + self.vdir[k];
                }
                normalised(d)
            }
            ViewType::Cylindrical => {
                let a = (self.horiz * (PI / 180.0)) * x;
                let (s, c) = a.sin_cos();
                let mut d = [0.0; 3];
                for k in 0..3 {
                    d[k] = (c * self.vdir[k] + s * self.hvec[k]) + y * self.vvec[k];
                }
                normalised(d)
            }
            ViewType::Hemispherical => {
                let sum = x * x * self.hn2 + y * y * self.vn2;
                if sum > 1.0 {
                    return None;
                }
                unnormalised(comb((1.0 - sum).sqrt(), x, y))
            }
            ViewType::Angular => {
                let x = x * (self.horiz * (1.0 / 180.0));
                let y = y * (self.vert * (1.0 / 180.0));
                let d2 = x * x + y * y;
                if d2 > 1.0 {
                    return None;
                }
                let r = d2.sqrt();
                let z = (PI * r).cos();
                let f = if d2 > FTINY * FTINY {
                    (1.0 - z * z).sqrt() / r
                } else {
                    PI
                };
                unnormalised(comb(z, x * f, y * f))
            }
            ViewType::Planisphere => {
                let x = x * self.hn2.sqrt();
                let y = y * self.vn2.sqrt();
                let d = x * x + y * y;
                let z = (1.0 - d) / (d + 1.0);
                let f = z + 1.0;
                unnormalised(comb(z, x * f, y * f))
            }
        }
    }

    /// The view options as Radiance prints them (no leading `VIEW=`; starts with a blank).
    pub fn options_string(&self) -> String {
        let g7 = |v: f64| fmt_g(v, 7);
        let g5 = |v: f64| fmt_g(v, 5);
        let d: Vec<f64> = self.vdir.iter().map(|c| c * self.vdist).collect();
        format!(
            " -vt{} -vp {} {} {} -vd {} {} {} -vu {} {} {} -vh {} -vv {} -vo {} -va {} -vs {} -vl {}",
            self.vtype.letter(),
            g7(self.vp[0]),
            g7(self.vp[1]),
            g7(self.vp[2]),
            g7(d[0]),
            g7(d[1]),
            g7(d[2]),
            g5(self.vup[0]),
            g5(self.vup[1]),
            g5(self.vup[2]),
            g5(self.horiz),
            g5(self.vert),
            g5(self.vfore),
            g5(self.vaft),
            g5(self.hoff),
            g5(self.voff)
        )
    }

    /// The header line `VIEW= -vt…` (without newline).
    pub fn header_line(&self) -> String {
        format!("VIEW={}", self.options_string())
    }
}

/// Reduces a resolution so pixels have aspect `pa` for a view of aspect `va`
/// (Radiance's `normaspect`); `pa <= 0` is replaced by the aspect the resolution gives.
pub fn normaspect(va: f64, pa: &mut f64, xres: &mut i64, yres: &mut i64) {
    if *pa <= FTINY {
        *pa = va * *xres as f64 / *yres as f64;
    } else if va * (*xres as f64) > *pa * (*yres as f64) {
        *xres = (*yres as f64 / va * *pa + 0.5) as i64;
    } else {
        *yres = (*xres as f64 * va / *pa + 0.5) as i64;
    }
}

/// Parses a number as C's `atof` would accept a whole word.
pub fn parse_num(w: &str) -> Option<f64> {
    let t = w.trim();
    if let Ok(v) = t.parse::<f64>() {
        return v.is_finite().then_some(v);
    }
    // C accepts forms like "1." "-.5" "+3" which Rust parses too; "1e" or "0x" do not matter here.
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(s: &str) -> Vec<String> {
        s.split_whitespace().map(str::to_string).collect()
    }

    fn view(s: &str) -> View {
        let mut v = View::default();
        assert!(v.scan_line(s) > 0);
        v.setup().unwrap();
        v
    }

    #[test]
    fn perspective_corner_rays_match_radiance() {
        let v = view("-vtv -vp 0 0 0 -vd 0 1 0 -vu 0 0 1 -vh 90 -vv 90");
        let (o, d, m) = v.ray(0.25, 0.75).unwrap();
        assert_eq!(o, [0.0; 3]);
        assert_eq!(m, 0.0);
        let want = [-0.408248, 0.816497, 0.408248];
        for k in 0..3 {
            assert!((d[k] - want[k]).abs() < 1e-6, "{d:?}");
        }
    }

    #[test]
    fn parallel_with_clipping() {
        let v = view("-vtl -vh 2 -vv 1 -vo 1 -va 5");
        let (o, d, m) = v.ray(0.25, 0.5).unwrap();
        assert_eq!((o, d, m), ([-0.5, 1.0, 0.0], [0.0, 1.0, 0.0], 4.0));
    }

    #[test]
    fn fisheye_corner_is_outside() {
        let v = view("-vth -vh 180 -vv 180");
        assert!(v.ray(0.125, 0.875).is_none());
        let a = view("-vta -vh 360 -vv 360");
        assert!(a.ray(0.0, 0.0).is_none());
        assert!(a.ray(0.5, 0.5).is_some());
    }

    #[test]
    fn errors_are_reported() {
        let mut v = View {
            vup: [0.0, 1.0, 0.0],
            ..Default::default()
        };
        assert_eq!(v.setup().unwrap_err(), "view up parallel to view direction");
        let mut v = View {
            horiz: 180.0,
            ..Default::default()
        };
        assert_eq!(v.setup().unwrap_err(), "illegal horizontal view size");
        let mut v = View::default();
        assert!(v.apply_option(&words("-vtx")).is_err());
        assert!(v.apply_option(&words("-vp 1 2")).is_err());
    }

    #[test]
    fn view_line_round_trips() {
        let v = view("rview -vtv -vp 2 4.6 1.5 -vd 0 -1 -0.08 -vu 0 0 1 -vh 70 -vv 60");
        let line = v.header_line();
        assert_eq!(
            line,
            "VIEW= -vtv -vp 2 4.6 1.5 -vd 0 -1 -0.08 -vu 0 0 1 -vh 70 -vv 60 -vo 0 -va 0 -vs 0 -vl 0"
        );
        let mut w = View::default();
        assert!(w.apply_file_text(&line, "vwrays"));
        w.setup().unwrap();
        assert_eq!(w.options_string(), v.options_string());
    }

    #[test]
    fn aspect_reduces_resolution() {
        let v = view("-vtv -vh 60 -vv 60");
        let (mut pa, mut x, mut y) = (1.0, 100, 50);
        normaspect(v.aspect(), &mut pa, &mut x, &mut y);
        assert_eq!((x, y), (50, 50));
    }
}
