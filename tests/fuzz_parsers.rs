//! Fuzzing of every parser with proptest: matrices, pictures, information headers, `.rad`
//! scenes, MGF, `.cal` programs and expressions, BSDF XML and tensor trees, `.wea`/`.epw`
//! weather tapes, option files and view files. Each test takes small real inputs (fixtures,
//! `lib/*.cal`, or short texts written here when no small fixture exists) and applies up to
//! eight random edits: bytes replaced, flipped, inserted, deleted or duplicated, the input
//! truncated, interesting tokens (`nan`, `1e308`, `99999999999`, `NROWS=100000000`, braces,
//! NUL and 0xFF bytes, multi-byte characters …) inserted or put in place of a word.
//!
//! Property: the parser returns `Ok` or `Err` and never panics; where it returns numbers,
//! what the code guarantees is checked too (no NaN unless the input spells `nan`, finite
//! scene reals and picture pixels, non-negative BSDF values, valid weather dates).
//!
//! Bounded for CI: each test runs `FENESTRA_FUZZ_CASES` mutated inputs (default 8000, about ten
//! seconds in all with the optimised test profile). Longer runs locally:
//!
//! ```text
//! FENESTRA_FUZZ_CASES=100000 cargo test --profile testopt --test fuzz_parsers
//! ```
//!
//! Checks run on a thread with the tools' 1 GiB stack (`fenestra_cli::threads::STACK_BYTES`):
//! recursion within the parsers' own depth limits is legitimate. A failure names the parser
//! and prints the shrunk input (text and byte string, first 400 bytes). No failure-persistence
//! file is kept: each crash found becomes an explicit `#[test]` calling `assert_survives` at
//! the end of this file. A huge allocation or a stack overflow aborts the process instead; the
//! input under test is then left in `$TMPDIR/fenestra-fuzz-<pid>-<parser>.last`.
//!
//! Two legitimate inputs are neutralised because they are unsafe here: `!command` lines of
//! `.rad` text (every `!` becomes `#`, or mutations would run shell commands) and, in MGF,
//! includes of files other than the fixture's `sub/part.mgf` and arrays or iterations of more
//! than `MGF_MAX_INSTANCES` instances in all (they read arbitrary files or run for hours).

use std::any::Any;
use std::io::Cursor;
use std::panic::{self, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use fenestra_bsdf::{parse as parse_bsdf, BlockData, KlemsBasis, TensorTree};
use fenestra_calc::Program;
use fenestra_cli::expand::split_words;
use fenestra_cli::opts::{Kind, Opt, Spec};
use fenestra_cli::threads::STACK_BYTES;
use fenestra_formats::picture::Picture;
use fenestra_formats::view::View;
use fenestra_formats::{DataFormat, Header, Matrix, MatrixReader};
use fenestra_scene::{parse_str, Parser};
use fenestra_sky::weather::read_tape;
use proptest::collection::vec;
use proptest::prelude::{any, prop_oneof, ProptestConfig, Strategy, TestCaseError};
use proptest::sample::Index;
use proptest::test_runner::{TestError, TestRunner};

/// Cases per parser when `FENESTRA_FUZZ_CASES` is not set.
const DEFAULT_CASES: u32 = 8000;
/// Most edits applied to one seed.
const MAX_EDITS: usize = 8;
/// Bytes of a failing input shown in a failure message.
const SHOW: usize = 400;
/// Instances (`-a N` arrays times `-i N` iterations) a mutated MGF input may ask for in all.
const MGF_MAX_INSTANCES: u64 = 256;

/// Tokens inserted or put in place of a word: numbers parsers choke on, size fields,
/// structure characters of the formats, bytes that are not text.
const TOKENS: &[&[u8]] = &[
    b"nan",
    b"-NaN",
    b"inf",
    b"-inf",
    b"-1",
    b"0",
    b"1e308",
    b"-1e308",
    b"1e-320",
    b"99999999999",
    b"18446744073709551616",
    b"4294967296",
    b"NROWS=100000000",
    b"NCOLS=0",
    b"NCOMP=1",
    b"FORMAT=float",
    b"FORMAT=double",
    b"FORMAT=ascii",
    b"FORMAT=32-bit_rle_rgbe",
    b"EXPOSURE=0",
    b"BigEndian=1",
    b"-Y 3 +X",
    b"\x02\x02\x00\x11",
    b"\x02\x02\x7f\xff",
    b"\x01\x01\x01\xff",
    b"{",
    b"}",
    b"(",
    b")",
    b"\"",
    b"'",
    b";",
    b",",
    b":",
    b"=",
    b"#",
    b"\\\n",
    b"\n",
    b"\r\n",
    b"\t",
    b"\0",
    b"\xff\xff",
    b"\xc3\xa9",
    b"\xe2\x82\xac",
    b"\xf0\x9f\x98\x80",
    b"<",
    b">",
    b"</",
    b"/>",
    b"<!--",
    b"<![CDATA[",
    b"&amp;",
    b"&#0;",
    b"&bogus;",
    b"xf",
    b"-a",
    b"-i",
    b"o",
    b"$1",
    b"-vf",
    b".",
    b"e",
];

/// A parser under test: `Err` describes a violated property (errors of the parser itself
/// are fine and ignored).
type Check = fn(&[u8]) -> Result<(), String>;

/// Every parser, for the degenerate-input test.
const PARSERS: &[(&str, Check)] = &[
    ("matrix", check_matrix),
    ("picture", check_picture),
    ("header", check_header),
    ("rad", check_rad),
    ("mgf", check_mgf),
    ("cal", check_cal),
    ("cal expression", check_expr),
    ("BSDF XML", check_bsdf),
    ("tensor tree", check_tree),
    ("weather", check_weather),
    ("option file", check_options),
    ("view file", check_view),
];

/// Degenerate inputs every parser must survive.
const TINY_INPUTS: &[&[u8]] = &[
    b"",
    b"\n",
    b"\n\n",
    b"\0",
    b"\xff",
    b"\r",
    b"{",
    b"}",
    b"(",
    b"\"",
    b"#?RADIANCE\n\n",
    b"#?RADIANCE\nFORMAT=ascii\nNCOLS=1\n\n",
    b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 0 +X 0\n",
    b"place ",
    b"LOCATION,",
    b"<WindowElement/>",
    b"xf -a",
    b"i",
    b"void",
];

/// One edit of an input; positions are taken modulo the current length.
#[derive(Debug, Clone)]
enum Edit {
    /// Replace a byte.
    Set(Index, u8),
    /// Flip one bit of a byte.
    Flip(Index, u8),
    /// Insert random bytes.
    Insert(Index, Vec<u8>),
    /// Insert one of [`TOKENS`].
    Token(Index, usize),
    /// Replace the word around a position by one of [`TOKENS`].
    Word(Index, usize),
    /// Delete up to this many bytes.
    Delete(Index, usize),
    /// Cut the input short.
    Truncate(Index),
    /// Repeat up to this many bytes right after themselves.
    Duplicate(Index, usize),
}

/// A random edit, tokens and word replacements weighted up (they reach the parsers' fields).
fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        2 => (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Edit::Set(i, b)),
        2 => (any::<Index>(), 0u8..8).prop_map(|(i, b)| Edit::Flip(i, b)),
        2 => (any::<Index>(), vec(any::<u8>(), 1..8)).prop_map(|(i, b)| Edit::Insert(i, b)),
        4 => (any::<Index>(), 0..TOKENS.len()).prop_map(|(i, t)| Edit::Token(i, t)),
        4 => (any::<Index>(), 0..TOKENS.len()).prop_map(|(i, t)| Edit::Word(i, t)),
        2 => (any::<Index>(), 1usize..32).prop_map(|(i, n)| Edit::Delete(i, n)),
        1 => any::<Index>().prop_map(Edit::Truncate),
        2 => (any::<Index>(), 1usize..64).prop_map(|(i, n)| Edit::Duplicate(i, n)),
    ]
}

