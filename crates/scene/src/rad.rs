//! The Radiance scene-description parser (`.rad`): primitives, `void`, `alias`,
//! statement comments and `!command` lines.

use std::fmt::Write as _;
use std::sync::Arc;

use anyhow::{anyhow, bail, Context, Result};

use crate::model::{Loc, Primitive, Scene};
use crate::source::{command_output, decode_text};
use crate::words::{parse_count, parse_real, Words};

/// Builds a [`Scene`] from several inputs; modifiers resolve across inputs in order.
#[derive(Debug, Default)]
pub struct Parser {
    scene: Scene,
    /// With [`Parser::keeping_real_words`]: each primitive's real arguments as written
    /// (empty for primitives that did not come from Radiance text).
    real_words: Option<Vec<Vec<String>>>,
}

/// How deep `!command` output may itself run commands.
const MAX_COMMAND_DEPTH: usize = 32;

impl Parser {
    /// An empty parser.
    pub fn new() -> Self {
        Parser::default()
    }

    /// A parser that also keeps every primitive's real arguments as written (for tools that
    /// print them back verbatim, as genskyvec prints the sun's radiance).
    pub fn keeping_real_words() -> Self {
        Parser {
            real_words: Some(Vec::new()),
            ..Parser::default()
        }
    }

    /// The scene read so far.
    pub fn finish(self) -> Scene {
        self.scene
    }

    /// The scene read so far and, per primitive, its real arguments as written (empty
    /// lists unless the parser was made by [`Parser::keeping_real_words`]).
    pub fn finish_with_words(self) -> (Scene, Vec<Vec<String>>) {
        let n = self.scene.prims.len();
        let mut words = self.real_words.unwrap_or_default();
        words.resize(n, Vec::new());
        (self.scene, words)
    }

    fn pad_words(&mut self) {
        let n = self.scene.prims.len();
        if let Some(w) = self.real_words.as_mut() {
            w.resize(n, Vec::new());
        }
    }

    /// The scene read so far, by reference.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Reads one input: `-` is standard input, a name ending in `.mgf` is MGF, anything
    /// else Radiance scene text.
    pub fn add_path(&mut self, path: &str) -> Result<()> {
        if path == "-" {
            let mut bytes = Vec::new();
            std::io::Read::read_to_end(&mut std::io::stdin(), &mut bytes)
                .context("cannot read the scene from standard input")?;
            return self.add_str(&decode_text(bytes), "-");
        }
        let bytes =
            std::fs::read(path).with_context(|| format!("cannot open scene file '{path}'"))?;
        if crate::compiled::is_radiance_octree(&bytes) {
            let oct =
                crate::radoct::read(&bytes).with_context(|| format!("{path}: Radiance octree"))?;
            return match oct {
                crate::radoct::RadianceOctree::Frozen(text) => self.add_str(&text, path),
                crate::radoct::RadianceOctree::Files(files) => {
                    for f in files {
                        self.add_path(&f)
                            .with_context(|| format!("{path}: a scene file the octree lists"))?;
                    }
                    Ok(())
                }
            };
        }
        if crate::compiled::is_compiled(&bytes) {
            let c = crate::compiled::read(&bytes).with_context(|| path.to_string())?;
            return self.add_scene(c.scene);
        }
        let text = decode_text(bytes);
        if path.to_ascii_lowercase().ends_with(".mgf") {
            return self.add_mgf(&text, path);
        }
        self.add_str(&text, path)
    }

    /// Reads MGF text (converted to Radiance primitives as mgf2rad does); `file` names
    /// it in locations and locates its includes.
    pub fn add_mgf(&mut self, text: &str, file: &str) -> Result<()> {
        let prims = crate::mgf::convert(text, file)?;
        self.add_converted(prims)
    }

    /// Appends an already-resolved scene (e.g. a compiled one), shifting its modifier indices.
    pub fn add_scene(&mut self, scene: Scene) -> Result<()> {
        let off = self.scene.prims.len();
        for mut p in scene.prims {
            p.modifier = p.modifier.map(|m| m + off);
            self.scene.prims.push(p);
        }
        self.pad_words();
        Ok(())
    }

    /// Appends primitives produced by a converter (MGF), resolving their modifiers by name.
    pub(crate) fn add_converted(&mut self, prims: Vec<Primitive>) -> Result<()> {
        for mut p in prims {
            p.modifier = self.resolve_modifier(&p.modifier_name, &p.loc, &p.ptype, &p.name)?;
            self.scene.prims.push(p);
        }
        self.pad_words();
        Ok(())
    }

    /// Reads Radiance scene text; `file` names it in locations and messages.
    pub fn add_str(&mut self, text: &str, file: &str) -> Result<()> {
        self.add_text(text, Arc::from(file), 0)
    }

