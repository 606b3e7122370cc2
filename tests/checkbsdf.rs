//! checkBSDF: Radiance's report section against the stored oracle output and the oracle run
//! live on reduced variants of blinds_kf.xml; fenestra's own section (totals, energy check).

mod common;

use std::path::{Path, PathBuf};

fn ours(dir: &Path, file: &Path) -> std::process::Output {
    common::fenestra("checkBSDF")
        .current_dir(dir)
        .arg(file)
        .output()
        .unwrap()
}

/// The Radiance part of our report: everything before fenestra's own section.
fn radiance_part(out: &[u8]) -> String {
    let s = String::from_utf8_lossy(out);
    s.split("--- fenestra:").next().unwrap().to_string()
}

/// blinds_kf.xml text with each `<WavelengthData>` element passed through `edit` (None drops it).
fn variant(dir: &Path, name: &str, edit: impl Fn(&str) -> Option<String>) -> PathBuf {
    let text = std::fs::read_to_string(common::fixture("threephase/blinds_kf.xml")).unwrap();
    let mut out = String::new();
    let mut rest = text.as_str();
    while let Some(i) = rest.find("<WavelengthData>") {
        out.push_str(&rest[..i]);
        let j = rest[i..].find("</WavelengthData>").unwrap() + i + "</WavelengthData>".len();
        if let Some(e) = edit(&rest[i..j]) {
            out.push_str(&e);
        }
        rest = &rest[j..];
    }
    out.push_str(rest);
    let p = dir.join(name);
    std::fs::write(&p, out).unwrap();
    p
}

/// Scales (and offsets) the numbers of a block's ScatteringData.
fn rescale(block: &str, f: impl Fn(f64) -> f64) -> String {
    let a = block.find("<ScatteringData>").unwrap() + "<ScatteringData>".len();
    let b = block.find("</ScatteringData>").unwrap();
    let nums: Vec<String> = block[a..b]
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|w| !w.is_empty())
        .map(|w| format!("{}", f(w.parse::<f64>().unwrap())))
        .collect();
    format!("{}{}\n{}", &block[..a], nums.join(" "), &block[b..])
}

#[test]
fn stored_check_output_reproduced() {
    let out = ours(&common::fixture("threephase"), Path::new("blinds_kf.xml"));
    assert!(out.status.success());
    let want = std::fs::read_to_string(common::fixture("dctimestep/blinds_kf.check.txt")).unwrap();
    assert_eq!(radiance_part(&out.stdout), want);
}

/// The four components alone, in pairs, with a Lambertian offset (split off as π·min when the
/// minimum exceeds 0.01/π), and sawtooth.xml (reflection only): identical to the oracle.
#[test]
fn oracle_check_variants_identical() {
    let Some(o) = common::oracle() else { return };
    let dir = common::scratch("checkbsdf-variants");
    let dirs = [
        "Reflection Back",
        "Reflection Front",
        "Transmission Back",
        "Transmission Front",
    ];
    let mut files = vec![common::fixture("threephase/sawtooth.xml")];
    for mask in [1u32, 2, 4, 8, 12, 3, 7, 11] {
        let keep = move |b: &str| {
            b.contains(">Visible<")
                && dirs
                    .iter()
                    .enumerate()
                    .any(|(k, d)| mask & (1 << k) != 0 && b.contains(&format!(">{d}<")))
        };
        files.push(variant(&dir, &format!("m{mask}.xml"), |b| {
            keep(b).then(|| b.to_string())
        }));
    }
    files.push(variant(&dir, "lamb.xml", |b| {
        (b.contains(">Visible<") && b.contains(">Reflection Back<"))
            .then(|| rescale(b, |v| v + 0.01))
    }));
    for f in &files {
        let name = f.file_name().unwrap();
        let dirf = f.parent().unwrap();
        let mine = ours(dirf, Path::new(name));
        assert!(mine.status.success(), "{f:?}");
        let theirs = common::run_ok(o.command("checkBSDF").current_dir(dirf).arg(name));
        assert_eq!(
            radiance_part(&mine.stdout),
            String::from_utf8_lossy(&theirs),
            "{f:?}"
        );
    }
}

/// Adds `xyz[k]` to the values of a block of direction `d` (k: CIE-X, Visible, CIE-Z); other
/// blocks unchanged.
fn offset(block: &str, d: &str, xyz: [f64; 3]) -> String {
    if !block.contains(&format!(">{d}<")) {
        return block.to_string();
    }
    for (k, w) in ["CIE-X", "Visible", "CIE-Z"].iter().enumerate() {
        if block.contains(&format!(">{w}<")) {
            return rescale(block, |v| v + xyz[k]);
        }
    }
    block.to_string()
}

