//! rmtxop from the command line, against stored oracle outputs and the oracle's rmtxop.

mod common;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn words(s: &str) -> Vec<String> {
    s.split_whitespace().map(str::to_string).collect()
}

fn tp() -> PathBuf {
    common::fixture("threephase")
}

/// A fresh scratch folder `name` holding copies of the three-phase fixtures `files`.
fn scratch_with(name: &str, files: &[&str]) -> PathBuf {
    let dir = common::scratch(name);
    for f in files {
        std::fs::copy(tp().join(f), dir.join(f)).unwrap();
    }
    dir
}

/// The three-phase fixtures of [`oracle_operations_are_byte_identical`].
const OPS_FIXTURES: [&str; 7] = [
    "T.mtx",
    "D_rflux.dmx",
    "test.m1.smx",
    "blinds_kf.xml",
    "sawtooth.xml",
    "res_t1_mar21_1000_clear.dat",
    "img_t1_mar21_1000_clear.hdr",
];

/// The three-phase fixtures of [`oracle_streamed_conversion_is_identical`].
const STREAM_FIXTURES: [&str; 3] = [
    "T.mtx",
    "res_t1_mar21_1000_clear.dat",
    "img_t1_mar21_1000_clear.hdr",
];

fn run(mut c: Command, dir: &Path, args: &[String]) -> Output {
    c.current_dir(dir)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("cannot run {c:?}: {e}"))
}

/// Compares our stdout and exit status with the oracle's for `args` run in `dir`.
fn same_as_oracle(o: &common::Oracle, dir: &Path, args: &str) {
    let a = words(args);
    let theirs = run(o.command("rmtxop"), dir, &a);
    let ours = run(common::fenestra("rmtxop"), dir, &a);
    assert_eq!(
        theirs.status.success(),
        ours.status.success(),
        "exit status differs for rmtxop {args}: {}",
        String::from_utf8_lossy(&ours.stderr)
    );
    if theirs.stdout != ours.stdout {
        let pos = theirs
            .stdout
            .iter()
            .zip(&ours.stdout)
            .position(|(x, y)| x != y)
            .unwrap_or(theirs.stdout.len().min(ours.stdout.len()));
        panic!(
            "rmtxop {args}: output differs from the oracle's at byte {pos} (lengths {} and {})",
            theirs.stdout.len(),
            ours.stdout.len()
        );
    }
}

/// The stored oracle outputs `ill_*.dat` (made with `rmtxop -fa -c 47.435 119.93 11.635
/// res_*.dat` in the reference folder) are reproduced byte for byte, header included;
/// no oracle needed.
#[test]
fn lux_conversion_reproduces_stored_oracle_output() {
    for (res, ill) in [
        ("res_t1_mar21_1000_clear.dat", "ill_t1_mar21_1000_clear.dat"),
        (
            "res_t4_sep21_1200_overcast.dat",
            "ill_t4_sep21_1200_overcast.dat",
        ),
        (
            "res_rflux_t2_jun21_1500_clear.dat",
            "ill_rflux_t2_jun21_1500_clear.dat",
        ),
        ("annual_res.dat", "annual_ill.dat"),
    ] {
        let out = run(
            common::fenestra("rmtxop"),
            &tp(),
            &words(&format!("-fa -c 47.435 119.93 11.635 {res}")),
        );
        common::assert_ok(&out);
        let want = std::fs::read(common::fixture(&format!("matrices/{ill}"))).unwrap();
        assert!(out.stdout == want, "{ill} not reproduced");
    }
}

