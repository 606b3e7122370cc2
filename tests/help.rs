//! `--help` of the tools that parse their options by hand: one line per option (a
//! newcomer's first look), each line starting with the option.

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
        ("genskyvec", &["-m N", "-c r g b", "-d", "-5", "-h"]),
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
