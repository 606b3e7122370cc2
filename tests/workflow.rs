//! The documented three-phase workflow (docs/three-phase.md) run verbatim through `sh`
//! with fenestra's binaries on PATH, on a copy of the example office, with the sample
//! counts lowered so that it is fast; and examples/three-phase/matrices.sh.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Folder of the test binaries (target/<profile>).
fn bin_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    exe.parent().and_then(Path::parent).unwrap().to_path_buf()
}

/// A copy of examples/three-phase with a view file, in a scratch folder.
fn office(name: &str) -> PathBuf {
    let dir = common::scratch(name);
    let ex = repo().join("examples/three-phase");
    for sub in ["scene", "matrices", "weather"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    for e in std::fs::read_dir(ex.join("scene")).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), dir.join("scene").join(e.file_name())).unwrap();
    }
    for xml in ["blinds_kf.xml", "clear_glass_kf.xml"] {
        std::fs::copy(
            ex.join("matrices").join(xml),
            dir.join("matrices").join(xml),
        )
        .unwrap();
    }
    std::fs::copy(
        ex.join("weather/sf_year.wea"),
        dir.join("weather/sf_year.wea"),
    )
    .unwrap();
    std::fs::copy(common::fixture("vwrays/view.vf"), dir.join("scene/view.vf")).unwrap();
    dir
}

/// The ```sh block of docs/three-phase.md.
fn documented_commands() -> String {
    let doc = std::fs::read_to_string(repo().join("docs/three-phase.md")).unwrap();
    let start = doc.find("```sh\n").expect("a ```sh block") + 6;
    let end = start + doc[start..].find("```").expect("end of the block");
    doc[start..end].to_string()
}