/// One of `seeds` with 1 to [`MAX_EDITS`] edits applied.
fn mutated(seeds: Vec<Vec<u8>>) -> impl Strategy<Value = Vec<u8>> {
    (0..seeds.len(), vec(edit(), 1..=MAX_EDITS))
        .prop_map(move |(k, edits)| apply(&seeds[k], &edits))
}

/// `seed` with `edits` applied in order.
fn apply(seed: &[u8], edits: &[Edit]) -> Vec<u8> {
    let mut d = seed.to_vec();
    for e in edits {
        let len = d.len();
        match e {
            Edit::Set(i, b) if len > 0 => d[i.index(len)] = *b,
            Edit::Flip(i, bit) if len > 0 => d[i.index(len)] ^= 1u8 << *bit,
            Edit::Insert(i, bytes) => {
                let p = i.index(len + 1);
                splice(&mut d, p, p, bytes);
            }
            Edit::Token(i, t) => {
                let p = i.index(len + 1);
                splice(&mut d, p, p, TOKENS[*t]);
            }
            Edit::Word(i, t) if len > 0 => {
                let (start, end) = word_at(&d, i.index(len));
                splice(&mut d, start, end, TOKENS[*t]);
            }
            Edit::Delete(i, n) if len > 0 => {
                let p = i.index(len);
                splice(&mut d, p, (p + *n).min(len), &[]);
            }
            Edit::Truncate(i) => d.truncate(i.index(len + 1)),
            Edit::Duplicate(i, n) if len > 0 => {
                let p = i.index(len);
                let end = (p + *n).min(len);
                let copy = d[p..end].to_vec();
                splice(&mut d, end, end, &copy);
            }
            _ => {}
        }
    }
    d
}

/// Replaces `d[start..end]` by `with`.
fn splice(d: &mut Vec<u8>, start: usize, end: usize, with: &[u8]) {
    let tail = d.split_off(end);
    d.truncate(start);
    d.extend_from_slice(with);
    d.extend_from_slice(&tail);
}

/// The bounds of the white-space delimited word around `p` (empty between blanks).
fn word_at(d: &[u8], p: usize) -> (usize, usize) {
    let mut start = p;
    while start > 0 && !d[start - 1].is_ascii_whitespace() {
        start -= 1;
    }
    let mut end = p;
    while end < d.len() && !d[end].is_ascii_whitespace() {
        end += 1;
    }
    (start, end)
}

/// Cases per parser: `FENESTRA_FUZZ_CASES` or [`DEFAULT_CASES`].
fn cases() -> u32 {
    match std::env::var("FENESTRA_FUZZ_CASES") {
        Ok(v) => v
            .trim()
            .parse()
            .unwrap_or_else(|_| panic!("FENESTRA_FUZZ_CASES={v} is not a count")),
        Err(_) => DEFAULT_CASES,
    }
}

/// Runs `f` on a thread with the tools' stack size (parsers may recurse as deep as the
/// tools allow them to), passing its panic on.
fn on_tool_stack(f: impl FnOnce() + Send + 'static) {
    let worker = std::thread::Builder::new()
        .stack_size(STACK_BYTES)
        .spawn(f)
        .expect("cannot start a fuzzing thread");
    if let Err(payload) = worker.join() {
        panic::resume_unwind(payload);
    }
}

