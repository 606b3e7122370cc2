//! Language semantics through the public host interface.

use std::sync::Arc;

use fenestra_calc::{ErrorKind, Program};

fn val(src: &str, var: &str) -> Result<f64, fenestra_calc::CalcError> {
    let mut p = Program::for_rcalc();
    p.load_str("-e", src)?;
    let c = p.compile()?;
    let v = c.var(var).expect("variable");
    let mut st = c.state();
    c.eval_var(&mut st, v)
}

#[test]
fn precedence_matches_radiance() {
    assert_eq!(val("x = -2^2", "x").unwrap(), 4.0);
    assert_eq!(val("x = -(2^2)", "x").unwrap(), -4.0);
    assert_eq!(val("x = 2^3^2", "x").unwrap(), 512.0);
    assert_eq!(val("x = 2^-2", "x").unwrap(), 0.25);
    assert_eq!(val("x = 2*-3", "x").unwrap(), -6.0);
    assert_eq!(val("x = 1 - 2 - 3", "x").unwrap(), -4.0);
    assert_eq!(val("x = 8/4/2", "x").unwrap(), 1.0);
}

#[test]
fn builtins_and_redefinition() {
    assert_eq!(val("x = if(0, 1, 2)", "x").unwrap(), 2.0);
    assert_eq!(val("x = select(0.4, 1, 2)", "x").unwrap(), 2.0);
    assert_eq!(val("x = select(1.5, 7, 8)", "x").unwrap(), 8.0);
    // literal expressions that fail are refused when read, as Radiance's parser does
    assert_eq!(
        val("x = select(3, 7, 8)", "x").unwrap_err().kind,
        ErrorKind::Syntax
    );
    assert_eq!(val("x = 1/0", "x").unwrap_err().kind, ErrorKind::Syntax);
    assert_eq!(val("y = 3; x = select(y, 7, 8)", "x").unwrap(), 0.0);
    assert_eq!(
        val("y : 3; x = select(y, 7, 8)", "x").unwrap_err().kind,
        ErrorKind::Syntax
    );
    assert_eq!(val("y = 0; x = 1/y", "x").unwrap(), 0.0);
    assert_eq!(val("x : 1; x = 2", "x").unwrap(), 2.0);
    assert_eq!(val("x = max(1, 5, 3) + min(4, -2)", "x").unwrap(), 3.0);
    // `/2e-7` is evaluated as `* (1/2e-7)`, as Radiance's parser rewrites it: within 1 ulp.
    let d = val("d1(f,x) = (f(x+1e-7)-f(x-1e-7))/2e-7; x = d1(sin, 0)", "x").unwrap();
    assert!((d - (1e-7f64).sin() / 1e-7).abs() < 3e-16, "{d}");
}

#[test]
fn errors_name_the_place() {
    let e = val("a = 1;\nx = a + b", "x").unwrap_err();
    assert_eq!(e.kind, ErrorKind::UndefinedVariable);
    let l = e.location.unwrap();
    assert_eq!((l.line, l.column), (2, 9));
    assert_eq!(l.text, "x = a + b");
    let e = val("f(a,b) = a+b; x = f(1)", "x").unwrap_err();
    assert_eq!(e.kind, ErrorKind::TooFewArguments);
    let e = val("x = g(1)", "x").unwrap_err();
    assert_eq!(e.kind, ErrorKind::UndefinedFunction);
    let e = Program::new().load_str("f.cal", "x = (1").unwrap_err();
    assert_eq!(e.kind, ErrorKind::Syntax);
    assert!(e.to_string().starts_with("f.cal, line 1, column 7"), "{e}");
    // an undefined name in a branch not taken is not an error
    assert_eq!(val("x = if(1, 3, nothing)", "x").unwrap(), 3.0);
}

#[test]
fn runaway_recursion_is_an_error_not_a_crash() {
    let e = std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(|| val("f(n) = f(n+1); x = f(0)", "x").unwrap_err())
        .unwrap()
        .join()
        .unwrap();
    assert_eq!(e.kind, ErrorKind::Recursion);
    assert_eq!(
        val("fact(n) = if(n, n*fact(n-1), 1); x = fact(10)", "x").unwrap(),
        3628800.0
    );
}

#[test]
fn host_variables_functions_and_channels() {
    let mut p = Program::new();
    p.load_str("-e", "r = sqrt(Dx*Dx + Dy*Dy) + twice($2)")
        .unwrap();
    let d = p.bind_vars(&["Dx", "Dy"]);
    p.define_host_fn("twice", 1, Arc::new(|a: &[f64]| 2.0 * a[0]));
    let e = p.add_expr("-b", "r*10").unwrap();
    let c = p.compile().unwrap();
    let r = c.var("r").unwrap();
    let mut st = c.state();
    st.set_chans(&[0.0, 0.5]);
    st.set_all(&d, &[3.0, 4.0]);
    assert_eq!(c.eval_var(&mut st, r).unwrap(), 6.0);
    st.set(d[0], 0.0);
    assert_eq!(c.eval_var(&mut st, r).unwrap(), 5.0);
    assert_eq!(c.eval_expr(&mut st, e).unwrap(), 50.0);
}

#[test]
fn warnings_are_counted() {
    let mut p = Program::new();
    p.set_parse_constants(false);
    p.load_str("-e", "x = 1/0 + select(9, 1)").unwrap();
    let c = p.compile().unwrap();
    let mut st = c.state();
    c.eval_var(&mut st, c.var("x").unwrap()).unwrap();
    let w = st.take_warnings();
    assert_eq!((w.division_by_zero, w.select_domain), (1, 1));
}
