//! genBSDF (Klems): the reference blind against Radiance's own characterisation, an empty
//! frame (all light straight through), the oracle's tools reading our XML, bad input.

mod common;

use common::{fenestra, fixture, output_ok, run_ok, run_stdin, scratch};
use fenestra_bsdf::{read_file, Bsdf, Direction, KlemsBasis, Wavelength};

/// The four Klems blocks genBSDF writes with `+f +b`.
const ALL_BLOCKS: [Direction; 4] = [
    Direction::TransmissionBack,
    Direction::ReflectionBack,
    Direction::TransmissionFront,
    Direction::ReflectionFront,
];

/// Diffuse-incidence hemispherical total of a component: Σ λ_i · total(i) / π.
fn diffuse_total(b: &Bsdf, d: Direction) -> f64 {
    let m = b.klems(d, &Wavelength::Visible).expect("component");
    let lam = |i: usize| m.incident.projected_solid_angle(i).unwrap();
    (0..m.incident.len())
        .map(|i| lam(i) * m.hemispherical(i))
        .sum::<f64>()
        / std::f64::consts::PI
}

/// The reference blind (MGF), light from the room, `-c 100`: the diffuse-incidence totals
/// of transmission and reflection agree with Radiance's genBSDF output (`-c 1000`)
/// within 1.5%. Noise: our `-c 100` and `-c 1000` runs differ by 0.2–0.25% on these totals
/// (measured), the reference's own by less; 1.5% is about 5 times that.
#[test]
fn reference_blind_matches_radiance_genbsdf() {
    let dir = scratch("genbsdf-blind");
    let mut c = fenestra("genBSDF");
    c.args(["-n", "2", "-c", "100", "+mgf"])
        .arg(fixture("genbsdf/blinds_curved20.mgf"))
        .current_dir(&dir);
    let xml = run_ok(&mut c);
    std::fs::write(dir.join("ours.xml"), &xml).unwrap();
    let ours = read_file(&dir.join("ours.xml")).unwrap();
    let theirs = read_file(&fixture("threephase/blinds_kf.xml")).unwrap();
    for d in [Direction::TransmissionBack, Direction::ReflectionBack] {
        let (a, b) = (diffuse_total(&theirs, d), diffuse_total(&ours, d));
        eprintln!("{d:?}: Radiance {a:.4}, fenestra {b:.4}");
        assert!(
            (a - b).abs() <= 0.015 * a,
            "{d:?}: Radiance {a} fenestra {b}"
        );
    }
    // the sizes genBSDF writes: width, height and thickness from the bounding box
    assert!((ours.width.unwrap() - 0.3).abs() < 1e-6);
    assert!((ours.thickness.unwrap() - theirs.thickness.unwrap()).abs() < 1e-4);
    assert!((ours.height.unwrap() - theirs.height.unwrap()).abs() < 1e-4);
}

/// A 1 x 1 m black frame, 5 cm wide, 1 cm deep, at Z in [-0.01, 0] (a 0.9 m opening).
fn frame_scene() -> String {
    let mut s = String::from("void plastic black\n0\n0\n5 0 0 0 0 0\n");
    for (k, (x0, x1, y0, y1)) in [
        (0.0, 1.0, 0.0, 0.05),
        (0.0, 1.0, 0.95, 1.0),
        (0.0, 0.05, 0.05, 0.95),
        (0.95, 1.0, 0.05, 0.95),
    ]
    .into_iter()
    .enumerate()
    {
        s.push_str(&format!(
            "black polygon f{k}\n0\n0\n12 {x0} {y0} 0 {x1} {y0} 0 {x1} {y1} 0 {x0} {y1} 0\n"
        ));
    }
    s.push_str("black polygon back\n0\n0\n12 0 0 -0.01 1 0 -0.01 1 0.05 -0.01 0 0.05 -0.01\n");
    s
}

/// An empty frame lets every ray through the opening straight on: each incident patch
/// sends its light to one outgoing patch (the matrix is diagonal under Radiance's index
/// mapping) and nothing is reflected; what misses the opening hits the frame (black).
#[test]
fn empty_frame_transmits_straight_through() {
    let dir = scratch("genbsdf-frame");
    std::fs::write(dir.join("frame.rad"), frame_scene()).unwrap();
    let mut c = fenestra("genBSDF");
    c.args(["-c", "200", "+f", "+b", "frame.rad"])
        .current_dir(&dir);
    std::fs::write(dir.join("frame.xml"), run_ok(&mut c)).unwrap();
    let b = read_file(&dir.join("frame.xml")).unwrap();
    let basis = KlemsBasis::full();
    for d in [Direction::TransmissionBack, Direction::TransmissionFront] {
        let m = b.klems(d, &Wavelength::Visible).unwrap();
        for i in 0..basis.len() {
            let lam = |o: usize| basis.projected_solid_angle(o).unwrap();
            let diag = m.get(i, i) * lam(i);
            let off: f64 = (0..basis.len())
                .filter(|&o| o != i)
                .map(|o| m.get(o, i) * lam(o))
                .sum();
            assert!(off <= 1e-12, "{d:?} patch {i}: off-diagonal {off}");
            // the opening is 81% of the area; oblique rays start a frame's depth away from
            // the plane they cross (1 cm, up to 5.7 cm sideways at the last ring), so some
            // pass beside the frame and some meet its depth
            assert!(diag > 0.5 && diag < 0.95, "{d:?} patch {i}: {diag}");
        }
        let normal = m.get(0, 0) * basis.projected_solid_angle(0).unwrap();
        assert!(
            (normal - 0.81).abs() < 0.03,
            "{d:?} normal incidence {normal}"
        );
    }
    for d in [Direction::ReflectionBack, Direction::ReflectionFront] {
        let m = b.klems(d, &Wavelength::Visible).unwrap();
        assert!(m.values.iter().all(|v| *v == 0.0));
    }
}

/// Radiance's own tools read our XML: checkBSDF reports the same dimensions, rmtxop builds
/// its 145 x 145 matrix.
#[test]
fn oracle_reads_our_xml() {
    let Some(o) = common::oracle() else { return };
    let dir = scratch("genbsdf-oracle");
    let mut c = fenestra("genBSDF");
    c.args(["-c", "20", "+mgf"])
        .arg(fixture("genbsdf/blinds_curved20.mgf"))
        .current_dir(&dir);
    std::fs::write(dir.join("ours.xml"), run_ok(&mut c)).unwrap();
    let mut c = o.command("checkBSDF");
    c.arg("ours.xml").current_dir(&dir);
    let text = String::from_utf8(run_ok(&mut c)).unwrap();
    assert!(
        text.contains("Dimensions (W x H x Thickness): 30 x 28.856"),
        "{text}"
    );
    assert!(text.contains("Klems_Full"), "{text}");
    // the device embedded as MGF (+geom meter, the default), as Radiance's genBSDF does
    assert!(text.contains("Has Geometry: 1"), "{text}");
    let mut c = fenestra("genBSDF");
    c.args(["-c", "4", "+mgf", "-geom", "meter"])
        .arg(fixture("genbsdf/blinds_curved20.mgf"))
        .current_dir(&dir);
    std::fs::write(dir.join("nogeom.xml"), run_ok(&mut c)).unwrap();
    let mut c = o.command("checkBSDF");
    c.arg("nogeom.xml").current_dir(&dir);
    let text = String::from_utf8(run_ok(&mut c)).unwrap();
    assert!(text.contains("Has Geometry: 0"), "{text}");
    let mut c = o.command("rmtxop");
    c.arg("ours.xml").current_dir(&dir);
    let text = String::from_utf8(run_ok(&mut c)).unwrap();
    assert!(
        text.contains("NROWS=145") && text.contains("NCOLS=145"),
        "{text}"
    );
}

