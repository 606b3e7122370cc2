//! dctimestep from the command line, against the stored three-phase results computed with
//! Radiance 6.0a (`tests/fixtures/threephase/`, copied from `../shared/reference/threephase/`)
//! and against the oracle's dctimestep run live.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

const SKIES: [&str; 4] = [
    "t1_mar21_1000_clear",
    "t2_jun21_1500_clear",
    "t3_dec21_1200_clear",
    "t4_sep21_1200_overcast",
];

fn tp(name: &str) -> PathBuf {
    common::fixture(&format!("threephase/{name}"))
}

fn ours() -> Command {
    let mut c = common::fenestra("dctimestep");
    c.current_dir(common::fixture("threephase"));
    c
}

fn run(mut c: Command) -> Vec<u8> {
    common::run_ok(&mut c)
}

/// Header lines (without the clock lines CAPDATE/GMT) and the data after the blank line.
fn split(out: &[u8]) -> (Vec<String>, Vec<u8>) {
    let end = out
        .windows(2)
        .position(|w| w == b"\n\n")
        .expect("header end");
    let head = String::from_utf8_lossy(&out[..end]);
    let lines = head
        .lines()
        .filter(|l| !l.starts_with("CAPDATE=") && !l.starts_with("GMT="))
        .map(str::to_string)
        .collect();
    (lines, out[end + 2..].to_vec())
}

fn ascii(body: &[u8]) -> Vec<f64> {
    String::from_utf8_lossy(body)
        .split_whitespace()
        .map(|w| w.parse().expect("number"))
        .collect()
}

fn floats(body: &[u8]) -> Vec<f64> {
    body.chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64)
        .collect()
}

/// Largest relative difference (0 where both are 0).
fn worst_rel(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len(), "value counts");
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            // f64::max would drop a NaN; a non-finite value on either side is a failure.
            assert!(
                x.is_finite() && y.is_finite(),
                "non-finite value: {x} vs {y}"
            );
            if x == y {
                0.0
            } else {
                (x - y).abs() / x.abs().max(y.abs())
            }
        })
        .fold(0.0, f64::max)
}

fn stored(name: &str) -> Vec<f64> {
    ascii(&split(&std::fs::read(tp(name)).unwrap()).1)
}

/// Two independently rounded `%.6e` prints of numbers that agree to float precision
/// differ by at most one unit in the 7th digit: 1e-6 relative for mantissas near 1
/// (Radiance rounds D·s and T·(D·s) to float on the way, we compute V·(T·D) in double).
const PRINT_TOL: f64 = 2e-6;

/// The stored `res_rflux_*.dat` are not the product of the stored `V_rflux.vmx`/`D_rflux.dmx`:
/// the oracle run live on them differs from those files by up to 1.8e-4 (another Monte Carlo
/// realisation of the rfluxmtx matrices was kept). They are compared within 5e-4; the live
/// oracle comparison (`oracle_rflux_route`) checks that route to print precision.
const STORED_RFLUX_TOL: f64 = 5e-4;

/// T given as the oracle's own matrix (`T.mtx` = `rmtxop -ff blinds_kf.xml`): every stored
/// result is reproduced to print precision (rflux route: see STORED_RFLUX_TOL).
#[test]
fn stored_results_reproduced_with_oracle_t_matrix() {
    for sky in SKIES {
        for (v, d, res, tol) in [
            ("V.vmx", "D.dmx", format!("res_{sky}.dat"), PRINT_TOL),
            (
                "V_rflux.vmx",
                "D_rflux.dmx",
                format!("res_rflux_{sky}.dat"),
                STORED_RFLUX_TOL,
            ),
        ] {
            let mut c = ours();
            c.args([v, "T.mtx", d, &format!("sky_{sky}.skv")]);
            let got = ascii(&split(&run(c)).1);
            let w = worst_rel(&got, &stored(&res));
            assert!(w < tol, "{res}: worst relative difference {w}");
        }
    }
}

