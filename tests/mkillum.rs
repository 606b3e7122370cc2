//! mkillum: directive handling and output layout against the oracle's live mkillum, the
//! reference window (Radiance's stored distributions and proxy renderings), thread-count
//! independence and bad input.

mod common;

use std::path::Path;
use std::process::Command;

fn fx(name: &str) -> String {
    common::fixture("mkillum").join(name).display().to_string()
}

/// Replaces every number in `text` by `N` (layout comparison).
fn mask_numbers(text: &str) -> String {
    let mut out = String::new();
    let mut chars = text.chars().peekable();
    let mut prev_word = false;
    while let Some(c) = chars.next() {
        let starts_number = (c.is_ascii_digit() || c == '-' || c == '.')
            && !prev_word
            && (c.is_ascii_digit()
                || chars
                    .peek()
                    .is_some_and(|d| d.is_ascii_digit() || *d == '.'));
        if starts_number {
            while chars
                .peek()
                .is_some_and(|d| d.is_ascii_alphanumeric() || "+-.".contains(*d))
            {
                chars.next();
            }
            out.push('N');
            prev_word = true;
            continue;
        }
        prev_word = c.is_ascii_alphanumeric() || c == '_';
        out.push(c);
    }
    out
}

/// The `3 r g b` colour lines of an mkillum output, in order.
fn colours(text: &str) -> Vec<[f64; 3]> {
    text.lines()
        .filter_map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            (w.len() == 4 && w[0] == "3" && text.contains("illum"))
                .then(|| [w[1], w[2], w[3]].map(|x| x.parse::<f64>().unwrap_or(f64::NAN)))
        })
        .collect()
}

/// The reference case's mkillum options (`../shared/reference/mkillum/commands.sh`).
const REFERENCE_OPTS: [&str; 10] = [
    "-n", "2", "-ab", "2", "-ad", "1024", "-aa", "0", "-lw", "1e-4",
];

fn ours(dir: &Path) -> Command {
    let mut c = common::fenestra("mkillum");
    c.current_dir(dir);
    c.env(
        "RAYPATH",
        format!(".:{}", common::fixture("threephase").display()),
    );
    c
}

const SKY: &str = "void glow skyglow 0 0 4 2 2.5 3 0\nskyglow source sky 0 0 4 0 0 1 180\n\
                   void glow groundglow 0 0 4 .5 .4 .3 0\ngroundglow source ground 0 0 4 0 0 -1 180\n";

const CANDIDATES: &str = "# candidates\nvoid plastic wall 0 0 5 .5 .5 .5 0 0\n\
#@mkillum i=void c=a d=4 s=8 f=wdist\n\
void polygon up_window 0 0 12 0 0 1  0 1 1  1 1 1  1 0 1\n\
#@mkillum c=d d=10 s=4 m=side\n\
void polygon side_window 0 0 12 0 0 0 0 0 1 1 0 1 1 0 0\n\
#@mkillum c=n d=0 q=4 l+x\n\
void ring roof_ring 0 0 8 0 0 3 0 0 -1 0 0.5\n\
#@mkillum e=void b=100\n\
wall polygon dim 0 0 9 0 0 5 1 0 5 0 1 5\n\
#@mkillum a d=3 s=4\n\
wall sphere ball 0 0 4 0 0 10 0.5\n\
wall cylinder tube 0 0 7 0 0 0 0 0 1 0.1\n\
void polygon flat 0 0 9 0 0 0 1 0 0 2 0 0\n\
wall alias wall2 wall\n\
#@mkillum n\n\
void polygon passed 0 0 9 0 0 0 1 0 0 1 1 0\n";

