//! dametrics: annual metrics per sensor from an illuminance matrix, on hand-made inputs
//! whose metrics are computed by hand; occupancy from a weather tape; error bands from
//! standard-error files (added in quadrature); bad input refused with a message.

mod common;

use std::path::Path;

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

fn run(dir: &Path, args: &[&str]) -> std::process::Output {
    let mut c = common::fenestra("dametrics");
    c.args(args).current_dir(dir);
    c.output().unwrap()
}

/// [`run`], asserting success (the failure message is the tool's stderr).
fn run_ok(dir: &Path, args: &[&str]) -> std::process::Output {
    let out = run(dir, args);
    common::assert_ok(&out);
    out
}

/// A .wea of `hours` (month 1, day 1.., local hours given) with zero irradiance.
fn wea(hours: &[f64]) -> String {
    let mut s = String::from(
        "place test\nlatitude 40\nlongitude 100\ntime_zone 105\nsite_elevation 0\nweather_data_file_units 1\n",
    );
    for (k, h) in hours.iter().enumerate() {
        s.push_str(&format!("1 {} {h} 0 0\n", k / 24 + 1));
    }
    s
}

#[test]
fn metrics_by_hand_with_occupancy_and_bands() {
    let dir = common::scratch("dametrics-hand");
    // 2 sensors × 5 hours, lux (one component); hours 7.5 (unoccupied), 9.5, 10.5, 12.5, 18.5
    write(
        &dir,
        "ill.dat",
        "#?RADIANCE\nNROWS=2\nNCOLS=5\nNCOMP=1\nFORMAT=ascii\n\n\
         5000 50 280 320 2500\n\
         10 400 400 90 3000\n",
    );
    write(&dir, "t.wea", &wea(&[7.5, 9.5, 10.5, 12.5, 18.5]));
    // two error parts (RGB, grey): per-channel sd 0.06 and 0.08 → lux sd (×179) 10.74 and
    // 14.32 → in quadrature 17.9 lux
    let grey = |v: f64| format!("{v} {v} {v}");
    let e = |v: f64| {
        format!(
            "#?RADIANCE\nNROWS=2\nNCOLS=5\nNCOMP=3\nFORMAT=ascii\n\n{}\n{}\n",
            vec![grey(v); 5].join("\t"),
            vec![grey(v); 5].join("\t")
        )
    };
    write(&dir, "a.err", &e(0.06));
    write(&dir, "b.err", &e(0.08));
    let out = run_ok(
        &dir,
        &["-w", "t.wea", "-E", "a.err", "-E", "b.err", "ill.dat"],
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .take(2)
        .map(|l| l.split_whitespace().collect())
        .collect();
    // sensor 1, occupied hours 9.5, 10.5, 12.5: 50, 280, 320 → DA 1/3, UDI 2/3 (280, 320),
    // mean 216.7; ±2σ = ±35.8: 280 and 320 may flip DA (band 0–66.7 %, 66.7 % flip);
    // 50 (14–86) stays below 100: UDI certain
    assert_eq!(rows[0][1..4], ["33.3", "66.7", "216.7"], "{text}");
    assert_eq!(
        rows[0][4..9],
        ["0.0–66.7", "66.7", "66.7–66.7", "0.0", "17.9"],
        "{text}"
    );
    // sensor 2: 400, 400, 90 → DA 2/3, UDI 2/3, mean 296.7; 90 (54–126) may reach 100 (UDI
    // band 66.7–100)
    assert_eq!(rows[1][1..4], ["66.7", "66.7", "296.7"], "{text}");
    assert_eq!(
        rows[1][4..9],
        ["66.7–66.7", "0.0", "66.7–100.0", "33.3", "17.9"],
        "{text}"
    );
    let room = text.lines().last().unwrap();
    // sDA300/50%: sensor 2 only (50 %); sensor 1 could reach 66.7 % ≥ 50 %: band 50–100 %
    assert!(
        room.starts_with("room: sDA300/50% 50.0 % (within ±2σ: 50.0–100.0)"),
        "{room}"
    );
    assert!(room.ends_with("over 2 sensors, 3 occupied hours"), "{room}");
    // the floor-plan map: a cell per sensor and panel, values printed
    write(&dir, "p.pts", "0.5 0.5 0.8 0 0 1\n1.5 0.5 0.8 0 0 1\n");
    run_ok(
        &dir,
        &["-w", "t.wea", "-p", "p.pts", "-m", "map.svg", "ill.dat"],
    );
    let svg = std::fs::read_to_string(dir.join("map.svg")).unwrap();
    assert_eq!(svg.matches("stroke=\"white\"").count(), 4, "{svg}");
    assert!(
        svg.contains(">33<") && svg.contains(">67<") && svg.contains("DA300 (%)"),
        "{svg}"
    );
    // every column occupied without -w; -t, -u, -z change the thresholds
    let out = run(&dir, &["-t", "250", "-u", "60", "5000", "ill.dat"]);
    let text = String::from_utf8_lossy(&out.stdout);
    let r: Vec<&str> = text.lines().nth(1).unwrap().split_whitespace().collect();
    // sensor 1 over 5 hours: ≥250: 5000, 280, 320, 2500 → 80 %; 60..5000: 5000 (=), 280, 320, 2500 → 80 %
    assert_eq!(r[1..3], ["80.0", "80.0"], "{text}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_input_is_refused_with_a_message() {
    let dir = common::scratch("dametrics-bad");
    write(
        &dir,
        "ill.dat",
        "#?RADIANCE\nNROWS=1\nNCOLS=3\nNCOMP=1\nFORMAT=ascii\n\n1 2 3\n",
    );
    write(
        &dir,
        "e.err",
        "#?RADIANCE\nNROWS=1\nNCOLS=2\nNCOMP=1\nFORMAT=ascii\n\n1 2\n",
    );
    write(&dir, "t.wea", &wea(&[9.5, 10.5]));
    write(
        &dir,
        "nan.dat",
        "#?RADIANCE\nNROWS=1\nNCOLS=3\nNCOMP=1\nFORMAT=ascii\n\n1 nan 3\n",
    );
    write(&dir, "p.pts", "0 0 0 0 0 1\n1 abc\n");
    for (args, want) in [
        (&["-E", "e.err", "ill.dat"][..], "1×2 standard errors"),
        (
            &["-w", "t.wea", "ill.dat"],
            "2 hours but the matrix has 3 columns",
        ),
        (&["-o", "8", "18", "ill.dat"], "-o needs -w"),
        (&["-u", "2000", "100", "ill.dat"], "below the second"),
        (&["-z", "0", "ill.dat"], "positive"),
        (&["-m", "x.svg", "ill.dat"], "-m needs -p"),
        (
            &["nan.dat"],
            "row 1 (sensor), column 2 (hour) is not a finite number",
        ),
        (&["-p", "p.pts", "ill.dat"], "p.pts, line 2"),
        (&["missing.dat"], "missing.dat"),
        (&[], "one illuminance matrix expected"),
    ] {
        let out = run(&dir, args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(want),
            "{args:?}: {err}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