/// The exact pipe of examples/three-phase/run.sh: data from stdin (`-`).
#[test]
fn stdin_pipe_form_works() {
    let mut child = common::fenestra("rmtxop")
        .args(words("-fa -c 47.435 119.93 11.635 -"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let data = std::fs::read(tp().join("res_t1_mar21_1000_clear.dat")).unwrap();
    child.stdin.take().unwrap().write_all(&data).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success());
    let want = std::fs::read(common::fixture("matrices/ill_t1_mar21_1000_clear.dat")).unwrap();
    let want = String::from_utf8(want)
        .unwrap()
        .replace("res_t1_mar21_1000_clear.dat\n", "-\n");
    assert_eq!(String::from_utf8(out.stdout).unwrap(), want);
}

/// Transposing twice gives the input back; the header notes the operation.
#[test]
fn transpose_twice_is_identity() {
    let dir = common::scratch("rmtxop-tt");
    let once = run(
        common::fenestra("rmtxop"),
        &tp(),
        &words("-ff -t test.m1.smx"),
    );
    assert!(once.status.success());
    std::fs::write(dir.join("t.f"), &once.stdout).unwrap();
    let text = String::from_utf8_lossy(&once.stdout[..400]).to_string();
    assert!(
        text.contains("NROWS=56") && text.contains("NCOLS=146"),
        "{text}"
    );
    let back = run(common::fenestra("rmtxop"), &dir, &words("-fa -t t.f"));
    let orig = run(common::fenestra("rmtxop"), &tp(), &words("-fa test.m1.smx"));
    let data = |o: &Output| {
        let s = String::from_utf8_lossy(&o.stdout).to_string();
        s[s.find("\n\n").unwrap()..].to_string()
    };
    assert_eq!(data(&back), data(&orig));
}

/// Format conversions of every reference matrix with a header (NROWS present: the
/// oracle's rmtxop cannot read matrices without it) are byte-identical with the
/// oracle's, ascii and binary alike: same single-precision storage, same printing.
#[test]
fn oracle_format_conversions_are_byte_identical() {
    let Some(o) = common::oracle() else { return };
    let mut files: Vec<(PathBuf, String)> = Vec::new();
    for sub in ["threephase", "sky"] {
        let dir = common::fixture(sub);
        let mut names: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| {
                let p = dir.join(n);
                let head = std::fs::read(&p).map(|b| b[..b.len().min(2000)].to_vec());
                head.is_ok_and(|h| {
                    h.starts_with(b"#?RADIANCE") && String::from_utf8_lossy(&h).contains("NROWS=")
                })
            })
            .collect();
        names.sort();
        files.extend(names.into_iter().map(|n| (dir.clone(), n)));
    }
    assert!(files.len() >= 20, "few fixtures found: {}", files.len());
    for (dir, name) in &files {
        for fmt in ["-fa", "-ff", "-fd"] {
            same_as_oracle(&o, dir, &format!("{fmt} {name}"));
        }
    }
}

/// Products (a chain is multiplied cheapest pair first, as the oracle does, which
/// decides the single-precision rounding), sums, scaling, component transforms,
/// transposes, XML input and RGBE output: byte-identical with the oracle.
#[test]
fn oracle_operations_are_byte_identical() {
    let Some(o) = common::oracle() else { return };
    let dir = scratch_with("rmtxop-ops", &OPS_FIXTURES);
    for f in ["m23h.txt", "m32h.txt"] {
        std::fs::copy(common::fixture(&format!("matrices/{f}")), dir.join(f)).unwrap();
    }
    // EXPOSURE lines are undone as a single-precision scale (noted as "Applied scalar").
    let pic = common::run_ok(
        o.command("pfilt")
            .args(["-1", "-e", "0.37"])
            .arg(tp().join("img_t1_mar21_1000_clear.hdr")),
    );
    std::fs::write(dir.join("e.hdr"), pic).unwrap();
    std::fs::write(
        dir.join("ex.txt"),
        "#?RADIANCE\nfoo\nEXPOSURE=3\nEXPOSURE=0.7\nNROWS=1\nNCOLS=4\nNCOMP=3\nFORMAT=ascii\n\n\
         1 2 3 0.7 1.1 13.7 5 7 11 0.123 100.9 17\n",
    )
    .unwrap();
    for case in [
        "-fa e.hdr",
        "-ff -s 0.3 e.hdr",
        "-fa ex.txt",
        "-fa !cat<ex.txt",
        "-ff -t !cat<T.mtx",
        "-ff T.mtx D_rflux.dmx test.m1.smx",
        "-ff -t test.m1.smx -t D_rflux.dmx T.mtx",
        "-fa T.mtx . T.mtx . D_rflux.dmx . test.m1.smx",
        "-fa -s 0.3 T.mtx + -s 0.7 T.mtx",
        "-fd -s 0.3 0.2 0.1 T.mtx + -t -s 0.7 T.mtx",
        "-fa -c .2 .3 .5 -s 1.7 T.mtx",
        "-ff -c .2 .3 .5 .1 .1 .1 -s 3 2 T.mtx",
        "-fa -c 47.435 119.93 11.635 -t res_t1_mar21_1000_clear.dat",
        "-fa T.mtx * T.mtx",
        "-fa sawtooth.xml",
        "-fa -rb sawtooth.xml",
        "-fc T.mtx",
        "-fa img_t1_mar21_1000_clear.hdr",
        "-fa m23h.txt m32h.txt",
        "-fa m23h.txt + m23h.txt",
        "-fa -t m32h.txt + m23h.txt",
        "-fa m23h.txt + m23h.txt m32h.txt",
        "-fa -c 1 1 1 -t m23h.txt",
        "-fa -s 2 m23h.txt",
        "-fc -c 1 1 1 m23h.txt",
        "m23h.txt",
        "m23h.txt m23h.txt",
    ] {
        same_as_oracle(&o, &dir, case);
    }
    // Written to a file, binary headers are padded so data start aligned, as Radiance does.
    for fmt in ["-ff", "-fd"] {
        let write = |mut c: Command, out: &str| {
            let f = std::fs::File::create(dir.join(out)).unwrap();
            let st = c
                .current_dir(&dir)
                .args([fmt, "T.mtx"])
                .stdout(f)
                .status()
                .unwrap();
            assert!(st.success());
            std::fs::read(dir.join(out)).unwrap()
        };
        let a = write(o.command("rmtxop"), "o.bin");
        let b = write(common::fenestra("rmtxop"), "f.bin");
        assert!(a == b, "{fmt} to a file differs from the oracle's");
    }
}

