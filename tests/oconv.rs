//! oconv: compiled scenes round-trip, are accepted wherever scene files are, Radiance's
//! octrees (frozen or not) are read, and every malformed scene in a small corpus gives one
//! clear error with file and line, no panic and no output.

mod common;

use std::process::Command;

fn mkillum_files() -> Vec<String> {
    ["materials", "room", "sky", "window_glass"]
        .iter()
        .map(|f| {
            common::fixture(&format!("scene/mkillum/{f}.rad"))
                .display()
                .to_string()
        })
        .collect()
}

#[test]
fn compiled_scene_round_trips() {
    let files = mkillum_files();
    let d = common::scratch("oconv-rt");
    let oct = d.join("scene.oct");
    let bytes = common::run_ok(common::fenestra("oconv").args(&files));
    std::fs::write(&oct, &bytes).unwrap();
    let head = String::from_utf8_lossy(&bytes[..200.min(bytes.len())]).into_owned();
    assert!(
        head.starts_with("#?FENESTRA_SCENE\nFORMAT=fenestra_scene\nVERSION=1\n"),
        "{head}"
    );
    common::cli::assert_contains(&head, &["INPUT=", "room.rad"]);
    let refs: Vec<&str> = files.iter().map(String::as_str).collect();
    let direct = fenestra_scene::load(&refs).unwrap();
    let c = fenestra_scene::compiled::read_file(oct.to_str().unwrap()).unwrap();
    assert_eq!(c.scene, direct);
    assert_eq!(c.inputs, files);
    // A compiled scene is accepted wherever scene files are, also mixed with .rad files.
    let again = fenestra_scene::load(&[oct.to_str().unwrap()]).unwrap();
    assert_eq!(again, direct);
    // oconv -i extends a compiled scene.
    let ext = common::run_ok(
        common::fenestra("oconv")
            .arg("-i")
            .arg(&oct)
            .arg(common::fixture("scene/mkillum/exterior.rad")),
    );
    std::fs::write(d.join("ext.oct"), &ext).unwrap();
    let c2 = fenestra_scene::compiled::read_file(d.join("ext.oct").to_str().unwrap()).unwrap();
    assert!(c2.scene.prims.len() > direct.prims.len());
    assert_eq!(&c2.scene.prims[..direct.prims.len()], &direct.prims[..]);
}

#[test]
fn a_damaged_radiance_octree_is_reported() {
    // a header and a magic number, then the data stop: "truncated octree", naming the file
    let f = common::cli::scratch_file(
        "oconv-radoct",
        "rad.oct",
        b"#?RADIANCE\noconv room.rad\nFORMAT=Radiance_octree\n\n\x01\x1f-1.5\0",
    );
    let e = fenestra_scene::load(&[f.to_str().unwrap()]).unwrap_err();
    let msg = format!("{e:#}");
    assert!(
        msg.contains("truncated octree") && msg.contains("rad.oct"),
        "{msg}"
    );
}

