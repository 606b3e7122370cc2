//! The tools' documentation pages (docs/tools/*.md), built into the binaries so that an
//! installed fenestra can show them: `fenestra doc TOOL`.

/// Every page: (tool name, markdown text).
pub const PAGES: &[(&str, &str)] = &[
    ("checkBSDF", include_str!("../docs/tools/checkBSDF.md")),
    ("dametrics", include_str!("../docs/tools/dametrics.md")),
    ("dctimestep", include_str!("../docs/tools/dctimestep.md")),
    ("errplot", include_str!("../docs/tools/errplot.md")),
    ("fenestra", include_str!("../docs/tools/fenestra.md")),
    ("genBSDF", include_str!("../docs/tools/genBSDF.md")),
    ("gendaylit", include_str!("../docs/tools/gendaylit.md")),
    ("gendaymtx", include_str!("../docs/tools/gendaymtx.md")),
    ("genklemsamp", include_str!("../docs/tools/genklemsamp.md")),
    ("gensky", include_str!("../docs/tools/gensky.md")),
    ("genskyvec", include_str!("../docs/tools/genskyvec.md")),
    ("getinfo", include_str!("../docs/tools/getinfo.md")),
    ("hdr2png", include_str!("../docs/tools/hdr2png.md")),
    ("mkillum", include_str!("../docs/tools/mkillum.md")),
    ("oconv", include_str!("../docs/tools/oconv.md")),
    ("pcomb", include_str!("../docs/tools/pcomb.md")),
    ("rcalc", include_str!("../docs/tools/rcalc.md")),
    ("rcontrib", include_str!("../docs/tools/rcontrib.md")),
    ("rfluxmtx", include_str!("../docs/tools/rfluxmtx.md")),
    ("rmtxop", include_str!("../docs/tools/rmtxop.md")),
    ("rtcontrib", include_str!("../docs/tools/rtcontrib.md")),
    ("rtrace", include_str!("../docs/tools/rtrace.md")),
    ("total", include_str!("../docs/tools/total.md")),
    ("vwrays", include_str!("../docs/tools/vwrays.md")),
    ("xform", include_str!("../docs/tools/xform.md")),
];

/// The page of `tool` (names as installed; case-sensitive).
pub fn page(tool: &str) -> Option<&'static str> {
    PAGES.iter().find(|(n, _)| *n == tool).map(|(_, t)| *t)
}