/// Bad input: no geometry, a device in front of Z = 0, an unknown unit, an MGF syntax error:
/// one clear error each, nothing on standard output.
#[test]
fn bad_input_is_one_clear_error() {
    let dir = scratch("genbsdf-bad");
    std::fs::write(
        dir.join("empty.rad"),
        "void plastic m\n0\n0\n5 .5 .5 .5 0 0\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("front.rad"),
        "void plastic m\n0\n0\n5 .5 .5 .5 0 0\nm polygon p\n0\n0\n12 0 0 0.1 1 0 0.1 1 1 0.2 0 1 0.2\n",
    )
    .unwrap();
    std::fs::write(dir.join("bad.mgf"), "m x =\n\trd 2 3\nf a b\n").unwrap();
    for (args, want) in [
        (vec!["empty.rad"], "no device geometry"),
        (vec!["front.rad"], "Device entirely inside room!"),
        (
            vec!["-geom", "furlong", "front.rad"],
            "Illegal geometry unit",
        ),
        (vec!["+mgf", "bad.mgf"], "bad.mgf"),
    ] {
        let mut c = fenestra("genBSDF");
        c.args(&args).current_dir(&dir);
        let out = run_stdin(c, b"");
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert!(out.stdout.is_empty(), "{args:?}: output written");
        let e = String::from_utf8_lossy(&out.stderr);
        assert!(e.contains(want), "{args:?}: {e}");
    }
}

/// The summary on standard error (hemispherical totals per side, largest T+R, transmission
/// reciprocity) is what checkBSDF's library computes from the XML written; `-q` silences it.
#[test]
fn summary_matches_the_file_and_q_silences_it() {
    let dir = scratch("genbsdf-summary");
    std::fs::write(dir.join("frame.rad"), frame_scene()).unwrap();
    let mut c = fenestra("genBSDF");
    c.args(["-c", "30", "+f", "+b", "frame.rad"])
        .current_dir(&dir);
    let out = c.output().unwrap();
    assert!(out.status.success());
    std::fs::write(dir.join("frame.xml"), &out.stdout).unwrap();
    let b = read_file(&dir.join("frame.xml")).unwrap();
    let err = String::from_utf8(out.stderr).unwrap();
    let t = diffuse_total(&b, Direction::TransmissionBack);
    let want = "light from the room (Back): T normal ";
    let line = err
        .lines()
        .find(|l| l.starts_with(want))
        .unwrap_or_else(|| panic!("no summary in {err:?}"));
    assert!(line.contains(&format!("diffuse {t:.4}")), "{line} vs {t}");
    assert!(err.contains("light from outside (Front): "), "{err}");
    assert!(err.contains("transmission reciprocity"), "{err}");
    let mut c = fenestra("genBSDF");
    c.args(["-q", "-c", "30", "+f", "+b", "frame.rad"])
        .current_dir(&dir);
    let out = c.output().unwrap();
    assert!(out.status.success());
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // the same data (only the command line in the comment differs)
    std::fs::write(dir.join("quiet.xml"), &out.stdout).unwrap();
    let q = read_file(&dir.join("quiet.xml")).unwrap();
    assert_eq!(diffuse_total(&q, Direction::TransmissionBack), t);
}

/// Three-phase check: dctimestep with the reference office's V and D and our XML for the
/// reference blind (`-c 200 +f +b`) against the same with Radiance's genBSDF file
/// (`res_*.dat`, Radiance's dctimestep), 45 sensors, an overcast and a low-sun clear sky.
/// Tolerances: the sensor means within 2.5% and each sensor within 5%. Measured noise: our
/// `-c 200` and `-c 1000` files against Radiance's differ by at most 1.3% in the mean and
/// 2.7% at a sensor over four skies; the limits are about twice that.
#[test]
fn three_phase_with_our_blind_matches_radiance_file() {
    let dir = scratch("genbsdf-3ph");
    let mut c = fenestra("genBSDF");
    c.args(["-q", "-n", "2", "-c", "200", "+f", "+b", "+mgf"])
        .arg(fixture("genbsdf/blinds_curved20.mgf"))
        .current_dir(&dir);
    std::fs::write(dir.join("ours.xml"), run_ok(&mut c)).unwrap();
    let lux = |v: &[f64]| -> Vec<f64> {
        v.chunks(3)
            .map(|p| 179.0 * (0.265 * p[0] + 0.670 * p[1] + 0.065 * p[2]))
            .collect()
    };
    for sky in ["t4_sep21_1200_overcast", "t3_dec21_1200_clear"] {
        let mut c = fenestra("dctimestep");
        c.arg("-h")
            .arg(fixture("threephase/V.vmx"))
            .arg(dir.join("ours.xml"))
            .arg(fixture("threephase/D.dmx"))
            .arg(fixture(&format!("threephase/sky_{sky}.skv")));
        let ours = lux(&common::numbers(&run_ok(&mut c)));
        let text = std::fs::read_to_string(fixture(&format!("threephase/res_{sky}.dat"))).unwrap();
        let body = text.split("\n\n").nth(1).expect("header");
        let theirs = lux(&common::numbers(body.as_bytes()));
        assert_eq!(ours.len(), 45, "{sky}");
        assert_eq!(theirs.len(), 45, "{sky}");
        let (mo, mt) = (
            ours.iter().sum::<f64>() / 45.0,
            theirs.iter().sum::<f64>() / 45.0,
        );
        eprintln!("{sky}: mean {mo:.1} lux vs Radiance's file {mt:.1}");
        assert!((mo - mt).abs() <= 0.025 * mt, "{sky}: mean {mo} vs {mt}");
        common::agree(sky, &theirs, &ours, 0.05, 0.0);
    }
}

/// `-E`: each element's standard error, from the spread of the per-sample contributions,
/// written as a BSDF file of the same layout; the values are the same as without `-E` (and
/// with `-n 1` as with `-n 2`).
/// Checked as z-scores of our `-c 100` file against Radiance's genBSDF file (`-c 1000`,
/// 1023 samples per direction against our 110, so its own noise adds about 10% to the
/// variance; z uses ours only, scaled by √1.1). The spread over √N is exact for independent
/// samples and an upper bound for the jointly stratified (Sobol) ones drawn: on this blind
/// 1.41× (reflection) and 1.59× (transmission) the replicate spread at `-c 100`, so z comes
/// out narrower than N(0, 1). Reflection is smooth: measured mean z² 0.90 and 0.88 (1.15 and
/// 1.05 with the former, independently stratified sampler), 99.4% and 99.6% within 3 —
/// limits 0.7–1.6 and 98% (an `-E` too small or grossly too large fails). Transmission has
/// rare straight-through paths at grazing incidence that 110 samples can miss entirely (the
/// sample's spread is then 0 or tiny, mean z² 18 and 75): measured 98.9% and 98.6% within
/// |z| < 3 and a median |z| of 0.59 and 0.62 (N(0, 1): 0.674); limits 97% and 0.45–0.9.
#[test]
fn standard_errors_explain_the_difference_from_radiance() {
    let dir = scratch("genbsdf-errors");
    let blind = fixture("genbsdf/blinds_curved20.mgf");
    let mut c = fenestra("genBSDF");
    c.args([
        "-q", "-n", "2", "-c", "100", "-E", "err.xml", "+f", "+b", "+mgf",
    ])
    .arg(&blind)
    .current_dir(&dir);
    std::fs::write(dir.join("ours.xml"), run_ok(&mut c)).unwrap();
    let mut c = fenestra("genBSDF");
    c.args(["-q", "-n", "1", "-c", "100", "+f", "+b", "+mgf"])
        .arg(&blind)
        .current_dir(&dir);
    std::fs::write(dir.join("plain.xml"), run_ok(&mut c)).unwrap();
    let ours = read_file(&dir.join("ours.xml")).unwrap();
    let plain = read_file(&dir.join("plain.xml")).unwrap();
    let err = read_file(&dir.join("err.xml")).unwrap();
    let theirs = read_file(&fixture("threephase/blinds_kf.xml")).unwrap();
    let vis = Wavelength::Visible;
    for d in ALL_BLOCKS {
        let (o, e, t) = (
            &ours.klems(d, &vis).unwrap().values,
            &err.klems(d, &vis).unwrap().values,
            &theirs.klems(d, &vis).unwrap().values,
        );
        assert_eq!(
            o,
            &plain.klems(d, &vis).unwrap().values,
            "{d:?}: -E changed values"
        );
        assert!(e.iter().all(|v| v.is_finite() && *v >= 0.0), "{d:?}");
        let mut z: Vec<f64> = o
            .iter()
            .zip(e)
            .zip(t)
            .filter(|((_, e), _)| **e > 0.0)
            .map(|((o, e), t)| (o - t) / (e * 1.1f64.sqrt()))
            .collect();
        assert!(
            z.len() > 20_000,
            "{d:?}: {} elements with an error",
            z.len()
        );
        let n = z.len() as f64;
        let z2 = z.iter().map(|v| v * v).sum::<f64>() / n;
        let within3 = z.iter().filter(|v| v.abs() < 3.0).count() as f64 / n;
        z.iter_mut().for_each(|v| *v = v.abs());
        z.sort_by(f64::total_cmp);
        let median = z[z.len() / 2];
        eprintln!("{d:?}: mean z² {z2:.2}, |z|<3 {within3:.4}, median |z| {median:.3}");
        if matches!(d, Direction::ReflectionBack | Direction::ReflectionFront) {
            assert!((0.7..=1.6).contains(&z2), "{d:?}: mean z² {z2}");
            assert!(within3 >= 0.98, "{d:?}: {within3}");
        } else {
            assert!(within3 >= 0.97, "{d:?}: {within3}");
            assert!((0.45..=0.9).contains(&median), "{d:?}: median |z| {median}");
        }
    }
}