/// The rfluxmtx route (binary float V and D) against the oracle run live: print precision.
#[test]
fn oracle_rflux_route() {
    let Some(o) = common::oracle() else { return };
    for sky in SKIES {
        let args = [
            "V_rflux.vmx".to_string(),
            "T.mtx".into(),
            "D_rflux.dmx".into(),
            format!("sky_{sky}.skv"),
        ];
        let mut a = ours();
        a.args(&args);
        let mut b = oracle_cmd(&o);
        b.args(&args);
        let w = worst_rel(&ascii(&split(&run(a)).1), &ascii(&split(&run(b)).1));
        assert!(w < PRINT_TOL, "{sky}: worst relative difference {w}");
    }
}

/// T read from the XML, colour included: our XML loader reproduces Radiance's dithered
/// chromaticity quantisation (crates/bsdf/src/radiance.rs), so every channel of every stored
/// result is reproduced to print precision (rflux route: see STORED_RFLUX_TOL).
#[test]
fn stored_results_from_xml_reproduced() {
    for sky in SKIES {
        for (v, d, res, tol) in [
            ("V.vmx", "D.dmx", format!("res_{sky}.dat"), PRINT_TOL),
            (
                "V_rflux.vmx",
                "D_rflux.dmx",
                format!("res_rflux_{sky}.dat"),
                STORED_RFLUX_TOL,
            ),
        ] {
            let mut c = ours();
            c.args([v, "blinds_kf.xml", d, &format!("sky_{sky}.skv")]);
            let (head, body) = split(&run(c));
            let got = ascii(&body);
            let want = stored(&res);
            let wc = worst_rel(&got, &want);
            eprintln!("{res}: worst relative difference per channel {wc:.2e}");
            assert!(wc < tol, "{res}: channel worst relative difference {wc}");
            let (want_head, _) = split(&std::fs::read(tp(&res)).unwrap());
            // Same header apart from the command line (file names differ for rflux).
            assert_eq!(head[0], want_head[0]);
            assert_eq!(head[2..], want_head[2..], "{res}: header");
        }
    }
}

/// sawtooth.xml holds reflection data only: T is zero and the output is exactly the
/// stored file's data (all `0.000000e+00`).
#[test]
fn sawtooth_gives_exact_zeros() {
    let mut c = ours();
    c.args([
        "V.vmx",
        "sawtooth.xml",
        "D.dmx",
        "sky_t1_mar21_1000_clear.skv",
    ]);
    let (head, body) = split(&run(c));
    let (want_head, want_body) =
        split(&std::fs::read(tp("res_sawtooth_t1_mar21_1000_clear.dat")).unwrap());
    assert_eq!(head, want_head);
    assert_eq!(body, want_body);
}

/// The annual sky matrix (56 hours, night hours zero): rows = sensors, columns = hours,
/// night columns exactly zero.
#[test]
fn annual_sky_matrix() {
    let mut c = ours();
    c.args(["V.vmx", "T.mtx", "D.dmx", "test.m1.smx"]);
    let (head, body) = split(&run(c));
    assert!(head.contains(&"NROWS=45".to_string()) && head.contains(&"NCOLS=56".to_string()));
    let text = String::from_utf8(body.clone()).unwrap();
    let want_text =
        String::from_utf8(split(&std::fs::read(tp("annual_res.dat")).unwrap()).1).unwrap();
    assert_eq!(text.lines().count(), 45);
    for (l, wl) in text.lines().zip(want_text.lines()) {
        let (els, wels): (Vec<&str>, Vec<&str>) =
            (l.split('\t').collect(), wl.split('\t').collect());
        assert_eq!(els.len(), 56);
        for (e, we) in els.iter().zip(&wels) {
            if we.starts_with("0.000000e+00 0.000000e+00 0.000000e+00") {
                assert_eq!(e, we, "zero step must be exact");
            }
        }
    }
    let w = worst_rel(&ascii(&body), &stored("annual_res.dat"));
    assert!(w < PRINT_TOL, "annual: worst relative difference {w}");
}

