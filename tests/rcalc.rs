//! rcalc from the command line, and differential tests against the oracle's rcalc:
//! lib/rayinit.cal function by function, the bin functions of lib/*.cal on the
//! reference directions, and a generated corpus of small programs.

mod common;

use std::path::Path;
use std::process::Command;

/// A run's (success, stdout, stderr).
type Run = (bool, String, String);

/// Runs a command with `input` on stdin (a program that fails early may close its input: the
/// broken pipe is ignored); returns (success, stdout, stderr).
fn run_with(cmd: Command, input: &[u8]) -> Run {
    let out = common::run_stdin(cmd, input);
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The oracle's rcalc and ours with `args` on `input`: (theirs, ours).
fn both(o: &common::Oracle, args: &[&str], input: &[u8]) -> (Run, Run) {
    let mut oc = o.command("rcalc");
    oc.args(args);
    (run_with(oc, input), run_with(ours(args), input))
}

/// The oracle's rcalc and ours with `-e prog` on `input`, asserting both succeed with the same
/// output; returns their error output (theirs, ours).
fn same_output(o: &common::Oracle, prog: &str, input: &[u8]) -> (String, String) {
    let ((ok_o, out_o, err_o), (ok_f, out_f, err_f)) = both(o, &["-e", prog], input);
    assert!(ok_o && ok_f, "{prog}: {err_f}");
    assert_eq!(out_f, out_o, "{prog}");
    (err_o, err_f)
}

/// Our rcalc with our lib/ on RAYPATH.
fn ours(args: &[&str]) -> Command {
    let mut c = common::fenestra("rcalc");
    c.env("RAYPATH", format!(".:{}", lib().display()));
    c.args(args);
    c
}

fn lib() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("lib")
}

/// All combinations of `n` values from `grid`, one record per line.
fn grid_records(grid: &[f64], n: usize) -> String {
    let mut idx = vec![0usize; n];
    let mut s = String::new();
    loop {
        let rec: Vec<String> = idx.iter().map(|&i| format!("{}", grid[i])).collect();
        s.push_str(&rec.join(" "));
        s.push('\n');
        let mut k = 0;
        loop {
            if k == n {
                return s;
            }
            idx[k] += 1;
            if idx[k] < grid.len() {
                break;
            }
            idx[k] = 0;
            k += 1;
        }
    }
}

/// Why exact: rcalc prints with a fixed number of significant digits and both
/// sides evaluate the same arithmetic in double precision; the definitions in
/// our lib/rayinit.cal follow the same operation order as Radiance's.
#[test]
fn oracle_rayinit_functions() {
    let Some(o) = common::oracle() else { return };
    let wide = [-2.5, -1.0, -0.3, 0.0, 0.25, 0.5, 1.0, 1.7, 3.0, 20.0];
    let narrow = [-1.0, 0.0, 0.3, 1.0, 2.5];
    let unit = [0.001, 0.1, 0.3, 0.5, 0.5001, 0.7, 0.95, 0.999];
    // (expression over $1..$n, arity, grid)
    let cases: &[(&str, usize, &[f64])] = &[
        ("bound($1,$2,$3)", 3, &wide),
        ("Acos($1)", 1, &wide),
        ("Asin($1)", 1, &wide),
        ("Atan2($1,$2)", 2, &wide),
        ("Exp($1*50)", 1, &wide),
        ("Sqrt($1)", 1, &wide),
        ("and($1,$2)", 2, &wide),
        ("or($1,$2)", 2, &wide),
        ("not($1)", 1, &wide),
        ("xor($1,$2)", 2, &wide),
        ("abs($1)", 1, &wide),
        ("sgn($1)", 1, &wide),
        ("sq($1)", 1, &wide),
        ("inside($1,$2,$3)", 3, &wide),
        ("frac($1)", 1, &wide),
        ("mod($1,$2)", 2, &wide),
        ("tri($1,$2)", 2, &wide),
        ("linterp($1,$2,$3)", 3, &wide),
        ("noop($1)", 1, &wide),
        ("clip($1)", 1, &wide),
        ("noneg($1)", 1, &wide),
        ("red($1,$2,$3)", 3, &narrow),
        ("green($1,$2,$3)", 3, &narrow),
        ("blue($1,$2,$3)", 3, &narrow),
        ("grey($1,$2,$3)", 3, &wide),
        ("clip_r($1,$2,$3)", 3, &narrow),
        ("clip_g($1,$2,$3)", 3, &narrow),
        ("clip_b($1,$2,$3)", 3, &narrow),
        ("clipgrey($1,$2,$3)", 3, &wide),
        ("fade($1,$2,$3*8)", 3, &wide),
        ("hermite($1,$2,$3,$4,$5)", 5, &narrow),
        ("bezier($1,$2,$3,$4,$5)", 5, &narrow),
        ("bspline($1,$2,$3,$4,$5)", 5, &narrow),
        ("unif2norm($1)", 1, &unit),
        ("nrand($1)", 1, &wide),
        ("dot(va,vb)", 3, &narrow),
        ("cross(1,va,vb)", 3, &narrow),
        ("cross(2,va,vb)", 3, &narrow),
        ("cross(3,va,vb)", 3, &narrow),
        ("PI+$1", 1, &narrow),
        ("DEGREE*$1", 1, &narrow),
        ("FTINY*$1", 1, &narrow),
    ];
    let vecs = "va(i)=select(i,$1,$2,$3);vb(i)=select(i,$3,-$1,$2*2);";
    for (expr, n, grid) in cases {
        let input = grid_records(grid, *n);
        let prog = format!("{vecs}$1={expr}");
        let args = ["-f", "rayinit.cal", "-e", &prog];
        let ((ook, oout, oerr), (fok, fout, ferr)) = both(&o, &args, input.as_bytes());
        assert_eq!(
            ook, fok,
            "{expr}: exit status differs\noracle: {oerr}\nours: {ferr}"
        );
        assert_eq!(
            oout.lines().count(),
            input.lines().count(),
            "{expr}: oracle stopped early: {oerr}"
        );
        for ((i, a), b) in input.lines().zip(oout.lines()).zip(fout.lines()) {
            assert_eq!(a, b, "{expr} on record '{i}'");
        }
        assert_eq!(oout, fout, "{expr}");
    }
}