/// From a coloured XML BSDF, Radiance stores each element's chromaticity quantised with a
/// random dither (see tests/bsdf_xml.rs), so only the luminance is reproducible: the
/// `-c .265 .670 .065` (Y) matrix agrees within 2e-5 relative (float storage and the
/// 4-digit primaries' round-off), also through a product with D; so do the reflection
/// matrices (`-rf`, `-rb`; grey sawtooth.xml within 2e-7: single-precision rounding of the
/// diffuse split).
#[test]
fn oracle_xml_luminance_agrees() {
    let Some(o) = common::oracle() else { return };
    let dir = scratch_with(
        "rmtxop-xml",
        &["blinds_kf.xml", "D_rflux.dmx", "sawtooth.xml"],
    );
    for case in [
        "-fd -c .265 .670 .065 -rf blinds_kf.xml",
        "-fd -c .265 .670 .065 -rb blinds_kf.xml",
        "-fd -c .265 .670 .065 blinds_kf.xml",
        "-fd -c .265 .670 .065 -rf sawtooth.xml",
        "-fd -c .265 .670 .065 blinds_kf.xml -c .265 .670 .065 D_rflux.dmx",
    ] {
        let a = words(case);
        let values = |out: Output| -> Vec<f64> {
            assert!(out.status.success());
            let p = out.stdout.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
            out.stdout[p..]
                .chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                .collect()
        };
        let theirs = values(run(o.command("rmtxop"), &dir, &a));
        let ours = values(run(common::fenestra("rmtxop"), &dir, &a));
        assert_eq!(theirs.len(), ours.len());
        let mut worst = 0.0f64;
        for (t, u) in theirs.iter().zip(&ours) {
            if t.abs() > 1e-6 {
                worst = worst.max((u / t - 1.0).abs());
            } else {
                assert!(u.abs() < 2e-6, "{case}: oracle {t}, ours {u}");
            }
        }
        eprintln!("{case}: max relative difference {worst:.2e}");
        assert!(worst < 2e-5, "{case}: luminance differs by {worst:e}");
    }
}