/// `-o out_%04d.dat`: one file per hour with FRAME=i, each a 45×1 column of the annual result.
#[test]
fn per_step_output_files() {
    let dir = common::scratch("dctimestep-per-step");
    let spec = dir.join("out_%04d.dat");
    let mut c = ours();
    c.arg("-o")
        .arg(&spec)
        .args(["V.vmx", "T.mtx", "D.dmx", "test.m1.smx"]);
    assert!(run(c).is_empty());
    let all = stored("annual_res.dat");
    for t in 0..56 {
        let f = dir.join(format!("out_{t:04}.dat"));
        let (head, body) = split(&std::fs::read(&f).unwrap());
        assert!(head.contains(&format!("FRAME={t}")), "{head:?}");
        assert!(head.contains(&"NROWS=45".to_string()) && head.contains(&"NCOLS=1".to_string()));
        let got = ascii(&body);
        let want: Vec<f64> = (0..45)
            .flat_map(|r| (0..3).map(move |c| (r, c)))
            .map(|(r, c)| all[(r * 56 + t) * 3 + c])
            .collect();
        let w = worst_rel(&got, &want);
        assert!(w < PRINT_TOL, "step {t}: {w}");
    }
    assert!(!dir.join("out_0056.dat").exists());
    // A single time step writes index 0 without FRAME=.
    let spec = dir.join("one_%d.dat");
    let mut c = ours();
    c.arg("-o")
        .arg(&spec)
        .args(["V.vmx", "T.mtx", "D.dmx", "sky_t1_mar21_1000_clear.skv"]);
    run(c);
    let (head, _) = split(&std::fs::read(dir.join("one_0.dat")).unwrap());
    assert!(!head.iter().any(|l| l.starts_with("FRAME=")));
}

fn oracle_cmd(o: &common::Oracle) -> Command {
    let mut c = o.command("dctimestep");
    c.current_dir(common::fixture("threephase"));
    c
}

/// Header lines identical to the oracle's (clock lines aside) and numbers equal to print
/// precision (float output: 1e-6, one float rounding each side plus Radiance's float
/// intermediates) for every output format, with and without -h, reshaped with -x/-y.
#[test]
fn oracle_headers_and_values_match() {
    let Some(o) = common::oracle() else { return };
    let cases: [&[&str]; 9] = [
        &[],
        &["-of"],
        &["-od"],
        &["-h"],
        &["-h", "-of"],
        &["-y", "45"],
        &["-x", "5", "-y", "9"],
        &["-x", "45"],
        &["-oa"],
    ];
    for sky in ["sky_t2_jun21_1500_clear.skv", "test.m1.smx"] {
        for opts in cases {
            let args: Vec<&str> = opts
                .iter()
                .copied()
                .chain(["V.vmx", "T.mtx", "D.dmx", sky])
                .collect();
            let mut a = ours();
            a.args(&args);
            let mut b = oracle_cmd(&o);
            b.args(&args);
            let (oa, ob) = (a.output().unwrap(), b.output().unwrap());
            assert_eq!(
                oa.status.success(),
                ob.status.success(),
                "{args:?}: exit status"
            );
            if !ob.status.success() {
                continue;
            }
            let (ha, ba, hb, bb) = if opts.contains(&"-h") {
                (vec![], oa.stdout.clone(), vec![], ob.stdout.clone())
            } else {
                let (ha, ba) = split(&oa.stdout);
                let (hb, bb) = split(&ob.stdout);
                (ha, ba, hb, bb)
            };
            assert_eq!(ha, hb, "{args:?}: header");
            let (va, vb) = if opts.contains(&"-of") {
                (floats(&ba), floats(&bb))
            } else if opts.contains(&"-od") {
                let d = |b: &[u8]| -> Vec<f64> {
                    b.chunks_exact(8)
                        .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                        .collect()
                };
                (d(&ba), d(&bb))
            } else {
                assert_eq!(
                    String::from_utf8_lossy(&ba).lines().count(),
                    String::from_utf8_lossy(&bb).lines().count(),
                    "{args:?}: line layout"
                );
                (ascii(&ba), ascii(&bb))
            };
            let w = worst_rel(&va, &vb);
            assert!(w < PRINT_TOL, "{args:?}: worst relative difference {w}");
        }
    }
}