/// Names that need a renderer (host variables, arg(), noise) fail under both rcalcs.
#[test]
fn oracle_rayinit_renderer_names_fail_in_rcalc() {
    let Some(o) = common::oracle() else { return };
    for expr in [
        "U",
        "V",
        "A1",
        "AC",
        "D(1)",
        "Idx",
        "noise3a(1,2,3)",
        "turbulence(1,2,3,.3)",
    ] {
        let prog = format!("$1={expr}");
        let args = ["-n", "-f", "rayinit.cal", "-e", &prog];
        let ((ook, _, _), (fok, _, ferr)) = both(&o, &args, b"");
        assert!(!ook, "oracle accepted {expr}");
        assert!(!fok, "we accepted {expr}");
        assert!(ferr.contains("rayinit.cal"), "{expr}: {ferr}");
    }
}

/// Reads a bins table: a header line, then tab-separated columns.
fn table(path: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split('\t').map(str::to_string).collect())
        .collect()
}

/// Directions (columns `dx..dx+3`) as rcalc input, with six slightly turned copies of
/// each (for rows exactly on a boundary, where the neighbouring bin is also accepted).
fn dirs_input(rows: &[Vec<String>], dx: usize) -> String {
    let mut s = String::new();
    for r in rows {
        let d: Vec<f64> = (0..3).map(|k| r[dx + k].parse().unwrap()).collect();
        s.push_str(&format!("{} {} {}\n", r[dx], r[dx + 1], r[dx + 2]));
        for k in 0..6 {
            let mut e = d.clone();
            e[k / 2] += if k % 2 == 0 { 1e-9 } else { -1e-9 };
            let n = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
            s.push_str(&format!(
                "{:.17e} {:.17e} {:.17e}\n",
                e[0] / n,
                e[1] / n,
                e[2] / n
            ));
        }
    }
    s
}

/// Compares one output column of ours (7 lines per row: the direction then its nudged
/// copies) with the oracle's column; boundary kinds (3, 6) accept a nudged answer.
fn compare_bins(
    what: &str,
    rows: &[Vec<String>],
    kind_col: usize,
    want_col: usize,
    ours: &[Vec<String>],
    col: usize,
) -> usize {
    let mut boundary_neighbours = 0;
    for (i, r) in rows.iter().enumerate() {
        let want = &r[want_col];
        let got = &ours[7 * i][col];
        if got == want {
            continue;
        }
        let kind = r[kind_col].as_str();
        let near = (1..7).any(|k| &ours[7 * i + k][col] == want);
        assert!(
            (kind == "3" || kind == "6") && near,
            "{what}: row {i} ({} {} {}, kind {kind}): ours {got}, oracle {want}",
            r[kind_col - 3],
            r[kind_col - 2],
            r[kind_col - 1]
        );
        boundary_neighbours += 1;
    }
    boundary_neighbours
}