/// Bad inputs: one clear message naming the problem, non-zero exit, nothing on stdout.
#[test]
fn bad_input_fails_cleanly() {
    let dir = common::scratch("rmtxop-bad");
    let t = std::fs::read(tp().join("T.mtx")).unwrap();
    std::fs::write(dir.join("trunc.f"), &t[..1000]).unwrap();
    let res = std::fs::read_to_string(tp().join("res_t1_mar21_1000_clear.dat")).unwrap();
    std::fs::write(dir.join("more.dat"), res.replace("NROWS=45", "NROWS=50")).unwrap();
    std::fs::write(dir.join("fewer.dat"), res.replace("NROWS=45", "NROWS=40")).unwrap();
    std::fs::write(
        dir.join("fmt.dat"),
        res.replace("FORMAT=ascii", "FORMAT=fancy"),
    )
    .unwrap();
    let tt = String::from_utf8_lossy(&t[..300]).to_string();
    let hlen = tt.find("\n\n").unwrap() + 2;
    let mut cols = tt[..hlen].replace("NCOLS=145", "NCOLS=146").into_bytes();
    cols.extend_from_slice(&t[hlen..]);
    std::fs::write(dir.join("cols.f"), cols).unwrap();
    std::fs::copy(common::fixture("matrices/m23h.txt"), dir.join("m23h.txt")).unwrap();
    for (args, want) in [
        ("trunc.f", "truncated"),
        ("more.dat", "unexpected end of data"),
        ("fewer.dat", "more data than the header"),
        ("fmt.dat", "unknown data format"),
        ("cols.f", "truncated"),
        ("missing.mtx", "missing.mtx"),
        ("m23h.txt m23h.txt", "mismatched sizes"),
        ("m23h.txt + -t m23h.txt", "mismatched"),
        ("-c 1 2 m23h.txt", "coefficients"),
        ("-s 1 2 m23h.txt", "one factor"),
        (
            "m23h.txt +",
            "missing matrix argument after the last operator",
        ),
        ("m23h.txt -R x.rep", "-R after the last matrix"),
        ("-fx m23h.txt", "unknown output format"),
        ("-fc -c 1 1 1 1 1 1 m23h.txt", "RGBE"),
        ("-rf missing.xml", "missing.xml"),
        ("-E e.err -R x.rep m23h.txt / m23h.txt", "not '/'"),
    ] {
        let out = run(
            common::fenestra("rmtxop"),
            &dir,
            &words(&format!("-fa {args}")),
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "rmtxop {args} succeeded");
        assert!(out.stdout.is_empty(), "rmtxop {args} wrote output");
        assert!(
            err.contains(want),
            "rmtxop {args}: message '{err}' lacks '{want}'"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}

/// Mutated inputs (bytes flipped, truncated, duplicated, header keys changed) never make
/// rmtxop panic: it either succeeds or fails with a message and no output.
#[test]
fn mutated_inputs_never_panic() {
    let dir = common::scratch("rmtxop-fuzz");
    let sources = [
        std::fs::read(common::fixture("matrices/m23h.txt")).unwrap(),
        std::fs::read(tp().join("res_t1_mar21_1000_clear.dat")).unwrap(),
        {
            let out = run(
                common::fenestra("rmtxop"),
                &tp(),
                &words("-ff res_t1_mar21_1000_clear.dat"),
            );
            out.stdout
        },
        {
            let out = run(
                common::fenestra("rmtxop"),
                &tp(),
                &words("-fd -t res_t1_mar21_1000_clear.dat"),
            );
            out.stdout
        },
    ];
    let mut seed = 0x9e3779b97f4a7c15u64;
    let mut rnd = |n: usize| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % n.max(1) as u64) as usize
    };
    let swaps = [
        ("NROWS=", "NROWS=9"),
        ("NCOLS=", "NCOLS=0"),
        ("NCOMP=", "NCOMP=7"),
        ("FORMAT=ascii", "FORMAT=float"),
        ("FORMAT=float", "FORMAT=double"),
        ("BigEndian=0", "BigEndian=1"),
        ("\n\n", "\n"),
    ];
    let mut runs = 0;
    for src in &sources {
        for k in 0..24 {
            let mut d = src.clone();
            match k % 4 {
                0 => {
                    for _ in 0..1 + rnd(8) {
                        let i = rnd(d.len());
                        d[i] ^= 1 << rnd(8);
                    }
                }
                1 => d.truncate(rnd(d.len())),
                2 => {
                    let i = rnd(d.len());
                    let tail = d[i..].to_vec();
                    d.extend_from_slice(&tail);
                }
                _ => {
                    let (a, b) = swaps[rnd(swaps.len())];
                    // Replace in the header only (binary data stay as they are).
                    if let Some(p) = d.windows(2).position(|w| w == b"\n\n") {
                        let head = String::from_utf8_lossy(&d[..p + 2]).replacen(a, b, 1);
                        let mut nd = head.into_bytes();
                        nd.extend_from_slice(&d[p + 2..]);
                        d = nd;
                    }
                }
            }
            std::fs::write(dir.join("m.in"), &d).unwrap();
            for args in ["-fa m.in", "-ff -t m.in", "-fa -c 1 1 1 m.in"] {
                let out = run(common::fenestra("rmtxop"), &dir, &words(args));
                let err = String::from_utf8_lossy(&out.stderr);
                assert!(!err.contains("panicked"), "rmtxop {args} panicked: {err}");
                assert!(matches!(out.status.code(), Some(0) | Some(1)), "{err}");
                if !out.status.success() {
                    assert!(out.stdout.is_empty(), "rmtxop {args} failed after writing");
                    assert!(err.contains("fatal"), "{err}");
                }
                runs += 1;
            }
        }
    }
    eprintln!("{runs} mutated runs without a panic");
}