/// RGBE output (`-oc`, also reshaped) and the picture-component form are byte-identical
/// with the oracle's apart from the clock lines: RGBE's 8-bit mantissas hide the
/// float-rounding differences of the products.
#[test]
fn oracle_rgbe_and_picture_form_identical() {
    let Some(o) = common::oracle() else { return };
    let cases: [&[&str]; 5] = [
        &[
            "-oc",
            "V.vmx",
            "T.mtx",
            "D.dmx",
            "sky_t1_mar21_1000_clear.skv",
        ],
        &[
            "-oc",
            "-x",
            "9",
            "V.vmx",
            "T.mtx",
            "D.dmx",
            "sky_t1_mar21_1000_clear.skv",
        ],
        &["-oc", "V.vmx", "T.mtx", "D.dmx", "test.m1.smx"],
        &[
            "vimg/v%03d.hdr",
            "T.mtx",
            "D.dmx",
            "sky_t3_dec21_1200_clear.skv",
        ],
        // -x/-y are ignored by the picture form, as by Radiance.
        &[
            "-x",
            "16",
            "vimg/v%03d.hdr",
            "T.mtx",
            "D.dmx",
            "sky_t3_dec21_1200_clear.skv",
        ],
    ];
    for args in cases {
        let mut a = ours();
        a.args(args);
        let mut b = oracle_cmd(&o);
        b.args(args);
        let (ra, rb) = (run(a), run(b));
        assert_eq!(split(&ra), split(&rb), "{args:?}");
    }
}

/// The picture form with the XML against the stored `img_*.hdr` (32×26): every channel of
/// every decoded pixel agrees to RGBE rounding (one mantissa step of the pixel's shared
/// exponent, 1/128 of its largest channel at most, on each side).
#[test]
fn picture_form_matches_stored_image() {
    let mut c = ours();
    c.args([
        "vimg/v%03d.hdr",
        "blinds_kf.xml",
        "D.dmx",
        "sky_t1_mar21_1000_clear.skv",
    ]);
    let out = c.output().unwrap();
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("changing output type to -oc"));
    let read =
        |b: &[u8]| fenestra_formats::picture::Picture::read(&mut &b[..], "test").expect("picture");
    let got = read(&out.stdout);
    let want = read(&std::fs::read(tp("img_t1_mar21_1000_clear.hdr")).unwrap());
    assert_eq!(got.res, want.res);
    assert_eq!((got.res.scanlen(), got.res.numscans()), (32, 26));
    let (hg, _) = split(&out.stdout);
    let (hw, _) = split(&std::fs::read(tp("img_t1_mar21_1000_clear.hdr")).unwrap());
    assert_eq!(hg, hw);
    for (g, w) in got.pixels.iter().zip(&want.pixels) {
        let big = g.iter().chain(w).fold(0f32, |a, b| a.max(*b)) as f64;
        for c in 0..3 {
            let (a, b) = (g[c] as f64, w[c] as f64);
            assert!(a.is_finite() && b.is_finite(), "pixel {g:?} vs {w:?}");
            assert!(
                (a - b).abs() <= big / 128.0,
                "pixel channel {c}: {g:?} vs {w:?}"
            );
        }
    }
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn mtx(rows: usize, cols: usize, vals: impl Fn(usize, usize) -> f64) -> String {
    let mut s = format!("#?RADIANCE\nNROWS={rows}\nNCOLS={cols}\nNCOMP=3\nFORMAT=ascii\n\n");
    for r in 0..rows {
        for c in 0..cols {
            let v = vals(r, c);
            s.push_str(&format!("{v} {} {} ", v * 2.0, v * 3.0));
        }
        s.push('\n');
    }
    s
}

