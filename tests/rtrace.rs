//! rtrace: thread-count independence and agreement with the reference implementation.

mod common;

use std::path::{Path, PathBuf};

const SCENE: [&str; 5] = [
    "materials.rad",
    "room.rad",
    "exterior.rad",
    "window_glass.rad",
    "sky.rad",
];

fn scene_args() -> Vec<String> {
    let dir = common::fixture("rtrace_glass_room");
    SCENE
        .iter()
        .map(|f| dir.join(f).display().to_string())
        .collect()
}

fn sensors() -> Vec<u8> {
    std::fs::read(common::fixture("rtrace_glass_room").join("s9.pts")).unwrap()
}

fn values(out: &[u8]) -> Vec<[f64; 3]> {
    String::from_utf8_lossy(out)
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|w| w.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

fn ours(seed: u64, n: u32, extra: &[&str]) -> Vec<u8> {
    let mut c = common::fenestra("rtrace");
    c.args([
        "-h",
        "-I+",
        "-aa",
        "0",
        "-n",
        &n.to_string(),
        "-seed",
        &seed.to_string(),
    ]);
    c.args(extra);
    c.args(scene_args());
    common::pipe_ok(c, &sensors())
}

#[test]
fn one_and_two_threads_give_identical_bytes() {
    let a = ours(7, 1, &["-ab", "2", "-ad", "256", "-lw", "1e-4"]);
    let b = ours(7, 2, &["-ab", "2", "-ad", "256", "-lw", "1e-4"]);
    assert_eq!(a, b);
    assert_eq!(values(&a).len(), 9);
    let c = ours(8, 2, &["-ab", "2", "-ad", "256", "-lw", "1e-4"]);
    assert_ne!(a, c, "a different seed should change the Monte Carlo noise");
}

#[test]
fn header_and_formats() {
    let mut c = common::fenestra("rtrace");
    c.args(["-ff", "-ovn"]).args(scene_args());
    let mut input = Vec::new();
    for v in [2.0f32, 2.0, 1.5, 0.0, 0.0, 1.0] {
        input.extend(v.to_ne_bytes());
    }
    let out = common::pipe_ok(c, &input);
    let text = String::from_utf8_lossy(&out);
    assert!(
        text.starts_with("#?RADIANCE\n") && text.contains("FORMAT=float\n"),
        "{text}"
    );
    let body = &out[out.windows(2).position(|w| w == b"\n\n").unwrap() + 2..];
    assert_eq!(body.len(), 6 * 4);
    let nz = f32::from_ne_bytes(body[20..24].try_into().unwrap());
    assert_eq!(nz, -1.0, "ceiling normal faces the ray");
}

/// Differential test against the oracle's `rtrace -I` (-ab 3 -ad 4096 -lw 1e-5) on the
/// office with a glass window, a sun and uniform sky/ground glows.
///
/// Monte Carlo errors, measured: the oracle's single-run standard deviation per sensor
/// (green) over 200 seeds of its clock-seeded generator, ORACLE_SD (distributions close to
/// normal, |skew| ≤ 0.3), and ours, s, over 6 seeds here; the difference oracle −
/// mean(ours) has standard deviation √(σ² + s²/6). Each sensor must agree within 4.5 of
/// those (9 sensors: a false failure about 9 × 7e-6), plus 0.5% for the print precision and
/// systematic differences in ray offsets. (Before, σ was taken as s from 6 runs: a t test
/// with 5 degrees of freedom, failing about once in 120 runs on the dim sensors.)
#[test]
fn oracle_rtrace_irradiance_glass_room() {
    let Some((oracle, dir)) = common::cli::oracle_scratch("oracle_rtrace_glass_room") else {
        return;
    };
    let oct = dir.join("scene.oct");
    let mut oc = oracle.command("oconv");
    oc.args(scene_args());
    std::fs::write(&oct, common::run_ok(&mut oc)).unwrap();
    let mut rt = oracle.command("rtrace");
    rt.args([
        "-h", "-I+", "-ab", "3", "-ad", "4096", "-aa", "0", "-lw", "1e-5", "-n", "2",
    ])
    .arg(&oct);
    let theirs = values(&common::pipe_ok(rt, &sensors()));
    let k = 6;
    let runs: Vec<Vec<[f64; 3]>> = (0..k)
        .map(|s| values(&ours(s, 2, &["-ab", "3", "-ad", "4096", "-lw", "1e-5"])))
        .collect();
    const ORACLE_SD: [f64; 9] = [
        0.0168, 0.0294, 0.0373, 0.0320, 0.0154, 0.0194, 0.0248, 0.0268, 0.0222,
    ];
    assert_eq!(theirs.len(), ORACLE_SD.len());
    for i in 0..theirs.len() {
        let (mean, var) = green_mean_var(&runs, i);
        let sd = (ORACLE_SD[i].powi(2) + var / k as f64).sqrt();
        check_sensor(i, theirs[i][1], mean, var.sqrt(), 4.5 * sd + 0.005 * mean);
    }
}

/// Mean and sample variance of sensor `i`'s green value over `runs` (one list of sensor
/// values per run).
fn green_mean_var(runs: &[Vec<[f64; 3]>], i: usize) -> (f64, f64) {
    let n = runs.len() as f64;
    let xs: Vec<f64> = runs.iter().map(|r| r[i][1]).collect();
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var)
}