/// `+C`: CIE-X and CIE-Z blocks beside each `Visible` one, in wrapBSDF's order. The
/// reference blind's slats are slightly coloured: over all elements of each block, X/Y and
/// Z/Y agree with Radiance's genBSDF file within 0.002 (measured ≤ 0.0007 at `-c 100`; X, Y
/// and Z come from the same paths, so their ratio carries little noise). Radiance's
/// checkBSDF reads the file as coloured and its dctimestep gives our dctimestep's numbers.
#[test]
fn oracle_colour_blocks_match_radiance_chromaticity() {
    let dir = scratch("genbsdf-colour");
    let mut c = fenestra("genBSDF");
    c.args(["-q", "-n", "2", "-c", "100", "+C", "+f", "+b", "+mgf"])
        .arg(fixture("genbsdf/blinds_curved20.mgf"))
        .current_dir(&dir);
    std::fs::write(dir.join("col.xml"), run_ok(&mut c)).unwrap();
    let ours = read_file(&dir.join("col.xml")).unwrap();
    let theirs = read_file(&fixture("threephase/blinds_kf.xml")).unwrap();
    let sum = |b: &Bsdf, d: Direction, w: Wavelength| -> f64 {
        b.klems(d, &w).expect("block").values.iter().sum()
    };
    for d in ALL_BLOCKS {
        for w in [Wavelength::CieX, Wavelength::CieZ] {
            let ratio = |b: &Bsdf| sum(b, d, w.clone()) / sum(b, d, Wavelength::Visible);
            let (a, b) = (ratio(&theirs), ratio(&ours));
            eprintln!("{d:?} {w:?}/Y: Radiance {a:.4}, fenestra {b:.4}");
            assert!((a - b).abs() <= 0.002, "{d:?} {w:?}: {a} vs {b}");
        }
    }
    let Some(o) = common::oracle() else { return };
    let mut c = o.command("checkBSDF");
    c.arg("col.xml").current_dir(&dir);
    let report = String::from_utf8(run_ok(&mut c)).unwrap();
    assert!(report.contains("Color: 1"), "{report}");
    let f = |p: &str| fixture(&format!("threephase/{p}"));
    let sky = f("sky_t3_dec21_1200_clear.skv");
    let mut c = o.command("dctimestep");
    c.arg("-h")
        .arg(f("V.vmx"))
        .arg(dir.join("col.xml"))
        .arg(f("D.dmx"))
        .arg(&sky);
    let a = common::numbers(&run_ok(&mut c));
    let mut c = fenestra("dctimestep");
    c.arg("-h")
        .arg(f("V.vmx"))
        .arg(dir.join("col.xml"))
        .arg(f("D.dmx"))
        .arg(&sky);
    let b = common::numbers(&run_ok(&mut c));
    // printed with 7 significant digits by both (measured worst 8.4e-7)
    common::agree("dctimestep RGB", &a, &b, 5e-6, 0.0);
}

/// Every value finite and ≥ 0, and T + R ≤ 1 (plus noise) per incident patch.
fn check_finite_and_conserving(b: &Bsdf, what: &str) {
    let vis = Wavelength::Visible;
    for d in ALL_BLOCKS {
        let m = b.klems(d, &vis).expect("block");
        assert!(
            m.values.iter().all(|v| v.is_finite() && *v >= 0.0),
            "{what} {d:?}: a NaN, infinite or negative value"
        );
    }
    for (t, r) in [
        (Direction::TransmissionBack, Direction::ReflectionBack),
        (Direction::TransmissionFront, Direction::ReflectionFront),
    ] {
        let (t, r) = (b.klems(t, &vis).unwrap(), b.klems(r, &vis).unwrap());
        for i in 0..t.incident.len() {
            let sum = t.hemispherical(i) + r.hemispherical(i);
            assert!(sum <= 1.02, "{what}: incident patch {i} T+R = {sum}");
        }
    }
}

/// Hard geometry (issue 18): an opaque Lambertian panel (T = 0 everywhere; R = its
/// reflectance 0.5 at every incidence, since every path ends on one receiver or the other);
/// horizontal slats whose front edges lie exactly on Z = 0, with incident directions along
/// their surfaces; 1 mm slats 20 mm apart over a 10 m × 10 m sample. Nothing NaN, negative
/// or gaining light.
#[test]
fn hard_geometry_stays_finite_and_conserving() {
    let dir = scratch("genbsdf-hard");
    let mut panel = String::from("void plastic grey\n0\n0\n5 .5 .5 .5 0 0\n");
    panel.push_str("grey polygon panel\n0\n0\n12 0 0 -0.01 1 0 -0.01 1 1 -0.01 0 1 -0.01\n");
    // horizontal slats (normal +Y), 25 mm deep, front edge on Z = 0, 20 mm pitch, 0.3 m wide
    let mut flat = String::from("void plastic slat\n0\n0\n5 .7 .7 .7 0 0\n");
    for k in 0..15 {
        let y = 0.01 + 0.02 * k as f64;
        flat.push_str(&format!(
            "slat polygon s{k}\n0\n0\n12 0 {y} -0.025 0.3 {y} -0.025 0.3 {y} 0 0 {y} 0\n"
        ));
    }
    // 1 mm thick slats (top and bottom faces, front and back edges), 20 mm pitch, 10 m wide
    let mut thin = String::from("void plastic slat\n0\n0\n5 .7 .7 .7 0 0\n");
    for k in 0..500 {
        let (y0, y1) = (0.02 * k as f64, 0.02 * k as f64 + 0.001);
        for (n, (a, b, c, d)) in [
            (
                (0.0, y0, -0.025),
                (10.0, y0, -0.025),
                (10.0, y0, 0.0),
                (0.0, y0, 0.0),
            ),
            (
                (0.0, y1, -0.025),
                (0.0, y1, 0.0),
                (10.0, y1, 0.0),
                (10.0, y1, -0.025),
            ),
            (
                (0.0, y0, 0.0),
                (10.0, y0, 0.0),
                (10.0, y1, 0.0),
                (0.0, y1, 0.0),
            ),
            (
                (0.0, y0, -0.025),
                (0.0, y1, -0.025),
                (10.0, y1, -0.025),
                (10.0, y0, -0.025),
            ),
        ]
        .into_iter()
        .enumerate()
        {
            thin.push_str(&format!(
                "slat polygon t{k}_{n}\n0\n0\n12 {} {} {} {} {} {} {} {} {} {} {} {}\n",
                a.0, a.1, a.2, b.0, b.1, b.2, c.0, c.1, c.2, d.0, d.1, d.2
            ));
        }
    }
    for (name, text, c) in [
        ("panel", &panel, "20"),
        ("flat", &flat, "20"),
        ("thin", &thin, "20"),
    ] {
        std::fs::write(dir.join(format!("{name}.rad")), text).unwrap();
        let mut cmd = fenestra("genBSDF");
        cmd.args(["-q", "-n", "2", "-c", c, "+f", "+b", &format!("{name}.rad")])
            .current_dir(&dir);
        std::fs::write(dir.join(format!("{name}.xml")), run_ok(&mut cmd)).unwrap();
        let b = read_file(&dir.join(format!("{name}.xml"))).unwrap();
        check_finite_and_conserving(&b, name);
        if name == "panel" {
            let vis = Wavelength::Visible;
            for d in [Direction::TransmissionBack, Direction::TransmissionFront] {
                let m = b.klems(d, &vis).unwrap();
                assert!(m.values.iter().all(|v| *v == 0.0), "panel {d:?}");
            }
            for d in [Direction::ReflectionBack, Direction::ReflectionFront] {
                let m = b.klems(d, &vis).unwrap();
                for i in 0..m.incident.len() {
                    let r = m.hemispherical(i);
                    assert!((r - 0.5).abs() < 0.01, "panel {d:?} patch {i}: R {r}");
                }
            }
        }
    }
}

