//! `--help` of the tools: one line per option (a newcomer's first look), each line
//! starting with the option.

mod common;

#[test]
fn help_lists_each_option_on_its_own_line() {
    let cases: &[(&str, &[&str])] = &[
        (
            "rtrace",
            &[
                "-I | -i", "-ab N", "-ad N", "-as N", "-aa V", "-lw W", "-dt V", "-n N", "-seed N",
            ],
        ),
        (
            "gensky",
            &[
                "+s | -s", "+i | -i", "-c", "-u", "-g rfl", "-t turb", "-a lat", "-o lon", "-m mer",
            ],
        ),
        // from its option table (fenestra_cli::opts::Spec)
        ("genskyvec", &["-m N", "-c X Y Z", "-d", "-5", "-h"]),
        (
            "gendaymtx",
            &[
                "-m N", "-c r g b", "-g r g b", "-D file", "-A", "-r deg", "-5 deg", "-i min",
            ],
        ),
    ];
    for (tool, opts) in cases {
        let out = common::run_ok(common::fenestra(tool).arg("--help"));
        let text = String::from_utf8(out).unwrap();
        for o in *opts {
            assert!(
                text.lines().any(|l| l.trim_start().starts_with(o)),
                "{tool} --help has no line for {o}:\n{text}"
            );
        }
    }
}

#[test]
fn every_tool_has_its_documentation_page_built_in() {
    // `fenestra --help` lists the tools; `fenestra doc TOOL` prints docs/tools/TOOL.md, the
    // same text, for each (so an installed fenestra carries its documentation)
    let list = common::run_ok(common::fenestra("fenestra").arg("--help"));
    let text = String::from_utf8_lossy(&list);
    let tools: Vec<&str> = text
        .lines()
        .skip_while(|l| !l.starts_with("tools:"))
        .skip(1)
        .map(str::trim)
        .collect();
    assert!(tools.len() >= 20, "{text}");
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    for t in tools {
        let page = common::run_ok(common::fenestra("fenestra").args(["doc", t]));
        let want = std::fs::read(root.join(format!("docs/tools/{t}.md"))).unwrap();
        assert!(page == want, "fenestra doc {t}");
    }
    let out = common::fenestra("fenestra")
        .args(["doc", "nosuchtool"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    // the help of a tool points at it
    let help = common::run_ok(common::fenestra("dctimestep").arg("--help"));
    assert!(String::from_utf8_lossy(&help).contains("fenestra doc dctimestep"));
}

#[test]
fn the_sampling_tools_list_their_options() {
    // one line per option (or group of options) in --help, as the other tools
    for (tool, at_least) in [
        ("genBSDF", 12),
        ("mkillum", 5),
        ("rtcontrib", 12),
        ("rfluxmtx", 5),
    ] {
        let help = common::run_ok(common::fenestra(tool).arg("--help"));
        let text = String::from_utf8_lossy(&help);
        let lines = text
            .lines()
            .filter(|l| l.starts_with("  -") || l.starts_with("  +"))
            .count();
        assert!(lines >= at_least, "{tool}: {lines} option lines\n{text}");
        assert!(text.contains(&format!("fenestra doc {tool}")), "{tool}");
    }
}