fn run_ours(args: &[&str], input: &str) -> Vec<Vec<String>> {
    let (ok, out, err) = run_with(ours(args), input.as_bytes());
    assert!(ok, "rcalc {args:?}: {err}");
    out.lines()
        .map(|l| l.split('\t').map(str::to_string).collect())
        .collect()
}

/// lib/klems_*.cal against the oracle's bins (the `_lib` columns, computed by the
/// oracle's rcalc with the .cal files shipped with it). Exact, except on rows lying
/// exactly on a boundary (kinds 3 and 6) where the neighbouring bin is accepted.
#[test]
fn klems_bins_match_oracle_tables() {
    for (file, f, cal) in [
        ("klems_full_bins.tsv", "kbin", "klems_full.cal"),
        ("klems_half_bins.tsv", "khbin", "klems_half.cal"),
        ("klems_quarter_bins.tsv", "kqbin", "klems_quarter.cal"),
    ] {
        let rows = table(&common::fixture(&format!("klems/{file}")));
        let input = dirs_input(&rows, 1);
        let prog = format!(
            "Dx=$1;Dy=$2;Dz=$3;$1={f}(0,0,1,0,1,0);$2={f}(0,0,-1,0,1,0);$3={f}(0,1,0,0,0,1);$4={f}(-1,0,0,0,0,1);$5={f}(0.6,0,0.8,0.1,1,0.3)"
        );
        let rh = run_ours(&["-f", cal, "-e", &prog], &input);
        let lh = run_ours(
            &[
                "-f",
                cal,
                "-e",
                "RHS=-1",
                "-e",
                &format!("Dx=$1;Dy=$2;Dz=$3;$1={f}(0,0,1,0,1,0)"),
            ],
            &input,
        );
        assert_eq!(rh.len(), 7 * rows.len());
        let mut near = 0;
        for (k, name) in ["front", "back", "south", "east", "tilt"]
            .iter()
            .enumerate()
        {
            near += compare_bins(&format!("{cal} {name}"), &rows, 4, 5 + k, &rh, k);
        }
        near += compare_bins(&format!("{cal} frontLH"), &rows, 4, 10, &lh, 0);
        eprintln!(
            "{cal}: {} rows x 6 frames, {near} boundary rows took the neighbouring bin",
            rows.len()
        );
    }
}

/// lib/reinhart.cal against the oracle's `rbin`/`Nrbins` for MF 1, 2, 4 (same tolerance rule).
#[test]
fn reinhart_bins_match_oracle_tables() {
    for mf in [1, 2, 4] {
        let rows = table(&common::fixture(&format!("rcalc/reinhart{mf}_rbin.tsv")));
        let input = dirs_input(&rows, 0);
        let out = run_ours(
            &[
                "-e",
                &format!("MF:{mf}"),
                "-f",
                "reinhart.cal",
                "-e",
                "Dx=$1;Dy=$2;Dz=$3;$1=rbin;$2=Nrbins",
            ],
            &input,
        );
        let near = compare_bins(&format!("reinhart MF {mf}"), &rows, 3, 4, &out, 0);
        compare_bins(&format!("Nrbins MF {mf}"), &rows, 3, 5, &out, 1);
        eprintln!(
            "reinhart MF {mf}: {} rows, {near} boundary rows took the neighbouring bin",
            rows.len()
        );
    }
}