    fn add_text(&mut self, text: &str, file: Arc<str>, depth: usize) -> Result<()> {
        let mut w = Words::new(text);
        while let Some(c) = w.skip_space() {
            let line = w.line();
            let loc = Loc {
                file: file.clone(),
                line,
            };
            match c {
                b'#' => {
                    w.rest_of_line();
                }
                b'!' => {
                    let (cmd, open) = w.command();
                    if open {
                        bail!("{loc}: unterminated !command (the last line ends with '\\' at end of input): !{}", cmd.trim_end());
                    }
                    self.run_command(&cmd, &loc, depth)?;
                }
                _ => self.primitive(&mut w, &loc)?,
            }
        }
        Ok(())
    }

    fn run_command(&mut self, cmd: &str, loc: &Loc, depth: usize) -> Result<()> {
        if depth >= MAX_COMMAND_DEPTH {
            bail!("{loc}: !commands nested more than {MAX_COMMAND_DEPTH} deep: !{cmd}");
        }
        let out = command_output(cmd).with_context(|| format!("{loc}: !{cmd}"))?;
        let name: Arc<str> = Arc::from(format!("!{}", short_command(cmd)));
        self.add_text(&out, name, depth + 1)
            .with_context(|| format!("in the output of the !command at {loc}"))
    }

    fn primitive(&mut self, w: &mut Words, loc: &Loc) -> Result<()> {
        let word = |w: &mut Words, what: &str| -> Result<String> {
            match w.word() {
                Ok(Some(s)) => Ok(s),
                Ok(None) => Err(anyhow!("{loc}: unexpected end of input, expected {what}")),
                Err(e) => Err(anyhow!("{loc}: {e}")),
            }
        };
        let modifier_name = word(w, "a modifier name")?;
        let ptype = word(
            w,
            &format!("a primitive type after modifier '{modifier_name}'"),
        )?;
        let name = word(w, &format!("an identifier after '{modifier_name} {ptype}'"))?;
        if ptype == "alias" {
            let target = word(w, &format!("the name aliased by '{name}'"))?;
            return self.alias(modifier_name, name, target, loc);
        }
        let rule = crate::types::rule(&ptype).ok_or_else(|| {
            anyhow!(
                "{loc}: unknown primitive type '{ptype}' (for '{modifier_name} {ptype} {name}')"
            )
        })?;
        let what = format!("{} {}", rule.name, name);
        let count = |w: &mut Words, kind: &str| -> Result<usize> {
            let s = word(w, &format!("the {kind}-argument count of {what}"))?;
            parse_count(&s).ok_or_else(|| {
                anyhow!("{loc}: {what}: expected the {kind}-argument count, got '{s}'")
            })
        };
        // the string or integer arguments: their count, then as many words
        let args = |w: &mut Words, kind: &str| -> Result<Vec<String>> {
            let n = count(w, kind)?;
            let mut v = Vec::with_capacity(n.min(64)); // counts are checked by what follows
            for k in 0..n {
                v.push(word(
                    w,
                    &format!("{kind} argument {} of {n} of {what}", k + 1),
                )?);
            }
            Ok(v)
        };
        let sargs = args(w, "string")?;
        let ns = sargs.len();
        let iargs = args(w, "integer")?;
        let ni = iargs.len();
        let nr = count(w, "real")?;
        let mut rargs = Vec::with_capacity(nr.min(64));
        let mut rwords = Vec::new();
        for k in 0..nr {
            let s = word(w, &format!("real argument {} of {nr} of {what}", k + 1))?;
            let v = parse_real(&s).ok_or_else(|| {
                anyhow!(
                    "{loc}: {what}: real argument {} is not a number: '{s}'",
                    k + 1
                )
            })?;
            rargs.push(v);
            if self.real_words.is_some() {
                rwords.push(s);
            }
        }
        crate::types::check(&ptype, ns, ni, nr).map_err(|e| anyhow!("{loc}: {what}: {e}"))?;
        let modifier = self.resolve_modifier(&modifier_name, loc, &ptype, &name)?;
        self.scene.prims.push(Primitive {
            modifier,
            modifier_name,
            ptype,
            name,
            sargs,
            iargs,
            rargs,
            loc: loc.clone(),
        });
        if let Some(words) = self.real_words.as_mut() {
            words.resize(self.scene.prims.len() - 1, Vec::new());
            words.push(rwords);
        }
        Ok(())
    }

    fn resolve_modifier(
        &self,
        modifier_name: &str,
        loc: &Loc,
        ptype: &str,
        name: &str,
    ) -> Result<Option<usize>> {
        if modifier_name == "void" {
            return Ok(None);
        }
        match self
            .scene
            .find_modifier(modifier_name, self.scene.prims.len())
        {
            Some(i) => Ok(Some(i)),
            None => bail!("{loc}: undefined modifier '{modifier_name}' (used by {ptype} '{name}')"),
        }
    }

