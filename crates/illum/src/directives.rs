//! `#@mkillum` directives and the state they set, which persists from line to line:
//! material and data-file names, selection, colour, sampling density and count, light
//! type, brightness threshold and output redirection.

/// Which surfaces are converted.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Select {
    /// `a`: all surfaces.
    All,
    /// `n`: none (everything passes unchanged).
    None,
    /// `i=mod`: only surfaces modified by `mod`.
    Only(String),
    /// `e=mod`: all but those modified by `mod`.
    Except(String),
}

/// Colour handling (`c=`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Colour {
    /// `c=n`: a grey distribution, grey average.
    None,
    /// `c=a`: grey distribution, average colour.
    Average,
    /// `c=d`: one distribution per channel.
    Distribution,
}

/// The directives in effect.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// `m=`: name of the generated material (and of its `.dist` pattern).
    pub matname: String,
    /// `f=`: data-file base name.
    pub datafile: String,
    /// Number appended to the data-file name (incremented per distribution written).
    pub dfnum: u32,
    /// `f=` was given: data files may be overwritten.
    pub clobber: bool,
    /// Selection.
    pub select: Select,
    /// Colour handling.
    pub colour: Colour,
    /// `l+`: output `light` and add sources explicitly.
    pub light: bool,
    /// `d=`: directions per projected steradian (0: diffuse).
    pub sampdens: i64,
    /// `s=`: rays per direction.
    pub nsamps: i64,
    /// `b=`: minimum average brightness.
    pub minbrt: f64,
    /// `d=file.xml`: the window's BSDF (the distribution is its transmission of the
    /// sampled outside; fenestra, as Radiance 4 had it).
    pub bsdf: Option<String>,
    /// `u=`: the BSDF's up vector (fenestra; default +Z, or +Y for a window facing up or down).
    pub up: Option<glam::DVec3>,
    /// `p+`: a distribution with a peak in one cell is sampled again at 4× the density, while
    /// that stays within d=4096 (fenestra; `p-`, the default, only warns).
    pub refine: bool,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            matname: "illum_mat".into(),
            datafile: "illum".into(),
            dfnum: 0,
            clobber: false,
            select: Select::All,
            colour: Colour::None,
            light: false,
            sampdens: 48,
            nsamps: 32,
            minbrt: 0.0,
            bsdf: None,
            up: None,
            refine: false,
        }
    }
}

/// What a directive line asked for besides changing the settings.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LineEffect {
    /// Directives that could not be read.
    pub errors: usize,
    /// `o=file`: following output goes to this file.
    pub output: Option<String>,
    /// `!`: the input was already processed.
    pub processed: bool,
    /// Warnings to print (before the error count).
    pub warnings: Vec<String>,
    /// `d=file`: a BSDF file was named (the caller loads it).
    pub bsdf: Option<String>,
}

/// `true` for an integer word (optional sign, digits), as Radiance's `isintd`.
fn is_int(w: &str) -> bool {
    let d = w.strip_prefix(['+', '-']).unwrap_or(w);
    !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit())
}

/// An up vector: `±X`, `±Y`, `±Z` or `x,y,z` (not zero), normalised.
fn direction(s: &str) -> Option<glam::DVec3> {
    let (neg, rest) = match s.as_bytes().first() {
        Some(b'-') => (true, &s[1..]),
        Some(b'+') => (false, &s[1..]),
        _ => (false, s),
    };
    let sign = if neg { -1.0 } else { 1.0 };
    let d = match rest {
        "x" | "X" => glam::DVec3::X * sign,
        "y" | "Y" => glam::DVec3::Y * sign,
        "z" | "Z" => glam::DVec3::Z * sign,
        _ => {
            let v: Vec<f64> = s
                .split(',')
                .map(|w| w.trim().parse::<f64>().ok())
                .collect::<Option<_>>()?;
            if v.len() != 3 {
                return None;
            }
            glam::DVec3::new(v[0], v[1], v[2])
        }
    };
    let l = d.length();
    (l > 0.0 && l.is_finite()).then(|| d / l)
}