/// One block of a device characterised by the oracle's genBSDF (pyradiance's port driving
/// Radiance's rfluxmtx, rcontrib and rmtxop) and by ours at the same `-c`, `+f +b`.
struct PortBlock {
    /// Which block.
    dir: Direction,
    /// Diffuse-incidence totals: the oracle's, ours.
    totals: (f64, f64),
    /// Element by element, |z| = |difference| / (our standard error × √2), sorted (both runs
    /// have the same sample count; elements without an error left out).
    z: Vec<f64>,
}

impl PortBlock {
    /// The median |z|.
    fn median(&self) -> f64 {
        self.z[self.z.len() / 2]
    }

    /// The share of elements within |z| < 3.
    fn within3(&self) -> f64 {
        self.z.iter().filter(|v| **v < 3.0).count() as f64 / self.z.len() as f64
    }

    /// Asserts the element-wise agreement: a median |z| in `median` and at least 97.5% of
    /// the elements within |z| < 3.
    fn assert_z(&self, median: std::ops::RangeInclusive<f64>) {
        let (d, m, w) = (self.dir, self.median(), self.within3());
        assert!(median.contains(&m), "{d:?}: median |z| {m}");
        assert!(w >= 0.975, "{d:?}: {w} within |z| < 3");
    }
}

