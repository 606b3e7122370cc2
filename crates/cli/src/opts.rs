//! Radiance-style option parsing on a declared option table.
//!
//! Radiance options are not POSIX: names have several letters (`-ab 4`), values may be
//! glued to the name (`-faf`), take several words (`-vd 0 -1 0`), and booleans toggle
//! (`-I`, `-I+`, `-I-`, `+I`). A tool declares its options in a [`Spec`]; [`Spec::parse`]
//! returns the options and positional words in command-line order, so tools whose options
//! apply to the next file (rmtxop, pcomb) can act on them in place. `--help` renders the
//! table through clap.

use anyhow::{anyhow, bail, Result};

/// What an option takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// No value: `-h`; `+h` is also accepted and reported through [`OptHit::plus`].
    Flag,
    /// Boolean: `-I` flips, `-I+`/`+I`/`-Iy` set, `-I-`/`-In` clear.
    Toggle,
    /// One integer word.
    Int,
    /// One real-number word.
    Real,
    /// One word.
    Word,
    /// Three real-number words (`-vd x y z`).
    Vec3,
    /// A fixed number of words.
    Words(usize),
    /// The rest of the argument after the name (`-faf` gives `af`; may be empty).
    Attached,
}

/// One declared option.
#[derive(Debug, Clone)]
pub struct Opt {
    /// Identifier the tool matches on (usually the name).
    pub key: &'static str,
    /// Name as typed after `-` or `+`.
    pub name: &'static str,
    /// What the option takes.
    pub kind: Kind,
    /// One-line help.
    pub help: &'static str,
}

impl Opt {
    /// An option whose key is its name.
    pub fn new(name: &'static str, kind: Kind, help: &'static str) -> Self {
        Opt {
            key: name,
            name,
            kind,
            help,
        }
    }

    /// An option with a key that differs from its name (for a name declared twice).
    pub fn keyed(key: &'static str, name: &'static str, kind: Kind, help: &'static str) -> Self {
        Opt {
            key,
            name,
            kind,
            help,
        }
    }

    fn value_words(&self) -> usize {
        match self.kind {
            Kind::Flag | Kind::Toggle | Kind::Attached => 0,
            Kind::Int | Kind::Real | Kind::Word => 1,
            Kind::Vec3 => 3,
            Kind::Words(n) => n,
        }
    }

    /// Whether this option accepts the text glued after its name.
    fn accepts_rest(&self, rest: &str) -> bool {
        match self.kind {
            Kind::Attached => true,
            Kind::Toggle => toggle_char(rest).is_some(),
            _ => rest.is_empty(),
        }
    }
}

/// A Radiance boolean option `arg` named `name` (`-I`, `+I`, `-I+`, `-Iy`, `-I0` …):
/// its new value given the `current` one, `None` when `arg` is not that option. `-name`
/// flips, `+name` sets; a suffix `+ y Y t T 1` sets and `- n N f F 0` clears, as
/// Radiance's `check_bool`. Every tool's toggles go through this rule.
pub fn bool_option(arg: &str, name: &str, current: bool) -> Option<bool> {
    let plus = arg.starts_with('+');
    if !plus && !arg.starts_with('-') {
        return None;
    }
    let rest = arg[1..].strip_prefix(name)?;
    match toggle_char(rest)? {
        None => Some(plus || !current),
        Some(v) => Some(v),
    }
}

fn toggle_char(rest: &str) -> Option<Option<bool>> {
    match rest {
        "" => Some(None),
        "+" | "y" | "Y" | "t" | "T" | "1" => Some(Some(true)),
        "-" | "n" | "N" | "f" | "F" | "0" => Some(Some(false)),
        _ => None,
    }
}

/// The value given to an option.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// A flag (no value).
    None,
    /// A toggle: `Some(v)` sets, `None` flips.
    Toggle(Option<bool>),
    /// Integer value.
    Int(i64),
    /// Real value.
    Real(f64),
    /// One word.
    Word(String),
    /// Three reals.
    Vec3([f64; 3]),
    /// Several words.
    Words(Vec<String>),
}

/// An option as found on the command line.
#[derive(Debug, Clone, PartialEq)]
pub struct OptHit {
    /// The declared key.
    pub key: &'static str,
    /// True when written with `+` instead of `-`.
    pub plus: bool,
    /// The value.
    pub value: Value,
    /// The argument as typed (for messages).
    pub text: String,
}

