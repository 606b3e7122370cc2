//! gensky against the Radiance reference descriptions and, for generated cases,
//! the oracle's gensky. The text must be identical to the printed digits
//! (sun direction to 6 decimals, i.e. the solar position well within 0.01°).

mod common;

fn words(line: &str) -> Vec<String> {
    line.split_whitespace().map(str::to_string).collect()
}

#[test]
fn reference_descriptions() {
    let dir = common::fixture("sky");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "rad") {
            continue;
        }
        let want = std::fs::read(&p).unwrap();
        let first = String::from_utf8_lossy(&want)
            .lines()
            .next()
            .unwrap()
            .to_string();
        let args = words(first.trim_start_matches("# "));
        let got = common::run_ok(common::fenestra("gensky").args(&args[1..]));
        assert_eq!(common::tail(&got), common::tail(&want), "{}", p.display());
        n += 1;
    }
    assert_eq!(n, 6);
}

fn generated_cases() -> Vec<Vec<String>> {
    let mut r = common::Lcg(5);
    let mut cases = Vec::new();
    for k in 0..240 {
        let mut a: Vec<String> = Vec::new();
        if k % 12 == 0 {
            a.push("-ang".into());
            a.push(format!("{:.2}", r.unit() * 100.0 - 5.0));
            a.push(format!("{:.2}", r.unit() * 360.0 - 180.0));
        } else {
            a.push(format!("{}", 1 + (r.unit() * 12.0) as i32));
            a.push(format!("{}", 1 + (r.unit() * 28.0) as i32));
            let h = r.unit() * 24.0;
            let t = match k % 5 {
                0 => format!("{}:{:02}", h as i32, (r.unit() * 60.0) as i32),
                1 => format!("+{h:.3}"),
                2 => format!(
                    "{}{}",
                    h as i32,
                    r.pick(&["PST", "EST", "CET", "gmt", "JST", "NZST", "IST", "NST"])
                ),
                _ => format!("{h:.2}"),
            };
            a.push(t);
        }
        a.push(r.pick(&["+s", "-s", "+i", "-i", "-c", "-u"]).into());
        let lat = r.unit() * 170.0 - 85.0;
        let lon = r.unit() * 360.0 - 180.0;
        a.extend([
            "-a".into(),
            format!("{lat:.2}"),
            "-o".into(),
            format!("{lon:.2}"),
        ]);
        a.extend([
            "-m".into(),
            format!("{}", ((lon / 15.0).round() * 15.0) as i32),
        ]);
        match k % 7 {
            0 => a.extend(["-g".into(), format!("{:.2}", r.unit())]),
            1 => a.extend(["-t".into(), format!("{:.2}", 1.5 + r.unit() * 6.0)]),
            2 => a.extend(["-b".into(), format!("{:.1}", r.unit() * 50.0)]),
            3 => a.extend(["-B".into(), format!("{:.1}", r.unit() * 300.0)]),
            4 => a.extend(["-R".into(), format!("{:.1}", r.unit() * 900.0)]),
            5 => a.extend(["-r".into(), format!("{:.4e}", r.unit() * 1e7)]),
            _ => {
                if k % 12 != 0 {
                    // mostly 1960-2039; every fifth outside 1950-2050 (1600-2999), where
                    // Radiance's almanac day count leaves the Gregorian calendar
                    let y = if k % 5 == 0 {
                        1600 + (r.unit() * 1400.0) as i32
                    } else {
                        1960 + (r.unit() * 80.0) as i32
                    };
                    a.extend(["-y".into(), y.to_string()]);
                }
            }
        }
        cases.push(a);
    }
    // Hard cases: sun at the zenith (clamped to 87°), just below the horizon,
    // polar night and midnight sun, the year boundary.
    for c in [
        "3 21 12 +s -a 0 -o 0 -m 0",
        "6 21 12 +s -a 23.44 -o 0 -m 0",
        "-ang 90 0 +s",
        "-ang -0.1 40 +s",
        "12 21 12 +s -a 80 -o 0 -m 0",
        "6 21 0 +s -a 80 -o 0 -m 0",
        "12 31 23:59 +i -a 45",
        "1 1 0:01 +s -a -45",
        "6 21 +12 -c -a 90",
    ] {
        cases.push(words(c));
    }
    cases
}

#[test]
fn oracle_gensky_generated_cases() {
    common::tails_match_oracle("gensky", &generated_cases(), |a, want, got| {
        assert_eq!(want.status.success(), got.status.success(), "{a:?}");
    });
}

#[test]
fn bad_input_is_a_use_error() {
    for a in [
        &["13", "1", "12"][..],
        &["3", "21"],
        &["3", "21", "12XYZ"],
        &["3", "21", "12", "-q"],
    ] {
        let out = common::fenestra("gensky").args(a).output().unwrap();
        assert!(!out.status.success(), "{a:?}");
        assert!(!out.stderr.is_empty());
    }
}