/// lib/tregenza.cal against the oracle's tregenza.cal, run live on the same directions.
#[test]
fn oracle_tregenza_bins() {
    let Some(o) = common::oracle() else { return };
    let rows = table(&common::fixture("rcalc/reinhart1_rbin.tsv"));
    let input: String = rows
        .iter()
        .map(|r| format!("{} {} {}\n", r[0], r[1], r[2]))
        .collect();
    let args = [
        "-f",
        "tregenza.cal",
        "-e",
        "Dx=$1;Dy=$2;Dz=$3;$1=tbin;$2=Ntbins",
    ];
    let ((ook, oout, oerr), (fok, fout, ferr)) = both(&o, &args, input.as_bytes());
    assert!(ook, "{oerr}");
    assert!(fok, "{ferr}");
    let mut differ = 0;
    for ((r, a), b) in rows.iter().zip(oout.lines()).zip(fout.lines()) {
        if a != b {
            assert!(
                r[3] == "3" || r[3] == "6",
                "tbin on {r:?}: oracle {a}, ours {b}"
            );
            differ += 1;
        }
    }
    assert_eq!(oout.lines().count(), fout.lines().count());
    eprintln!(
        "tregenza: {} rows, {differ} boundary rows differ",
        rows.len()
    );
}

/// A small deterministic generator (xorshift64*).
struct Gen(u64);

impl Gen {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn pick<'a>(&mut self, v: &[&'a str]) -> &'a str {
        v[self.below(v.len())]
    }
}

/// A numeric literal in one of the forms the language accepts.
fn literal(g: &mut Gen) -> String {
    let d = g.below(100);
    let f = g.below(1000);
    match g.below(9) {
        0 => format!("{d}"),
        1 => format!("{d}."),
        2 => format!(".{f}"),
        3 => format!("{d}.{f}"),
        4 => format!("{d}e{}", g.below(5)),
        5 => format!("{d}.{f}E-{}", g.below(4)),
        6 => format!(".{f}e+{}", g.below(3)),
        7 => format!("{d}.{f}e-{}", 1 + g.below(6)),
        _ => g
            .pick(&["0", "1", "2", "10", "0.5", "1e-7", "3.5e2"])
            .to_string(),
    }
}

/// A random expression; `names` are the variables and parameters in scope.
fn expr(g: &mut Gen, depth: u32, names: &[&str], funcs: &[(&str, usize)]) -> String {
    if depth == 0 || g.below(10) < 3 {
        return match g.below(4) {
            0 | 1 => literal(g),
            2 if !names.contains(&"NOCHAN") => format!("${}", 1 + g.below(3)),
            _ if names.iter().any(|n| *n != "NOCHAN") => loop {
                let n = g.pick(names);
                if n != "NOCHAN" {
                    break n.to_string();
                }
            },
            _ => literal(g),
        };
    }
    let sub = |g: &mut Gen| expr(g, depth - 1, names, funcs);
    match g.below(14) {
        0..=4 => {
            let op = g.pick(&["+", "-", "*", "/", "^", "+", "-", "*"]);
            let (a, b) = (sub(g), sub(g));
            if op == "^" {
                // keep powers moderate: small exponent
                format!("{a}^{}", g.pick(&["2", "3", "-1", "(-2)", "1"]))
            } else if g.below(3) == 0 {
                format!("({a}){op}({b})")
            } else {
                format!("{a}{op}{b}")
            }
        }
        5 => format!("-{}", sub(g)),
        6 => format!("if({}, {}, {})", sub(g), sub(g), sub(g)),
        7 => {
            let n = 1 + g.below(3);
            let args: Vec<String> = (0..n).map(|_| sub(g)).collect();
            let idx = g
                .pick(&["0", "1", "2", "3", "1.4", "2.6", "4", "-1"])
                .to_string();
            let idx = if g.below(3) == 0 { sub(g) } else { idx };
            format!("select({idx}, {})", args.join(", "))
        }
        8 | 9 => {
            // arguments kept inside each function's domain: NaN propagation through
            // max/min differs (see docs/tools/rcalc.md), the fixed programs probe it
            let x = sub(g);
            match g.pick(&[
                "sqrt", "sin", "cos", "tan", "asin", "acos", "atan", "exp", "log", "log10",
                "floor", "ceil", "rand",
            ]) {
                "sqrt" => format!("sqrt(({x})*({x}))"),
                "asin" => format!("asin(sin({x}))"),
                "acos" => format!("acos(cos({x}))"),
                "exp" => format!("exp(sin({x}))"),
                "log" => format!("log(({x})*({x})+1)"),
                "log10" => format!("log10(({x})*({x})+.5)"),
                f => format!("{f}({x})"),
            }
        }
        10 => {
            let f = g.pick(&["atan2", "max", "min"]);
            format!("{f}({}, {})", sub(g), sub(g))
        }
        11 => format!("max({}, {}, {})", sub(g), sub(g), sub(g)),
        _ if !funcs.is_empty() => {
            let (f, n) = funcs[g.below(funcs.len())];
            let args: Vec<String> = (0..n).map(|_| sub(g)).collect();
            format!("{f}({})", args.join(", "))
        }
        _ => format!("({})", sub(g)),
    }
}

