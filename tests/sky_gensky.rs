//! gensky against the Radiance reference descriptions and, for generated cases,
//! the oracle's gensky. The text must be identical to the printed digits
//! (sun direction to 6 decimals, i.e. the solar position well within 0.01°).

mod common;

fn words(line: &str) -> Vec<String> {
    line.split_whitespace().map(str::to_string).collect()
}

/// Output without the first line (the command, which names the program path).
fn tail(b: &[u8]) -> String {
    let s = String::from_utf8_lossy(b);
    s.split_once('\n').map(|x| x.1).unwrap_or("").to_string()
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
        assert_eq!(tail(&got), tail(&want), "{}", p.display());
        n += 1;
    }
    assert_eq!(n, 6);
}

/// A small deterministic generator for test cases (no external crates).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn pick<'a>(&mut self, v: &[&'a str]) -> &'a str {
        v[(self.next() * v.len() as f64) as usize % v.len()]
    }
}

fn generated_cases() -> Vec<Vec<String>> {
    let mut r = Lcg(5);
    let mut cases = Vec::new();
    for k in 0..240 {
        let mut a: Vec<String> = Vec::new();
        if k % 12 == 0 {
            a.push("-ang".into());
            a.push(format!("{:.2}", r.next() * 100.0 - 5.0));
            a.push(format!("{:.2}", r.next() * 360.0 - 180.0));
        } else {
            a.push(format!("{}", 1 + (r.next() * 12.0) as i32));
            a.push(format!("{}", 1 + (r.next() * 28.0) as i32));
            let h = r.next() * 24.0;
            let t = match k % 5 {
                0 => format!("{}:{:02}", h as i32, (r.next() * 60.0) as i32),
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
        let lat = r.next() * 170.0 - 85.0;
        let lon = r.next() * 360.0 - 180.0;
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
            0 => a.extend(["-g".into(), format!("{:.2}", r.next())]),
            1 => a.extend(["-t".into(), format!("{:.2}", 1.5 + r.next() * 6.0)]),
            2 => a.extend(["-b".into(), format!("{:.1}", r.next() * 50.0)]),
            3 => a.extend(["-B".into(), format!("{:.1}", r.next() * 300.0)]),
            4 => a.extend(["-R".into(), format!("{:.1}", r.next() * 900.0)]),
            5 => a.extend(["-r".into(), format!("{:.4e}", r.next() * 1e7)]),
            _ => {
                if k % 12 != 0 {
                    // mostly 1960-2039; every fifth outside 1950-2050 (1600-2999), where
                    // Radiance's almanac day count leaves the Gregorian calendar
                    let y = if k % 5 == 0 {
                        1600 + (r.next() * 1400.0) as i32
                    } else {
                        1960 + (r.next() * 80.0) as i32
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
    let Some(o) = common::oracle() else { return };
    let mut bad = Vec::new();
    let cases = generated_cases();
    for a in &cases {
        let want = o.command("gensky").args(a).output().unwrap();
        let got = common::fenestra("gensky").args(a).output().unwrap();
        assert_eq!(want.status.success(), got.status.success(), "{a:?}");
        if tail(&want.stdout) != tail(&got.stdout) {
            bad.push((a.join(" "), tail(&want.stdout), tail(&got.stdout)));
        }
    }
    for b in &bad {
        eprintln!("{}\n--- oracle\n{}--- ours\n{}", b.0, b.1, b.2);
    }
    assert!(bad.is_empty(), "{} of {} differ", bad.len(), cases.len());
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
