//! What getinfo -d prints: a picture's resolution string, or a matrix's shape (from its
//! header, or counted from its data when the header has no NROWS, as rtcontrib without -y
//! writes it).

use std::io::{BufRead, Read};

use anyhow::{Context, Result};

use crate::header::Header;
use crate::resolution::Resolution;

/// Whether a header announces a picture (an RLE format or none, no NCOLS, `#?` first).
pub fn is_picture(h: &Header) -> bool {
    h.format().is_none_or(|f| f.contains("_rle_"))
        && h.ncols().ok().flatten().is_none()
        && h.lines.first().is_some_and(|l| l.starts_with("#?"))
}

/// The resolution line after a picture's header (at most 128 bytes), `name` for messages.
pub fn read_resolution(r: &mut impl BufRead, name: &str) -> Result<Resolution> {
    let mut line = Vec::new();
    r.take(128)
        .read_until(b'\n', &mut line)
        .with_context(|| format!("{name}: read error"))?;
    let s = String::from_utf8_lossy(&line);
    Resolution::parse(s.trim_end())
        .with_context(|| format!("{name}: bad picture resolution string '{}'", s.trim_end()))
}

/// A picture's resolution string, or a matrix's shape (`NROWS=… NCOLS=… NCOMP=…`), of the
/// file `name` read from `r`; the header is read, the data only when rows must be counted.
pub fn dimensions(r: &mut impl BufRead, name: &str) -> Result<String> {
    let h = Header::read(r, name)?;
    if let (Ok(Some(nr)), Ok(Some(nc))) = (h.nrows(), h.ncols()) {
        let ncomp = h.ncomp().ok().flatten().unwrap_or(3);
        return Ok(format!("NROWS={nr} NCOLS={nc} NCOMP={ncomp}"));
    }
    if is_picture(&h) {
        let res = read_resolution(r, name)?;
        return Ok(res.to_string().trim_end().to_string());
    }
    // rcontrib/rtcontrib write NROWS only with -y: count the rows the data hold (fenestra)
    if let Ok(Some(nc)) = h.ncols() {
        let ncomp = h.ncomp().ok().flatten().unwrap_or(3);
        let per_row = nc * ncomp;
        let size = match h.format().map(str::trim) {
            Some("float") => Some(4),
            Some("double") => Some(8),
            Some("ascii") | None => None,
            Some(other) => anyhow::bail!("{name}: matrix format '{other}' without NROWS"),
        };
        let (values, rest) = match size {
            Some(b) => {
                let n = std::io::copy(r, &mut std::io::sink())
                    .with_context(|| format!("{name}: read error"))?
                    as usize;
                (n / b, n % b)
            }
            None => {
                let mut text = String::new();
                r.read_to_string(&mut text)
                    .with_context(|| format!("{name}: read error"))?;
                (text.split_whitespace().count(), 0)
            }
        };
        if per_row > 0 && rest == 0 && values % per_row == 0 {
            return Ok(format!(
                "NROWS={} NCOLS={nc} NCOMP={ncomp}",
                values / per_row
            ));
        }
        anyhow::bail!(
            "{name}: {values} values are not whole rows of NCOLS={nc} x NCOMP={ncomp} (a truncated matrix?)"
        );
    }
    anyhow::bail!("{name}: unknown file type (neither a picture nor a matrix with NCOLS)")
}
