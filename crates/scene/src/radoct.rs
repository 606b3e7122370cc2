//! Octrees written by Radiance's oconv. A frozen octree (`oconv -f`) carries the whole scene
//! after its tree: a table of type names, then every object (type, modifier, name, string
//! and real arguments) in Radiance's portable binary numbers; an ordinary octree lists the
//! scene files it was made from. Either way fenestra rebuilds the scene from the objects or
//! the files (its own accelerator replaces the tree, which is skipped).
//!
//! Format facts (Radiance's octree.h, readoct.c, sceneio.c, portio.c): an information header
//! with `FORMAT=Radiance_octree`; a 2-byte number `283 + object size`; four strings (the
//! bounding cube); the scene file names, ended by an empty string; the object count; the
//! tree in preorder (byte 0 empty, 1 a set of object numbers, 2 eight children); for a frozen
//! octree the type names ended by an empty string, then objects until a type byte of −1.
//! Integers are big-endian with the first byte's sign extended; a real is a 4-byte
//! mantissa m and a 1-byte exponent e: `(m + ½ − [m<0]) / (2³¹−1) · 2^e`.

use anyhow::{bail, Result};

/// What a Radiance octree holds.
#[derive(Debug, Clone, PartialEq)]
pub enum RadianceOctree {
    /// The scene files it was made from (to be read again).
    Files(Vec<String>),
    /// A frozen octree's scene, as Radiance scene text.
    Frozen(String),
}

struct Reader<'a> {
    b: &'a [u8],
    pos: usize,
}

impl Reader<'_> {
    fn byte(&mut self) -> Result<u8> {
        let Some(&c) = self.b.get(self.pos) else {
            bail!("truncated octree");
        };
        self.pos += 1;
        Ok(c)
    }

    fn int(&mut self, size: usize) -> Result<i64> {
        let c = self.byte()?;
        let mut r = i64::from(c as i8);
        for _ in 1..size {
            r = (r << 8) | i64::from(self.byte()?);
        }
        Ok(r)
    }

    fn string(&mut self) -> Result<String> {
        let rest = &self.b[self.pos.min(self.b.len())..];
        let Some(end) = rest.iter().position(|&c| c == 0) else {
            bail!("truncated octree (a string without its end)");
        };
        self.pos += end + 1;
        Ok(String::from_utf8_lossy(&rest[..end]).into_owned())
    }

    /// Strings up to the empty one that ends the list.
    fn string_list(&mut self) -> Result<Vec<String>> {
        let mut out = Vec::new();
        loop {
            let s = self.string()?;
            if s.is_empty() {
                return Ok(out);
            }
            out.push(s);
        }
    }

    fn real(&mut self) -> Result<f64> {
        let m = self.int(4)?;
        if m == 0 {
            self.byte()?;
            return Ok(0.0);
        }
        let e = self.int(1)?;
        let d = (m as f64 + 0.5 - if m < 0 { 1.0 } else { 0.0 }) * (1.0 / 2_147_483_647.0);
        Ok(d * 2f64.powi(e as i32))
    }

    fn skip(&mut self, n: usize) -> Result<()> {
        if self.pos + n > self.b.len() {
            bail!("truncated octree");
        }
        self.pos += n;
        Ok(())
    }
}

fn quote(w: &str) -> String {
    if w.is_empty() || w.chars().any(char::is_whitespace) {
        if w.contains('"') {
            format!("'{w}'")
        } else {
            format!("\"{w}\"")
        }
    } else {
        w.to_string()
    }
}

/// Reads a Radiance octree (`bytes` starting with its information header).
pub fn read(bytes: &[u8]) -> Result<RadianceOctree> {
    let Some(end) = bytes.windows(2).position(|w| w == b"\n\n") else {
        bail!("not an octree (no end of header)");
    };
    let mut r = Reader {
        b: bytes,
        pos: end + 2,
    };
    let objsize = r.int(2)? - 283;
    if !(1..=8).contains(&objsize) {
        bail!("incompatible octree format (object size {objsize})");
    }
    let objsize = objsize as usize;
    for _ in 0..4 {
        r.string()?;
    }
    let files = r.string_list()?;
    let nobj = r.int(objsize)?;
    if nobj < 0 || nobj as usize > bytes.len() {
        bail!("bad object count {nobj} in octree");
    }
    // the tree in preorder; fenestra builds its own accelerator
    let mut pending = 1usize;
    while pending > 0 {
        match r.byte()? {
            0 => pending -= 1,
            1 => {
                let n = r.int(objsize)?;
                if n < 0 {
                    bail!("damaged octree (a negative set size)");
                }
                r.skip(n as usize * objsize)?;
                pending -= 1;
            }
            2 => pending += 7,
            b => bail!("damaged octree (node type {b})"),
        }
    }
    if !files.is_empty() {
        return Ok(RadianceOctree::Files(files));
    }
    let types = r.string_list()?;
    let mut names: Vec<String> = Vec::with_capacity((nobj as usize).min(1 << 20));
    let mut text = String::new();
    loop {
        let t = r.int(1)?;
        if t == -1 {
            break;
        }
        let Some(ty) = types.get(t as usize) else {
            bail!("damaged octree (object type {t} beyond the type table)");
        };
        let m = r.int(objsize)?;
        let modifier = if m == -1 {
            "void".to_string()
        } else {
            match names.get(m as usize) {
                Some(n) => n.clone(),
                None => bail!("damaged octree (modifier {m} not yet defined)"),
            }
        };
        let name = r.string()?;
        let ns = r.int(2)?;
        let mut line = format!(
            "{} {} {}\n{}",
            quote(&modifier),
            ty,
            quote(&name),
            ns.max(0)
        );
        for _ in 0..ns.max(0) {
            line.push(' ');
            line.push_str(&quote(&r.string()?));
        }
        let nf = r.int(2)?;
        line.push_str(&format!("\n0\n{}", nf.max(0)));
        for _ in 0..nf.max(0) {
            line.push_str(&format!(" {}", r.real()?));
        }
        line.push_str("\n\n");
        text.push_str(&line);
        names.push(name);
    }
    if names.len() as i64 != nobj {
        bail!(
            "octree holds {} objects where its header says {nobj}",
            names.len()
        );
    }
    Ok(RadianceOctree::Frozen(text))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn portable_numbers_decode_as_radiance_s() {
        // mantissa 0x40000000 (≈ ½), exponent 1 → ≈ 1
        let b = [0x40, 0, 0, 0, 1];
        let mut r = Reader { b: &b, pos: 0 };
        assert!((r.real().unwrap() - 1.0).abs() < 1e-9);
        let b = [0xff, 0xfe];
        let mut r = Reader { b: &b, pos: 0 };
        assert_eq!(r.int(2).unwrap(), -2);
        let mut r = Reader {
            b: &[0, 0, 0],
            pos: 0,
        };
        assert!(r.real().is_err());
    }
}