/// Checks the seeds, then mutated seeds, on a tool-sized stack; panics naming `parser` and
/// the shrunk input.
fn fuzz(parser: &'static str, seeds: Vec<Vec<u8>>, check: Check) {
    on_tool_stack(move || fuzz_here(parser, seeds, check));
}

/// [`fuzz`] on the current thread.
fn fuzz_here(parser: &str, seeds: Vec<Vec<u8>>, check: Check) {
    assert!(!seeds.is_empty(), "{parser}: no seed inputs");
    for s in &seeds {
        assert_survives(parser, check, s);
    }
    let trace = std::env::temp_dir().join(format!(
        "fenestra-fuzz-{}-{}.last",
        std::process::id(),
        parser.replace(' ', "_")
    ));
    let config = ProptestConfig {
        cases: cases(),
        failure_persistence: None,
        ..ProptestConfig::default()
    };
    let mut runner = TestRunner::new(config);
    let result = runner.run(&mutated(seeds), |input| {
        // Left behind if the process aborts (allocation failure, stack overflow).
        let _ = std::fs::write(trace.as_path(), input.as_slice());
        outcome(check, &input).map_err(TestCaseError::fail)
    });
    let _ = std::fs::remove_file(trace.as_path());
    match result {
        Ok(()) => {}
        Err(TestError::Fail(reason, input)) => {
            panic!("{parser} fuzzing: {reason}\n{}", describe(&input))
        }
        Err(TestError::Abort(reason)) => panic!("{parser} fuzzing stopped: {reason}"),
    }
}

/// Panics with the parser's name and the input when `check` fails or panics on `input`.
fn assert_survives(parser: &str, check: Check, input: &[u8]) {
    if let Err(e) = outcome(check, input) {
        panic!("{parser}: {e}\n{}", describe(input));
    }
}

/// Runs one check, a panic becoming an error that quotes its message.
fn outcome(check: Check, input: &[u8]) -> Result<(), String> {
    match panic::catch_unwind(AssertUnwindSafe(|| check(input))) {
        Ok(result) => result,
        Err(payload) => Err(format!("panicked: {}", panic_text(payload.as_ref()))),
    }
}

/// The message of a panic payload.
fn panic_text(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "(no message)".to_string()
    }
}

/// An input for a failure message: its size, then its start as text and as a byte string.
fn describe(input: &[u8]) -> String {
    let head = &input[..input.len().min(SHOW)];
    format!(
        "input of {} bytes; the first {} as text:\n{:?}\nas bytes:\nb\"{}\"",
        input.len(),
        head.len(),
        String::from_utf8_lossy(head),
        head.escape_ascii()
    )
}

/// Whether the input spells `nan` (any case), the one way a NaN may legitimately come in.
fn has_nan_text(input: &[u8]) -> bool {
    input.windows(3).any(|w| w.eq_ignore_ascii_case(b"nan"))
}

// ---------------------------------------------------------------------------------------
// Checks, one per parser.
// ---------------------------------------------------------------------------------------

/// Matrix reader (`MatrixReader::from_reader` + `Matrix::read_from`): consistent shape;
/// ascii and RGBE data without a literal `nan` give no NaN.
fn check_matrix(input: &[u8]) -> Result<(), String> {
    let Ok(reader) = MatrixReader::from_reader(Cursor::new(input.to_vec()), "fuzz") else {
        return Ok(());
    };
    let Ok(m) = Matrix::read_from(reader) else {
        return Ok(());
    };
    let size = m
        .nrows
        .checked_mul(m.ncols)
        .and_then(|n| n.checked_mul(m.ncomp));
    if size != Some(m.data.len()) {
        return Err(format!(
            "{} values for {} x {} x {}",
            m.data.len(),
            m.nrows,
            m.ncols,
            m.ncomp
        ));
    }
    let textual = matches!(
        m.format,
        DataFormat::Ascii | DataFormat::Rgbe | DataFormat::Xyze
    );
    if textual && !has_nan_text(input) && m.data.iter().any(|v| v.is_nan()) {
        return Err(format!(
            "NaN read from {} data that never says nan",
            m.format
        ));
    }
    Ok(())
}

/// Picture reader (`Picture::read`): one pixel per position, all finite (RGBE decodes to
/// finite values); the view setup, reorientation and exposure removal must not panic.
fn check_picture(input: &[u8]) -> Result<(), String> {
    let mut r = input;
    let Ok(mut pic) = Picture::read(&mut r, "fuzz") else {
        return Ok(());
    };
    let (w, h) = pic.scan_dims();
    if w.checked_mul(h) != Some(pic.pixels.len()) {
        return Err(format!("{} pixels for {w} x {h}", pic.pixels.len()));
    }
    if pic.pixels.iter().flatten().any(|v| !v.is_finite()) {
        return Err("non-finite pixel decoded".to_string());
    }
    if let Some(mut view) = pic.info.view.clone() {
        let _ = view.setup();
    }
    let _ = pic.to_standard();
    pic.undo_exposure();
    Ok(())
}

/// Information header (`Header::read` and its typed getters): never longer than the input.
fn check_header(input: &[u8]) -> Result<(), String> {
    let mut r = input;
    let Ok(h) = Header::read(&mut r, "fuzz") else {
        return Ok(());
    };
    if h.byte_len > input.len() as u64 {
        return Err(format!(
            "header of {} bytes in {} bytes of input",
            h.byte_len,
            input.len()
        ));
    }
    let _ = (h.format(), h.nrows(), h.ncols(), h.ncomp());
    let _ = (h.exposure(), h.colorcorr(), h.big_endian());
    Ok(())
}