#[test]
fn oracle_directives_and_layout() {
    // Every directive kind (i= e= a n c=a/d/n d= d=0 s= m= f= b= l+, two bad ones), a
    // polygon, a ring, a sphere, a cylinder (not convertible), a zero-area polygon, an
    // alias and void surfaces, under a sky and a ground glow (-ab 0: each ray returns the
    // glow it meets). Output text must be identical with the numbers masked, the same data
    // files must be written, and the averages agree: exactly (1e-5) where every ray sees
    // one glow (the up window, 2 2.5 3), within 1e-4 for the ring (both 2.3998..), and within 13% for the
    // side window, half sky half ground: 12 of its rays straddle the horizon and go to sky
    // or ground at random in Radiance (unseeded), so its average is the exact one plus
    // k/108 of the sky-ground difference with k = Binomial(12, 1/2) - 6 (10000 seeds of the
    // oracle: sd 1.73, range exactly -6..6): 2.6% sd in blue, and k = -6 gives 1.50 against
    // 1.65, 0.09999999999999987 below, which a 10% limit passed only by rounding. 13% is 5
    // sd and covers every k. Ours gives the exact 1.25 1.45 1.65 (its strata split each
    // such bin evenly).
    let Some(o) = common::oracle() else { return };
    let root = common::scratch("mkillum-directives");
    let mut outs = Vec::new();
    for side in ["theirs", "ours"] {
        let d = root.join(side);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("scene.rad"), SKY).unwrap();
        let (mut oconv, mut mk) = if side == "theirs" {
            (o.command("oconv"), o.command("mkillum"))
        } else {
            (common::fenestra("oconv"), ours(&d))
        };
        let oct = common::run_ok(oconv.arg("scene.rad").current_dir(&d));
        std::fs::write(d.join("s.oct"), oct).unwrap();
        mk.args(["-ab", "0", "s.oct"]).current_dir(&d);
        let out = common::run_stdin(mk, CANDIDATES.as_bytes());
        assert!(
            out.status.success(),
            "{side}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(err.contains("2 error(s) in option line"), "{side}: {err}");
        assert!(
            err.contains("cannot make illum for cylinder \"tube\""),
            "{side}: {err}"
        );
        outs.push(String::from_utf8(out.stdout).unwrap());
    }
    assert_eq!(mask_numbers(&outs[0]), mask_numbers(&outs[1]));
    for f in ["wdist.dat", "wdistR1.dat", "wdistG1.dat", "wdistB1.dat"] {
        assert!(root.join("ours").join(f).exists(), "{f}");
        assert!(root.join("theirs").join(f).exists(), "{f}");
    }
    let (a, b) = (colours(&outs[1]), colours(&outs[0]));
    // up window, side window, ring; the sphere stays as it was (b=100 still applies)
    assert_eq!(a.len(), 3, "{a:?}");
    assert_eq!(a.len(), b.len());
    let tol = [1e-5, 0.13, 1e-4];
    for ((x, y), t) in a.iter().zip(&b).zip(tol) {
        for k in 0..3 {
            assert!((x[k] / y[k] - 1.0).abs() <= t, "{x:?} vs {y:?}");
        }
    }
    // the up window's distribution is uniform: both files are all ones
    let up = std::fs::read_to_string(root.join("ours/wdist.dat")).unwrap();
    assert_eq!(
        up,
        std::fs::read_to_string(root.join("theirs/wdist.dat")).unwrap()
    );
    let _ = std::fs::remove_dir_all(&root);
}

/// Values of a data file (dimensions, values).
fn datafile(path: &Path) -> (Vec<(f64, f64, usize)>, Vec<f64>) {
    let t = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let w: Vec<&str> = t.split_whitespace().collect();
    let nd: usize = w[0].parse().unwrap();
    let mut dims = Vec::new();
    for k in 0..nd {
        dims.push((
            w[1 + 3 * k].parse().unwrap(),
            w[2 + 3 * k].parse().unwrap(),
            w[3 + 3 * k].parse().unwrap(),
        ));
    }
    let vals = w[1 + 3 * nd..].iter().map(|x| x.parse().unwrap()).collect();
    (dims, vals)
}

/// The `-E` file's relative standard errors of the first surface.
fn rel_errors(path: &Path) -> Vec<f64> {
    let t = std::fs::read_to_string(path).unwrap();
    t.lines()
        .nth(2)
        .unwrap()
        .split_whitespace()
        .map(|x| x.parse().unwrap())
        .collect()
}

fn lux(text: &[u8]) -> Vec<f64> {
    common::numbers(text)
        .chunks(3)
        .map(|c| 179.0 * (0.265 * c[0] + 0.670 * c[1] + 0.065 * c[2]))
        .collect()
}