/// Two-phase form, headerless sky with -n, zero sky, and the size checks.
#[test]
fn two_phase_headerless_and_errors() {
    let dir = common::scratch("dctimestep-small");
    let dc = write(&dir, "dc.mtx", &mtx(2, 3, |r, c| (r * 3 + c + 1) as f64));
    // Two steps, patches as rows: step 0 = (1,2,3) grey, step 1 all zero.
    let sky = "1 1 1 0 0 0\n2 2 2 0 0 0\n3 3 3 0 0 0\n";
    let skyf = write(&dir, "sky.txt", sky);
    let mut c = common::fenestra("dctimestep");
    c.args(["-n", "2"]).arg(&dc).arg(&skyf);
    let (head, body) = split(&run(c));
    assert!(head.contains(&"NROWS=2".to_string()) && head.contains(&"NCOLS=2".to_string()));
    let text = String::from_utf8(body).unwrap();
    // Row 0: 1·1+2·2+3·3 = 14 (×2, ×3 per channel); night step exact zeros.
    assert_eq!(
        text.lines().next().unwrap(),
        "1.400000e+01 2.800000e+01 4.200000e+01\t0.000000e+00 0.000000e+00 0.000000e+00"
    );
    // The same sky on stdin with a header, 1-argument form.
    let headed = format!("#?RADIANCE\nNROWS=3\nNCOLS=2\nNCOMP=3\nFORMAT=ascii\n\n{sky}");
    let mut c = common::fenestra("dctimestep");
    c.arg(&dc)
        .stdin(std::fs::File::open(write(&dir, "skyh.txt", &headed)).unwrap());
    assert_eq!(split(&run(c)).1, text.as_bytes());

    let fails = |args: &[&Path], what: &[&str]| {
        let out = common::fenestra("dctimestep").args(args).output().unwrap();
        assert!(!out.status.success(), "{args:?} should fail");
        assert!(out.stdout.is_empty() || !out.stdout.starts_with(b"#?"));
        let err = String::from_utf8_lossy(&out.stderr);
        for w in what {
            assert!(err.contains(w), "{args:?}: '{err}' lacks '{w}'");
        }
    };
    // Sky of 4 patches for a 3-column DC (e.g. MF 1 vs MF 2).
    let sky4 = write(&dir, "sky4.mtx", &mtx(4, 1, |_, _| 1.0));
    fails(&[&dc, &sky4], &["sky4.mtx", "4 rows", "3 columns"]);
    // D rows vs T columns, V columns vs T rows, D columns vs sky rows.
    let t = write(&dir, "t.mtx", &mtx(3, 2, |_, _| 1.0));
    let d_bad = write(&dir, "d3.mtx", &mtx(3, 4, |_, _| 1.0));
    let d_ok = write(&dir, "d2.mtx", &mtx(2, 4, |_, _| 1.0));
    let v_ok = write(&dir, "v.mtx", &mtx(5, 3, |_, _| 1.0));
    let v_bad = write(&dir, "v2.mtx", &mtx(5, 2, |_, _| 1.0));
    let sky3 = write(&dir, "sky3.mtx", &mtx(3, 1, |_, _| 1.0));
    fails(
        &[&v_ok, &t, &d_bad, &sky4],
        &["d3.mtx", "3 rows", "t.mtx", "2 columns"],
    );
    fails(
        &[&v_bad, &t, &d_ok, &sky4],
        &["v2.mtx", "2 columns", "t.mtx", "3 rows"],
    );
    fails(
        &[&v_ok, &t, &d_ok, &sky3],
        &["sky3.mtx", "3 rows", "d2.mtx", "4 columns"],
    );
    let mut c = common::fenestra("dctimestep");
    c.arg(&v_ok).arg(&t).arg(&d_ok).arg(&sky4);
    let vals = ascii(&split(&run(c)).1);
    // V·T·D·s with elements (1, 2, 3) everywhere: 3·2·4 = 24 paths of c⁴ per channel.
    assert_eq!(&vals[..3], &[24.0, 24.0 * 16.0, 24.0 * 81.0]);
    // Reshape that does not fit.
    let out = common::fenestra("dctimestep")
        .args(["-x", "2", "-y", "2"])
        .arg(&dc)
        .arg(&sky3)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("Bad dimensions: 2x2 != 2x1"));
}

/// `pcomb '!dctimestep …' '!dctimestep …'` for two window groups (here the same group
/// twice with two skies) equals the oracle's pcomb of the oracle's dctimestep pictures.
#[test]
fn oracle_pcomb_of_dctimestep_pictures() {
    let Some(o) = common::oracle() else { return };
    let ours_bin = common::fenestra("dctimestep").get_program().to_owned();
    let ours_bin = ours_bin.to_string_lossy();
    let oracle_bin = o.bin("dctimestep");
    let oracle_bin = oracle_bin.to_string_lossy();
    let args = |bin: &str, sky: &str| format!("!{bin} vimg/v%03d.hdr T.mtx D.dmx {sky}");
    let (s1, s2) = (
        "sky_t1_mar21_1000_clear.skv",
        "sky_t4_sep21_1200_overcast.skv",
    );
    let mut a = common::fenestra("pcomb");
    a.current_dir(common::fixture("threephase"))
        .arg(args(&ours_bin, s1))
        .arg(args(&ours_bin, s2));
    let mut b = o.command("pcomb");
    b.current_dir(common::fixture("threephase"))
        .arg(args(&oracle_bin, s1))
        .arg(args(&oracle_bin, s2));
    let (ra, rb) = (run(a), run(b));
    let pa = fenestra_formats::picture::Picture::read(&mut &ra[..], "t").unwrap();
    let pb = fenestra_formats::picture::Picture::read(&mut &rb[..], "t").unwrap();
    assert_eq!(pa.res, pb.res);
    assert_eq!(pa.pixels, pb.pixels);
}