/// One generated program: constants, a variable, functions with parameters, outputs.
fn program(g: &mut Gen) -> String {
    let mut s = String::new();
    // constants (`:`) use no input columns ("NOCHAN"): Radiance evaluates them when read
    s.push_str(&format!("k1 : {};\n", expr(g, 2, &["NOCHAN"], &[])));
    s.push_str(&format!("k2 : {};\n", expr(g, 2, &["k1", "NOCHAN"], &[])));
    s.push_str(&format!("v1 = {};\n", expr(g, 3, &["k1", "k2"], &[])));
    s.push_str(&format!("f1(a) = {};\n", expr(g, 3, &["a", "k1"], &[])));
    s.push_str(&format!(
        "f2(a, b) = {};\n",
        expr(g, 3, &["a", "b", "v1"], &[("f1", 1)])
    ));
    let funcs = [("f1", 1), ("f2", 2)];
    let names = ["k1", "k2", "v1"];
    for c in 1..=3 {
        s.push_str(&format!("${c} = {};\n", expr(g, 4, &names, &funcs)));
    }
    s
}

/// Why exact: both rcalcs print 9 significant digits (or inf/nan) of the same
/// double-precision arithmetic; programs that fail must fail under both.
/// Every program must give the oracle's output (a NaN on one side only is a difference).
#[test]
fn oracle_generated_corpus() {
    let Some(o) = common::oracle() else { return };
    let mut g = Gen(0x9e37_79b9_7f4a_7c15);
    let input = "0.5 2 -3\n0 1e-3 7.25\n-1.5 0 100\n3 -0.25 0.125\n";
    let fixed = [
        "$1 = -2^2; $2 = 2^-1; $3 = -2^-2",
        "$1 = 2^3^2; $2 = 1-2-3; $3 = 2/4/8",
        "$1 = 1/0; $2 = floor(1/0 + 1); $3 = if(1/0, 1, 2)",
        "$1 = select(0, 5, 6, 7); $2 = select(3.49, 5, 6, 7); $3 = select(9, 1, 2) + 1",
        "$1 = 1e308*10; $2 = -1e308*10; $3 = 0*(1e308*10)",
        "$1 = exp(710); $2 = log(0); $3 = sqrt(-1)",
        "$1 = 10^400; $2 = (-8)^(1/3); $3 = 0^0",
        "$1 = rand($1); $2 = rand(-$2); $3 = rand(1e10)",
        "f(n) = if(n, n*f(n-1), 1); $1 = f(5); $2 = f(10); $3 = f(0)",
        "$1 = .5e1 + 5.e-1 + 5E0; $2 = 007; $3 = 1.e+2",
        "c : 3; d = c*$1; $1 = d; $2 = c; $3 = -c^2",
        "g(x) = x*x; h(f, x) = f(x) + 1; $1 = h(g, 3); $2 = h(sin, 0); $3 = h(g, $1)",
        "$1 = max($1, $2, $3); $2 = min($1, $2, $3); $3 = atan2($2, $1)",
        "$1 = acos(2); $2 = asin(-1.5); $3 = floor(-0.5) + ceil(-0.5)",
        "$1 = -$1 - 0; $2 = -$2 + -$2; $3 = $3/10 - $3*0.1",
    ];
    let mut progs: Vec<String> = fixed.iter().map(|s| s.to_string()).collect();
    while progs.len() < 330 {
        progs.push(program(&mut g));
    }
    let (mut same, mut both_fail, mut nan_differ, mut differ) = (0, 0, 0, Vec::new());
    for p in &progs {
        let ((ook, oout, oerr), (fok, fout, ferr)) = both(&o, &["-e", p], input.as_bytes());
        if !ook || !fok {
            assert_eq!(
                ook, fok,
                "exit status differs for\n{p}\noracle: {oerr}\nours: {ferr}"
            );
            both_fail += 1;
            continue;
        }
        if oout == fout {
            same += 1;
        } else if oout.contains("nan") || fout.contains("nan") {
            nan_differ += 1;
            eprintln!("--- differs where a NaN is involved:\n{p}\noracle:\n{oout}ours:\n{fout}");
        } else {
            differ.push(format!("{p}\noracle:\n{oout}ours:\n{fout}"));
        }
    }
    eprintln!(
        "corpus: {} programs, {same} identical output, {both_fail} fail under both, \
         {nan_differ} differ where a NaN is involved, {} differ otherwise",
        progs.len(),
        differ.len()
    );
    for d in &differ {
        eprintln!("--- differs:\n{d}");
    }
    assert!(
        differ.is_empty() && nan_differ == 0,
        "{} programs differ from the oracle",
        differ.len() + nan_differ
    );
}