/// Characterises the device `rad` (written as `file` in a scratch folder `name`) with the
/// oracle's genBSDF and ours at `-c samples`, `+f +b`, and compares the four blocks; `None`
/// without the oracle.
fn against_oracle_port(name: &str, file: &str, rad: &str, samples: u32) -> Option<Vec<PortBlock>> {
    let o = common::oracle()?;
    // the venv's python: <venv>/lib/pythonX.Y/site-packages/pyradiance/bin
    let bindir = o.bin("rmtxop").parent().expect("bin").to_path_buf();
    let venv = bindir.ancestors().nth(5).expect("venv").to_path_buf();
    let python = venv.join("bin/python");
    assert!(python.exists(), "no python at {}", python.display());
    let dir = scratch(name);
    std::fs::write(dir.join(file), rad).unwrap();
    let script = format!(
        "from pyradiance import genbsdf\n\
         r = genbsdf.generate_bsdf('{file}', nsamp={samples}, nproc=2, front=True)\n\
         [open(n + '.txt', 'wb').write(d) for n, d in [('tb', r.back.transmittance), \
         ('rb', r.back.reflectance), ('tf', r.front.transmittance), ('rf', r.front.reflectance)]]\n"
    );
    let path = format!(
        "{}:{}",
        bindir.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let mut c = std::process::Command::new(&python);
    c.args(["-c", &script])
        .env("PATH", path)
        .env("RAYPATH", format!(".:{}", o.lib().display()))
        .current_dir(&dir);
    run_ok(&mut c);
    let mut c = fenestra("genBSDF");
    let samples = samples.to_string();
    c.args([
        "-q", "-n", "2", "-c", &samples, "-E", "err.xml", "+f", "+b", file,
    ])
    .current_dir(&dir);
    std::fs::write(dir.join("ours.xml"), run_ok(&mut c)).unwrap();
    let ours = read_file(&dir.join("ours.xml")).unwrap();
    let err = read_file(&dir.join("err.xml")).unwrap();
    let basis = KlemsBasis::full();
    let lam: Vec<f64> = (0..basis.len())
        .map(|k| basis.projected_solid_angle(k).unwrap())
        .collect();
    let np = lam.len();
    let vis = Wavelength::Visible;
    let mut blocks = Vec::new();
    for (name, d) in [
        ("tb", Direction::TransmissionBack),
        ("rb", Direction::ReflectionBack),
        ("tf", Direction::TransmissionFront),
        ("rf", Direction::ReflectionFront),
    ] {
        // the oracle's matrix: rows = outgoing patch, columns = incident, flux fractions
        let f = common::numbers(&std::fs::read(dir.join(format!("{name}.txt"))).unwrap());
        assert_eq!(f.len(), np * np, "{name}");
        let (m, e) = (&ours.klems(d, &vis).unwrap(), &err.klems(d, &vis).unwrap());
        let (mut t_ours, mut t_theirs) = (0.0, 0.0);
        let mut z = Vec::new();
        for o in 0..np {
            for i in 0..np {
                let theirs = f[o * np + i] / lam[o];
                let (v, se) = (m.get(o, i), e.get(o, i));
                t_ours += v * lam[o] * lam[i];
                t_theirs += theirs * lam[o] * lam[i];
                if se > 0.0 {
                    z.push(((v - theirs) / (se * 2f64.sqrt())).abs());
                }
            }
        }
        z.sort_by(f64::total_cmp);
        let pi = std::f64::consts::PI;
        let block = PortBlock {
            dir: d,
            totals: (t_theirs / pi, t_ours / pi),
            z,
        };
        eprintln!(
            "{d:?}: diffuse total oracle {:.4} ours {:.4}; median |z| {:.3}, |z|<3 {:.4} ({} elements)",
            block.totals.0,
            block.totals.1,
            block.median(),
            block.within3(),
            block.z.len()
        );
        blocks.push(block);
    }
    Some(blocks)
}

/// A glazed blind of our own (a `glass` pane behind 15 tilted slats of coloured, slightly
/// rough `plastic`: specular 0.02, roughness 0.05) through the oracle's genBSDF and ours, both
/// `-c 100 +f +b`. Diffuse-incidence totals of all four blocks within 1.5% (measured 0.3–1.0%;
/// the oracle's totals vary by 5e-5 relative over 42 of its runs — its rfluxmtx repeats its
/// samples — ours by up to 0.8% between `-c 100` and `-c 200`: the gap is our sampling).
/// Element by element: median |z| 0.55–0.85 (N(0, 1): 0.674; measured 0.66–0.70 with the
/// former sampler, 0.62–0.65 with the Sobol one, whose `-E` is an upper bound) and at least
/// 97.5% within |z| < 3 (measured 98.8–99.0%, now 98.6–99.1%; the tail is rare straight-through paths, see
/// `standard_errors_explain_the_difference_from_radiance`). Before the tracer kept weak
/// rough lobes in the ambient coefficient, the slats' reflection came out 4.7% low here.
#[test]
fn oracle_genbsdf_port_agrees_on_a_glazed_blind() {
    let mut rad = String::from(
        "void glass pane\n0\n0\n3 0.86 0.86 0.86\n\
         pane polygon glazing\n0\n0\n12 0 0 -0.03 0 0.3 -0.03 0.3 0.3 -0.03 0.3 0 -0.03\n\
         void plastic slat\n0\n0\n5 0.6 0.55 0.5 0.02 0.05\n",
    );
    let (st, ct) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    for k in 0..15 {
        let y = 0.01 + 0.02 * k as f64;
        let (dy, dz) = (0.01 * st, 0.01 * ct);
        let (ya, za, yb, zb) = (y - dy, -0.012 - dz, y + dy, -0.012 + dz);
        rad.push_str(&format!(
            "slat polygon s{k}\n0\n0\n12 0 {ya} {za} 0.3 {ya} {za} 0.3 {yb} {zb} 0 {yb} {zb}\n"
        ));
    }
    let Some(blocks) = against_oracle_port("genbsdf-glazed", "glazed.rad", &rad, 100) else {
        return;
    };
    for b in blocks {
        let ((a, o), d) = (b.totals, b.dir);
        assert!((a - o).abs() <= 0.015 * a, "{d:?}: {a} vs {o}");
        b.assert_z(0.55..=0.85);
    }
}

/// A diffusing `trans` pane (reflectance 0.8, transmissivity 0.6, no specular part), `-c 50`.
/// Every sample's light leaves the pane in full, split over the hemisphere, so the
/// diffuse-incidence totals carry no sampling noise: transmission 0.8 × 0.6 = 0.48 and
/// reflection 0.8 × 0.4 = 0.32 for both tools within 0.1% (measured 0.00–0.01%). Element by
/// element the distribution is smooth, where joint stratification gains little, so z is about
/// N(0, 1): median |z| 0.55–0.85 (measured 0.669–0.681 in two runs) and at least 97.5%
/// within 3 (measured 99.5–99.7%), the glazed blind's limits.
#[test]
fn oracle_genbsdf_port_agrees_on_a_diffusing_trans_pane() {
    let rad = "void trans diffuser\n0\n0\n7 0.8 0.8 0.8 0 0 0.6 0\n\
        diffuser polygon pane\n0\n0\n12 0 0 -0.002 0 0.3 -0.002 0.3 0.3 -0.002 0.3 0 -0.002\n";
    let Some(blocks) = against_oracle_port("genbsdf-trans", "trans.rad", rad, 50) else {
        return;
    };
    for b in blocks {
        let d = b.dir;
        let exact = match d {
            Direction::TransmissionBack | Direction::TransmissionFront => 0.48,
            _ => 0.32,
        };
        for (who, t) in [("oracle", b.totals.0), ("ours", b.totals.1)] {
            assert!(
                (t - exact).abs() <= 1e-3 * exact,
                "{d:?} {who}: {t} vs {exact}"
            );
        }
        b.assert_z(0.55..=0.85);
    }
}

/// A perforated screen: a 0.3 m square plate of grey, slightly glossy `plastic` (0.5, specular
/// 0.02, roughness 0.08) with 10 × 10 square holes of 15 mm in 30 mm cells (open fraction ¼),
/// as 130 polygons at z = −1 mm; `-c 200` (210 samples). Light passes only straight through
/// the holes, so transmission is the open fraction at every incidence, one element per
/// incident patch (its Klems partner).
/// Noise, from the open fraction as a binomial draw of 210 samples per incident patch: the
/// diffuse-incidence transmission total of an independently sampled run has a relative sd of
/// 1.0%, reflection 0.33% (both tools stratify, so theirs is at most that). Limits: our
/// transmission within 3% of ¼ (measured +0.9% and −0.4%), ours and the oracle's totals within
/// 4 × √2 of those sds (5.6% and 1.9%; measured +2.3%/+0.9% and −0.8%/−0.3%: the oracle's
/// repeats its sample positions, 0.2466 both ways). Elements: at least 97.5% within |z| < 3
/// (measured 99.99–100%) and a median |z| of 0.3–0.85: our `-E` is the independent-sample
/// error, an upper bound that the joint stratification beats most on straight-through light,
/// so z there is the oracle's noise over √2 of it (median about 0.674 / √2 = 0.48; measured
/// 0.46–0.58); 0.3 is where `-E` would overstate even the independent-sample error by 60%.
#[test]
fn oracle_genbsdf_port_agrees_on_a_perforated_screen() {
    let (cell, hole, z) = (0.03, 0.015, -0.001);
    let edge = (cell - hole) / 2.0;
    let mut rad = String::from("void plastic grey\n0\n0\n5 0.5 0.5 0.5 0.02 0.08\n");
    let mut quads = Vec::new();
    for r in 0..10 {
        let y = r as f64 * cell;
        quads.push((0.0, y, 0.3, y + edge));
        quads.push((0.0, y + edge + hole, 0.3, y + cell));
        for c in 0..=10 {
            let x0 = if c == 0 { 0.0 } else { c as f64 * cell - edge };
            let x1 = if c == 10 { 0.3 } else { c as f64 * cell + edge };
            quads.push((x0, y + edge, x1, y + edge + hole));
        }
    }
    for (k, (x0, y0, x1, y1)) in quads.iter().enumerate() {
        rad.push_str(&format!(
            "grey polygon p{k}\n0\n0\n12 {x0} {y0} {z} {x1} {y0} {z} {x1} {y1} {z} {x0} {y1} {z}\n"
        ));
    }
    let Some(blocks) = against_oracle_port("genbsdf-screen", "screen.rad", &rad, 200) else {
        return;
    };
    for b in blocks {
        let ((a, o), d) = (b.totals, b.dir);
        let transmission = matches!(
            d,
            Direction::TransmissionBack | Direction::TransmissionFront
        );
        let sd = if transmission { 0.010 } else { 0.0033 };
        assert!(
            (a - o).abs() <= 4.0 * 2f64.sqrt() * sd * a,
            "{d:?}: {a} vs {o}"
        );
        if transmission {
            assert!((o - 0.25).abs() <= 0.03 * 0.25, "{d:?}: {o} vs 0.25");
            assert_eq!(b.z.len(), 145, "{d:?}: one element per incident patch");
        }
        b.assert_z(0.3..=0.85);
    }
}

/// Directional-hemispherical totals (Lambertian part included) of a tensor-tree file's
/// transmission and reflection for views from the room side at a spread of directions.
fn tree_totals(path: &std::path::Path) -> Vec<(f64, f64)> {
    use fenestra_bsdf::tree_render::{Lobe, TreeBsdf};
    let b = fenestra_bsdf::read_file(path).unwrap();
    let t = TreeBsdf::load(&b).expect("a tensor tree");
    let mut out = Vec::new();
    for th in [5.0f64, 20.0, 35.0, 50.0, 65.0, 80.0] {
        for ph in [0.0f64, 60.0, 120.0, 180.0, 240.0, 300.0] {
            let (t_, p_) = (th.to_radians(), ph.to_radians());
            let v = [t_.sin() * p_.cos(), t_.sin() * p_.sin(), t_.cos()];
            // the tree's part plus the Lambertian part Radiance's loader splits off it
            let tot =
                |lobe| t.slice(lobe, true, v).map_or(0.0, |s| s.total()) + t.lambertian(lobe, true);
            out.push((tot(Lobe::Transmission), tot(Lobe::Reflection)));
        }
    }
    out
}

/// Compares two files' view totals: every view's transmission and reflection within 4
/// binomial sd (`var` = 1/n₁ + 1/n₂ for n₁ and n₂ rays per incident cell) + 0.01; returns
/// the mean transmissions and reflections (ours, theirs).
fn compare_views(a: &[(f64, f64)], b: &[(f64, f64)], var: f64) -> [f64; 4] {
    let mean =
        |v: &[(f64, f64)], f: fn(&(f64, f64)) -> f64| v.iter().map(f).sum::<f64>() / v.len() as f64;
    let bound = |p: f64| 4.0 * (p * (1.0 - p).max(0.0) * var).sqrt() + 0.01;
    let mut worst = 0.0f64;
    for (x, y) in a.iter().zip(b) {
        worst = worst.max((x.0 - y.0).abs()).max((x.1 - y.1).abs());
        assert!(
            (x.0 - y.0).abs() < bound(0.5 * (x.0 + y.0)),
            "T {} vs {}",
            x.0,
            y.0
        );
        assert!(
            (x.1 - y.1).abs() < bound(0.5 * (x.1 + y.1)),
            "R {} vs {}",
            x.1,
            y.1
        );
    }
    let m = [
        mean(a, |x| x.0),
        mean(b, |x| x.0),
        mean(a, |x| x.1),
        mean(b, |x| x.1),
    ];
    eprintln!(
        "mean transmission {:.4} vs {:.4}, reflection {:.4} vs {:.4}; largest difference at a view {worst:.4}",
        m[0], m[1], m[2], m[3]
    );
    m
}

#[test]
fn tensor_tree_t4_agrees_with_radiance_s_file() {
    // genBSDF -t4 4 -c 100 (backward, as the reference's -t4 4 -c 400) on the reference
    // blind; both files read by fenestra's tree loader, totals compared at 36 views from
    // the room side. Tolerances from the sampling noise of both (100 and 400 samples per
    // incident cell; the totals are binomial shares p of a cell's rays): mean transmission
    // and reflection within 3% (measured +0.4%, +0.2%), each view within
    // 4·sqrt(p(1 − p)(1/100 + 1/400)) + 0.01 (measured: largest 0.12 where the bound is
    // 0.21; reflection within 0.012). The oracle's checkBSDF must read our file and
    // report the same kind of tree.
    let dir = common::scratch("genbsdf-t4");
    let mut c = common::fenestra("genBSDF");
    c.args(["-n", "2", "-q", "-t4", "4", "-c", "100", "+mgf"])
        .arg(common::fixture("genbsdf/blinds_curved20.mgf"));
    let xml = common::run_ok(&mut c);
    let ours = dir.join("t4.xml");
    std::fs::write(&ours, &xml).unwrap();
    let a = tree_totals(&ours);
    let b = tree_totals(&common::fixture("genbsdf/blinds_t4.xml"));
    let [ta, tb, ra, rb] = compare_views(&a, &b, 1.0 / 100.0 + 1.0 / 400.0);
    assert!((ta / tb - 1.0).abs() < 0.03 && (ra / rb - 1.0).abs() < 0.03);
    if let Some(o) = common::oracle() {
        let out = common::run_ok(o.command("checkBSDF").arg(&ours));
        let text = String::from_utf8_lossy(&out);
        assert!(text.contains("Anisotropic_Tensor_Tree"), "{text}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn tensor_tree_of_an_empty_frame_is_straight_through() {
    // the frame of the Klems test, -t4 3 both sides: every incident cell's transmission
    // leaves through the same cell (the trees' conventions map a straight ray's incident and
    // outgoing directions to the same cell), 81% near normal incidence (the open area), no
    // reflection; the file renders: fenestra's loader finds the four components.
    use fenestra_bsdf::tree_render::{Lobe, TreeBsdf};
    let dir = scratch("genbsdf-frame-t4");
    std::fs::write(dir.join("frame.rad"), frame_scene()).unwrap();
    let mut c = fenestra("genBSDF");
    c.args(["-q", "-t4", "3", "-c", "100", "+f", "+b", "frame.rad"])
        .current_dir(&dir);
    std::fs::write(dir.join("frame.xml"), run_ok(&mut c)).unwrap();
    let b = read_file(&dir.join("frame.xml")).unwrap();
    let t = TreeBsdf::load(&b).expect("a tensor tree");
    for front in [true, false] {
        assert!(t.has(Lobe::Transmission, front), "front {front}");
        let v = [0.05, 0.02, 1.0f64];
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        let v = [v[0] / n, v[1] / n, if front { v[2] / n } else { -v[2] / n }];
        let s = t.slice(Lobe::Transmission, front, v).unwrap();
        assert!(
            (s.total() - 0.81).abs() < 0.04,
            "front {front}: {}",
            s.total()
        );
        let r = t
            .slice(Lobe::Reflection, front, v)
            .map_or(0.0, |s| s.total());
        assert!(r < 1e-6, "front {front}: reflection {r}");
        // straight through: the outgoing direction sampled is the continuation of the view
        let d = s.sample(0.5, 0.5, 0.5).unwrap();
        assert!(
            (d[0] + v[0]).abs() < 0.2 && (d[1] + v[1]).abs() < 0.2,
            "front {front}: view {v:?} sampled {d:?}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn tensor_tree_t3_agrees_with_radiance_s_file() {
    // genBSDF -t3 5 -c 500 +f +b on the reference blind against Radiance's -t3 5 -c 2000
    // file: totals (Lambertian parts included) at 36 views from the room side. An isotropic
    // tree turns with the view's azimuth, so the 36 views are 6 independent incidence
    // angles: the means may differ by 4 sd of binomial shares p over 500 and 2000 rays,
    // averaged over 6 (measured: T -0.7%, R +3.0%, within 0.2 and 0.7 sd), each view by the
    // binomial bound of the t4 test; the oracle's checkBSDF reads it as an isotropic tree.
    let dir = common::scratch("genbsdf-t3");
    let mut c = common::fenestra("genBSDF");
    c.args(["-n", "2", "-q", "-t3", "5", "-c", "500", "+f", "+b", "+mgf"])
        .arg(common::fixture("genbsdf/blinds_curved20.mgf"));
    let ours = dir.join("t3.xml");
    std::fs::write(&ours, common::run_ok(&mut c)).unwrap();
    let a = tree_totals(&ours);
    let b = tree_totals(&common::fixture("genbsdf/blinds_t3.xml"));
    let [ta, tb, ra, rb] = compare_views(&a, &b, 1.0 / 500.0 + 1.0 / 2000.0);
    let sd6 = |p: f64| (p * (1.0 - p) * (0.002 + 0.0005) / 6.0).sqrt();
    assert!((ta - tb).abs() < 4.0 * sd6(tb), "T {ta} vs {tb}");
    assert!((ra - rb).abs() < 4.0 * sd6(rb), "R {ra} vs {rb}");
    if let Some(o) = common::oracle() {
        let out = common::run_ok(o.command("checkBSDF").arg(&ours));
        let text = String::from_utf8_lossy(&out);
        assert!(text.contains("Isotropic_Tensor_Tree"), "{text}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn tensor_tree_colour_blocks_hold_the_slats_chromaticity() {
    // -t4 3 +C on the reference blind: after each Visible tree come CIE-u and CIE-v trees
    // (genBSDF's u′ = 4X/(X + 15Y + 3Z), v′ = 9Y/(…), 4/19 and 9/19 where nothing arrives).
    // The slats are MGF "WarmWhite" (cxy .36 .37: u′ 0.2143, v′ 0.4955) and "MidGrey"
    // (equal-energy grey: 4/19, 9/19): the median of every colour tree's values must lie
    // between grey and warm white (measured: reflection u′ 0.2137, v′ 0.4906;
    // transmission 0.2145, 0.4963, the light that passes after warm bounces being a
    // little warmer than the file's mean); the oracle's checkBSDF reads it as coloured.
    let dir = common::scratch("genbsdf-t4-colour");
    let mut c = common::fenestra("genBSDF");
    c.args(["-n", "2", "-q", "-t4", "3", "-c", "100", "+C", "+mgf"])
        .arg(common::fixture("genbsdf/blinds_curved20.mgf"));
    let xml = String::from_utf8(common::run_ok(&mut c)).unwrap();
    let path = dir.join("t4c.xml");
    std::fs::write(&path, &xml).unwrap();
    let b = read_file(&path).unwrap();
    let kinds: Vec<String> = b
        .blocks
        .iter()
        .map(|k| format!("{} {}", k.wavelength.xml_name(), k.direction.xml_name()))
        .collect();
    assert_eq!(
        kinds,
        [
            "Visible Transmission Back",
            "CIE-u Transmission Back",
            "CIE-v Transmission Back",
            "Visible Reflection Back",
            "CIE-u Reflection Back",
            "CIE-v Reflection Back"
        ]
    );
    // medians of the u′ and v′ trees' written values
    let mut medians = Vec::new();
    for part in xml.split("<Wavelength unit=\"Integral\">").skip(1) {
        let kind = &part[..5];
        if kind != "CIE-u" && kind != "CIE-v" {
            continue;
        }
        let data = &part
            [part.find("<ScatteringData>").unwrap() + 16..part.find("</ScatteringData>").unwrap()];
        let mut v: Vec<f64> = data
            .split(|c: char| c.is_whitespace() || c == '{' || c == '}')
            .filter_map(|w| w.parse().ok())
            .collect();
        v.sort_by(f64::total_cmp);
        medians.push((kind.to_string(), v[v.len() / 2]));
    }
    assert_eq!(medians.len(), 4);
    for (kind, m) in &medians {
        let (grey, warm) = if kind == "CIE-u" {
            (4.0 / 19.0, 0.2143)
        } else {
            (9.0 / 19.0, 0.4955)
        };
        assert!(*m > grey - 1e-3 && *m < warm + 0.003, "{kind} median {m}");
    }
    if let Some(o) = common::oracle() {
        let out = common::run_ok(o.command("checkBSDF").arg(&path));
        assert!(String::from_utf8_lossy(&out).contains("Color: 1"));
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs genBSDF with `args` whole, then with `-checkpoint` killed once `lines` directions are
/// in its file, then again to completion: the resumed XML must be the uninterrupted one (the
/// command-line comment aside), the checkpoint gone.
fn resumes_as_uninterrupted(name: &str, args: &[&str], lines: usize) {
    let dir = scratch(name);
    let mgf = fixture("genbsdf/blinds_curved20.mgf");
    let mut c = fenestra("genBSDF");
    c.args(args).arg(&mgf).current_dir(&dir);
    let full = String::from_utf8(run_ok(&mut c)).unwrap();
    let ck = dir.join("ck.txt");
    let mut c = fenestra("genBSDF");
    c.args(["-checkpoint", "ck.txt"])
        .args(args)
        .arg(&mgf)
        .current_dir(&dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null());
    let mut child = c.spawn().unwrap();
    let start = std::time::Instant::now();
    loop {
        let n = std::fs::read_to_string(&ck)
            .map(|t| t.lines().count())
            .unwrap_or(0);
        if n >= lines || start.elapsed().as_secs() > 60 {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let _ = child.kill();
    let _ = child.wait();
    let kept = std::fs::read_to_string(&ck)
        .map(|t| t.lines().count())
        .unwrap_or(0);
    assert!(kept > 1, "the killed run left its checkpoint");
    let mut c = fenestra("genBSDF");
    c.args(["-checkpoint", "ck.txt"])
        .args(args)
        .arg(&mgf)
        .current_dir(&dir);
    let out = output_ok(&mut c);
    assert!(String::from_utf8_lossy(&out.stderr).contains("resuming from 'ck.txt'"));
    let strip = |t: &str| -> String {
        t.lines()
            .filter(|l| !l.contains("Created by"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    assert!(
        strip(&full) == strip(&String::from_utf8_lossy(&out.stdout)),
        "{name}: resumed XML differs"
    );
    assert!(
        !ck.exists(),
        "the checkpoint is removed when the run completes"
    );
    // a checkpoint of another run is refused
    std::fs::write(&ck, "fenestra genBSDF checkpoint 1 0123456789abcdef\n").unwrap();
    let mut c = fenestra("genBSDF");
    c.args(["-checkpoint", "ck.txt"])
        .args(args)
        .arg(&mgf)
        .current_dir(&dir);
    let out = c.output().unwrap();
    assert!(!out.status.success() && out.stdout.is_empty());
    assert!(String::from_utf8_lossy(&out.stderr).contains("another run"));
}

#[test]
fn killed_run_resumes_from_its_checkpoint() {
    resumes_as_uninterrupted(
        "genbsdf-checkpoint",
        &["-q", "-n", "2", "-c", "100", "+mgf"],
        40,
    );
}

#[test]
fn killed_tree_run_resumes_from_its_checkpoint() {
    resumes_as_uninterrupted(
        "genbsdf-checkpoint-tree",
        &["-q", "-n", "2", "-t4", "4", "-c", "30", "+mgf"],
        60,
    );
}

/// `-E` with a tensor tree: the standard errors come as a tree file of the same rank that
/// the oracle's checkBSDF reads, and they fall as 1/√samples (4× the samples: half the error).
#[test]
fn tree_errors_fall_as_one_over_root_samples() {
    let dir = scratch("genbsdf-tree-errors");
    let mgf = fixture("genbsdf/blinds_curved20.mgf");
    let mut mean_se = Vec::new();
    for c in ["20", "80"] {
        let mut g = fenestra("genBSDF");
        g.args([
            "-q", "-n", "2", "-t4", "3", "-t", "0", "-c", c, "-E", "err.xml", "+mgf",
        ])
        .arg(&mgf)
        .current_dir(&dir);
        run_ok(&mut g);
        let text = std::fs::read_to_string(dir.join("err.xml")).unwrap();
        assert!(text.contains("TensorTree4") && text.contains("Standard errors"));
        // the mean of every number inside the trees' ScatteringData
        let mut sum = 0.0;
        let mut n = 0usize;
        for block in text.split("<ScatteringData>").skip(1) {
            let data = block.split("</ScatteringData>").next().unwrap();
            for w in
                data.split(|ch: char| ch.is_whitespace() || ch == '{' || ch == '}' || ch == ',')
            {
                if let Ok(v) = w.parse::<f64>() {
                    sum += v;
                    n += 1;
                }
            }
        }
        assert!(n > 0);
        mean_se.push(sum / n as f64);
    }
    // the sample grid rounds -c to 25 and 90 samples for this 30 × 28.9 cm device (genBSDF -v),
    // so the errors should fall by √(90/25) = 1.90. With -t 0 no cells merge, so both means
    // are over the same cells (reduced trees merged different cells: 1.74 once, 1.58 after
    // the directions were stratified). Each cell's error is estimated from the spread of
    // its samples (about 14% relative noise at 25 samples, less in the mean), and cells
    // whose few samples all missed give 0 at -c 20: ±0.3 (measured 1.85)
    let ratio = mean_se[0] / mean_se[1];
    eprintln!("se(-c 20) / se(-c 80) = {ratio}");
    assert!((ratio - 1.9).abs() < 0.3, "se(-c 20) / se(-c 80) = {ratio}");
    if let Some(o) = common::oracle() {
        let mut c = o.command("checkBSDF");
        c.arg("err.xml").current_dir(&dir);
        let text = String::from_utf8(run_ok(&mut c)).unwrap();
        assert!(text.contains("Anisotropic_Tensor_Tree"), "{text}");
    }
}

/// `-k kh|kq`: the half and quarter Klems bases. The oracle reads both (rmtxop: 77 × 77 and
/// 41 × 41) and its checkBSDF report is ours (Unknown_Matrix for the 77-patch half basis,
/// as Radiance 6 names matrices by their 145/73/41 patches); the diffuse transmittance
/// (hemispherical average) agrees with the full basis's.
#[test]
fn half_and_quarter_klems_bases() {
    let dir = scratch("genbsdf-bases");
    let mgf = fixture("genbsdf/blinds_curved20.mgf");
    let mut diffuse = Vec::new();
    for (k, n) in [("kf", 145usize), ("kh", 77), ("kq", 41)] {
        let mut g = fenestra("genBSDF");
        g.args(["-q", "-n", "2", "-k", k, "-c", "60", "+mgf"])
            .arg(&mgf)
            .current_dir(&dir);
        let xml = run_ok(&mut g);
        let f = dir.join(format!("{k}.xml"));
        std::fs::write(&f, &xml).unwrap();
        let b = read_file(&f).unwrap();
        let Some(fenestra_bsdf::BlockData::Klems(m)) = b.blocks.first().map(|b| &b.data) else {
            panic!("{k}: a Klems block expected")
        };
        assert_eq!(m.incident.len(), n, "{k}");
        diffuse.push(diffuse_total(&b, Direction::TransmissionBack));
        if let Some(o) = common::oracle() {
            let mut c = o.command("rmtxop");
            c.arg(&f).current_dir(&dir);
            let text = String::from_utf8(run_ok(&mut c)).unwrap();
            assert!(text.contains(&format!("NROWS={n}\n")), "{text}");
            let mut c = o.command("checkBSDF");
            c.arg(&f).current_dir(&dir);
            let theirs = String::from_utf8(run_ok(&mut c)).unwrap();
            let mut c = fenestra("checkBSDF");
            c.arg(&f).current_dir(&dir);
            let ours = String::from_utf8(run_ok(&mut c)).unwrap();
            assert!(ours.starts_with(&theirs), "{k}:\n{ours}\nvs\n{theirs}");
        }
    }
    // the same device: hemispherical diffuse transmittance within 3% between bases (Monte
    // Carlo at -c 60 and the coarser bases' wider patches)
    for d in &diffuse[1..] {
        assert!((d / diffuse[0] - 1.0).abs() < 0.03, "{diffuse:?}");
    }
}

/// The streamed reduction (the one `-t4 7` uses: the grid never held, every incident cell
/// traced twice) writes the same files as the in-memory one, colour and standard errors
/// included, at L = 3 and 4.
#[test]
fn streamed_tree_reduction_writes_the_same_files() {
    let scene = fenestra_scene::parse_str(&common::red_slats(), "red.rad").unwrap();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    for log2 in [3u32, 4] {
        let mut files = Vec::new();
        for stream in [false, true] {
            let mut o = fenestra_genbsdf::Options::genbsdf();
            o.samples = 12;
            o.forward = true;
            o.backward = true;
            o.colour = true;
            o.errors = true;
            o.stream_trees = stream;
            let got = fenestra_genbsdf::tree4::characterise(
                &scene,
                &o,
                4,
                log2,
                90.0,
                false,
                &pool,
                &|| {},
            )
            .unwrap();
            let xml = fenestra_bsdf::write::klems_xml(&got.bsdf, None).unwrap();
            let err = fenestra_bsdf::write::klems_xml(&got.errors.unwrap(), None).unwrap();
            files.push((xml, err));
        }
        assert!(files[0].0.contains("CIE-u"));
        assert_eq!(files[0].0, files[1].0, "L = {log2}: values");
        assert_eq!(files[0].1, files[1].1, "L = {log2}: errors");
    }
}

/// `-t4 7` (2^28 cells per component; the grid alone would be a gigabyte in single
/// precision): runs in bounded memory, says so with -v, and writes a file our reader and the
/// oracle's checkBSDF read. A black slab keeps the tree small (everything merges), so the
/// peak is the engine's own: below 100 MB (measured 18 MB). The same-files test above
/// covers the reduction's values.
#[test]
fn t4_7_runs_in_bounded_memory() {
    let dir = scratch("genbsdf-t4-7");
    std::fs::write(
        dir.join("black.rad"),
        "void plastic black 0 0 5 0 0 0 0 0\n\
         black polygon slab 0 0 12 0 0 -0.01 0.3 0 -0.01 0.3 0.3 -0.01 0 0.3 -0.01\n",
    )
    .unwrap();
    let mut g = fenestra("genBSDF");
    g.args([
        "-v",
        "-n",
        "2",
        "-t4",
        "7",
        "-c",
        "1",
        "+f",
        "+b",
        "-geom",
        "meter",
        "black.rad",
    ])
    .current_dir(&dir);
    let out = common::output_ok(&mut g);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("reflection not averaged"), "{err}");
    // the memory line exists where the system reports it (Linux)
    if cfg!(target_os = "linux") {
        let mb: f64 = err
            .lines()
            .find_map(|l| l.split("peak resident memory ").nth(1))
            .and_then(|v| v.trim_end_matches(" MB").parse().ok())
            .expect("peak memory line");
        assert!(mb < 100.0, "peak {mb} MB");
    }
    std::fs::write(dir.join("b7.xml"), &out.stdout).unwrap();
    let b = read_file(&dir.join("b7.xml")).unwrap();
    assert_eq!(b.blocks.len(), 4);
    if let Some(o) = common::oracle() {
        let mut c = o.command("checkBSDF");
        c.arg("b7.xml").current_dir(&dir);
        // all zero: the oracle drops the empty trees and calls the rest Lambertian
        let text = String::from_utf8(run_ok(&mut c)).unwrap();
        assert!(text.contains("Pure_Lambertian"), "{text}");
    }
}

/// The oracle's rtrace renders our files as it renders Radiance's: the reference office
/// (tests/fixtures/rtrace_threephase_bsdf) under the overcast sky, its south window a `BSDF`
/// material with, in turn, our `-t4 4 -c 100` tree and Radiance's `-t4 4 -c 400` tree of the
/// reference blind, then our Klems `-c 100 +f +b` file and Radiance's `-c 1000` one; the
/// oracle's rtrace `-ab 1 -ad 2048 -lw 1e-4 -aa 0 -as 0`, mean luminance over the 45 sensors,
/// 24 runs per file over shuffled sensor orders (its only run-to-run variation). Each pair
/// within 4 combined standard errors of the means plus 1% for the two files' own sampling,
/// which no rerun of rtrace averages away: per incident patch, the transmission totals of our
/// `-c 100` file carry about 3.5% relative noise and Radiance's `-c 1000` file about 1.5%
/// (replicate spreads measured on this blind); the overcast sky's light reaches the sensors
/// through a few dozen patches, so the files' difference in a sky-weighted mean is about
/// 3.8% / √30 ≈ 0.7% (sd), and 1% is 1.4 of those sds: the allowance is not wide. Measured (24 runs): tree
/// 1.6303 vs 1.6365 (−0.38%), Klems 1.6376 vs 1.6258 (+0.73%), standard errors 0.0018–0.0023.
#[test]
fn oracle_rtrace_renders_our_files_as_its_own() {
    let Some(o) = common::oracle() else { return };
    let dir = common::office_scratch(
        "genbsdf-oracle-renders",
        &["sky_t4_sep21_1200_overcast.rad", "window_bsdf.rad"],
    );
    std::fs::copy(
        fixture("dctimestep/blinds_t4.xml"),
        dir.join("theirs_t4.xml"),
    )
    .unwrap();
    std::fs::copy(
        fixture("threephase/blinds_kf.xml"),
        dir.join("theirs_kf.xml"),
    )
    .unwrap();
    let mgf = fixture("genbsdf/blinds_curved20.mgf");
    for (file, args) in [
        ("ours_t4.xml", ["-t4", "4", "-c", "100"].as_slice()),
        ("ours_kf.xml", ["-c", "100", "+f", "+b"].as_slice()),
    ] {
        let mut c = fenestra("genBSDF");
        c.args(["-q", "-n", "2"]).args(args).arg("+mgf").arg(&mgf);
        std::fs::write(dir.join(file), run_ok(&mut c)).unwrap();
    }
    let window = std::fs::read_to_string(dir.join("window_bsdf.rad")).unwrap();
    let text = std::fs::read_to_string(dir.join("sensors.pts")).unwrap();
    let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
    let render = |xml: &str| -> (f64, f64) {
        std::fs::write(dir.join("window.rad"), window.replace("blinds_kf.xml", xml)).unwrap();
        common::oracle_octree(
            &o,
            &dir,
            &[
                "materials.rad",
                "room.rad",
                "exterior.rad",
                "window.rad",
                "sky_t4_sep21_1200_overcast.rad",
                "skyfunc_glow.rad",
            ],
        );
        let means: Vec<f64> = (0..24u64)
            .map(|k| {
                let mut next = common::xorshift(k + 11);
                let mut order = lines.clone();
                for i in (1..order.len()).rev() {
                    order.swap(i, (next() * (i + 1) as f64) as usize);
                }
                let mut c = o.command("rtrace");
                c.args([
                    "-h", "-I+", "-aa", "0", "-as", "0", "-ab", "1", "-ad", "2048",
                ])
                .args(["-lw", "1e-4", "scene.oct"])
                .current_dir(&dir);
                let v = common::numbers(&common::pipe_ok(c, (order.join("\n") + "\n").as_bytes()));
                v.chunks(3)
                    .map(|c| 0.265 * c[0] + 0.670 * c[1] + 0.065 * c[2])
                    .sum::<f64>()
                    / (v.len() / 3) as f64
            })
            .collect();
        common::mean_sem(&means)
    };
    for (ours, theirs) in [
        ("ours_t4.xml", "theirs_t4.xml"),
        ("ours_kf.xml", "theirs_kf.xml"),
    ] {
        let ((mo, so), (mt, st)) = (render(ours), render(theirs));
        let se = (so * so + st * st).sqrt();
        eprintln!(
            "{ours}: {mo:.4} ± {so:.4}, {theirs}: {mt:.4} ± {st:.4} ({:+.2}%)",
            100.0 * (mo / mt - 1.0)
        );
        assert!(mo > 0.0 && mt > 0.0);
        assert!(
            (mo - mt).abs() <= 4.0 * se + 0.01 * mt,
            "{ours} {mo} ± {so} vs {theirs} {mt} ± {st}"
        );
    }
}