/// Picture form over 56 time steps: per-step files (`-o i%02d.hdr`, FRAME=i) and one stream (a
/// full header before the first frame, then `FRAME=i`, FORMAT and resolution before each
/// later one) as the oracle writes them; `-h` leaves picture headers on, as in Radiance.
/// Pixels within one RGBE mantissa step (Radiance sums the components in float, alternating
/// the order from step to step).
#[test]
fn oracle_picture_form_time_steps() {
    let Some(o) = common::oracle() else { return };
    let fx = common::fixture("threephase");
    let args: Vec<String> = vec![
        "-o".into(),
        "i%02d.hdr".into(),
        fx.join("vimg/v%03d.hdr").display().to_string(),
        fx.join("T.mtx").display().to_string(),
        fx.join("D.dmx").display().to_string(),
        fx.join("test.m1.smx").display().to_string(),
    ];
    let (da, db) = (
        common::scratch("dctimestep-frames-a"),
        common::scratch("dctimestep-frames-b"),
    );
    let mut a = common::fenestra("dctimestep");
    a.current_dir(&da).args(&args);
    run(a);
    let mut b = o.command("dctimestep");
    b.current_dir(&db).args(&args);
    run(b);
    let read = |p: PathBuf| {
        let bytes = std::fs::read(&p).unwrap();
        let pic = fenestra_formats::picture::Picture::read(&mut &bytes[..], "t").unwrap();
        (split(&bytes).0, pic)
    };
    for t in 0..56 {
        let name = format!("i{t:02}.hdr");
        let ((ha, pa), (hb, pb)) = (read(da.join(&name)), read(db.join(&name)));
        assert_eq!(ha, hb, "{name}: header");
        assert_eq!(pa.res, pb.res);
        for (x, y) in pa.pixels.iter().zip(&pb.pixels) {
            for c in 0..3 {
                let m = x[c].max(y[c]);
                assert!(
                    (x[c] - y[c]).abs() <= m / 128.0 + 1e-30,
                    "{name}: {x:?} vs {y:?}"
                );
            }
        }
    }
    // One stream, with and without -h.
    for h in [false, true] {
        let mut v: Vec<&str> = Vec::new();
        if h {
            v.push("-h");
        }
        v.extend(["vimg/v%03d.hdr", "T.mtx", "D.dmx", "test.m1.smx"]);
        let mut a = ours();
        a.args(&v);
        let mut b = oracle_cmd(&o);
        b.args(&v);
        let (ra, rb) = (run(a), run(b));
        let count = |d: &[u8], pat: &[u8]| d.windows(pat.len()).filter(|w| *w == pat).count();
        assert_eq!(count(&ra, b"#?RADIANCE"), 1);
        assert_eq!(count(&ra, b"FRAME="), 56);
        assert_eq!(
            count(
                &ra,
                b"\nFORMAT=32-bit_rle_rgbe\n\n-Y       26 +X       32\n"
            ),
            56
        );
        assert_eq!(count(&rb, b"FRAME="), 56);
        assert_eq!(split(&ra).0, split(&rb).0, "first header");
        assert_eq!(ra.len(), rb.len());
    }
}

/// A Reinhart MF 2 sky (578 patches) with the MF 1 daylight matrix is an error naming both
/// files and sizes; a sun-only MF 1 sky vector agrees with the oracle to print precision.
#[test]
fn mf2_sky_rejected_and_sun_only_sky() {
    let m2 = common::fixture("sky/s01_clear_sun_sf_equinox_noon.m2.skv");
    let mut c = ours();
    c.args(["V.vmx", "T.mtx", "D.dmx"]).arg(&m2);
    let out = c.output().unwrap();
    assert!(!out.status.success());
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    for w in ["m2.skv", "578 rows", "D.dmx", "146 columns"] {
        assert!(err.contains(w), "'{err}' lacks '{w}'");
    }
    let Some(o) = common::oracle() else { return };
    let sun = common::fixture("sky/s01_clear_sun_sf_equinox_noon.m1.sunonly.skv");
    let mut a = ours();
    a.args(["V.vmx", "T.mtx", "D.dmx"]).arg(&sun);
    let mut b = oracle_cmd(&o);
    b.args(["V.vmx", "T.mtx", "D.dmx"]).arg(&sun);
    let (ra, rb) = (split(&run(a)), split(&run(b)));
    assert_eq!(ra.0[2..], rb.0[2..]);
    let w = worst_rel(&ascii(&ra.1), &ascii(&rb.1));
    assert!(w < PRINT_TOL, "sun only: {w}");
}