/// Prints sensor `i`'s oracle value `theirs` against our `mean` (whose spread is `sd`) and
/// asserts that they agree within `tol`.
fn check_sensor(i: usize, theirs: f64, mean: f64, sd: f64, tol: f64) {
    let diff = theirs - mean;
    eprintln!(
        "sensor {i}: oracle {theirs:.4} ours {mean:.4} (sd {sd:.4}) diff {:+.2}%",
        100.0 * diff / mean
    );
    assert!(
        diff.abs() <= tol,
        "sensor {i}: oracle {theirs} vs ours {mean} (tolerance {tol})"
    );
}

/// The office of a stored reference case in `dir` with `window` and `sky`: the paths of its
/// scene files, and the sensor points.
fn office_case(dir: &Path, window: &str, sky: &str) -> (Vec<PathBuf>, Vec<u8>) {
    let files = [
        "materials.rad",
        "room.rad",
        "exterior.rad",
        window,
        sky,
        "skyfunc_glow.rad",
    ];
    let input = std::fs::read(dir.join("sensors.pts")).unwrap();
    (files.iter().map(|f| dir.join(f)).collect(), input)
}

/// Agreement with the stored oracle output `irr_glass_noproxy.dat` (reference case mkillum:
/// office, clear glass, gensky clear sky with sun, `-ab 5 -ad 8192 -lw 1e-5`, 45 sensors).
///
/// Our single-run Monte Carlo spread per sensor is measured over 5 seeds; the oracle's
/// single realisation has the same sampling rules, so the difference has standard deviation
/// s*sqrt(1 + 1/5) (s floored at the median relative spread of all sensors). Every sensor must lie within 4.5 of those plus 0.5% (print digits and
/// ray-offset differences): for 45 normal errors a false failure has probability ~3e-4; s
/// itself comes from 5 runs, which the 4.5 (rather than 4) allows for. The mean over the
/// sensors must agree within 1%.
#[test]
fn reference_mkillum_glass_irradiance() {
    let dir = common::fixture("rtrace_mkillum_glass");
    let (files, input) = office_case(&dir, "window_glass.rad", "sky.rad");
    let theirs = values(&std::fs::read(dir.join("irr_glass_noproxy.dat")).unwrap());
    let k = 5;
    let runs: Vec<Vec<[f64; 3]>> = (0..k)
        .map(|seed| {
            let mut c = common::fenestra("rtrace");
            c.args([
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
                "-n",
                "2",
                "-seed",
                &seed.to_string(),
            ]);
            c.args(&files);
            values(&common::pipe_ok(c, &input))
        })
        .collect();
    let (mut sum_o, mut sum_f) = (0.0, 0.0);
    let stats: Vec<(f64, f64)> = (0..theirs.len())
        .map(|i| {
            let (mean, var) = green_mean_var(&runs, i);
            (mean, var.sqrt())
        })
        .collect();
    // A standard deviation from 5 runs is itself uncertain (4 degrees of freedom); it is
    // not allowed below the median relative spread of all sensors times the sensor's value.
    let mut rel: Vec<f64> = stats.iter().map(|(m, s)| s / m).collect();
    rel.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let med_rel = rel[rel.len() / 2];
    for i in 0..theirs.len() {
        let (mean, s) = stats[i];
        let var = s.max(med_rel * mean).powi(2);
        let sd = var.sqrt() * (1.0 + 1.0 / k as f64).sqrt();
        check_sensor(i, theirs[i][1], mean, var.sqrt(), 4.5 * sd + 0.005 * mean);
        sum_o += theirs[i][1];
        sum_f += mean;
    }
    assert!(
        (sum_o / sum_f - 1.0).abs() < 0.01,
        "means: oracle {sum_o} ours {sum_f}"
    );
}

