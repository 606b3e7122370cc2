//! MGF input: fenestra's reader against the reference implementation's mgf2rad.

mod common;

use fenestra_scene::{load, parse_str, Primitive};

fn close(a: f64, b: f64) -> bool {
    // mgf2rad prints material reals with 6 decimals ("%f") and coordinates with 12
    // significant digits: compare to that printing.
    (a - b).abs() <= 1e-6 + 1e-9 * a.abs().max(b.abs())
}

fn same(ours: &[Primitive], theirs: &[Primitive]) -> Result<(), String> {
    if ours.len() != theirs.len() {
        return Err(format!(
            "{} primitives vs mgf2rad's {}",
            ours.len(),
            theirs.len()
        ));
    }
    for (o, t) in ours.iter().zip(theirs) {
        let what = format!(
            "{} {} {} (mgf2rad: {} {} {})",
            o.modifier_name, o.ptype, o.name, t.modifier_name, t.ptype, t.name
        );
        if o.ptype != t.ptype || o.name != t.name || o.modifier_name != t.modifier_name {
            return Err(format!("differs: {what}"));
        }
        if o.rargs.len() != t.rargs.len()
            || o.rargs.iter().zip(&t.rargs).any(|(a, b)| !close(*a, *b))
        {
            return Err(format!("{what}: reals {:?} vs {:?}", o.rargs, t.rargs));
        }
    }
    Ok(())
}

#[test]
fn oracle_mgf2rad_agrees() {
    let Some(oracle) = common::oracle() else {
        return;
    };
    for name in ["blinds_curved20.mgf", "materials.mgf"] {
        let dir = common::fixture("mgf");
        let out = oracle
            .command("mgf2rad")
            .arg(name)
            .current_dir(&dir)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let theirs = parse_str(&String::from_utf8_lossy(&out.stdout), "mgf2rad").unwrap();
        let path = dir.join(name);
        let ours = load(&[path.to_str().unwrap()]).unwrap();
        if let Err(e) = same(&ours.prims, &theirs.prims) {
            panic!("{name}: {e}");
        }
    }
}

#[test]
fn mgf_errors_name_file_and_line() {
    let dir = common::scratch("mgf_errors");
    let cases = [
        ("v a =\n\tp 0 0 0\nf a b c\n", ":3", "undefined vertex"),
        ("m x =\n\trd 2\n", ":2", "out of range"),
        ("xf -t 1 0 0\no\n", ":1", "not closed"),
        ("c\n\tcxy .3\n", ":2", "takes 2"),
        ("m g =\n\tir 1.5 0\n\tts .9 0\n\tsides 1\nv a =\n p 0 0 0\nv b =\n p 1 0 0\nv c =\n p 0 1 0\nf a b c\n", ":11", "dielectric"),
    ];
    for (k, (text, line, what)) in cases.iter().enumerate() {
        let f = dir.join(format!("bad{k}.mgf"));
        std::fs::write(&f, text).unwrap();
        let e = format!("{:#}", load(&[f.to_str().unwrap()]).unwrap_err());
        assert!(
            e.contains(&format!("bad{k}.mgf{line}")) && e.contains(what),
            "case {k}: {e}"
        );
    }
}

#[test]
fn oconv_reads_mgf() {
    let f = common::fixture("mgf").join("blinds_curved20.mgf");
    let out = common::fenestra("oconv").arg(&f).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stdout.starts_with(b"#?FENESTRA_SCENE"));
}