impl OptHit {
    /// Integer value (0 when the option is not an integer option).
    pub fn int(&self) -> i64 {
        match self.value {
            Value::Int(i) => i,
            Value::Real(r) => r as i64,
            _ => 0,
        }
    }

    /// The integer value when it is positive; otherwise an error with the message `msg`
    /// makes of the value.
    pub fn positive_int(&self, msg: impl FnOnce(i64) -> String) -> Result<i64> {
        let v = self.int();
        if v <= 0 {
            bail!("{}", msg(v));
        }
        Ok(v)
    }

    /// Real value (0 when the option is not numeric).
    pub fn real(&self) -> f64 {
        match self.value {
            Value::Real(r) => r,
            Value::Int(i) => i as f64,
            _ => 0.0,
        }
    }

    /// Word value (the glued text for attached options; empty otherwise).
    pub fn word(&self) -> &str {
        match &self.value {
            Value::Word(w) => w,
            _ => "",
        }
    }

    /// Three reals (zeros when not a vector option).
    pub fn vec3(&self) -> [f64; 3] {
        match self.value {
            Value::Vec3(v) => v,
            _ => [0.0; 3],
        }
    }

    /// The words of a [`Kind::Words`] option.
    pub fn words(&self) -> &[String] {
        match &self.value {
            Value::Words(w) => w,
            _ => &[],
        }
    }

    /// The words of a [`Kind::Words`] option as reals, with a clear error.
    pub fn reals(&self) -> Result<Vec<f64>> {
        self.words()
            .iter()
            .map(|w| {
                parse_real(w).ok_or_else(|| anyhow!("{}: expected a number, got '{w}'", self.text))
            })
            .collect()
    }

    /// New state of a boolean: `+x` and `-x+` set, `-x-` clears, plain `-x` flips.
    pub fn toggle(&self, current: bool) -> bool {
        match self.value {
            Value::Toggle(Some(v)) => v,
            Value::Toggle(None) => {
                if self.plus {
                    true
                } else {
                    !current
                }
            }
            _ => self.plus,
        }
    }
}

/// A command-line item: an option or a positional word.
#[derive(Debug, Clone, PartialEq)]
pub enum Item {
    /// An option.
    Opt(OptHit),
    /// A positional word (file name, number, `-` for stdin …).
    Pos(String),
}

/// The option table of one tool.
#[derive(Debug, Clone)]
pub struct Spec {
    prog: &'static str,
    about: &'static str,
    usage: Option<&'static str>,
    opts: Vec<Opt>,
    interleaved: bool,
}

impl Spec {
    /// A new table for program `prog`.
    pub fn new(prog: &'static str, about: &'static str) -> Self {
        Spec {
            prog,
            about,
            usage: None,
            opts: Vec::new(),
            interleaved: false,
        }
    }

    /// Adds an option.
    pub fn opt(mut self, o: Opt) -> Self {
        self.opts.push(o);
        self
    }

    /// Adds several options in order: a tool's option table, or a shared group such as the
    /// view options.
    pub fn opts(mut self, table: impl IntoIterator<Item = Opt>) -> Self {
        self.opts.extend(table);
        self
    }

    /// A usage line for `--help` (e.g. `"[options] V T D sky"`).
    pub fn usage(mut self, u: &'static str) -> Self {
        self.usage = Some(u);
        self
    }

    /// When true, options may follow positional words (rmtxop, pcomb); when false
    /// (Radiance's usual rule) everything after the first positional word is positional.
    pub fn interleaved(mut self, yes: bool) -> Self {
        self.interleaved = yes;
        self
    }

    /// The declared options.
    pub fn options(&self) -> &[Opt] {
        &self.opts
    }