/// Scene text (`parse_str`, `!commands` disabled): finite reals, modifiers defined earlier.
fn check_rad(input: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(input).replace('!', "#");
    let Ok(scene) = parse_str(&text, "fuzz.rad") else {
        return Ok(());
    };
    for (i, p) in scene.prims.iter().enumerate() {
        if let Some(v) = p.rargs.iter().find(|v| !v.is_finite()) {
            return Err(format!("{} {} has the real argument {v}", p.ptype, p.name));
        }
        if p.modifier.is_some_and(|m| m >= i) {
            return Err(format!(
                "{} {} (primitive {i}) has modifier {:?}",
                p.ptype, p.name, p.modifier
            ));
        }
    }
    Ok(())
}

/// MGF conversion (`Parser::add_mgf`, inputs tamed by [`tame_mgf`]): modifiers defined earlier.
fn check_mgf(input: &[u8]) -> Result<(), String> {
    let text = tame_mgf(&String::from_utf8_lossy(input));
    // Named inside the fixture directory so that `i sub/part.mgf` finds the real file.
    let file = fixture("tests/fixtures/mgf/fuzz.mgf");
    let mut parser = Parser::new();
    if parser.add_mgf(&text, &file.to_string_lossy()).is_err() {
        return Ok(());
    }
    for (i, p) in parser.finish().prims.iter().enumerate() {
        if p.modifier.is_some_and(|m| m >= i) {
            return Err(format!(
                "{} {} (primitive {i}) has modifier {:?}",
                p.ptype, p.name, p.modifier
            ));
        }
    }
    Ok(())
}

/// Comments out the logical MGF lines (continuations joined as the converter joins them)
/// that include a file other than `sub/part.mgf` or push the instances of `-a`/`-i` counts
/// past [`MGF_MAX_INSTANCES`].
fn tame_mgf(text: &str) -> String {
    let raw: Vec<&str> = text.lines().collect();
    let mut keep = vec![true; raw.len()];
    let mut budget = MGF_MAX_INSTANCES;
    let mut logical = String::new();
    let mut first = 0;
    for (i, line) in raw.iter().enumerate() {
        if logical.is_empty() {
            first = i;
        }
        if let Some(head) = line.strip_suffix('\\') {
            logical.push_str(head);
            logical.push(' ');
            continue;
        }
        logical.push_str(line);
        let words: Vec<&str> = logical.split_whitespace().collect();
        let foreign = words.first() == Some(&"i") && words.get(1) != Some(&"sub/part.mgf");
        let instances = words
            .windows(2)
            .filter(|w| w[0] == "-a" || w[0] == "-i")
            .filter_map(|w| w[1].parse::<u64>().ok())
            .fold(1u64, u64::saturating_mul);
        if foreign || instances > budget {
            keep[first..=i].fill(false);
        } else {
            budget /= instances.max(1);
        }
        logical.clear();
    }
    raw.iter()
        .zip(&keep)
        .map(|(line, &k)| if k { *line } else { "#" })
        .collect::<Vec<_>>()
        .join("\n")
}

/// `.cal` definitions (`Program::load_str`, then `Program::compile`).
fn check_cal(input: &[u8]) -> Result<(), String> {
    check_program(input, |prog, text| prog.load_str("fuzz.cal", text))
}

/// A standalone `.cal` expression (`Program::add_expr`, then `Program::compile`).
fn check_expr(input: &[u8]) -> Result<(), String> {
    check_program(input, |prog, text| prog.add_expr("fuzz", text))
}

/// The input as text given to a renderer's program by `load`, then `Program::compile` when
/// it loaded.
fn check_program<T, E>(
    input: &[u8],
    load: impl FnOnce(&mut Program, &str) -> Result<T, E>,
) -> Result<(), String> {
    let text: &str = &String::from_utf8_lossy(input);
    let mut prog = Program::for_renderer();
    if load(&mut prog, text).is_ok() {
        let _ = prog.compile();
    }
    Ok(())
}

/// BSDF XML (`fenestra_bsdf::parse`): Klems matrices complete, finite and non-negative;
/// tensor trees evaluate to non-negative values.
fn check_bsdf(input: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(input);
    let Ok(bsdf) = parse_bsdf(&text, "fuzz.xml") else {
        return Ok(());
    };
    for b in &bsdf.blocks {
        match &b.data {
            BlockData::Klems(m) => {
                let n = m.incident.len().checked_mul(m.outgoing.len());
                if n != Some(m.values.len()) {
                    return Err(format!(
                        "{} values for {} x {} patches",
                        m.values.len(),
                        m.outgoing.len(),
                        m.incident.len()
                    ));
                }
                if let Some(v) = m.values.iter().find(|v| !v.is_finite() || **v < 0.0) {
                    return Err(format!("Klems value {v} kept"));
                }
            }
            BlockData::Tree(t) => probe_tree(t)?,
        }
    }
    Ok(())
}

/// Tensor-tree text (`TensorTree::parse`, ranks 3 and 4): lookups give values >= 0.
fn check_tree(input: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(input);
    for rank in [3, 4] {
        let Ok(t) = TensorTree::parse(rank, &text) else {
            continue;
        };
        if t.rank() != rank {
            return Err(format!("rank {} tree read as rank {rank}", t.rank()));
        }
        for pos in [[0.0; 4], [1.0; 4], [0.5, 0.25, 0.75, 0.999]] {
            let v = t.lookup(&pos[..rank]);
            if v.is_nan() || v < 0.0 {
                return Err(format!("lookup at {pos:?} gave {v}"));
            }
        }
        probe_tree(&t)?;
    }
    Ok(())
}