/// `true` for a real number word, as Radiance's `isfltd`.
fn is_real(w: &str) -> bool {
    !w.is_empty() && w.parse::<f64>().is_ok_and(|v| v.is_finite())
}

impl Settings {
    /// The printed defaults (`mkillum -defaults`).
    pub fn defaults_text(&self) -> String {
        let c = match self.colour {
            Colour::Distribution => "c=d\t\t\t\t# color distribution",
            Colour::Average => "c=a\t\t\t\t# color average",
            Colour::None => "c=n\t\t\t\t# color none",
        };
        format!(
            "m={:<15}\t\t# material name\nf={:<15}\t\t# data file name\n{c}\n{}\nd={}\t\t\t\t# density of directions\ns={}\t\t\t\t# samples per direction\nb={:.6}\t\t\t# minimum average brightness\n",
            self.matname,
            self.datafile,
            if self.light {
                "l+\t\t\t\t# light type on"
            } else {
                "l-\t\t\t\t# light type off"
            },
            self.sampdens,
            self.nsamps,
            self.minbrt
        )
    }

    /// Applies the words after `#@mkillum` (one line).
    pub fn apply(&mut self, text: &str) -> LineEffect {
        let mut fx = LineEffect::default();
        for w in text.split_whitespace() {
            let ok = self.apply_word(w, &mut fx);
            if fx.processed {
                return fx;
            }
            if !ok {
                fx.errors += 1;
            }
        }
        fx
    }

    fn apply_word(&mut self, w: &str, fx: &mut LineEffect) -> bool {
        let value = |k: &str| w.strip_prefix(k).filter(|v| !v.is_empty());
        match w.as_bytes()[0] {
            b'm' => match value("m=") {
                Some(v) => {
                    self.matname = v.to_string();
                    if !self.clobber {
                        self.datafile = v.to_string();
                        self.dfnum = 0;
                    }
                    true
                }
                None => false,
            },
            b'f' if w.starts_with("f=") => {
                match value("f=") {
                    None => {
                        self.datafile = self.matname.clone();
                        self.clobber = false;
                    }
                    Some(v) => {
                        self.datafile = v.to_string();
                        self.clobber = true;
                    }
                }
                self.dfnum = 0;
                true
            }
            b'i' | b'e' if w.as_bytes().get(1) == Some(&b'=') => {
                let m = w[2..].to_string();
                self.select = if w.starts_with('i') {
                    Select::Only(m)
                } else {
                    Select::Except(m)
                };
                true
            }
            b'a' => {
                self.select = Select::All;
                true
            }
            b'n' => {
                self.select = Select::None;
                true
            }
            b'c' => match w.as_bytes().get(2).filter(|_| w.starts_with("c=")) {
                Some(b'a') => {
                    self.colour = Colour::Average;
                    true
                }
                Some(b'd') => {
                    self.colour = Colour::Distribution;
                    true
                }
                Some(b'n') => {
                    self.colour = Colour::None;
                    true
                }
                _ => false,
            },
            b'd' if w.starts_with("d=") => match value("d=") {
                None => true,
                Some(v) if is_int(v) => {
                    self.sampdens = v.parse().unwrap_or(0);
                    self.bsdf = None;
                    true
                }
                Some(v) => {
                    self.bsdf = Some(v.to_string());
                    fx.bsdf = Some(v.to_string());
                    true
                }
            },
            b'u' => match value("u=").and_then(direction) {
                Some(d) => {
                    self.up = Some(d);
                    true
                }
                None => false,
            },
            b's' => match value("s=") {
                Some(v) if is_int(v) => {
                    self.nsamps = v.parse().unwrap_or(0);
                    true
                }
                _ => false,
            },
            b'l' | b'p' => match w.as_bytes().get(1) {
                Some(b'+' | b'-') => {
                    let flag = if w.starts_with('l') {
                        &mut self.light
                    } else {
                        &mut self.refine
                    };
                    *flag = w.as_bytes()[1] == b'+';
                    w.len() == 2
                }
                _ => false,
            },
            b'b' => match value("b=") {
                Some(v) if is_real(v) => {
                    self.minbrt = v.parse::<f64>().unwrap_or(0.0).max(0.0);
                    true
                }
                _ => false,
            },
            b'o' => match value("o=") {
                Some(v) => {
                    fx.output = Some(v.to_string());
                    true
                }
                None => false,
            },
            b'!' => {
                fx.processed = true;
                self.select = Select::None;
                true
            }
            _ => false,
        }
    }