    /// Parses `args` (args\[0\] = program name). `--help` prints help and returns [`crate::Exit`]`(0)`.
    pub fn parse(&self, args: &[String]) -> Result<Vec<Item>> {
        let mut items = Vec::new();
        let mut i = 1;
        let mut positional_only = false;
        while i < args.len() {
            let a = &args[i];
            i += 1;
            if a == "--help"
                || a == "-help" && !self.opts.iter().any(|o| "help".starts_with(o.name))
            {
                print!("{}", self.help_text());
                return Err(crate::Exit(0).into());
            }
            if a == "--version" {
                println!("{} (fenestra) {}", self.prog, env!("CARGO_PKG_VERSION"));
                return Err(crate::Exit(0).into());
            }
            // a negative number is a positional word unless it is a declared option
            // (genskyvec's `-5`)
            let is_opt = !positional_only
                && a.len() > 1
                && (a.starts_with('-') || a.starts_with('+'))
                && (!looks_numeric(a) || self.opts.iter().any(|o| o.name == &a[1..]));
            if !is_opt {
                items.push(Item::Pos(a.clone()));
                if !self.interleaved {
                    positional_only = true;
                }
                continue;
            }
            let plus = a.starts_with('+');
            let body = &a[1..];
            let opt = self
                .find(body)
                .ok_or_else(|| anyhow!("unknown option '{a}' (see '{} --help')", self.prog))?;
            let rest = &body[opt.name.len()..];
            let n = opt.value_words();
            if i + n > args.len() {
                bail!(
                    "option '{a}' needs {n} value{} ({})",
                    if n == 1 { "" } else { "s" },
                    opt.help
                );
            }
            let vals = &args[i..i + n];
            i += n;
            let value =
                match opt.kind {
                    Kind::Flag => Value::None,
                    Kind::Toggle => Value::Toggle(toggle_char(rest).flatten()),
                    Kind::Attached => Value::Word(rest.to_string()),
                    Kind::Int => Value::Int(parse_int(&vals[0]).ok_or_else(|| {
                        anyhow!("option '{a}' expects an integer, got '{}'", vals[0])
                    })?),
                    Kind::Real => Value::Real(parse_real(&vals[0]).ok_or_else(|| {
                        anyhow!("option '{a}' expects a number, got '{}'", vals[0])
                    })?),
                    Kind::Word => Value::Word(vals[0].clone()),
                    Kind::Vec3 => {
                        let mut v = [0.0; 3];
                        for (k, w) in vals.iter().enumerate() {
                            v[k] = parse_real(w).ok_or_else(|| {
                                anyhow!(
                                    "option '{a}' expects three numbers, got '{}'",
                                    vals.join(" ")
                                )
                            })?;
                        }
                        Value::Vec3(v)
                    }
                    Kind::Words(_) => Value::Words(vals.to_vec()),
                };
            items.push(Item::Opt(OptHit {
                key: opt.key,
                plus,
                value,
                text: a.clone(),
            }));
        }
        Ok(items)
    }

    /// [`Spec::parse`] with the options and the positional words returned apart, each in
    /// command-line order (for tools that do not apply options to the file that follows).
    pub fn parse_apart(&self, args: &[String]) -> Result<(Vec<OptHit>, Vec<String>)> {
        let mut hits = Vec::new();
        let mut words = Vec::new();
        for item in self.parse(args)? {
            match item {
                Item::Opt(hit) => hits.push(hit),
                Item::Pos(word) => words.push(word),
            }
        }
        Ok((hits, words))
    }

    /// The longest declared name that prefixes `body` and accepts what follows it;
    /// among equal names a non-attached option that takes the empty rest wins.
    fn find(&self, body: &str) -> Option<&Opt> {
        let mut best: Option<&Opt> = None;
        for o in &self.opts {
            if !body.starts_with(o.name) || !o.accepts_rest(&body[o.name.len()..]) {
                continue;
            }
            best = match best {
                None => Some(o),
                Some(b) if o.name.len() > b.name.len() => Some(o),
                Some(b)
                    if o.name.len() == b.name.len()
                        && b.kind == Kind::Attached
                        && o.kind != Kind::Attached =>
                {
                    Some(o)
                }
                keep => keep,
            };
        }
        best
    }