/// Evaluates a tree for a few direction pairs: every value must be >= 0.
fn probe_tree(t: &TensorTree) -> Result<(), String> {
    const DIRS: [[f64; 3]; 4] = [
        [0.0, 0.0, 1.0],
        [0.6, 0.0, 0.8],
        [0.0, -0.6, 0.8],
        [0.48, 0.6, 0.64],
    ];
    for inc in DIRS {
        for out in DIRS {
            let v = t.eval(inc, out);
            if v.is_nan() || v < 0.0 {
                return Err(format!("tree value {v} for {inc:?} -> {out:?}"));
            }
        }
    }
    Ok(())
}

/// Weather tapes (`read_tape`), as bytes and as lossy text: valid dates, no NaN.
fn check_weather(input: &[u8]) -> Result<(), String> {
    check_tape(input)?;
    let text = String::from_utf8_lossy(input);
    if text.as_bytes() != input {
        check_tape(text.as_bytes())?;
    }
    Ok(())
}

/// One `read_tape` call and its properties.
fn check_tape(input: &[u8]) -> Result<(), String> {
    let mut r = input;
    let Ok(tape) = read_tape(&mut r) else {
        return Ok(());
    };
    let nan_ok = has_nan_text(input);
    let loc = &tape.location;
    if !nan_ok && (loc.latitude.is_nan() || loc.longitude.is_nan() || loc.timezone.is_nan()) {
        return Err(format!("NaN in the location {loc:?}"));
    }
    for rec in &tape.records {
        if !(1..=12).contains(&rec.month) || !(0.0..=24.0).contains(&rec.hour) {
            return Err(format!("illegal date kept: {rec:?}"));
        }
        let values = [
            rec.dir_irrad,
            rec.diff_irrad,
            rec.glob_irrad,
            rec.dir_illum,
            rec.diff_illum,
            rec.dew_point,
        ];
        if !nan_ok && values.iter().flatten().any(|v| v.is_nan()) {
            return Err(format!("NaN in {rec:?}"));
        }
    }
    Ok(())
}

/// An option table with every kind of option, for option files.
fn option_spec() -> Spec {
    Spec::new("fuzz", "option-file fuzzing")
        .opt(Opt::new("ab", Kind::Int, "bounces"))
        .opt(Opt::new("aa", Kind::Real, "accuracy"))
        .opt(Opt::new("I", Kind::Toggle, "irradiance"))
        .opt(Opt::new("h", Kind::Flag, "no header"))
        .opt(Opt::new("vp", Kind::Vec3, "view point"))
        .opt(Opt::new("f", Kind::Attached, "formats"))
        .opt(Opt::new("o", Kind::Word, "output"))
        .opt(Opt::new("x", Kind::Words(2), "two words"))
        .interleaved(true)
}

/// Option files (`split_words`, then `Spec::parse`): no word spans lines.
fn check_options(input: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(input);
    let Ok(words) = split_words(&text) else {
        return Ok(());
    };
    if let Some(w) = words.iter().find(|w| w.contains('\n')) {
        return Err(format!("word {w:?} spans lines"));
    }
    let mut args = vec!["fuzz".to_string()];
    // --help and --version print to standard output: not what is being tested.
    args.extend(
        words
            .into_iter()
            .filter(|w| w != "--help" && w != "--version"),
    );
    let _ = option_spec().parse(&args);
    Ok(())
}