    /// `modifier alias newid oldid`: a copy of modifier `oldid` named `newid`, modified
    /// by `modifier` (or by `oldid`'s own modifier when `modifier` is `inherit`).
    fn alias(
        &mut self,
        modifier_name: String,
        name: String,
        target: String,
        loc: &Loc,
    ) -> Result<()> {
        let n = self.scene.prims.len();
        let t = self.scene.find_modifier(&target, n).ok_or_else(|| {
            anyhow!("{loc}: alias '{name}' refers to undefined modifier '{target}'")
        })?;
        let orig = &self.scene.prims[t];
        let (modifier, modifier_name) = if modifier_name == "inherit" {
            (orig.modifier, orig.modifier_name.clone())
        } else {
            let m = self.resolve_modifier(&modifier_name, loc, "alias", &name)?;
            (m, modifier_name)
        };
        let p = Primitive {
            modifier,
            modifier_name,
            ptype: orig.ptype.clone(),
            name,
            sargs: orig.sargs.clone(),
            iargs: orig.iargs.clone(),
            rargs: orig.rargs.clone(),
            loc: loc.clone(),
        };
        self.scene.prims.push(p);
        if let Some(words) = self.real_words.as_mut() {
            // an alias's arguments are its target's, words included
            let w = words.get(t).cloned().unwrap_or_default();
            words.resize(n, Vec::new());
            words.push(w);
        }
        Ok(())
    }
}

/// A command shortened for use as a location's file name.
fn short_command(cmd: &str) -> String {
    let one: String = cmd.split_whitespace().collect::<Vec<_>>().join(" ");
    if one.chars().count() > 60 {
        let s: String = one.chars().take(57).collect();
        format!("{s}...")
    } else {
        one
    }
}

/// Parses Radiance scene text into a scene; `file` names it in messages.
pub fn parse_str(text: &str, file: &str) -> Result<Scene> {
    let mut p = Parser::new();
    p.add_str(text, file)?;
    Ok(p.finish())
}

/// Loads and concatenates scene inputs (`.rad` or anything else as Radiance text, `.mgf`
/// as MGF, `-` for standard input, compiled scenes from `oconv`); modifiers resolve across
/// files in order. A Radiance octree is refused with a message to pass the .rad files.
pub fn load(paths: &[&str]) -> Result<Scene> {
    let mut p = Parser::new();
    for path in paths {
        p.add_path(path)?;
    }
    Ok(p.finish())
}

/// Formats a real as C's `%g` does (6 significant digits).
pub(crate) fn fmt_g(v: f64, prec: usize) -> String {
    crate::cfmt::g(v, prec)
}

/// Appends one primitive in Radiance syntax.
pub(crate) fn write_primitive(s: &mut String, p: &Primitive) {
    let _ = writeln!(s, "\n{} {} {}", p.modifier_name, p.ptype, p.name);
    let _ = write!(s, "{}", p.sargs.len());
    for a in &p.sargs {
        let _ = write!(s, " {}", quote(a));
    }
    let _ = write!(s, "\n{}", p.iargs.len());
    for a in &p.iargs {
        let _ = write!(s, " {a}");
    }
    let _ = write!(s, "\n{}", p.rargs.len());
    for v in &p.rargs {
        let _ = write!(s, " {}", fmt_g(*v, 17));
    }
    s.push('\n');
}

