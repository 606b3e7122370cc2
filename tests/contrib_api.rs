//! The contribution engine driven in-process (no rtcontrib process, pipe or temporary
//! file), as genBSDF and rfluxmtx will drive it: the same bytes as the rtcontrib command
//! on the same input, for streamed records, rays read beforehand, and the `-c 0` sum.

mod common;

use common::{fenestra, fixture, run_stdin, scratch};
use fenestra_contrib::bins::{BinRequest, Bins, CalcDefs};
use fenestra_contrib::engine::{Engine, InFormat, RayInput, RunOptions, Tracked};
use fenestra_contrib::output::{self, Format, HeaderInfo, ModOut, Spec, Stream};
use fenestra_contrib::run;
use fenestra_trace::{TraceOptions, Tracer};

/// Runs the Reinhart D-matrix case in-process with `count` rays per record, writing the
/// file `name`; `stream`: records from the input as it is read, else from rays read first.
fn in_process(dir: &std::path::Path, count: usize, stream: bool, name: &str) {
    std::env::set_var("FENESTRA_LIB", concat!(env!("CARGO_MANIFEST_DIR"), "/lib"));
    let scene = fenestra_scene::load(&[
        fixture("rcontrib/sky_uniform.rad").to_str().unwrap(),
        fixture("rcontrib/open_box.rad").to_str().unwrap(),
    ])
    .unwrap();
    let mut o = TraceOptions::rcontrib();
    o.dt = 0.0;
    let tracer = Tracer::new(&scene, &o).unwrap();
    let mut defs = CalcDefs::new();
    defs.push_expr("MF:1").unwrap();
    defs.push_file("reinhart.cal").unwrap();
    let nbins = (defs.eval_now("Nrbins").unwrap() + 0.5) as usize;
    let bins = Bins::compile(
        &defs,
        &[BinRequest {
            expr: "rbin",
            params: &[],
        }],
    )
    .unwrap();
    let scene_mods: Vec<usize> = scene
        .prims
        .iter()
        .enumerate()
        .filter(|(_, p)| p.name == "skyglow" && !p.is_surface())
        .map(|(k, _)| k)
        .collect();
    let tracked = vec![Tracked { scene_mods, nbins }];
    let opts = RunOptions {
        irradiance_at_hit: false,
        limit_dist: false,
        irradiance: false,
        value: false,
        count,
        errors: false,
        batches: 4,
        replicas: 0,
    };
    let spec = Spec::parse(dir.join(name).to_str().unwrap()).unwrap();
    let plans = output::plan(
        &[ModOut {
            name: "skyglow",
            spec: Some(&spec),
            nbins,
        }],
        false,
    );
    let info = HeaderInfo {
        scene_lines: Vec::new(),
        command: String::new(),
        xres: 0,
        yres: 0,
        format: Format::Ascii,
        header: false,
        extra: Vec::new(),
    };
    let values = plans
        .into_iter()
        .map(|p| Stream::open(p, &info).unwrap())
        .collect();
    let mut out = run::Outputs {
        values,
        errors: Vec::new(),
        replicas: Vec::new(),
        budget: Default::default(),
        format: Format::Ascii,
    };
    let pool = fenestra_cli::threads::pool(2).unwrap();
    let engine = Engine::new(&tracer, &bins, scene.prims.len(), &tracked, opts);
    let text = std::fs::read(fixture("rcontrib/d_rays.dat")).unwrap();
    let mut input = RayInput::new(&text[..], InFormat::Ascii);
    let none = |_: u64| {};
    if count == 0 {
        let rays = input.read_all(None).unwrap();
        run::sum_run(&engine, &rays, &[None], &pool, &mut out, &none).unwrap();
    } else if stream {
        let plan = run::StreamPlan {
            count,
            flush_every: 0,
            expect: None,
            skip_records: 0,
        };
        let end = run::streamed_run(&engine, &mut input, plan, &pool, &mut out, &none).unwrap();
        assert_eq!(end.rays, 200);
    } else {
        let rays = input.read_all(None).unwrap();
        run::buffered_run(&engine, &rays, count, 0, &pool, &mut out, &none).unwrap();
    }
    out.finish().unwrap();
}

/// The engine in-process gives the bytes of `rtcontrib -h -c N -o file` on the same rays.
#[test]
fn in_process_run_equals_rtcontrib_bytes() {
    let dir = scratch("contrib-api");
    let rays = std::fs::read(fixture("rcontrib/d_rays.dat")).unwrap();
    for (count, stream) in [(7usize, true), (7, false), (1, true), (0, false)] {
        let tool_name = format!("tool_{count}_{stream}.dat");
        let mut c = fenestra("rtcontrib");
        c.args(["-h", "-n", "2", "-c", &count.to_string(), "-o", &tool_name])
            .args([
                "-e",
                "MF:1",
                "-f",
                "reinhart.cal",
                "-b",
                "rbin",
                "-bn",
                "Nrbins",
            ])
            .args(["-m", "skyglow"])
            .arg(fixture("rcontrib/sky_uniform.rad"))
            .arg(fixture("rcontrib/open_box.rad"))
            .current_dir(&dir);
        let o = run_stdin(c, &rays);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let api_name = format!("api_{count}_{stream}.dat");
        in_process(&dir, count, stream, &api_name);
        let a = std::fs::read(dir.join(&tool_name)).unwrap();
        let b = std::fs::read(dir.join(&api_name)).unwrap();
        assert!(!a.is_empty());
        assert!(
            a == b,
            "-c {count} stream {stream}: in-process output differs"
        );
    }
}