    /// The `--help` text: clap renders name, about and usage; the option table follows
    /// in Radiance's spelling (clap cannot spell multi-letter single-dash options).
    pub fn help_text(&self) -> String {
        let rows: Vec<(String, &str)> = self
            .opts
            .iter()
            .map(|o| {
                let shown = match o.kind {
                    Kind::Flag => format!("-{}", o.name),
                    Kind::Toggle => format!("-{}[+|-]", o.name),
                    Kind::Int => format!("-{} N", o.name),
                    Kind::Real => format!("-{} X", o.name),
                    Kind::Word => format!("-{} WORD", o.name),
                    Kind::Vec3 => format!("-{} X Y Z", o.name),
                    Kind::Words(n) => format!("-{} {}", o.name, vec!["W"; n].join(" ")),
                    Kind::Attached => format!("-{}VALUE", o.name),
                };
                (shown, o.help)
            })
            .collect();
        let width = rows.iter().map(|r| r.0.len()).max().unwrap_or(0);
        let mut table = String::from("Options:\n");
        for (shown, help) in &rows {
            table.push_str(&format!("  {shown:<width$}  {help}\n"));
        }
        table.push_str(
            "\nOptions use Radiance's syntax: -ab 4, -faf, -vd x y z, -I/-I+/-I-/+I, @optfile, $VAR.",
        );
        table.push_str(&format!(
            "\nFull documentation: fenestra doc {0} (docs/tools/{0}.md in the source).",
            self.prog
        ));
        let mut cmd = clap::Command::new(self.prog)
            .about(self.about)
            .disable_help_flag(true)
            .disable_version_flag(true)
            .after_help(table);
        if let Some(u) = self.usage {
            cmd = cmd.override_usage(format!("{} {}", self.prog, u));
        }
        cmd.render_help().to_string()
    }
}

/// Whether an argument is a negative number (a positional, not an option).
fn looks_numeric(a: &str) -> bool {
    a.len() > 1
        && a.starts_with('-')
        && a[1..].starts_with(|c: char| c.is_ascii_digit() || c == '.')
        && parse_real(a).is_some()
}

/// Parses an integer word (also accepts a real with no fraction, e.g. `4.0`).
pub fn parse_int(w: &str) -> Option<i64> {
    w.trim().parse::<i64>().ok().or_else(|| {
        let r = parse_real(w)?;
        (r.fract() == 0.0 && r.abs() < 9.0e18).then_some(r as i64)
    })
}