fn sh(dir: &Path, script: &str) -> std::process::Output {
    let path = format!(
        "{}:{}",
        bin_dir().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    Command::new("sh")
        .arg("-ec")
        .arg(script)
        .current_dir(dir)
        .env("PATH", path)
        .env("FENESTRA_LIB", repo().join("lib"))
        .env("FENESTRA_NO_PROGRESS", "1")
        .env_remove("RAYPATH")
        .output()
        .expect("sh")
}

/// Lux per sensor (first column after the header) of an ascii matrix.
fn values(text: &str) -> Vec<f64> {
    let body = text.split("\n\n").nth(1).expect("header then body");
    body.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect()
}

#[test]
fn documented_workflow_runs_verbatim() {
    let dir = office("workflow-doc");
    let cmds = documented_commands();
    // only the sample counts change
    let fast = cmds
        .replace("-c 1000", "-c 20")
        .replace("-ad 50000", "-ad 64")
        .replace("-ad 1000", "-ad 64")
        .replace("-ad 2000", "-ad 64")
        .replace("-ab 6", "-ab 2");
    assert_ne!(fast, cmds);
    let out = sh(&dir.join("scene"), &fast);
    assert!(
        out.status.success(),
        "workflow failed: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let scene = dir.join("scene");
    let read =
        |f: &str| std::fs::read_to_string(scene.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
    for g in ["SouthGroup", "WestGroup"] {
        let v = read(&format!("V_{g}.vmx"));
        // 45 sensor rows in the body; rtcontrib without -y writes no NROWS (as Radiance),
        // and a NROWS line, if any, must agree
        assert_eq!(values(&v).len(), 45, "V rows");
        let head = v.split("\n\n").next().unwrap();
        assert!(
            head.lines()
                .all(|l| !l.starts_with("NROWS=") || l == "NROWS=45"),
            "V NROWS"
        );
        assert!(v.contains("NCOLS=145"));
        let d = read(&format!("D_{g}.dmx"));
        assert!(d.contains("NCOLS=146"));
        assert_eq!(values(&d).len(), 145);
    }
    // one sky: south-group lux per sensor, near what the reference matrices give (res_t1 of
    // the reference office, which has no west window, converted to lux): the lowered -ab/-ad
    // lose some interreflected light, so the room mean is compared within 25%
    let ill = values(&read("ill_south.dat"));
    assert_eq!(ill.len(), 45);
    assert!(ill.iter().all(|x| x.is_finite() && *x > 0.0));
    // both groups: the sum is the south group's light plus the west group's
    let west = values(&read("ill_west.dat"));
    let both = values(&read("ill.dat"));
    assert_eq!(both.len(), 45);
    for k in 0..45 {
        assert!(
            (both[k] - ill[k] - west[k]).abs() <= 1e-3 * both[k].max(1.0),
            "sensor {k}"
        );
        assert!(west[k] > 0.0);
    }
    let reference: Vec<f64> = {
        let t = std::fs::read_to_string(common::fixture("threephase/res_t1_mar21_1000_clear.dat"))
            .unwrap();
        let body = t.split("\n\n").nth(1).unwrap();
        body.lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| {
                let c: Vec<f64> = l.split_whitespace().map(|w| w.parse().unwrap()).collect();
                47.435 * c[0] + 119.93 * c[1] + 11.635 * c[2]
            })
            .collect()
    };
    assert_eq!(reference.len(), 45);
    let (mo, mr) = (
        ill.iter().sum::<f64>() / 45.0,
        reference.iter().sum::<f64>() / 45.0,
    );
    eprintln!("mean lux: workflow {mo:.1}, reference matrices {mr:.1}");
    assert!((mo / mr - 1.0).abs() < 0.25, "{mo} vs {mr}");
    // the year: 45 sensors x 8760 hours
    let annual = read("annual_ill.dat");
    assert!(annual.contains("NROWS=45") && annual.contains("NCOLS=8760"));
    // the picture: 145 V pictures and the result
    for g in ["SouthGroup", "WestGroup"] {
        assert!(scene.join(format!("vimg/{g}_000.hdr")).is_file());
        assert!(scene.join(format!("vimg/{g}_144.hdr")).is_file());
    }
    let pic = std::fs::read(scene.join("window_light.hdr")).unwrap();
    assert!(pic.starts_with(b"#?RADIANCE"));
    let text = String::from_utf8_lossy(&pic);
    let res = text
        .lines()
        .find(|l| l.starts_with("-Y"))
        .map(|l| l.split_whitespace().collect::<Vec<_>>().join(" "));
    assert_eq!(res.as_deref(), Some("-Y 26 +X 32"));
}

#[test]
fn matrices_script_writes_v_and_d() {
    let dir = office("workflow-script");
    // matrices.sh from the repository, run on the copy (it works on the scene folder next to it)
    std::fs::copy(
        repo().join("examples/three-phase/matrices.sh"),
        dir.join("matrices.sh"),
    )
    .unwrap();
    let out = sh(
        &dir,
        "FENESTRA_BIN=\"$(dirname \"$(command -v rtcontrib)\")\" V_OPTS='-ab 1 -ad 32 -lw 1e-3' \
         D_OPTS='-ab 1 -ad 32 -lw 1e-3' D_C=10 bash ./matrices.sh out",
    );
    assert!(
        out.status.success(),
        "matrices.sh failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    for g in ["SouthGroup", "WestGroup"] {
        let v = std::fs::read_to_string(dir.join(format!("out/V_{g}.vmx"))).unwrap();
        let d = std::fs::read_to_string(dir.join(format!("out/D_{g}.dmx"))).unwrap();
        assert_eq!(values(&v).len(), 45);
        assert_eq!(values(&d).len(), 145);
    }
}

/// The matrices bundled in examples/three-phase/matrices are what matrices.sh writes at its
/// defaults: same numbers (headers differ only in dates and the output path). Fails when an
/// engine change alters them, so that they are regenerated with it.
#[test]
fn bundled_matrices_are_what_the_script_writes() {
    let dir = office("workflow-bundled");
    std::fs::copy(
        repo().join("examples/three-phase/matrices.sh"),
        dir.join("matrices.sh"),
    )
    .unwrap();
    let out = sh(
        &dir,
        "FENESTRA_BIN=\"$(dirname \"$(command -v rtcontrib)\")\" bash ./matrices.sh out",
    );
    assert!(
        out.status.success(),
        "matrices.sh failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let data = |p: PathBuf| {
        let text = std::fs::read_to_string(&p).unwrap();
        text.split_once("\n\n")
            .expect("header then data")
            .1
            .to_string()
    };
    for f in [
        "V_SouthGroup.vmx",
        "V_WestGroup.vmx",
        "D_SouthGroup.dmx",
        "D_WestGroup.dmx",
    ] {
        let fresh = data(dir.join("out").join(f));
        let bundled = data(repo().join("examples/three-phase/matrices").join(f));
        assert!(
            fresh == bundled,
            "{f}: the bundled matrix is not what matrices.sh writes now; regenerate it \
             (examples/three-phase/matrices/README.md)"
        );
    }
}