/// View files (`View::apply_file_text`, then `View::setup` and a few rays).
fn check_view(input: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(input);
    let mut view = View::default();
    if view.apply_file_text(&text, "vwrays") && view.setup().is_ok() {
        for (x, y) in [(0.5, 0.5), (0.0, 0.0), (1.0, 0.25)] {
            let _ = view.ray(x, y);
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------
// Seeds.
// ---------------------------------------------------------------------------------------

/// A path under the repository root.
fn fixture(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The bytes of a file under the repository root.
fn seed(rel: &str) -> Vec<u8> {
    let path = fixture(rel);
    std::fs::read(&path).unwrap_or_else(|e| panic!("cannot read seed {}: {e}", path.display()))
}

/// Several files concatenated (a scene whose modifiers are in another file).
fn seeds_joined(rels: &[&str]) -> Vec<u8> {
    rels.iter().copied().flat_map(seed).collect()
}

/// The first `n` lines of a file.
fn seed_head(rel: &str, n: usize) -> Vec<u8> {
    let bytes = seed(rel);
    let text = String::from_utf8_lossy(&bytes);
    let mut head = text.lines().take(n).collect::<Vec<_>>().join("\n");
    head.push('\n');
    head.into_bytes()
}

/// A 2 x 2 x 3 little-endian binary matrix (`float` or `double`).
fn binary_matrix(format: &str) -> Vec<u8> {
    let mut out =
        format!("#?RADIANCE\nNROWS=2\nNCOLS=2\nNCOMP=3\nBigEndian=0\nFORMAT={format}\n\n")
            .into_bytes();
    for k in 0..12 {
        let v = 0.25 * f64::from(k) - 1.0;
        if format == "float" {
            out.extend_from_slice(&(v as f32).to_le_bytes());
        } else {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// A 2 x 3 RGBE matrix: an old-style repeat marker in the first row, flat pixels after.
fn rgbe_matrix() -> Vec<u8> {
    let mut out =
        b"#?RADIANCE\nNROWS=2\nNCOLS=3\nNCOMP=3\nEXPOSURE=0.5\nFORMAT=32-bit_rle_rgbe\n\n".to_vec();
    out.extend_from_slice(&[10, 20, 30, 128, 1, 1, 1, 2]);
    out.extend_from_slice(&[1, 2, 3, 130, 4, 5, 6, 131, 7, 8, 9, 132]);
    out
}

/// Matrices: ascii fixtures with and without NROWS, binary, RGBE and a picture.
fn matrix_seeds() -> Vec<Vec<u8>> {
    vec![
        seed("tests/fixtures/matrices/m23h.txt"),
        seed("tests/fixtures/matrices/m32h.txt"),
        seed("tests/fixtures/matrices/ill_t1_mar21_1000_clear.dat"),
        seed("tests/fixtures/rcontrib/e_out/skyglow_000.dat"),
        b"#?RADIANCE\nNCOLS=3\nNCOMP=1\n\n1 2 3\n4 5 6\n-7e-3 inf 8\n".to_vec(),
        binary_matrix("float"),
        binary_matrix("double"),
        rgbe_matrix(),
        seed("tests/fixtures/threephase/img_t1_mar21_1000_clear.hdr"),
    ]
}

/// A 5 x 2 picture with a view, an exposure, an old-style repeat marker and flat pixels.
fn small_picture() -> Vec<u8> {
    let mut out = b"#?RADIANCE\nrpict -vtv -vp 0 0 1 -vd 0 1 0 -vh 60 -vv 45\n\
VIEW= -vth -vh 170 -vv 170\nEXPOSURE=2\nCOLORCORR=1 1.1 0.9\nPIXASPECT=1\n\
FORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 5\n"
        .to_vec();
    out.extend_from_slice(&[
        200, 100, 50, 128, 10, 20, 30, 129, 1, 1, 1, 2, 64, 64, 64, 127,
    ]);
    for k in 0..5u8 {
        out.extend_from_slice(&[k * 40, 255 - k * 40, 7, 120 + k]);
    }
    out
}

/// A 3 x 2 XYZE picture stored in columns (`+X 3 +Y 2`).
fn column_picture() -> Vec<u8> {
    let mut out = b"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n+X 3 +Y 2\n".to_vec();
    for k in 0..6u8 {
        out.extend_from_slice(&[k * 30, k * 20, k * 10, 130]);
    }
    out
}

/// Pictures: two run-length encoded fixtures and two small flat ones.
fn picture_seeds() -> Vec<Vec<u8>> {
    vec![
        seed("tests/fixtures/threephase/img_t1_mar21_1000_clear.hdr"),
        seed("tests/fixtures/picture/vimg/v000.hdr"),
        small_picture(),
        column_picture(),
    ]
}

/// Headers: those of the matrices and pictures, and one with repeated keys.
fn header_seeds() -> Vec<Vec<u8>> {
    let mut seeds = matrix_seeds();
    seeds.extend(picture_seeds());
    seeds.push(
        b"#?RADIANCE\nEXPOSURE=2\nEXPOSURE=0.5\nCOLORCORR=1 1.1 0.9\nBigEndian = 1\r\n\
NROWS=4\nNROWS=2\n\n"
            .to_vec(),
    );
    seeds
}

/// Scenes: every primitive type, a room with its materials, a BSDF window and skies.
fn rad_seeds() -> Vec<Vec<u8>> {
    vec![
        seed("tests/fixtures/scene/types.rad"),
        seeds_joined(&[
            "tests/fixtures/rtrace_glass_room/materials.rad",
            "tests/fixtures/rtrace_glass_room/room.rad",
            "tests/fixtures/rtrace_glass_room/window_glass.rad",
        ]),
        seeds_joined(&[
            "tests/fixtures/scene/mkillum/window_bsdf.rad",
            "tests/fixtures/rcontrib/sky_uniform.rad",
        ]),
        seed("tests/fixtures/sky/s01_clear_sun_sf_equinox_noon.rad"),
        seed("tests/fixtures/rcontrib/open_box.rad"),
    ]
}

/// MGF: materials and surfaces with an include, a slat array, and the included file.
fn mgf_seeds() -> Vec<Vec<u8>> {
    vec![
        seed("tests/fixtures/mgf/materials.mgf"),
        seed("tests/fixtures/mgf/blinds_curved20.mgf"),
        seed("tests/fixtures/mgf/sub/part.mgf"),
    ]
}

/// Definitions using most of the `.cal` syntax.
const CAL_SEED: &str = "{ fuzz seed { nested } comment }
half : PI / 2;
sq(x) = x * x;
hyp(a, b) = sqrt(sq(a) + sq(b));
$1 = hyp($2, $3) ^ -2 ^ 2;
$2 = if(Dx - .5, select(2, 1, 2, 3), -1e-3);
r = rand(floor(10.5)) + max(1, 2, 3) - -4;
c : 3 * (2 + 1) / 0.5;
";

/// `.cal` files: the library's, and [`CAL_SEED`].
fn cal_seeds() -> Vec<Vec<u8>> {
    let mut seeds: Vec<Vec<u8>> = [
        "lib/skybright.cal",
        "lib/perezlum.cal",
        "lib/klems_quarter.cal",
        "lib/tregenza.cal",
        "lib/illum.cal",
        "lib/reinhartb.cal",
    ]
    .into_iter()
    .map(seed)
    .collect();
    seeds.push(CAL_SEED.as_bytes().to_vec());
    seeds
}

/// Standalone expressions as rcontrib and rcalc take them.
fn expr_seeds() -> Vec<Vec<u8>> {
    [
        "if(Dx, if(Dy, 0, 3), if(Dy, 1, 2))",
        "kbin(-Dx, -Dy, -Dz, 0, 0, 1)",
        "and(gt($1, 0), lt($2, 1)) * 3 ^ -2 ^ 2",
        "select(floor(2.5), 1e308, -1e-308, .5e3)",
        "sqrt(-1) + log(0) / exp(710) - (((1)))",
    ]
    .iter()
    .map(|s| s.as_bytes().to_vec())
    .collect()
}

/// A custom two-ring angle basis of 5 patches named `Tiny`.
const TINY_BASIS: &str = "<AngleBasis><AngleBasisName>Tiny</AngleBasisName>
<AngleBasisBlock><Theta>0</Theta><nPhis>1</nPhis>
<ThetaBounds><LowerTheta>0</LowerTheta><UpperTheta>45</UpperTheta></ThetaBounds></AngleBasisBlock>
<AngleBasisBlock><Theta>67.5</Theta><nPhis>4</nPhis>
<ThetaBounds><LowerTheta>45</LowerTheta><UpperTheta>90</UpperTheta></ThetaBounds></AngleBasisBlock>
</AngleBasis>";

/// A Klems BSDF XML file: `structure` Columns or Rows, basis definition `basis_xml`, basis
/// `basis` of `n` patches, two blocks of `n` x `n` values.
fn klems_seed(structure: &str, basis_xml: &str, basis: &str, n: usize) -> Vec<u8> {
    let values: Vec<String> = (0..n * n)
        .map(|k| format!("{:.2}", (k % 7) as f64 * 0.15))
        .collect();
    let values = values.join(" ");
    let block = |direction: &str| {
        format!(
            "<WavelengthDataBlock>
<WavelengthDataDirection>{direction}</WavelengthDataDirection>
<ColumnAngleBasis>{basis}</ColumnAngleBasis>
<RowAngleBasis>{basis}</RowAngleBasis>
<ScatteringDataType>BTDF</ScatteringDataType>
<ScatteringData>{values}</ScatteringData>
</WavelengthDataBlock>"
        )
    };
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<!-- Created by: fenestra fuzz seed -->
<WindowElement xmlns="http://windows.lbl.gov" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">
<WindowElementType>System</WindowElementType>
<FileType>BSDF</FileType>
<Optical>
<Layer>
<Material><Name>Seed &amp; co</Name><Manufacturer>fuzz</Manufacturer><DeviceType>Other</DeviceType>
<Thickness unit="millimeter">6</Thickness><Width unit="meter">1</Width><Height unit="inch">40</Height></Material>
<DataDefinition>
<IncidentDataStructure>{structure}</IncidentDataStructure>
{basis_xml}
</DataDefinition>
<WavelengthData>
<LayerNumber>System</LayerNumber>
<Wavelength unit="Integral">Visible</Wavelength>
{}
{}
</WavelengthData>
</Layer>
</Optical>
</WindowElement>
"#,
        block("Transmission Front"),
        block("Reflection Back")
    )
    .into_bytes()
}

/// A tensor-tree BSDF XML file with an MGF geometry, a Visible block and a CIE-v block.
fn tree_seed(structure: &str, visible: &str, cie_v: &str) -> Vec<u8> {
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<WindowElement xmlns="http://windows.lbl.gov">
<FileType>BSDF</FileType>
<Optical>
<Layer>
<Material><Name>tree</Name><Width unit="millimeter">300</Width><Thickness>0.01</Thickness></Material>
<Geometry format="MGF"><MGFblock unit="meter">m w =
	rd .5
v a =
	p 0 0 0
v b =
	p 1 0 0
v c =
	p 0 1 0
f a b c
</MGFblock></Geometry>
<DataDefinition><IncidentDataStructure>{structure}</IncidentDataStructure></DataDefinition>
<WavelengthData><LayerNumber>System</LayerNumber><Wavelength unit="Integral">Visible</Wavelength>
<WavelengthDataBlock><WavelengthDataDirection>Transmission Front</WavelengthDataDirection>
<ScatteringDataType>BTDF</ScatteringDataType><ScatteringData>{visible}</ScatteringData></WavelengthDataBlock>
<WavelengthDataBlock><WavelengthDataDirection>Reflection Back</WavelengthDataDirection>
<ScatteringDataType>BRDF</ScatteringDataType><ScatteringData>{{ 0.05 }}</ScatteringData></WavelengthDataBlock>
</WavelengthData>
<WavelengthData><LayerNumber>System</LayerNumber><Wavelength unit="Integral">CIE-v</Wavelength>
<WavelengthDataBlock><WavelengthDataDirection>Transmission Front</WavelengthDataDirection>
<ScatteringData>{cie_v}</ScatteringData></WavelengthDataBlock>
</WavelengthData>
</Layer>
</Optical>
</WindowElement>
"#
    )
    .into_bytes()
}

/// A rank-3 tree: one branch level, one child a grid of 8 values.
const TREE3: &str = "{ {0.1 0.2 0.3 0.4 0.5 0.6 0.7 0.8} {1} {2} {3} {4} {5} {6} {7} }";
/// A rank-4 tree: a grid of 16 values.
const TREE4: &str = "{ 0.1 0.2 0.3 0.4 0.5 0.6 0.7 0.8 0.9 1 1.1 1.2 1.3 1.4 1.5 1.6 }";

/// BSDF XML: Klems with a custom basis (Columns) and with the quarter basis (Rows), tensor
/// trees of rank 3 and 4.
fn bsdf_seeds() -> Vec<Vec<u8>> {
    let quarter = KlemsBasis::quarter();
    vec![
        klems_seed("Columns", TINY_BASIS, "Tiny", 5),
        klems_seed(
            "Rows",
            &format!(
                "<AngleBasis><AngleBasisName>{}</AngleBasisName></AngleBasis>",
                quarter.name()
            ),
            quarter.name(),
            quarter.len(),
        ),
        tree_seed(
            "TensorTree3",
            TREE3,
            "{ 0.46 0.47 0.46 0.47 0.46 0.47 0.46 0.47 }",
        ),
        tree_seed("TensorTree4", TREE4, "{ 0.47 }"),
    ]
}

/// Tensor-tree texts: grids of rank 3 and 4, a branch, one value, commas as separators.
fn tree_seeds() -> Vec<Vec<u8>> {
    let grid: Vec<String> = (0..64).map(|k| (f64::from(k) / 64.0).to_string()).collect();
    vec![
        b"{ 0.1 0.2 0.3 0.4 0.5 0.6 0.7 0.8 }".to_vec(),
        TREE3.as_bytes().to_vec(),
        TREE4.as_bytes().to_vec(),
        format!("{{\n{}\n}}", grid.join(", ")).into_bytes(),
        b"{ 5 }".to_vec(),
    ]
}

/// Weather: four .wea fixtures and the first records of two .epw fixtures.
fn weather_seeds() -> Vec<Vec<u8>> {
    vec![
        seed("tests/fixtures/sky/hard_polar.wea"),
        seed("tests/fixtures/sky/hard_tropic.wea"),
        seed("tests/fixtures/sky/two_days.wea"),
        seed("tests/fixtures/sky/test.wea"),
        seed_head("tests/fixtures/sky/two_days_dew11.epw", 12),
        seed_head("tests/fixtures/sky/two_days_dewvar.epw", 12),
    ]
}

/// An option file using every kind of option, quotes and comments.
const OPTIONS_SEED: &str = "# rtrace options for the fuzz seed
-ab 4 -aa .1 -I+ -h
  # an indented comment -ab 9
-vp 1 2.5 -3e-2 -faf -o \"out file.dat\" -x 'a b' c
+I -ab 0 -I- scene.oct
";

/// Option files: [`OPTIONS_SEED`] and a view file read as options.
fn option_seeds() -> Vec<Vec<u8>> {
    vec![
        OPTIONS_SEED.as_bytes().to_vec(),
        seed("tests/fixtures/vwrays/view.vf"),
    ]
}

/// View files: two fixtures, a `VIEW=` line with every option, renderer command lines.
fn view_seeds() -> Vec<Vec<u8>> {
    vec![
        seed("tests/fixtures/vwrays/view.vf"),
        seed("examples/three-phase/scene/view.vf"),
        b"VIEW= -vta -vp 0 0 1 -vd 0 0 1 -vu 0 1 0 -vh 180 -vv 180 -vo 0.1 -va 10 -vs 0.1 -vl -0.1\n"
            .to_vec(),
        b"rpict -vtl -vp 0 0 0 -vd 1 0 0 -vh 10 -vv 5 -x 64\nVIEW= -vts -vh 120\n\nrvu -vtc\n"
            .to_vec(),
    ]
}

// ---------------------------------------------------------------------------------------
// Tests.
// ---------------------------------------------------------------------------------------

/// Every parser survives empty and degenerate inputs.
#[test]
fn tiny_inputs() {
    on_tool_stack(|| {
        for input in TINY_INPUTS {
            for (parser, check) in PARSERS {
                assert_survives(parser, *check, input);
            }
        }
    });
}

/// Fuzzes the matrix reader.
#[test]
fn fuzz_matrix() {
    fuzz("matrix", matrix_seeds(), check_matrix);
}

/// Fuzzes the picture reader.
#[test]
fn fuzz_picture() {
    fuzz("picture", picture_seeds(), check_picture);
}

/// Fuzzes the information-header reader.
#[test]
fn fuzz_header() {
    fuzz("header", header_seeds(), check_header);
}

/// Fuzzes the `.rad` scene parser.
#[test]
fn fuzz_rad() {
    fuzz("rad", rad_seeds(), check_rad);
}

/// Fuzzes the MGF converter.
#[test]
fn fuzz_mgf() {
    fuzz("mgf", mgf_seeds(), check_mgf);
}

/// Fuzzes the `.cal` parser and compiler.
#[test]
fn fuzz_cal() {
    fuzz("cal", cal_seeds(), check_cal);
}

/// Fuzzes the `.cal` expression parser.
#[test]
fn fuzz_cal_expression() {
    fuzz("cal expression", expr_seeds(), check_expr);
}

/// Fuzzes the BSDF XML reader.
#[test]
fn fuzz_bsdf_xml() {
    fuzz("BSDF XML", bsdf_seeds(), check_bsdf);
}

/// Fuzzes the tensor-tree parser.
#[test]
fn fuzz_tensor_tree() {
    fuzz("tensor tree", tree_seeds(), check_tree);
}

/// Fuzzes the `.wea`/`.epw` weather reader.
#[test]
fn fuzz_weather() {
    fuzz("weather", weather_seeds(), check_weather);
}

/// Fuzzes option-file splitting and option parsing.
#[test]
fn fuzz_option_file() {
    fuzz("option file", option_seeds(), check_options);
}

/// Fuzzes view-file reading.
#[test]
fn fuzz_view_file() {
    fuzz("view file", view_seeds(), check_view);
}

// Regression cases found by the fuzzer go below, one `#[test]` each:
// `assert_survives("weather", check_weather, b"...")`.