/// Parses a real word (finite values only).
pub fn parse_real(w: &str) -> Option<f64> {
    let v: f64 = w.trim().parse().ok()?;
    v.is_finite().then_some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(v: &[&str]) -> Vec<String> {
        v.iter().map(|x| x.to_string()).collect()
    }

    fn rc_spec() -> Spec {
        Spec::new("rcontrib", "test")
            .opt(Opt::new("ab", Kind::Int, "bounces"))
            .opt(Opt::new("ad", Kind::Int, "divisions"))
            .opt(Opt::new("a", Kind::Flag, "a flag named a"))
            .opt(Opt::keyed("fmt", "f", Kind::Attached, "format"))
            .opt(Opt::keyed("cal", "f", Kind::Word, "cal file"))
            .opt(Opt::keyed("fo", "fo", Kind::Toggle, "force"))
            .opt(Opt::new("I", Kind::Toggle, "irradiance"))
            .opt(Opt::new("vd", Kind::Vec3, "direction"))
            .opt(Opt::new("c", Kind::Words(3), "colour"))
    }

    #[test]
    fn bool_options_as_radiance() {
        assert_eq!(bool_option("-I", "I", false), Some(true));
        assert_eq!(bool_option("-I", "I", true), Some(false));
        assert_eq!(bool_option("+I", "I", true), Some(true));
        for on in ["-I+", "-Iy", "-IY", "-It", "-IT", "-I1", "+I1"] {
            assert_eq!(bool_option(on, "I", false), Some(true), "{on}");
        }
        for off in ["-I-", "-In", "-IN", "-If", "-IF", "-I0"] {
            assert_eq!(bool_option(off, "I", true), Some(false), "{off}");
        }
        assert_eq!(bool_option("-Io", "I", false), None);
        assert_eq!(bool_option("-i", "I", false), None);
        assert_eq!(bool_option("I", "I", false), None);
    }

    #[test]
    fn radiance_forms_parse() {
        let items = rc_spec()
            .parse(&s(&[
                "rcontrib",
                "-ab",
                "4",
                "-faf",
                "-f",
                "x.cal",
                "-fo",
                "-I+",
                "+I",
                "-I",
                "-vd",
                "0",
                "-1",
                "0",
                "-c",
                "1",
                "2",
                "3",
                "-a",
                "scene.oct",
                "-ab",
            ]))
            .unwrap();
        let keys: Vec<_> = items
            .iter()
            .map(|i| match i {
                Item::Opt(o) => o.key.to_string(),
                Item::Pos(p) => format!("pos:{p}"),
            })
            .collect();
        assert_eq!(
            keys,
            s(&[
                "ab",
                "fmt",
                "cal",
                "fo",
                "I",
                "I",
                "I",
                "vd",
                "c",
                "a",
                "pos:scene.oct",
                "pos:-ab"
            ])
        );
        let Item::Opt(ab) = &items[0] else { panic!() };
        assert_eq!(ab.int(), 4);
        let Item::Opt(f) = &items[1] else { panic!() };
        assert_eq!(f.word(), "af");
        let Item::Opt(i1) = &items[4] else { panic!() };
        assert!(i1.toggle(false));
        let Item::Opt(i2) = &items[5] else { panic!() };
        assert!(i2.toggle(false));
        let Item::Opt(i3) = &items[6] else { panic!() };
        assert!(i3.toggle(false) && !i3.toggle(true));
        let Item::Opt(vd) = &items[7] else { panic!() };
        assert_eq!(vd.vec3(), [0.0, -1.0, 0.0]);
    }

    #[test]
    fn interleaved_mode_keeps_parsing_after_files() {
        let spec =
            Spec::new("rmtxop", "t")
                .interleaved(true)
                .opt(Opt::new("t", Kind::Flag, "transpose"));
        let items = spec.parse(&s(&["rmtxop", "a", "-t", "b", "-"])).unwrap();
        assert_eq!(items.len(), 4);
        assert!(matches!(&items[1], Item::Opt(o) if o.key == "t"));
        assert_eq!(items[3], Item::Pos("-".into()));
    }

    #[test]
    fn errors_are_clear() {
        let e = rc_spec().parse(&s(&["x", "-zz"])).unwrap_err().to_string();
        assert!(e.contains("unknown option '-zz'"), "{e}");
        let e = rc_spec()
            .parse(&s(&["x", "-ab", "four"]))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("expects an integer") && e.contains("four"),
            "{e}"
        );
        let e = rc_spec()
            .parse(&s(&["x", "-vd", "1", "2"]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("needs 3 values"), "{e}");
        let e = rc_spec()
            .parse(&s(&["x", "-ab", "nan"]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("expects an integer"), "{e}");
    }

    #[test]
    fn negative_numbers_are_positional() {
        let spec = Spec::new("t", "t")
            .interleaved(true)
            .opt(Opt::new("s", Kind::Real, "scale"));
        let items = spec.parse(&s(&["t", "-s", "-2.5", "-3"])).unwrap();
        assert!(matches!(&items[0], Item::Opt(o) if o.real() == -2.5));
        assert_eq!(items[1], Item::Pos("-3".into()));
    }

    #[test]
    fn option_tables_and_positive_integers() {
        let spec = Spec::new("t", "t").opts([
            Opt::new("n", Kind::Int, "count"),
            Opt::new("h", Kind::Flag, "header"),
        ]);
        assert_eq!(spec.options().len(), 2);
        let items = spec.parse(&s(&["t", "-n", "3", "-n", "0"])).unwrap();
        let msg = |v: i64| format!("-n {v}: must be positive");
        let Item::Opt(three) = &items[0] else {
            panic!()
        };
        assert_eq!(three.positive_int(msg).unwrap(), 3);
        let Item::Opt(zero) = &items[1] else { panic!() };
        let e = zero.positive_int(msg).unwrap_err().to_string();
        assert_eq!(e, "-n 0: must be positive");
    }

    #[test]
    fn options_and_words_apart() {
        let spec = Spec::new("t", "t")
            .interleaved(true)
            .opt(Opt::new("c", Kind::Int, "count"));
        let (hits, words) = spec.parse_apart(&s(&["t", "a", "-c", "2", "b"])).unwrap();
        assert_eq!(hits.len(), 1);
        assert_eq!((hits[0].key, hits[0].int()), ("c", 2));
        assert_eq!(words, s(&["a", "b"]));
    }

    #[test]
    fn help_lists_options() {
        let h = rc_spec().help_text();
        assert!(
            h.contains("-ab N") && h.contains("bounces") && h.contains("-vd X Y Z"),
            "{h}"
        );
    }
}