    /// Whether a surface with modifier `m` is converted.
    pub fn selects(&self, m: &str) -> bool {
        match &self.select {
            Select::All => true,
            Select::None => false,
            Select::Only(x) => x == m,
            Select::Except(x) => x != m,
        }
    }

    /// The numbers of altitude and azimuth divisions of a hemisphere (1 × 1 when diffuse).
    pub fn flat_divisions(&self) -> (usize, usize) {
        flat_divisions(self.sampdens)
    }

    /// The same for a whole sphere.
    pub fn round_divisions(&self) -> (usize, usize) {
        round_divisions(self.sampdens)
    }
}

/// Altitude and azimuth divisions of a hemisphere at `d=dens` (1 × 1 when diffuse).
pub fn flat_divisions(dens: i64) -> (usize, usize) {
    if dens <= 0 {
        return (1, 1);
    }
    let n = (std::f64::consts::PI * dens as f64) as i64;
    let nalt = ((n as f64 / std::f64::consts::PI).sqrt() + 0.5) as i64;
    let nazi = (std::f64::consts::PI * nalt as f64 + 0.5) as i64;
    (nalt.max(1) as usize, nazi.max(1) as usize)
}

/// The same for a whole sphere.
pub fn round_divisions(dens: i64) -> (usize, usize) {
    if dens <= 0 {
        return (1, 1);
    }
    let n = (4.0 * std::f64::consts::PI * dens as f64) as i64;
    let nalt = ((2.0 / std::f64::consts::PI * n as f64).sqrt() + 0.5) as i64;
    let nazi = (std::f64::consts::PI / 2.0 * nalt as f64 + 0.5) as i64;
    (nalt.max(1) as usize, nazi.max(1) as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directives_set_state_and_count_errors() {
        let mut s = Settings::default();
        let fx = s.apply("i=glass_mat d=4 s=8 c=a f=wdist");
        assert_eq!(fx.errors, 0);
        assert_eq!(s.select, Select::Only("glass_mat".into()));
        assert_eq!((s.sampdens, s.nsamps, s.colour), (4, 8, Colour::Average));
        assert_eq!((s.datafile.as_str(), s.clobber), ("wdist", true));
        assert_eq!(s.flat_divisions(), (2, 6));
        let fx = s.apply("m=win l+ q=3 b=x d=blinds.xml u=0,0,2");
        assert_eq!(fx.errors, 2);
        assert_eq!(fx.bsdf.as_deref(), Some("blinds.xml"));
        assert_eq!(s.up, Some(glam::DVec3::Z));
        assert_eq!(s.apply("u=0,0,0").errors, 1);
        assert_eq!(s.matname, "win");
        assert_eq!(s.datafile, "wdist", "f= given: m= keeps the data-file name");
        assert!(s.light);
        s.apply("f=");
        assert_eq!((s.datafile.as_str(), s.clobber), ("win", false));
        assert!(s.apply("a b=2 !").processed);
        assert_eq!(s.select, Select::None);
        s.sampdens = 100;
        assert_eq!(s.flat_divisions(), (10, 31));
    }
}