fn synthetic_xml(
    dir: &Path,
    name: &str,
    incident: &fenestra_bsdf::KlemsBasis,
    outgoing: &fenestra_bsdf::KlemsBasis,
    f: impl Fn(usize, usize) -> f64,
) -> PathBuf {
    use fenestra_bsdf::{Block, BlockData, Bsdf, Direction, KlemsMatrix, Wavelength};
    let values = (0..outgoing.len())
        .flat_map(|o| (0..incident.len()).map(move |i| (o, i)))
        .map(|(o, i)| f(o, i))
        .collect();
    let b = Bsdf {
        name: "synthetic".into(),
        blocks: vec![Block {
            wavelength: Wavelength::Visible,
            direction: Direction::TransmissionFront,
            data_type: "BTDF".into(),
            data: BlockData::Klems(KlemsMatrix {
                incident: incident.clone(),
                outgoing: outgoing.clone(),
                values,
            }),
        }],
        ..Default::default()
    };
    let p = dir.join(name);
    std::fs::write(&p, fenestra_bsdf::write::klems_xml(&b, None).unwrap()).unwrap();
    p
}

/// Grey synthetic XML T against the oracle (no colour quantisation): a specular glazing
/// (diagonal peak 1e4 sr⁻¹) and mixed bases (incident Klems full, outgoing half: T is 77×145,
/// so V needs 77 columns; a 145-column V is an error naming both).
#[test]
fn oracle_specular_and_mixed_basis_xml() {
    let dir = common::scratch("dctimestep-xml");
    let (full, half) = (
        fenestra_bsdf::KlemsBasis::full(),
        fenestra_bsdf::KlemsBasis::half(),
    );
    let spec = synthetic_xml(
        &dir,
        "spec.xml",
        full,
        full,
        |o, i| {
            if o == i {
                1e4
            } else {
                0.0
            }
        },
    );
    let mixed = synthetic_xml(&dir, "mixed.xml", full, half, |o, i| {
        ((o * 7 + i * 3) % 11) as f64 * 0.01
    });
    let v77 = write(
        &dir,
        "v77.mtx",
        &mtx(6, 77, |r, c| ((r + c) % 5) as f64 * 1e-3),
    );
    let d = tp("D.dmx");
    let sky = tp("sky_t2_jun21_1500_clear.skv");
    // Wrong V for the mixed T.
    let out = common::fenestra("dctimestep")
        .arg(tp("V.vmx"))
        .arg(&mixed)
        .arg(&d)
        .arg(&sky)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("V.vmx")
            && err.contains("145 columns")
            && err.contains("mixed.xml")
            && err.contains("77 rows"),
        "{err}"
    );
    let Some(o) = common::oracle() else { return };
    for (v, t) in [(tp("V.vmx"), &spec), (v77.clone(), &mixed)] {
        let mut a = common::fenestra("dctimestep");
        a.arg(&v).arg(t).arg(&d).arg(&sky);
        let mut b = o.command("dctimestep");
        b.arg(&v).arg(t).arg(&d).arg(&sky);
        let (ra, rb) = (split(&run(a)), split(&run(b)));
        assert_eq!(ra.0, rb.0, "{t:?}: header");
        let w = worst_rel(&ascii(&ra.1), &ascii(&rb.1));
        assert!(w < PRINT_TOL, "{t:?}: worst relative difference {w}");
    }
}

