//! errplot (the SVG charts of docs/accuracy.md) and benches/accuracy.sh --quick, which
//! draws them from a run of the whole pipeline.

mod common;

#[test]
fn errplot_draws_a_chart_and_refuses_bad_tables() {
    let dir = common::scratch("errplot");
    std::fs::write(
        dir.join("t.tsv"),
        "# knob\tx\ty\nD -c\t0.2\t5\nD -c\t0.8\t2.6\nV -ad\t0.05\t9\n\nV -ad\t0.1\t6\n",
    )
    .unwrap();
    let mut c = common::fenestra("errplot");
    c.args([
        "-t",
        "T",
        "-x",
        "wall time (s)",
        "-y",
        "error (%)",
        "-g",
        "D -c",
        "-H",
        "1.5",
        "limit",
        "-o",
        "c.svg",
        "t.tsv",
    ])
    .current_dir(&dir);
    common::run_ok(&mut c);
    let svg = std::fs::read_to_string(dir.join("c.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("wall time (s)") && svg.contains("error (%)"));
    assert_eq!(svg.matches("<polyline").count(), 2, "one line per series");
    assert!(svg.contains(">D -c<") && svg.contains(">V -ad<") && svg.contains(">limit<"));
    for (table, args, want) in [
        ("a\t1\n", &[][..], "t.tsv, line 1"),
        ("a\t1\tx\n", &[], "two numbers"),
        ("a\t1\t2\t3\n", &[], "three tab-separated"),
        ("a\t0\t2\n", &[], "log axes"),
        ("# nothing\n", &[], "no data lines"),
        ("a\t1\t2\n", &["-g", "b"], "no such series"),
    ] {
        std::fs::write(dir.join("t.tsv"), table).unwrap();
        let mut c = common::fenestra("errplot");
        c.args(args).arg("t.tsv").current_dir(&dir);
        common::cli::assert_refused(&c.output().unwrap(), want, table);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn accuracy_bench_runs_quick() {
    // benches/accuracy.sh --quick with the test build: every knob's rows, the four charts and
    // the generated block (numbers not checked: the quick reference is not converged).
    let dir = common::scratch("accuracy-quick");
    common::run_script(
        "benches/accuracy.sh",
        &["--quick".as_ref(), "--out".as_ref(), dir.as_os_str()],
        &[],
    );
    let tsv = std::fs::read_to_string(dir.join("curves.tsv")).unwrap();
    let rows: Vec<Vec<&str>> = tsv
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split('\t').collect())
        .collect();
    assert_eq!(rows.len(), 9, "{tsv}");
    for r in &rows {
        assert_eq!(r.len(), 8, "{r:?}");
        assert!(
            r[3..]
                .iter()
                .all(|v| v.parse::<f64>().is_ok_and(|x| x >= 0.0 && x.is_finite())),
            "{r:?}"
        );
    }
    for f in [
        "overcast.svg",
        "clear.svg",
        "udi.svg",
        "da300.svg",
        "method.svg",
    ] {
        let svg = std::fs::read_to_string(dir.join(f)).unwrap();
        assert!(
            svg.contains("wall time of") || svg.contains("sky patches"),
            "{f}"
        );
    }
    // the method table: MF 1 and 2 against the direct rtrace
    let method = std::fs::read_to_string(dir.join("method.tsv")).unwrap();
    let mfs: Vec<&str> = method
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| l.split('\t').next().unwrap())
        .collect();
    assert_eq!(mfs, ["1", "2"], "{method}");
    let gen = std::fs::read_to_string(dir.join("generated.md")).unwrap();
    assert!(
        gen.contains("| V-ab | 2 |") && gen.contains("direct rtrace"),
        "{gen}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