#[test]
fn oracle_octrees_are_read() {
    // Radiance's oconv, frozen (-f: the objects are in the octree, reals at 31-bit
    // precision) and plain (it lists the files, read again from the current folder): our
    // scene from each has the .rad files' primitives (frozen: reals within 1e-8 relative),
    // and rtrace gives the bytes it gives on the .rad files (-ab 1 on 3 points; the rounding
    // of the reals does not reach the printed digits here).
    let Some(o) = common::oracle() else { return };
    let d = common::scratch("oconv-oracle");
    let files = mkillum_files();
    let refs: Vec<&str> = files.iter().map(String::as_str).collect();
    let direct = fenestra_scene::load(&refs).unwrap();
    let mut outs = Vec::new();
    for (name, frozen) in [("frozen.oct", true), ("plain.oct", false)] {
        let mut c = o.command("oconv");
        if frozen {
            c.arg("-f");
        }
        let oct = common::run_ok(c.args(&files));
        let f = d.join(name);
        std::fs::write(&f, oct).unwrap();
        let scene = fenestra_scene::load(&[f.to_str().unwrap()]).unwrap();
        assert_eq!(scene.prims.len(), direct.prims.len(), "{name}");
        for (a, b) in scene.prims.iter().zip(&direct.prims) {
            assert_eq!((&a.name, &a.ptype, &a.sargs), (&b.name, &b.ptype, &b.sargs));
            assert_eq!(a.modifier, b.modifier, "{name}: {}", a.name);
            assert_eq!(a.rargs.len(), b.rargs.len());
            for (x, y) in a.rargs.iter().zip(&b.rargs) {
                assert!(
                    (x - y).abs() <= 1e-8 * y.abs().max(1e-30),
                    "{name}: {x} vs {y}"
                );
            }
        }
        let mut rt = common::fenestra("rtrace");
        rt.args(["-h", "-I+", "-ab", "1", "-ad", "64"]).arg(&f);
        outs.push(common::run_stdin(rt, b"2 2 0.8 0 0 1\n1 1 0.8 0 0 1\n3 4 0.8 0 0 1\n").stdout);
    }
    let mut rt = common::fenestra("rtrace");
    rt.args(["-h", "-I+", "-ab", "1", "-ad", "64"]).args(&files);
    let text = common::run_stdin(rt, b"2 2 0.8 0 0 1\n1 1 0.8 0 0 1\n3 4 0.8 0 0 1\n").stdout;
    assert!(!text.is_empty());
    assert_eq!(outs[0], text);
    assert_eq!(outs[1], text);
    // and oconv -i takes one
    let out = common::run_ok(
        common::fenestra("oconv")
            .arg("-i")
            .arg(d.join("frozen.oct"))
            .arg(common::fixture("scene/mkillum/exterior.rad")),
    );
    assert!(out.starts_with(b"#?FENESTRA_SCENE"));
}

/// (file, line named in the error, words the error must contain)
const BAD: &[(&str, u32, &[&str])] = &[
    ("polygon_count.rad", 3, &["polygon", "multiple of 3"]),
    ("plastic_count.rad", 1, &["plastic", "5"]),
    ("glass_strings.rad", 1, &["glass", "string"]),
    ("unknown_modifier.rad", 5, &["undefined modifier", "paint"]),
    ("unknown_type.rad", 2, &["unknown primitive type", "blob"]),
    ("unterminated_command.rad", 2, &["unterminated !command"]),
    ("failing_command.rad", 3, &["command failed"]),
    ("bad_number.rad", 1, &["not a number", "zero"]),
    ("integer_args.rad", 1, &["integer"]),
    ("truncated.rad", 1, &["end of input"]),
    ("bad_alias.rad", 1, &["nothing"]),
    ("unterminated_quote.rad", 2, &["unterminated quote"]),
];

#[test]
fn bad_scenes_give_one_clear_error() {
    let dir = common::fixture("scene/bad");
    for (file, line, words) in BAD {
        let path = dir.join(file);
        // xform, like Radiance's, does not resolve modifiers.
        let tools: &[&str] = if matches!(*file, "unknown_modifier.rad" | "bad_alias.rad") {
            &["oconv"]
        } else {
            &["oconv", "xform"]
        };
        for tool in tools {
            let out = Command::new(common::fenestra(tool).get_program())
                .current_dir(&dir)
                .arg(file)
                .output()
                .unwrap();
            let e = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(1), "{tool} {file}: {e}");
            assert!(out.stdout.is_empty(), "{tool} {file}: partial output");
            assert_eq!(e.lines().count(), 1, "{tool} {file}: {e}");
            assert!(e.contains(&format!("{file}:{line}")), "{tool} {file}: {e}");
            if *tool == "oconv" {
                for w in *words {
                    assert!(e.contains(w), "{tool} {file}: '{w}' missing in {e}");
                }
            }
        }
        let e = format!(
            "{:#}",
            fenestra_scene::load(&[path.to_str().unwrap()]).unwrap_err()
        );
        assert!(e.contains(&format!(":{line}")), "{file}: {e}");
    }
    let out = common::fenestra("oconv")
        .arg("no/such/scene.rad")
        .output()
        .unwrap();
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && e.contains("no/such/scene.rad"),
        "{e}"
    );
}