/// Picture form errors: components of different sizes and a component that is not a picture
/// are clear errors naming the files; nothing is written to the output.
#[test]
fn picture_form_errors() {
    use fenestra_formats::picture::{write_picture, PictureHeader};
    let dir = common::scratch("dctimestep-picture-errors");
    let pic = |name: &str, w: usize, h: usize| {
        let mut b = Vec::new();
        write_picture(
            &mut b,
            Some(&PictureHeader::default()),
            w,
            h,
            &vec![[1.0f32, 2.0, 3.0]; w * h],
        )
        .unwrap();
        std::fs::write(dir.join(name), b).unwrap();
    };
    pic("a000.hdr", 4, 3);
    pic("a001.hdr", 4, 3);
    pic("b000.hdr", 4, 3);
    pic("b001.hdr", 5, 3);
    std::fs::write(dir.join("c000.hdr"), mtx(1, 1, |_, _| 1.0)).unwrap();
    std::fs::write(dir.join("c001.hdr"), mtx(1, 1, |_, _| 1.0)).unwrap();
    let sky = write(&dir, "sky.mtx", &mtx(2, 1, |r, _| r as f64 + 1.0));
    // Good case: 1·a0 + 2·a1 per channel (×1, ×2, ×3 channel factors of the sky); RGBE
    // decoding adds half a mantissa step (1/64 of 27 at exponent 2^5) on input and output.
    let out = common::fenestra("dctimestep")
        .current_dir(&dir)
        .arg("a%03d.hdr")
        .arg(&sky)
        .output()
        .unwrap();
    common::assert_ok(&out);
    let p = fenestra_formats::picture::Picture::read(&mut &out.stdout[..], "t").unwrap();
    let want = [3.0f32, 12.0, 27.0];
    for px in &p.pixels {
        for c in 0..3 {
            assert!((px[c] - want[c]).abs() <= 27.0 / 64.0, "{px:?}");
        }
    }
    for (pattern, words) in [
        ("b%03d.hdr", ["b001.hdr", "5 x 3", "b000.hdr"]),
        ("c%03d.hdr", ["c000.hdr", "picture", "FORMAT"]),
    ] {
        let mut c = common::fenestra("dctimestep");
        c.current_dir(&dir).arg(pattern).arg(&sky);
        let (stdout, err) = common::output_err(&mut c, pattern);
        assert!(stdout.is_empty(), "{pattern}: output written");
        for w in words {
            assert!(err.contains(w), "{pattern}: '{err}' lacks '{w}'");
        }
    }
}

/// `-o name.exr` writes the picture form as OpenEXR: the same pixels as the RGBE picture
/// (which rounds each pixel to an 8-bit mantissa: within 1% of the largest channel).
#[test]
fn picture_form_writes_openexr_by_extension() {
    use fenestra_formats::picture::Picture;
    let dir = common::fixture("threephase");
    let scratch = common::scratch("dctimestep_exr");
    let exr = scratch.join("img.exr");
    let args = [
        "vimg/v%03d.hdr",
        "blinds_kf.xml",
        "D.dmx",
        "sky_t1_mar21_1000_clear.skv",
    ];
    let mut c = common::fenestra("dctimestep");
    c.current_dir(&dir).arg("-o").arg(&exr).args(args);
    common::run_ok(&mut c);
    let mut c = common::fenestra("dctimestep");
    c.current_dir(&dir).args(args);
    let hdr = common::run_ok(&mut c);
    let pic = Picture::read(&mut std::io::Cursor::new(hdr), "test").unwrap();
    let (w, h, want) = pic.to_standard();
    let img = exr::prelude::read_first_rgba_layer_from_file(
        &exr,
        |res, _| {
            (
                res.width(),
                res.height(),
                vec![[0f32; 3]; res.width() * res.height()],
            )
        },
        |st: &mut (usize, usize, Vec<[f32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let w = st.0;
            st.2[pos.y() * w + pos.x()] = [r, g, b];
        },
    )
    .unwrap();
    let (ew, eh, got) = img.layer_data.channel_data.pixels;
    assert_eq!((ew, eh), (w, h));
    assert!(want.iter().any(|p| p[1] > 0.0));
    for (k, (g, q)) in got.iter().zip(&want).enumerate() {
        let m = q.iter().fold(0f32, |a, b| a.max(*b));
        for c in 0..3 {
            assert!(
                (g[c] - q[c]).abs() <= 0.01 * m + 1e-30,
                "pixel {k}: exr {g:?} hdr {q:?}"
            );
        }
    }
}