fn run_scene(text: &str, input: &str, extra: &[&str]) -> std::process::Output {
    static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let k = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = common::scratch(&format!("rtrace_scene_{k}"));
    let f = dir.join("scene.rad");
    std::fs::write(&f, text).unwrap();
    let mut c = common::fenestra("rtrace");
    c.args(["-h"]).args(extra).arg(&f);
    // The tool may reject the scene and exit before reading its input: a
    // broken pipe is expected then (run_stdin ignores it), and the exit status tells the rest.
    common::run_stdin(c, input.as_bytes())
}

#[test]
fn bad_input_gives_one_clear_error_and_no_output() {
    let cases = [
        ("void plastic p 0 0 5 .5 .5 .5 0 0\np mesh m 1 x.rtm 0 0\n", "mesh"),
        ("void plastic p 0 0 5 .5 .5 .5 0 0\np instance i 1 x.oct 0 0\n", "instance"),
        ("void brightfunc b 2 f my.cal 0 0\nb plastic p 0 0 5 .5 .5 .5 0 0\np sphere s 0 0 4 0 0 0 1\n", "brightfunc"),
    ];
    for (text, what) in cases {
        let out = run_scene(text, "0 0 5 0 0 -1\n", &[]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{what}: should fail");
        assert!(
            out.stdout.is_empty(),
            "{what}: partial output {:?}",
            String::from_utf8_lossy(&out.stdout)
        );
        assert!(
            err.contains("fatal") && err.contains(what) && err.contains("scene.rad:"),
            "{what}: {err}"
        );
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn degenerate_polygon_is_a_warning_and_no_nan() {
    let text = "void plastic p 0 0 5 .5 .5 .5 0 0\n\
        p polygon line 0 0 9 0 0 0 1 0 0 2 0 0\n\
        p polygon dup 0 0 12 0 0 0 0 0 0 1 1 0 1 1 0\n\
        p polygon ok 0 0 12 -1 -1 0 1 -1 0 1 1 0 -1 1 0\n\
        void light l 0 0 3 10 10 10\nl sphere bulb 0 0 4 0 0 3 .1\n";
    let out = run_scene(text, "0 0 1 0 0 -1\n0 0 1 0 0 1\n", &["-ovl"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("degenerate") && err.contains("line"), "{err}");
    let text_out = String::from_utf8_lossy(&out.stdout);
    assert!(
        !text_out.contains("nan") && !text_out.contains("inf"),
        "{text_out}"
    );
    assert_eq!(text_out.lines().count(), 2);
}

#[test]
fn concave_polygon_shadow() {
    // an L-shaped blocker above the point: the notch lets the sun through
    let text = "void plastic p 0 0 5 .5 .5 .5 0 0\n\
        p polygon ell 0 0 18 -2 -2 1  2 -2 1  2 0 1  0 0 1  0 2 1  -2 2 1\n\
        void light s 0 0 3 1e4 1e4 1e4\ns source sun 0 0 4 0 0 1 1\n";
    let out = run_scene(text, "1 1 0 0 0 1\n-1 -1 0 0 0 1\n", &["-I+"]);
    let v = values(&out.stdout);
    assert!(v[0][0] > 0.0, "under the notch: lit {v:?}");
    assert_eq!(v[1][0], 0.0, "under the polygon: shadowed");
}

/// The BSDF window (Klems XML `blinds_kf.xml`) under the overcast reference sky: agreement
/// with the stored oracle output (`-ab 6 -ad 16384 -lw 1e-5`, 45 sensors).
///
/// One run of ours (the runs are expensive). Measured single-run spread of these sensors is
/// about 2% (repeated seeds while developing), the oracle's the same, so a sensor's difference
/// has sd ~2.8%: each must agree within 13% (4.6 sd; 45 sensors: false failure ~2e-4 for
/// normal errors). The mean over sensors has sd ~0.45%; it must agree within 2% (4.4 sd; the
/// Lambertian part of the matrices is not split off as Radiance does, which changes which
/// rays count as ambient bounces — measured effect on the mean: +0.5%).
#[test]
fn reference_threephase_bsdf_overcast() {
    let dir = common::fixture("rtrace_threephase_bsdf");
    let (files, input) = office_case(&dir, "window_bsdf.rad", "sky_t4_sep21_1200_overcast.rad");
    let theirs = values(&std::fs::read(dir.join("ref_t4_sep21_1200_overcast.dat")).unwrap());
    let mut c = common::fenestra("rtrace");
    c.env("RAYPATH", common::fixture("threephase"));
    c.args([
        "-h", "-I+", "-ab", "6", "-ad", "16384", "-aa", "0", "-lw", "1e-5", "-n", "2",
    ]);
    c.args(files);
    let ours = values(&common::pipe_ok(c, &input));
    assert_eq!(ours.len(), theirs.len());
    let (mut so, mut sf) = (0.0, 0.0);
    for (i, (o, f)) in theirs.iter().zip(&ours).enumerate() {
        let r = f[1] / o[1];
        eprintln!(
            "sensor {i}: oracle {:.4} ours {:.4} ratio {r:.3}",
            o[1], f[1]
        );
        assert!((r - 1.0).abs() < 0.13, "sensor {i}: ratio {r}");
        so += o[1];
        sf += f[1];
    }
    assert!((sf / so - 1.0).abs() < 0.02, "mean ratio {}", sf / so);
}

/// `-defaults` prints the options in effect (those given before it) in Radiance's layout,
/// `-version` names the program; a sky-only scene (a glow, no light source) runs without
/// the no-light-sources warning, which stays for a scene where nothing emits.
#[test]
fn defaults_version_and_warnings_as_radiance() {
    let dir = common::scratch("rtrace-defaults");
    let out =
        common::run_ok(common::fenestra("rtrace").args(["-ab", "3", "-ss", "0.5", "-defaults"]));
    let text = String::from_utf8_lossy(&out);
    common::cli::assert_contains(&text, &["-ab 3 ", "-ss 0.500000"]);
    assert!(text.lines().count() > 20);
    let out = common::run_ok(common::fenestra("rtrace").arg("-version"));
    assert!(String::from_utf8_lossy(&out).starts_with("fenestra "));
    // one upward ray in the scene file `name` holding `text`
    let run = |name: &str, text: &str| {
        std::fs::write(dir.join(name), text).unwrap();
        let mut c = common::fenestra("rtrace");
        c.args(["-h", name]).current_dir(&dir);
        common::run_stdin(c, b"0 0 0 0 0 1\n")
    };
    let o = run(
        "sky.rad",
        "void glow g\n0\n0\n4 1 1 1 0\ng source s\n0\n0\n4 0 0 1 180\n",
    );
    assert!(o.status.success());
    assert_eq!(
        String::from_utf8_lossy(&o.stderr),
        "",
        "a sky-only scene warned"
    );
    let o = run(
        "dark.rad",
        "void plastic m\n0\n0\n5 .5 .5 .5 0 0\nm sphere b\n0\n0\n4 0 0 5 1\n",
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("no light sources found"));
}

/// A uniform glow of radiance 1 over the whole sky and the whole ground.
const GLOW_SKY_AND_GROUND: &str =
    "void glow skyglow\n0\n0\n4 1 1 1 0\nskyglow source sky\n0\n0\n4 0 0 1 180\n\
     skyglow source ground\n0\n0\n4 0 0 -1 180\n";

/// A rough specular lobe too weak to sample (not above `-st`, default 0.15) joins its side's
/// ambient coefficient, as in Radiance: plastic (spec .02, rough .05), metal (spec .1, rough
/// .1) and a rough `trans` panel under a uniform glow sky (radiance 1 everywhere, so every
/// ambient sample sees 1 and `-ab 1` is exact in both tools). Each value is the
/// material's whole reflectance or transmittance on that side; tolerance 1e-4 (printed digits,
/// single-precision colours in Radiance). fenestra lost the lobe before (plastic 0.588 for
/// Radiance's 0.608 in red).
#[test]
fn oracle_weak_rough_lobes_join_the_ambient() {
    let Some((o, dir)) = common::cli::oracle_scratch("rtrace-weak-lobes") else {
        return;
    };
    let scene = format!(
        "{GLOW_SKY_AND_GROUND}void plastic pl\n0\n0\n5 .6 .55 .5 .02 .05\n\
        pl polygon f1\n0\n0\n12 -100 -100 0 -1 -100 0 -1 100 0 -100 100 0\n\
        void metal me\n0\n0\n5 .6 .55 .5 .1 .1\n\
        me polygon f2\n0\n0\n12 1 -100 0 100 -100 0 100 100 0 1 100 0\n\
        void trans tr\n0\n0\n7 .6 .55 .5 .03 .08 .5 .1\n\
        tr polygon f3\n0\n0\n12 -1 -100 0 1 -100 0 1 100 0 -1 100 0\n"
    );
    std::fs::write(dir.join("scene.rad"), scene).unwrap();
    // down onto each panel (reflection), and up at the trans panel from below (transmission
    // and reflection of the lower side)
    let rays = "-50 0 1 0 0 -1\n50 0 1 0 0 -1\n0 0 1 0 0 -1\n0 0 -1 0 0 1\n";
    let opts = ["-h", "-ab", "1", "-aa", "0", "-ad", "64", "-lw", "1e-4"];
    let (theirs, ours) = common::both_rtrace(&o, &dir, &opts, rays);
    eprintln!("oracle {theirs:?}\nours   {ours:?}");
    common::agree("weak rough lobes", &theirs, &ours, 1e-4, 1e-6);
}

/// Rough specular lobes above `-st` are sampled, reflected and transmitted, at `-ss 1` and at
/// `-ss 0` (one fixed direction, the lobe's median, as Radiance): a rough `trans` panel
/// (transmitted specular 0.25 > 0.15) over a rough plastic floor (spec .3), uniform glow sky
/// above and below, `-ab 1`. Before, fenestra lost the transmitted lobe (0.153 seen from
/// below for Radiance's 0.315) and at `-ss 0` the reflected one too. Means of 30 copies of
/// each ray.
#[test]
fn oracle_rough_specular_lobes_are_sampled() {
    let Some((o, dir)) = common::cli::oracle_scratch("rtrace-rough-lobes") else {
        return;
    };
    let scene = format!(
        "{GLOW_SKY_AND_GROUND}void trans tr\n0\n0\n7 .6 .55 .5 0 .1 .5 .5\n\
        tr polygon panel\n0\n0\n12 -100 -100 0 100 -100 0 100 100 0 -100 100 0\n\
        void plastic pl\n0\n0\n5 .6 .55 .5 .3 .1\n\
        pl polygon floor\n0\n0\n12 -100 -100 -5 100 -100 -5 100 100 -5 -100 100 -5\n"
    );
    std::fs::write(dir.join("scene.rad"), scene).unwrap();
    let kinds = ["0 0 1 0 0 -1\n", "0 0 -1 0 0 1\n", "0 0 -4 0 0 -1\n"];
    let rays: String = kinds
        .iter()
        .flat_map(|k| std::iter::repeat_n(*k, 30))
        .collect();
    for ss in ["1", "0"] {
        let opts = ["-h", "-ab", "1", "-aa", "0", "-ad", "512", "-ss", ss];
        let (theirs, ours) = common::both_rtrace(&o, &dir, &opts, &rays);
        // green channel of each copy, by ray kind
        for (k, kind) in kinds.iter().enumerate() {
            let pick = |v: &[f64]| -> Vec<f64> {
                v.chunks(3).skip(30 * k).take(30).map(|c| c[1]).collect()
            };
            let (ta, ts) = common::mean_sem(&pick(&theirs));
            let (oa, os) = common::mean_sem(&pick(&ours));
            eprintln!(
                "-ss {ss} ray {}: oracle {ta:.4} ± {ts:.4}, ours {oa:.4} ± {os:.4}",
                kind.trim()
            );
            // all three paths go through the rough transmitted lobe and come out 0.5-0.8% high
            // (0.3002 vs 0.2985, 0.2878 vs 0.2858, 0.1397 vs 0.1389 at -ss 1; over 5 s.e. each):
            // a residual not yet explained, held within 1.5% so that it cannot grow unseen
            assert!(
                (ta - oa).abs() <= 0.015 * ta,
                "-ss {ss} ray {k}: {ta} vs {oa}"
            );
        }
    }
}