/// Blocks of records evaluated on several threads give the output of one thread, in
/// the same order, with the same warnings and the same stop at an error, and so does
/// `-u` (records read and written one by one) (the input is
/// about 12 blocks of 256 KB, with warnings, `cond`, blank lines and a line without
/// its newline at the end).
#[test]
fn threads_give_the_output_of_one_thread() {
    let mut g = Gen(99);
    let mut input = String::new();
    for i in 0..150_000 {
        let n = g.below(5);
        for k in 0..n {
            let v = (g.below(20001) as f64 - 10000.0) / 3000.0;
            input += &format!("{}{v:.*}", if k > 0 { " " } else { "" }, g.below(9));
        }
        if i < 149_999 {
            input.push('\n');
        }
    }
    let progs: [&[&str]; 4] = [
        &[
            "-f",
            "reinhart.cal",
            "-e",
            "MF:2;Dx=$1;Dy=$2;Dz=$3;$1=rbin;$2=1/$1;$3=in(0)",
        ],
        &["-e", "$1=select($1,1,2);$2=$2;cond=$3+1"],
        &["-e", "$1=$1*$2+$3;$3=sqrt($2)", "-od"],
        // stops with an error at the first record whose $1 exceeds 3.3333 (after
        // about a third of the input)
        &["-e", "$1=if($1-3.3333, f(1), $1)"],
    ];
    for args in progs {
        let one = run_with(
            {
                let mut c = ours(args);
                c.env("FENESTRA_RCALC_THREADS", "1");
                c
            },
            input.as_bytes(),
        );
        let three = run_with(
            {
                let mut c = ours(args);
                c.env("FENESTRA_RCALC_THREADS", "3");
                c
            },
            input.as_bytes(),
        );
        // -u: record by record, the output flushed after each
        let flushed = run_with(
            {
                let mut c = ours(&[&["-u"], args].concat());
                c.env("FENESTRA_RCALC_THREADS", "1");
                c
            },
            input.as_bytes(),
        );
        assert!(
            one.1.len() > 100_000,
            "{args:?}: {} bytes of output",
            one.1.len()
        );
        assert_eq!(one.0, flushed.0, "{args:?}: exit status with -u");
        assert!(one.1 == flushed.1, "{args:?}: outputs differ with -u");
        assert_eq!(one.2, flushed.2, "{args:?}: messages differ with -u");
        assert_eq!(one.0, !args[1].contains("f(1)"), "{args:?}: exit status");
        assert_eq!(one.0, three.0, "{args:?}: exit status");
        assert!(one.1 == three.1, "{args:?}: outputs differ");
        assert_eq!(one.2, three.2, "{args:?}: messages differ");
    }
}

/// A read error (here a failing input command) stops rcalc after the records read
/// before it, with the same output on one thread, several threads and with `-u`.
#[test]
fn read_error_after_the_records_before_it() {
    for (threads, u) in [("1", false), ("3", false), ("1", true)] {
        let mut args = vec!["-e", "$1=$1*2"];
        if u {
            args.push("-u");
        }
        args.push("!printf '1\\n2\\n3\\n'; exit 3");
        let mut c = ours(&args);
        c.env("FENESTRA_RCALC_THREADS", threads);
        let (ok, out, err) = run_with(c, b"");
        assert!(!ok, "threads {threads}, -u {u}: exit status");
        assert_eq!(out, "2\n4\n6\n", "threads {threads}, -u {u}");
        assert!(
            err.contains("exit status: 3"),
            "threads {threads}, -u {u}: {err}"
        );
    }
}

