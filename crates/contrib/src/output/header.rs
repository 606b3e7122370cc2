//! The information header (and resolution string) of each output stream.

use super::*;

/// What every header carries.
#[derive(Debug, Clone)]
pub struct HeaderInfo {
    /// Lines from the scene's own header (e.g. the oconv command).
    pub scene_lines: Vec<String>,
    /// The command line without the scene files.
    pub command: String,
    /// `-x` and `-y`.
    pub xres: usize,
    /// `-y`.
    pub yres: usize,
    /// Output format.
    pub format: Format,
    /// Write the information header (`-h`).
    pub header: bool,
    /// Extra lines (e.g. what an error-estimate file holds).
    pub extra: Vec<String>,
}

/// The header (and resolution string) of a stream.
pub fn header_text(plan: &StreamPlan, info: &HeaderInfo) -> Vec<u8> {
    let mut h = String::new();
    let one = plan.items.len() == 1;
    if info.header {
        h.push_str("#?RADIANCE\n");
        for l in &info.scene_lines {
            h.push_str(l);
            h.push('\n');
        }
        h.push_str(&info.command);
        h.push('\n');
        h.push_str("SOFTWARE= fenestra\n");
        for l in fenestra_formats::picture::capdate_lines() {
            h.push_str(&l);
            h.push('\n');
        }
        h.push_str("NCOMP=3\n");
        if let Some(m) = &plan.modifier {
            h.push_str(&format!("MODIFIER={m}\n"));
        }
        if let Some(b) = plan.bin {
            h.push_str(&format!("BIN={b}\n"));
        }
        for l in &info.extra {
            h.push_str(l);
            h.push('\n');
        }
        if info.yres > 0 {
            h.push_str(&format!("NROWS={}\n", info.yres * info.xres.max(1)));
        }
        if !(info.xres > 0 && one) {
            h.push_str(&format!("NCOLS={}\n", plan.items.len()));
        }
        if matches!(info.format, Format::Float | Format::Double) {
            let be = if cfg!(target_endian = "big") { 1 } else { 0 };
            h.push_str(&format!("BigEndian={be}\n"));
        }
        h.push_str(&format!("FORMAT={}\n\n", info.format.as_str()));
    }
    if info.xres > 0 && info.yres > 0 && one {
        h.push_str(&format!("-Y {:8} +X {:8}\n", info.yres, info.xres));
    }
    h.into_bytes()
}