/// The reference room's scene files (paths) with the given window.
fn room_with(window: &str) -> Vec<String> {
    [
        "materials.rad",
        "room.rad",
        "exterior.rad",
        window,
        "sky.rad",
        "skyfunc_glow.rad",
    ]
    .iter()
    .map(|f| fx(f))
    .collect()
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Luminance of every direction of the first surface of an mkillum run in `dir` (output
/// text `out`, data files `base[RGB].dat`): the data file's value × the average colour, the
/// pole row and the wrap-around column left out.
fn direction_lums(dir: &Path, out: &str, base: &str) -> Vec<f64> {
    let avg = colours(out)[0];
    let chans: Vec<Vec<f64>> = ["R", "G", "B"]
        .iter()
        .zip(avg)
        .map(|(ch, a)| {
            let (d, v) = datafile(&dir.join(format!("{base}{ch}.dat")));
            let m = d[1].2;
            (1..d[0].2)
                .flat_map(|r| (0..m - 1).map(move |c| r * m + c))
                .map(|k| v[k] * a)
                .collect()
        })
        .collect();
    (0..chans[0].len())
        .map(|k| 0.265 * chans[0][k] + 0.670 * chans[1][k] + 0.065 * chans[2][k])
        .collect()
}

/// Per-direction spread of replicate runs (`runs[run][direction]`): the relative rms over
/// the directions of each direction's standard deviation, and the runs' mean per direction.
fn replicate_noise(runs: &[Vec<f64>]) -> (f64, Vec<f64>) {
    let k = runs.len() as f64;
    let n = runs[0].len();
    let means: Vec<f64> = (0..n)
        .map(|d| runs.iter().map(|r| r[d]).sum::<f64>() / k)
        .collect();
    let (mut sum, mut count) = (0.0, 0);
    for (d, &m) in means.iter().enumerate() {
        if m > 0.0 {
            let var = runs.iter().map(|r| (r[d] - m).powi(2)).sum::<f64>() / (k - 1.0);
            sum += var / (m * m);
            count += 1;
        }
    }
    ((sum / count as f64).sqrt(), means)
}

#[test]
fn oracle_sobol_bins_are_less_noisy_than_radiance_s() {
    // The reference glass window (its directive, d=100), four runs of each: Radiance's
    // mkillum at s=32 (its runs are seeded differently each time), ours at s=32 and at
    // s=16 (-seed 1..4). Noise: each direction's spread over the four runs, relative rms
    // over the 310 directions. Measured: Radiance 4.41-4.48%, ours 1.92% at s=32 and 2.82% at
    // s=16 (each figure's own uncertainty, from 310 three-degree-of-freedom variances, is a
    // few per cent of it). Checked: ours at s=32 below 0.7 × Radiance's and at s=16 below
    // 0.9 × (the speed claim at equal error rests on it), and the totals over the
    // directions agree within 1% (measured +0.08%; a run's total varies by about 0.25%).
    let Some(o) = common::oracle() else { return };
    let root = common::scratch("mkillum-sobol-noise");
    let scene = room_with("window_glass.rad");
    let directive = std::fs::read_to_string(fx("window_illum_glass.rad")).unwrap();
    let run = |side: &str, s: usize, seed: usize| -> Vec<f64> {
        let d = root.join(format!("{side}-{s}-{seed}"));
        std::fs::create_dir_all(&d).unwrap();
        let (mut oconv, mut mk) = if side == "theirs" {
            (o.command("oconv"), o.command("mkillum"))
        } else {
            let mut mk = ours(&d);
            mk.args(["-seed", &seed.to_string()]);
            (common::fenestra("oconv"), mk)
        };
        let oct = common::run_ok(oconv.args(&scene).current_dir(&d));
        std::fs::write(d.join("scene.oct"), oct).unwrap();
        mk.args(REFERENCE_OPTS).arg("scene.oct").current_dir(&d);
        let input = directive.replace("s=32", &format!("s={s}"));
        let out = String::from_utf8(common::pipe_ok(mk, input.as_bytes())).unwrap();
        direction_lums(&d, &out, "ill_glass")
    };
    let theirs: Vec<Vec<f64>> = (1..=4).map(|k| run("theirs", 32, k)).collect();
    let ours32: Vec<Vec<f64>> = (1..=4).map(|k| run("ours", 32, k)).collect();
    let ours16: Vec<Vec<f64>> = (1..=4).map(|k| run("ours", 16, k)).collect();
    let (nt, mt) = replicate_noise(&theirs);
    let (n32, m32) = replicate_noise(&ours32);
    let (n16, _) = replicate_noise(&ours16);
    assert_eq!(mt.len(), 310);
    assert!(n32 < 0.7 * nt, "s=32: ours {n32} against Radiance's {nt}");
    assert!(n16 < 0.9 * nt, "s=16: ours {n16} against Radiance's {nt}");
    let ratio = m32.iter().sum::<f64>() / mt.iter().sum::<f64>();
    assert!(
        (ratio - 1.0).abs() < 0.01,
        "totals: ours / Radiance's {ratio}"
    );
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn reference_glass_window_distribution_and_proxy() {
    // The reference command (mkillum -n 2 -ab 2 -ad 1024 -aa 0 -lw 1e-4, #@mkillum i=void
    // c=d d=100 s=32) on the glass window. Checks:
    // - output text identical to Radiance's with the numbers masked; average colour within
    //   1% (measured +0.1%);
    // - every direction's relative value against Radiance's file within 4 sd, the sd of a
    //   difference of two estimates: our per-direction standard error (-E, from the spread
    //   of its 32 rays) times sqrt 2, combined with a one-ray floor value/32 (a ray that
    //   meets a rare feature such as the window jamb moves a bin by 1/32, an event one
    //   realisation may miss: it leaves the spread at ~0). Measured: largest 2.6 sd;
    // - the sensors rendered with our proxy (our rtrace, -ab 5 -ad 8192) against Radiance's
    //   proxy rendering: mean within 2% (measured +0.4%), each sensor within 8% (Radiance's
    //   own proxy vs no-proxy: mean |difference| 4.4%, max 8.3%; measured: 3.4%).
    let dir = common::scratch("mkillum-glass");
    let scene = room_with("window_glass.rad");
    let mut oconv = common::fenestra("oconv");
    oconv.args(&scene);
    std::fs::write(dir.join("scene.oct"), common::run_ok(&mut oconv)).unwrap();
    let mut mk = ours(&dir);
    mk.args(REFERENCE_OPTS)
        .args(["-E", "err.txt", "scene.oct", "<"])
        .arg(fx("window_illum_glass.rad"));
    let out = String::from_utf8(common::run_ok(&mut mk)).unwrap();
    let theirs = std::fs::read_to_string(fx("illum_glass.rad")).unwrap();
    // the header names the command: compare from the directive line on
    let from = |t: &str| t[t.find("#@mkillum !").unwrap()..].to_string();
    assert_eq!(mask_numbers(&from(&out)), mask_numbers(&from(&theirs)));
    let (a, b) = (colours(&out)[0], colours(&theirs)[0]);
    for k in 0..3 {
        assert!((a[k] / b[k] - 1.0).abs() < 0.01, "{a:?} vs {b:?}");
    }
    let rel = rel_errors(&dir.join("err.txt"));
    for ch in ["R", "G", "B"] {
        let (da, va) = datafile(&dir.join(format!("ill_glass{ch}.dat")));
        let (db, vb) = datafile(Path::new(&fx(&format!("ill_glass{ch}.dat"))));
        assert_eq!(da, db);
        let m = da[1].2;
        let mut worst = 0.0f64;
        for r in 1..da[0].2 {
            for c in 0..m - 1 {
                let (x, y) = (va[r * m + c], vb[r * m + c]);
                let se = rel[(r - 1) * (m - 1) + c];
                let sd = (2.0 * se * se + (x.max(y) / 32.0).powi(2)).sqrt();
                worst = worst.max((x - y).abs() / sd);
            }
        }
        assert!(
            worst < 4.0,
            "{ch}: a direction {worst:.2} sd from Radiance's"
        );
    }
    // render the sensors through the proxy
    std::fs::write(dir.join("illum_glass.rad"), &out).unwrap();
    let mut oconv = common::fenestra("oconv");
    oconv
        .arg("-f")
        .args(&scene)
        .arg("illum_glass.rad")
        .current_dir(&dir);
    std::fs::write(dir.join("proxy.oct"), common::run_ok(&mut oconv)).unwrap();
    let mut rt = common::fenestra("rtrace");
    rt.args([
        "-n",
        "2",
        "-h",
        "-I+",
        "-ab",
        "5",
        "-ad",
        "8192",
        "-aa",
        "0",
        "-lw",
        "1e-5",
        "proxy.oct",
    ])
    .current_dir(&dir)
    .env("RAYPATH", ".");
    let pts = std::fs::read(fx("sensors.pts")).unwrap();
    let r = common::run_stdin(rt, &pts);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let mine = lux(&r.stdout);
    let rad = lux(&std::fs::read(fx("irr_glass_proxy.dat")).unwrap());
    assert_eq!(mine.len(), rad.len());
    assert!((mean(&mine) / mean(&rad) - 1.0).abs() < 0.02);
    for (x, y) in mine.iter().zip(&rad) {
        assert!((x / y - 1.0).abs() < 0.08, "{x} vs {y}");
    }
    // proxy against no proxy, as Radiance's agreement.txt states for its own: ratio 1.0047,
    // mean |difference| 4.4%, largest 8.3%. Ours: the ratio within 2% and the mean
    // |difference| below 1.5 x Radiance's (measured: 1.007, 1.3%)
    let noproxy = lux(&std::fs::read(fx("irr_glass_noproxy.dat")).unwrap());
    assert!((mean(&mine) / mean(&noproxy) - 1.0).abs() < 0.02);
    let d: Vec<f64> = mine
        .iter()
        .zip(&noproxy)
        .map(|(x, y)| (x / y - 1.0).abs())
        .collect();
    assert!(mean(&d) < 1.5 * 0.044, "mean |difference| {}", mean(&d));
    // our illum file and data files rendered by the oracle's rtrace: mean within 2% of
    // Radiance's rendering of its own proxy (two independent realisations of the same
    // settings; measured +0.08%)
    if let Some(o) = common::oracle() {
        let mut oconv = o.command("oconv");
        oconv
            .arg("-f")
            .args(&scene)
            .arg("illum_glass.rad")
            .current_dir(&dir);
        std::fs::write(dir.join("oracle_proxy.oct"), common::run_ok(&mut oconv)).unwrap();
        let mut rt = o.command("rtrace");
        rt.args([
            "-n",
            "2",
            "-h",
            "-I+",
            "-ab",
            "5",
            "-ad",
            "8192",
            "-aa",
            "0",
            "-lw",
            "1e-5",
            "oracle_proxy.oct",
        ])
        .current_dir(&dir);
        let r = common::run_stdin(rt, &pts);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        let theirs = lux(&r.stdout);
        eprintln!(
            "oracle rtrace with our proxy: mean {:.1} lux; Radiance's own proxy {:.1}",
            mean(&theirs),
            mean(&rad)
        );
        assert!((mean(&theirs) / mean(&rad) - 1.0).abs() < 0.02);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A window that sees a small, very bright patch (a white patch in full sun, off the
/// window's normal, against a dim sky) gets a warning naming the peak and what to do;
/// the same window without the sun gets none. (A peak straddling the pole's cells, which
/// meet at the normal, is shared among them and not reported.)
#[test]
fn a_peak_in_the_distribution_is_reported() {
    let root = common::scratch("mkillum-peak");
    for sun in [true, false] {
        let d = root.join(if sun { "sun" } else { "plain" });
        std::fs::create_dir_all(&d).unwrap();
        let mut scene = String::from(
            "void glow dim 0 0 4 .01 .01 .01 0\ndim source sky 0 0 4 0 0 1 180\n\
             void plastic white 0 0 5 .8 .8 .8 0 0\n\
             white polygon patch 0 0 12 1.2 0.1 1.5  1.2 0.4 1.5  1.5 0.4 1.5  1.5 0.1 1.5\n",
        );
        if sun {
            scene.push_str(
                "void light solar 0 0 3 1e6 1e6 1e6\nsolar source sun 0 0 4 0 0 -1 0.5\n",
            );
        }
        std::fs::write(d.join("scene.rad"), scene).unwrap();
        let mut mk = ours(&d);
        mk.args(["-ab", "0", "scene.rad"]);
        let out = common::run_stdin_ok(
            mk,
            b"#@mkillum c=d d=6 s=64\nvoid polygon w 0 0 12 0 0 0 0 0.5 0 0.5 0.5 0 0.5 0 0\n",
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(err.contains("carries"), sun, "{err}");
        if sun {
            assert!(
                err.contains("polygon \"w\"") && err.contains("raise d= (now 6)"),
                "{err}"
            );
            // p+ (fenestra): sampled again at 4x the density until no cell holds the peak
            let mut mk = ours(&d);
            mk.args(["-ab", "0", "scene.rad"]);
            let out = common::run_stdin_ok(
                mk,
                b"#@mkillum c=d d=6 s=64 p+ f=fine\nvoid polygon w 0 0 12 0 0 0 0 0.5 0 0.5 0.5 0 0.5 0 0\n",
            );
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(err.contains("at d=6: sampled again at d=24 (p+)"), "{err}");
            assert!(!err.contains("raise d="), "{err}");
            // the data file holds the finer grid: 80 directions at d=24 or 310 at d=96
            // (the pole row added), not 12
            let (grid, _) = datafile(&d.join("fineR.dat"));
            let cells: usize = grid.iter().map(|g| g.2).product();
            assert!(cells > 12 * 4, "{grid:?}");
        }
    }
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn same_output_for_any_thread_count() {
    let root = common::scratch("mkillum-threads");
    let mut texts = Vec::new();
    for n in ["1", "2"] {
        let d = root.join(n);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(
            d.join("scene.rad"),
            format!("{SKY}void plastic grey 0 0 5 .5 .5 .5 0 0\ngrey polygon box 0 0 12 -1 -1 2 1 -1 2 1 1 2 -1 1 2\n"),
        )
        .unwrap();
        let mut mk = ours(&d);
        mk.args(["-n", n, "-ab", "1", "-ad", "32", "scene.rad"]);
        let mut all = common::pipe_ok(
            mk,
            b"#@mkillum c=d d=6 s=6\nvoid polygon w 0 0 12 0 0 0 0 0.5 0 0.5 0.5 0 0.5 0 0\n",
        );
        for f in ["illumR.dat", "illumG.dat", "illumB.dat"] {
            all.extend(std::fs::read(d.join(f)).unwrap());
        }
        texts.push(all);
    }
    let strip = |t: &[u8]| -> Vec<u8> {
        let s = String::from_utf8_lossy(t);
        s.lines()
            .filter(|l| !l.starts_with("# "))
            .collect::<Vec<_>>()
            .join("\n")
            .into_bytes()
    };
    assert_eq!(strip(&texts[0]), strip(&texts[1]));
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn bad_input_is_reported_clearly() {
    let dir = common::scratch("mkillum-bad");
    std::fs::write(dir.join("scene.rad"), SKY).unwrap();
    let run = |input: &[u8]| {
        let mut mk = ours(&dir);
        mk.args(["-ab", "0", "scene.rad"]);
        common::run_stdin(mk, input)
    };
    // an unknown directive: echoed with the error count, the rest still processed
    let out = run(b"#@mkillum q=1 d=4 s=2\nvoid polygon w 0 0 9 0 0 0 1 0 0 0 1 0\n");
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("# mkillum: the following option line has 1 error(s):"),
        "{text}"
    );
    assert!(text.contains("illum illum_mat"), "{text}");
    // a zero-area polygon: warned about and passed through
    let out = run(b"#@mkillum d=4 s=2\nglass_mat polygon z 0 0 9 0 0 0 1 0 0 2 0 0\n");
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot make illum for polygon \"z\""));
    assert!(String::from_utf8_lossy(&out.stdout).contains("glass_mat polygon z"));
    // an octree as input
    let mut oconv = common::fenestra("oconv");
    oconv.arg("scene.rad").current_dir(&dir);
    let oct = common::run_ok(&mut oconv);
    let out = run(&oct);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("not scene text"));
    // a truncated primitive names the line
    let out = run(b"#@mkillum d=4\n\nvoid polygon w 0 0 9 0 0\n");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("line 3"), "{err}");
    // an unknown type
    let out = run(b"void polygonn w 0 0 9 0 0 0 1 0 0 0 1 0\n");
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown type \"polygonn\""));
    // a missing input file after '<'
    let mut mk = ours(&dir);
    mk.args(["scene.rad", "<", "missing.rad"]);
    let out = mk.output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing.rad"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn reference_bsdf_window_colour_distribution_and_proxy() {
    // The reference BSDF window (blinds_kf.xml: a coloured Klems file, CIE-X/Y/Z blocks).
    // - rtrace without proxy (-ab 5 -ad 8192, 45 sensors) against Radiance's: each
    //   channel's total within 2% (measured R -0.02%, G +1.2%, B +0.7%; before the BSDF
    //   material carried the file's colour, blue was 11.5% high);
    // - mkillum's average colour within 2% of Radiance's (measured -0.3%, -0.4%, -1.1%);
    // - per direction, the noise model of the glass test (sample-spread se x sqrt 2 with a
    //   one-ray floor) with a heavier tail allowed: rays scattered by the blind's BSDF
    //   toward the sun are rare events far larger than a bin's mean, so at most 3% of the
    //   310 directions beyond 3 sd and none beyond 10 (measured 3 and 6.8);
    // - the sensors rendered with our proxy against Radiance's proxy rendering: mean within
    //   3% (measured -0.2%), each sensor within 15% (measured 5.9%; Radiance's own proxy vs
    //   no-proxy differ by 17.5% on average, 138% at worst).
    let dir = common::scratch("mkillum-bsdf");
    let scene = room_with("window_bsdf.rad");
    let raypath = format!(".:{}", common::fixture("threephase").display());
    let pts = std::fs::read(fx("sensors.pts")).unwrap();
    let render = |oct: &str| -> Vec<u8> {
        let mut rt = common::fenestra("rtrace");
        rt.args([
            "-n", "2", "-h", "-I+", "-ab", "5", "-ad", "8192", "-aa", "0", "-lw", "1e-5", oct,
        ])
        .current_dir(&dir)
        .env("RAYPATH", &raypath);
        let r = common::run_stdin(rt, &pts);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        r.stdout
    };
    let mut oconv = common::fenestra("oconv");
    oconv.args(&scene);
    std::fs::write(dir.join("scene.oct"), common::run_ok(&mut oconv)).unwrap();
    let plain = common::numbers(&render("scene.oct"));
    let theirs = common::numbers(&std::fs::read(fx("irr_bsdf_noproxy.dat")).unwrap());
    for ch in 0..3 {
        let a: f64 = plain.iter().skip(ch).step_by(3).sum();
        let b: f64 = theirs.iter().skip(ch).step_by(3).sum();
        assert!((a / b - 1.0).abs() < 0.02, "channel {ch}: {a} vs {b}");
    }
    let mut mk = ours(&dir);
    mk.args(REFERENCE_OPTS)
        .args(["-E", "err.txt", "scene.oct", "<"])
        .arg(fx("window_illum_bsdf.rad"));
    let out = String::from_utf8(common::run_ok(&mut mk)).unwrap();
    let rad = std::fs::read_to_string(fx("illum_bsdf.rad")).unwrap();
    let (a, b) = (colours(&out)[0], colours(&rad)[0]);
    for k in 0..3 {
        assert!((a[k] / b[k] - 1.0).abs() < 0.02, "{a:?} vs {b:?}");
    }
    let rel = rel_errors(&dir.join("err.txt"));
    for ch in ["R", "G", "B"] {
        let (da, va) = datafile(&dir.join(format!("ill_bsdf{ch}.dat")));
        let (db, vb) = datafile(Path::new(&fx(&format!("ill_bsdf{ch}.dat"))));
        assert_eq!(da, db);
        let m = da[1].2;
        let (mut beyond3, mut worst, mut n) = (0, 0.0f64, 0);
        for r in 1..da[0].2 {
            for c in 0..m - 1 {
                let (x, y) = (va[r * m + c], vb[r * m + c]);
                let se = rel[(r - 1) * (m - 1) + c];
                let sd = (2.0 * se * se + (x.max(y) / 32.0).powi(2)).sqrt();
                let z = (x - y).abs() / sd;
                beyond3 += usize::from(z > 3.0);
                worst = worst.max(z);
                n += 1;
            }
        }
        assert!(
            beyond3 * 100 <= 3 * n && worst < 10.0,
            "{ch}: {beyond3} of {n} beyond 3 sd, worst {worst:.1}"
        );
    }
    std::fs::write(dir.join("illum_bsdf.rad"), &out).unwrap();
    let mut oconv = common::fenestra("oconv");
    oconv
        .arg("-f")
        .args(&scene)
        .arg("illum_bsdf.rad")
        .current_dir(&dir);
    std::fs::write(dir.join("proxy.oct"), common::run_ok(&mut oconv)).unwrap();
    let mine = lux(&render("proxy.oct"));
    let rad = lux(&std::fs::read(fx("irr_bsdf_proxy.dat")).unwrap());
    assert!((mean(&mine) / mean(&rad) - 1.0).abs() < 0.03);
    for (x, y) in mine.iter().zip(&rad) {
        assert!((x / y - 1.0).abs() < 0.15, "{x} vs {y}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn native_illum_patterns_give_the_cal_engine_s_numbers() {
    // A proxy's distribution over fenestra's own illum.cal is evaluated natively; the same
    // file with one comment added goes through the .cal engine. Both renderings (flat
    // colordata and brightdata illums, and a spherical one) must be the same bytes.
    let dir = common::scratch("mkillum-native");
    std::fs::write(
        dir.join("scene.rad"),
        format!("{SKY}void plastic grey 0 0 5 .5 .5 .5 0 0\ngrey polygon box 0 0 12 -1 -1 2 1 -1 2 1 1 2 -1 1 2\n"),
    )
    .unwrap();
    let mut mk = ours(&dir);
    mk.args(["-ab", "1", "-ad", "64", "scene.rad"]);
    let out = common::pipe_ok(
        mk,
        b"#@mkillum c=d d=12 s=4 m=a\nvoid polygon w 0 0 12 0 0 0 0 0.5 0 0.5 0.5 0 0.5 0 0\n\
          #@mkillum c=n m=b\nvoid polygon w2 0 0 12 1 0 0 1 0.5 0 1.5 0.5 0 1.5 0 0\n\
          #@mkillum m=c\nvoid sphere s 0 0 4 0 0 5 0.3\n",
    );
    std::fs::write(dir.join("illum.rad"), out).unwrap();
    std::fs::create_dir_all(dir.join("alt")).unwrap();
    let mut cal = std::fs::read_to_string(common::fenestra_lib().join("illum.cal")).unwrap();
    cal.push_str("{ a copy: not the shipped text }\n");
    std::fs::write(dir.join("alt/illum.cal"), cal).unwrap();
    let rays = b"0.2 0.2 -1 0 0 1\n0.3 0.1 -2 0.1 0.2 1\n1.2 0.2 -1 0 0.3 1\n0 0 3 0 0 1\n0.5 0.5 -0.5 0.2 0.2 1\n";
    let render = |raypath: &str| {
        let mut rt = common::fenestra("rtrace");
        rt.args(["-h", "-ab", "0", "-I+", "scene.rad", "illum.rad"])
            .current_dir(&dir)
            .env("RAYPATH", raypath);
        let r = common::run_stdin(rt, rays);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        r.stdout
    };
    let lib = common::fenestra_lib().display().to_string();
    let native = render(&format!(".:{lib}"));
    let engine = render(&format!(".:alt:{lib}"));
    assert_eq!(native, engine);
    assert!(common::numbers(&native).iter().any(|&v| v > 0.0));
    let _ = std::fs::remove_dir_all(&dir);
}

/// mkillum in BSDF-data mode (`d=blinds_kf.xml`) on the reference room's outside under
/// `sky`, then rtrace on the sensors with the window's BSDF material and the proxy.
fn bsdf_mode_lux(dir: &Path, sky: &str) -> Vec<f64> {
    bsdf_mode_lux_with(dir, sky, "blinds_kf.xml")
}

/// [`bsdf_mode_lux`] with the BSDF file `xml` in `d=` (found in `dir` or the fixtures).
fn bsdf_mode_lux_with(dir: &Path, sky: &str, xml: &str) -> Vec<f64> {
    let raypath = format!(".:{}", common::fixture("threephase").display());
    let outside: Vec<String> = ["materials.rad", "room.rad", "exterior.rad"]
        .iter()
        .map(|f| fx(f))
        .chain([sky.to_string(), fx("skyfunc_glow.rad")])
        .collect();
    let mut oconv = common::fenestra("oconv");
    oconv.args(&outside).current_dir(dir);
    std::fs::write(dir.join("outside.oct"), common::run_ok(&mut oconv)).unwrap();
    let input = std::fs::read_to_string(fx("window_illum.rad"))
        .unwrap()
        .replace("d=100 s=32 f=win_ill", &format!("d={xml} s=64 f=ill_bmode"));
    let mut mk = ours(dir);
    mk.args(REFERENCE_OPTS).arg("outside.oct");
    let illum = common::pipe_ok(mk, input.as_bytes());
    std::fs::write(dir.join("illum.rad"), illum).unwrap();
    let mut oconv = common::fenestra("oconv");
    oconv
        .arg("-f")
        .args(&outside)
        .arg(fx("window_bsdf.rad"))
        .arg("illum.rad")
        .current_dir(dir)
        .env("RAYPATH", &raypath);
    std::fs::write(dir.join("proxy.oct"), common::run_ok(&mut oconv)).unwrap();
    let mut rt = common::fenestra("rtrace");
    rt.args([
        "-n",
        "2",
        "-h",
        "-I+",
        "-ab",
        "5",
        "-ad",
        "8192",
        "-aa",
        "0",
        "-lw",
        "1e-5",
        "proxy.oct",
    ])
    .current_dir(dir)
    .env("RAYPATH", &raypath);
    let r = common::run_stdin(rt, &std::fs::read(fx("sensors.pts")).unwrap());
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    lux(&r.stdout)
}

/// Lux of dctimestep's output (header skipped).
fn res_lux(path: &Path) -> Vec<f64> {
    let t = std::fs::read(path).unwrap();
    let data = match t.windows(2).position(|w| w == b"\n\n") {
        Some(k) if t.starts_with(b"#?RADIANCE") => t[k + 2..].to_vec(),
        _ => t,
    };
    lux(&data)
}

fn mean_abs_rel(a: &[f64], b: &[f64]) -> (f64, f64) {
    let r: Vec<f64> = a.iter().zip(b).map(|(x, y)| (x / y - 1.0).abs()).collect();
    (mean(&r), r.iter().fold(0.0f64, |m, x| m.max(*x)))
}

#[test]
fn bsdf_data_mode_agrees_with_radiance_s_proxy_and_three_phase() {
    // d=blinds_kf.xml: the outside sampled over the BSDF's 145 incident patches (sun added
    // explicitly), the illum = T x incident radiance. The room is rendered with the BSDF
    // window and this proxy (rtrace -ab 5 -ad 8192).
    // Clear sky (the reference's, sun at 40.6 deg): against Radiance's mkillum proxy (made
    // by sampling through the BSDF material) mean within 3% (measured -0.8%), per-sensor
    // mean |difference| below 5% (measured 2.1%); against Radiance's rendering with the BSDF
    // material alone, mean within 5% (measured +1.7%; Radiance's own proxy: +2.5%).
    // Overcast sky (the three-phase reference's t4): against Radiance's three-phase result
    // (res_rflux_t4, same T) mean within 3% (measured +1.3%), per-sensor mean |difference|
    // below 6% and largest below 15% (measured 3.0% and 8.8%; Radiance's BSDF-material
    // rendering against the same three-phase result: 5.2% and 12.2%). A proxy is uniform
    // over the window, so single sensors differ more than means.
    let dir = common::scratch("mkillum-bsdf-mode");
    let clear = bsdf_mode_lux(&dir, &fx("sky.rad"));
    let proxy = lux(&std::fs::read(fx("irr_bsdf_proxy.dat")).unwrap());
    let material = lux(&std::fs::read(fx("irr_bsdf_noproxy.dat")).unwrap());
    assert!(
        (mean(&clear) / mean(&proxy) - 1.0).abs() < 0.03,
        "{} vs {}",
        mean(&clear),
        mean(&proxy)
    );
    assert!(mean_abs_rel(&clear, &proxy).0 < 0.05);
    assert!((mean(&clear) / mean(&material) - 1.0).abs() < 0.05);
    let ovc = common::fixture("rtrace_threephase_bsdf")
        .join("sky_t4_sep21_1200_overcast.rad")
        .display()
        .to_string();
    let overcast = bsdf_mode_lux(&dir, &ovc);
    let three =
        res_lux(&common::fixture("threephase").join("res_rflux_t4_sep21_1200_overcast.dat"));
    assert_eq!(overcast.len(), three.len());
    assert!(
        (mean(&overcast) / mean(&three) - 1.0).abs() < 0.03,
        "{} vs {}",
        mean(&overcast),
        mean(&three)
    );
    let (avg, worst) = mean_abs_rel(&overcast, &three);
    assert!(avg < 0.06 && worst < 0.15, "{avg} {worst}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bsdf_data_mode_takes_tensor_trees() {
    // d=blinds_t4.xml (Radiance's genBSDF -t4 4 tree of the reference blind, projected on
    // the Klems basis by fenestra_bsdf::tree_klems) against d=blinds_kf.xml (the same
    // blind characterised by Radiance as Klems) under the overcast sky, the room rendered
    // as in the test above. The two files are two independent characterisations (-c 400
    // tree, -c 1000 Klems): their transmissions seen from the room (row sums) differ by
    // up to 2.5% near normal and up to 29% at grazing views, so the sensors are compared
    // through their mean: within 5% (measured −0.3%; per sensor mean |difference| 1.2%, largest 2.7%).
    let dir = common::scratch("mkillum-bsdf-tree");
    std::fs::copy(
        common::fixture("dctimestep").join("blinds_t4.xml"),
        dir.join("blinds_t4.xml"),
    )
    .unwrap();
    let ovc = common::fixture("rtrace_threephase_bsdf")
        .join("sky_t4_sep21_1200_overcast.rad")
        .display()
        .to_string();
    let tree = bsdf_mode_lux_with(&dir, &ovc, "blinds_t4.xml");
    let klems = bsdf_mode_lux_with(&dir, &ovc, "blinds_kf.xml");
    let (avg, worst) = mean_abs_rel(&tree, &klems);
    eprintln!(
        "tree {} klems {} per-sensor mean |d| {avg} max {worst}",
        mean(&tree),
        mean(&klems)
    );
    assert!(
        (mean(&tree) / mean(&klems) - 1.0).abs() < 0.05,
        "{} vs {}",
        mean(&tree),
        mean(&klems)
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bsdf_data_mode_bad_files_are_reported_and_skipped() {
    // d= naming a missing or broken file: a warning with the reason, the option line counted
    // as having an error (echoed), the surface converted with what was in effect before.
    let dir = common::scratch("mkillum-bsdf-bad");
    std::fs::write(dir.join("scene.rad"), SKY).unwrap();
    std::fs::write(dir.join("broken.xml"), "<WindowElement><Optical>").unwrap();
    for (file, why) in [
        ("missing.xml", "cannot find BSDF file"),
        ("broken.xml", "cannot load BSDF file"),
    ] {
        let mut mk = ours(&dir);
        mk.args(["-ab", "0", "scene.rad"]);
        let input = format!(
            "#@mkillum d=4 s=2\n#@mkillum d={file}\nvoid polygon w 0 0 9 0 0 0 1 0 0 0 1 0\n"
        );
        let out = common::run_stdin(mk, input.as_bytes());
        assert!(out.status.success());
        let (text, err) = (
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr),
        );
        assert!(err.contains(why), "{err}");
        assert!(
            text.contains("the following option line has 1 error(s)"),
            "{text}"
        );
        assert!(text.contains("illum illum_mat"), "{text}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