/// A single large matrix is converted row by row (forced here with a zero limit):
/// same bytes as the oracle's, with scaling, component transforms and EXPOSURE.
#[test]
fn oracle_streamed_conversion_is_identical() {
    let Some(o) = common::oracle() else { return };
    let dir = scratch_with("rmtxop-stream", &STREAM_FIXTURES);
    for case in [
        "-fa T.mtx",
        "-ff -c .2 .3 .5 -s 2 T.mtx",
        "-fd -s 0.3 T.mtx",
        "-fc T.mtx",
        "-fa -c 47.435 119.93 11.635 res_t1_mar21_1000_clear.dat",
        "-fa !cat<res_t1_mar21_1000_clear.dat",
        "-ff img_t1_mar21_1000_clear.hdr",
    ] {
        let a = words(case);
        let theirs = run(o.command("rmtxop"), &dir, &a);
        let mut c = common::fenestra("rmtxop");
        c.env("FENESTRA_RMTXOP_STREAM", "0");
        let ours = run(c, &dir, &a);
        assert!(ours.status.success());
        assert!(
            theirs.stdout == ours.stdout,
            "streamed rmtxop {case} differs"
        );
    }
}

/// Matrices without NROWS (rcontrib's V.vmx, D.dmx: the oracle's rmtxop cannot read them)
/// are read to the end of their data; the chain V·T·D·s gives the stored oracle
/// `dctimestep` result (printed to 7 digits) within 2e-6 relative, the difference being
/// single-precision storage of the intermediate products.
#[test]
fn chain_without_nrows_matches_stored_dctimestep() {
    let out = run(
        common::fenestra("rmtxop"),
        &tp(),
        &words("-fa V.vmx T.mtx D.dmx sky_t1_mar21_1000_clear.skv"),
    );
    common::assert_ok(&out);
    let nums = |b: &[u8]| -> Vec<f64> {
        let s = String::from_utf8_lossy(b).to_string();
        let p = s.find("\n\n").unwrap() + 2;
        s[p..]
            .split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect()
    };
    let ours = nums(&out.stdout);
    let want = nums(&std::fs::read(tp().join("res_t1_mar21_1000_clear.dat")).unwrap());
    assert_eq!(ours.len(), 45 * 3);
    assert_eq!(ours.len(), want.len());
    let worst = ours
        .iter()
        .zip(&want)
        .map(|(a, b)| {
            // f64::max would drop a NaN: a non-finite value or a zero in the stored file fails
            assert!(a.is_finite() && b.is_finite() && *b != 0.0, "{a} vs {b}");
            (a / b - 1.0).abs()
        })
        .fold(0.0, f64::max);
    eprintln!("V·T·D·s vs stored dctimestep: max relative difference {worst:.1e}");
    assert!(worst < 2e-6, "{worst}");
}