/// Input words as C's `atof` reads them: signed zeros, hexadecimal with fraction and binary
/// exponent, numeric prefixes, `nan`, `inf`; the same output as the oracle's rcalc.
#[test]
fn oracle_input_words_read_as_c_atof() {
    let Some(o) = common::oracle() else { return };
    let input = b"-0\n0\n0x10\n-0x1.8p1\n0X1P-2\n0x\n1e3x\n-.5e1\nnan\n-inf\nabc\n";
    for e in ["$1=$1", "$1=-$1;$2=$1*2"] {
        same_output(&o, e, input);
    }
}

/// Zeros as Radiance's calcomp treats them: a literal or `:` constant zero times, over or to
/// the power of anything is that zero without evaluating the rest (`0*x`, `x*0`, `0/x`,
/// `0^x`, also inside function bodies); a division by zero at run time gives the signed zero
/// divisor with a warning. Each program of tests/fixtures/rcalc/zero_rules.txt on records with
/// signed zeros, infinities and NaN: the oracle's output and number of warnings.
#[test]
fn oracle_zero_rules() {
    let Some(o) = common::oracle() else { return };
    let progs = std::fs::read_to_string(common::fixture("rcalc/zero_rules.txt")).unwrap();
    let input = b"-0 inf\n0 nan\n-3 -0\n";
    let warnings = |err: &str| err.matches("Division by zero").count();
    let mut n = 0;
    for e in progs.lines().filter(|l| !l.trim().is_empty()) {
        let (err_o, err_f) = same_output(&o, e, input);
        assert_eq!(
            warnings(&err_f),
            warnings(&err_o),
            "{e}: {err_f} vs {err_o}"
        );
        n += 1;
    }
    assert_eq!(n, 28);
}

/// The oracle's rcalc reads our lib bin files (klems_full/half/quarter.cal, reinhart.cal)
/// and gives the bins our rcalc gives with them, on every direction of the bin tables and
/// their nudged copies: the files use only language the oracle evaluates the same way.
#[test]
fn oracle_rcalc_runs_our_bin_files() {
    let Some(o) = common::oracle() else { return };
    let mut cases = Vec::new();
    for (file, f, table_name) in [
        ("klems_full.cal", "kbin", "klems/klems_full_bins.tsv"),
        ("klems_half.cal", "khbin", "klems/klems_half_bins.tsv"),
        ("klems_quarter.cal", "kqbin", "klems/klems_quarter_bins.tsv"),
    ] {
        let prog = format!(
            "Dx=$1;Dy=$2;Dz=$3;$1={f}(0,0,1,0,1,0);$2={f}(0,0,-1,0,1,0);$3={f}(0,1,0,0,0,1);$4={f}(-1,0,0,0,0,1);$5={f}(0.6,0,0.8,0.1,1,0.3)"
        );
        cases.push((table_name.to_string(), 1, String::new(), file, prog));
        let lh = format!("Dx=$1;Dy=$2;Dz=$3;$1={f}(0,0,1,0,1,0)");
        cases.push((table_name.to_string(), 1, "RHS=-1".to_string(), file, lh));
    }
    for mf in [1, 2, 4] {
        cases.push((
            format!("rcalc/reinhart{mf}_rbin.tsv"),
            0,
            format!("MF:{mf}"),
            "reinhart.cal",
            "Dx=$1;Dy=$2;Dz=$3;$1=rbin;$2=Nrbins".to_string(),
        ));
    }
    for (table_name, dx, pre, file, prog) in &cases {
        let rows = table(&common::fixture(table_name));
        let input = dirs_input(&rows, *dx);
        let path = lib().join(file);
        let path = path.to_str().unwrap();
        let mut args = Vec::new();
        if !pre.is_empty() {
            args.extend(["-e", pre.as_str()]);
        }
        args.extend(["-f", path, "-e", prog.as_str()]);
        let ((ook, oout, oerr), (fok, fout, ferr)) = both(&o, &args, input.as_bytes());
        assert!(ook, "{oerr}");
        assert!(fok, "{ferr}");
        assert_eq!(oout.lines().count(), 7 * rows.len(), "{file} {pre}");
        assert_eq!(
            fout.lines().count(),
            7 * rows.len(),
            "{file} {pre}: fenestra"
        );
        for (i, (a, b)) in oout.lines().zip(fout.lines()).enumerate() {
            assert_eq!(a, b, "{file} {pre}: input line {i}");
        }
        eprintln!("{file} {pre}: {} lines agree", 7 * rows.len());
    }
}