fn quote(w: &str) -> String {
    if w.is_empty() || w.chars().any(|c| c.is_whitespace()) {
        if w.contains('"') {
            format!("'{w}'")
        } else {
            format!("\"{w}\"")
        }
    } else {
        w.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn real_words_are_kept_as_written_when_asked() {
        let text = "void light solar 0 0 3 6.643e+06 6.643E6 16\nsolar source sun 0 0 4 .5 -.5 .7 0.5\nvoid alias copy solar\n";
        let mut p = Parser::keeping_real_words();
        p.add_str(text, "t").unwrap();
        let (scene, words) = p.finish_with_words();
        assert_eq!(words.len(), scene.prims.len());
        assert_eq!(words[0], ["6.643e+06", "6.643E6", "16"]);
        assert_eq!(scene.prims[0].rargs, [6.643e6, 6.643e6, 16.0]);
        assert_eq!(words[1], [".5", "-.5", ".7", "0.5"]);
        assert_eq!(words[2], words[0]);
        // a plain parser keeps none
        let mut q = Parser::new();
        q.add_str(text, "t").unwrap();
        assert!(q.finish_with_words().1.iter().all(Vec::is_empty));
    }

    const SCENE: &str = "# a comment\nvoid plastic red 0 0 5 .5 .1 .1 0 0\n\
red polygon p1 0 0 12 0 0 0 1 0 0 1 1 0 0 1 0\n\
void brightfunc sky 2 skybr skybright.cal 0 7 1 2 3 4 5 6 7\n\
sky glow g 0 0 4 1 1 1 0\ng source sun 0 0 4 0 0 1 180\n\
sky alias red2 red\ninherit alias red3 red\nred2 \"sphere\" s 0 0 4 1 2 3 .5\n";

    #[test]
    fn parses_and_resolves() {
        let s = parse_str(SCENE, "t.rad").unwrap();
        assert_eq!(s.prims.len(), 8);
        assert_eq!(s.prims[1].modifier, Some(0));
        assert_eq!(s.prims[1].rargs.len(), 12);
        assert_eq!(s.prims[1].loc.line, 3);
        assert_eq!(s.prims[4].modifier, Some(3));
        assert_eq!(s.prims[5].ptype, "plastic");
        assert_eq!(s.prims[5].modifier, Some(2));
        assert_eq!(s.prims[6].modifier, None);
        assert_eq!(s.prims[7].modifier, Some(5));
        assert_eq!(s.prims[7].ptype, "sphere");
        assert_eq!(s.prims[2].sargs, vec!["skybr", "skybright.cal"]);
    }

    #[test]
    fn most_recent_definition_wins() {
        let t = "void plastic m 0 0 5 1 1 1 0 0\nm polygon m 0 0 9 0 0 0 1 0 0 0 1 0\n\
void metal m 0 0 5 1 1 1 0 0\nm sphere s 0 0 4 0 0 0 1\n";
        let s = parse_str(t, "t").unwrap();
        assert_eq!(s.prims[1].modifier, Some(0));
        assert_eq!(s.prims[3].modifier, Some(2));
    }

    #[test]
    fn errors_name_file_and_line() {
        let cases = [
            (
                "void plastic m 0 0 4 1 1 1 0\n",
                "t.rad:1",
                "real arguments",
            ),
            (
                "\n\nfoo polygon p 0 0 9 0 0 0 1 0 0 0 1 0\n",
                "t.rad:3",
                "undefined modifier 'foo'",
            ),
            (
                "void blob b 0 0 0\n",
                "t.rad:1",
                "unknown primitive type 'blob'",
            ),
            (
                "void plastic m 0 0 5 1 1 x 0 0\n",
                "t.rad:1",
                "not a number",
            ),
            ("void plastic m 0 0 5 1 1\n", "t.rad:1", "end of input"),
            ("!echo a \\", "t.rad:1", "unterminated !command"),
            ("\n!exit 3\n", "t.rad:2", "command failed"),
            (
                "void plastic m 1 x 0 5 1 1 1 0 0\n",
                "t.rad:1",
                "string arguments",
            ),
            (
                "void alias a nothing\n",
                "t.rad:1",
                "undefined modifier 'nothing'",
            ),
        ];
        for (text, at, what) in cases {
            let e = format!("{:#}", parse_str(text, "t.rad").unwrap_err());
            assert!(e.contains(at) && e.contains(what), "{text:?} → {e}");
        }
    }

    #[test]
    fn commands_are_run() {
        let t = "void plastic m 0 0 5 1 1 1 0 0\n!echo m sphere s 0 0 4 0 0 0 1\n";
        let s = parse_str(t, "t").unwrap();
        assert_eq!(s.prims.len(), 2);
        assert_eq!(&*s.prims[1].loc.file, "!echo m sphere s 0 0 4 0 0 0 1");
        let e = format!(
            "{:#}",
            parse_str("!echo m sphere s 0 0 4 0 0 0 1\n", "t").unwrap_err()
        );
        assert!(e.contains("t:1") && e.contains("undefined modifier"), "{e}");
    }

    #[test]
    fn xform_commands_run_in_process() {
        let d = std::env::temp_dir().join(format!("fenestra-scene-xf-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let f = d.join("box.rad");
        std::fs::write(
            &f,
            "void plastic m 0 0 5 1 1 1 0 0\nm sphere s 0 0 4 1 0 0 1\n",
        )
        .unwrap();
        let t = format!("!xform -n a -rz 90 -t 0 0 2 {}\n", f.display());
        let s = parse_str(&t, "t").unwrap();
        assert_eq!(s.prims[1].name, "a.s");
        let c = &s.prims[1].rargs;
        assert!(
            c[0].abs() < 1e-12 && (c[1] - 1.0).abs() < 1e-12 && c[2] == 2.0,
            "{c:?}"
        );
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn round_trip_through_text() {
        let s = parse_str(SCENE, "t").unwrap();
        let again = parse_str(&s.to_rad(), "t").unwrap();
        for (a, b) in s.prims.iter().zip(&again.prims) {
            assert_eq!(
                (&a.ptype, &a.name, &a.sargs, &a.rargs),
                (&b.ptype, &b.name, &b.sargs, &b.rargs)
            );
        }
    }
}