/// Radiance 6's rules found by a differential sweep: `-t -s -c` after the last matrix apply
/// to the result, a one-component right operand of `*` or `/` multiplies (divides) every
/// component, a command of products alone is multiplied from the right where Radiance's
/// rule prefers it (a one-column or narrow rightmost matrix), and `/` gives 0 for a zero
/// divisor with a warning line in the header. Byte-identical, except `/`: fenestra keeps
/// single-precision values and Radiance double, so a quotient can differ by one unit in
/// its 8th printed digit (2e-7 relative allowed).
#[test]
fn oracle_trailing_ops_broadcast_chain_order_division() {
    let Some(o) = common::oracle() else { return };
    let dir = common::scratch("rmtxop-rules");
    let mut rnd = common::xorshift(17);
    let mut write = |name: &str, r: usize, c: usize, n: usize, zero: bool| {
        let mut t = format!("#?RADIANCE\nNROWS={r}\nNCOLS={c}\nNCOMP={n}\nFORMAT=ascii\n\n");
        for i in 0..r {
            let row: Vec<String> = (0..c * n)
                .map(|k| {
                    if zero && i == 0 && k == 0 {
                        "0".to_string()
                    } else {
                        format!("{:.6}", rnd() * 3.0 - 1.0)
                    }
                })
                .collect();
            t += &(row.join(" ") + "\n");
        }
        std::fs::write(dir.join(name), t).unwrap();
    };
    write("A.mtx", 5, 7, 3, false);
    write("B.mtx", 7, 4, 3, false);
    write("E.mtx", 4, 4, 3, false);
    write("W.mtx", 4, 9, 3, false);
    write("v.mtx", 4, 1, 3, false);
    write("F1.mtx", 5, 7, 1, false);
    write("C.mtx", 5, 7, 3, false);
    write("Z.mtx", 5, 7, 3, true);
    for case in [
        "-fa A.mtx -t",
        "-fa A.mtx B.mtx -c 1 0 0",
        "-fa A.mtx + C.mtx -s 2 -t",
        "-fa A.mtx * F1.mtx",
        "-fa A.mtx . B.mtx . E.mtx",
        "-fa A.mtx . B.mtx . v.mtx",
        "-fa A.mtx . B.mtx . W.mtx",
        "-fa A.mtx . B.mtx + C.mtx -t . A.mtx",
    ] {
        same_as_oracle(&o, &dir, case);
    }
    // the broadcast with the one-component operand's replicas (-E): errors of A's shape
    let mut rep =
        String::from("#?RADIANCE\nNREPLICAS=2\nNROWS=10\nNCOLS=7\nNCOMP=1\nFORMAT=ascii\n\n");
    for i in 0..10 {
        let row: Vec<String> = (0..7)
            .map(|k| format!("{}", 0.5 + 0.01 * (i * 7 + k) as f64))
            .collect();
        rep += &(row.join(" ") + "\n");
    }
    std::fs::write(dir.join("F1.rep"), rep).unwrap();
    let out = run(
        common::fenestra("rmtxop"),
        &dir,
        &words("-fa -E e.err A.mtx * -R F1.rep F1.mtx"),
    );
    common::assert_ok(&out);
    let e = std::fs::read_to_string(dir.join("e.err")).unwrap();
    for field in ["NCOMP=3\n", "NROWS=5\n", "NCOLS=7\n"] {
        assert!(e.contains(field), "{field}: {e}");
    }
    for case in [
        "-fa A.mtx / F1.mtx",
        "-fa A.mtx / C.mtx",
        "-fa A.mtx / Z.mtx",
    ] {
        let a = words(case);
        let theirs = run(o.command("rmtxop"), &dir, &a);
        let ours = run(common::fenestra("rmtxop"), &dir, &a);
        assert!(theirs.status.success() && ours.status.success(), "{case}");
        let split = |b: &[u8]| {
            let s = String::from_utf8_lossy(b).into_owned();
            let (h, d) = s.split_once("\n\n").unwrap();
            (h.to_string(), common::numbers(d.as_bytes()))
        };
        let ((th, tv), (oh, ov)) = (split(&theirs.stdout), split(&ours.stdout));
        assert_eq!(th, oh, "{case}: header");
        common::agree(case, &tv, &ov, 2e-7, 1e-30);
        if case.contains("Z.mtx") {
            assert!(
                oh.contains("WARNING: zero divide(s) corrupted results"),
                "{oh}"
            );
            assert!(String::from_utf8_lossy(&ours.stderr).contains("element-wise division"));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