/// Lambertian parts (values offset so that the minimum exceeds 0.01/π), grey and coloured, on
/// either transmission block or both, a file with one transmission block, a matrix with zeros,
/// and two coloured files in one run (the colour dither goes on from file to file): Radiance's
/// section identical to the oracle's. This covers the coloured split in Sharp RGB (Lambertian
/// XYZ), the shared Lambertian transmission (a missing block's row; reciprocity with the back
/// block's part replaced by the front's) and pairs with a zero element left out.
#[test]
fn oracle_check_lambertian_variants_identical() {
    let Some(o) = common::oracle() else { return };
    let dir = common::scratch("checkbsdf-lambertian");
    let visible = |b: &str| b.contains(">Visible<");
    let (tf, tb, rb) = ("Transmission Front", "Transmission Back", "Reflection Back");
    let files = [
        variant(&dir, "tfl.xml", |b| {
            (visible(b) && b.contains(tf)).then(|| rescale(b, |v| v + 0.05))
        }),
        variant(&dir, "tbl.xml", |b| {
            (visible(b) && b.contains(tb)).then(|| rescale(b, |v| v + 0.05))
        }),
        variant(&dir, "lambg2.xml", |b| {
            visible(b).then(|| offset(b, tb, [0.04; 3]))
        }),
        variant(&dir, "lambg3.xml", |b| {
            visible(b).then(|| offset(&offset(b, tf, [0.05; 3]), tb, [0.02; 3]))
        }),
        variant(&dir, "zeros.xml", |b| {
            visible(b).then(|| {
                if b.contains(rb) {
                    rescale(b, |v| if v < 0.02 { 0.0 } else { v })
                } else {
                    b.to_string()
                }
            })
        }),
        variant(&dir, "lambc.xml", |b| {
            Some(offset(
                &offset(b, tf, [0.06, 0.05, 0.04]),
                rb,
                [0.02, 0.02, 0.03],
            ))
        }),
        variant(&dir, "lambc2.xml", |b| {
            Some(offset(b, tb, [0.03, 0.04, 0.05]))
        }),
        variant(&dir, "lambc3.xml", |b| {
            Some(offset(
                &offset(b, tf, [0.06, 0.05, 0.04]),
                tb,
                [0.03, 0.04, 0.05],
            ))
        }),
    ];
    let name = |f: &PathBuf| f.file_name().unwrap().to_owned();
    let mut runs: Vec<Vec<std::ffi::OsString>> = files.iter().map(|f| vec![name(f)]).collect();
    runs.push(vec![name(&files[5]), name(&files[6])]);
    for run in &runs {
        let mine = common::fenestra("checkBSDF")
            .current_dir(&dir)
            .args(run)
            .output()
            .unwrap();
        assert!(mine.status.success(), "{run:?}");
        // Radiance's part of each file's report.
        let ours: String = String::from_utf8_lossy(&mine.stdout)
            .split("=====================================================\n")
            .filter(|r| !r.is_empty())
            .map(|r| {
                format!(
                    "=====================================================\n{}",
                    radiance_part(r.as_bytes())
                )
            })
            .collect();
        let theirs = common::run_ok(o.command("checkBSDF").current_dir(&dir).args(run));
        assert_eq!(ours, String::from_utf8_lossy(&theirs), "{run:?}");
    }
}

/// Our section: normal and diffuse totals, and a warning when T + R exceeds 1 + 1%.
#[test]
fn totals_and_energy_warning() {
    let out = ours(&common::fixture("threephase"), Path::new("blinds_kf.xml"));
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    // Normal-incidence totals of the Visible blocks (sums of BSDF × projected solid angle).
    assert!(text.contains("Ext->Int Trans\t0.6252\t"), "{text}");
    assert!(text.contains("Interior Refl\t0.1766\t"), "{text}");
    assert!(!text.contains("WARNING"));
    let dir = common::scratch("checkbsdf-energy");
    let f = variant(&dir, "hot.xml", |b| {
        if b.contains(">Transmission Front<") && b.contains(">Visible<") {
            Some(rescale(b, |v| v * 1.5))
        } else {
            Some(b.to_string())
        }
    });
    let out = ours(&dir, Path::new(f.file_name().unwrap()));
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("energy not conserved for light from the exterior"),
        "{err}"
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("WARNING: energy not conserved"));
}

/// Tensor trees (genBSDF rank 3 and rank 4): the component table (Lambertian part from the
/// reachable part of the tree, largest directional total integrated exactly on the finest grid,
/// angle from the finest cell) equals the stored oracle output; the reciprocity rows say that
/// fenestra does not compute them for trees (Radiance's sampling for trees is not reproduced).
#[test]
fn tensor_tree_component_table() {
    for f in ["blinds_t3", "blinds_t4"] {
        let dir = common::fixture("dctimestep");
        let out = ours(&dir, Path::new(&format!("{f}.xml")));
        assert!(out.status.success(), "{f}");
        let text = radiance_part(&out.stdout);
        let want = std::fs::read_to_string(dir.join(format!("{f}.check.txt"))).unwrap();
        let cut = |s: &str| {
            s.split("Component\tReciprocity")
                .next()
                .unwrap()
                .to_string()
        };
        assert_eq!(cut(&text), cut(&want), "{f}");
        assert!(text.contains("Interior Refl\t(not computed by fenestra for tensor trees)"));
    }
}
