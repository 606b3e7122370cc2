//! fenestra's compiled-scene format (written by `oconv`, read by every tracing tool) and
//! recognition of Radiance octrees, which fenestra does not read.
//!
//! Layout: a text header in Radiance's style
//! (`#?FENESTRA_SCENE`, `FORMAT=fenestra_scene`, `VERSION=1`, one `INPUT=` line per input,
//! the command line, then an empty line), followed by binary sections, each a 4-byte tag,
//! a little-endian u64 length and the payload. `PRIM` holds the scene (see [`encode_scene`]);
//! other tags (e.g. a BVH added by the tracer) are kept and returned by [`read`]; the file
//! ends with an `END!` section of length 0.

use anyhow::{anyhow, bail, Context, Result};
use std::sync::Arc;

use crate::model::{Loc, Primitive, Scene};

/// First bytes of a fenestra compiled scene.
pub const MAGIC: &[u8] = b"#?FENESTRA_SCENE";

/// The format version this code writes and reads.
pub const VERSION: u32 = 1;

/// Tag of the scene section.
pub const TAG_SCENE: [u8; 4] = *b"PRIM";
/// Tag of the closing section.
pub const TAG_END: [u8; 4] = *b"END!";

/// True when `bytes` start like a fenestra compiled scene.
pub fn is_compiled(bytes: &[u8]) -> bool {
    bytes.starts_with(MAGIC)
}

/// True when `bytes` start like an octree written by Radiance's oconv.
pub fn is_radiance_octree(bytes: &[u8]) -> bool {
    if !bytes.starts_with(b"#?RADIANCE") {
        return false;
    }
    let head = &bytes[..bytes.len().min(8192)];
    let end = head
        .windows(2)
        .position(|w| w == b"\n\n")
        .unwrap_or(head.len());
    let header = String::from_utf8_lossy(&head[..end]);
    header.lines().any(|l| l.trim() == "FORMAT=Radiance_octree")
}

/// A compiled scene as read back.
#[derive(Debug, Clone)]
pub struct Compiled {
    /// The scene.
    pub scene: Scene,
    /// The inputs named in the header.
    pub inputs: Vec<String>,
    /// Header lines other than the magic, FORMAT, VERSION and INPUT lines (e.g. the command).
    pub header: Vec<String>,
    /// Sections other than the scene, in file order (tag, payload).
    pub sections: Vec<([u8; 4], Vec<u8>)>,
}

/// Writes a compiled scene: header naming `inputs` and `command`, the scene, then `extra` sections.
pub fn write(
    out: &mut impl std::io::Write,
    scene: &Scene,
    inputs: &[String],
    command: &str,
    extra: &[([u8; 4], Vec<u8>)],
) -> Result<()> {
    let mut h = String::new();
    h.push_str("#?FENESTRA_SCENE\nFORMAT=fenestra_scene\n");
    h.push_str(&format!("VERSION={VERSION}\n"));
    for i in inputs {
        h.push_str(&format!("INPUT={}\n", i.replace('\n', " ")));
    }
    if !command.is_empty() {
        h.push_str(&command.replace('\n', " "));
        h.push('\n');
    }
    h.push('\n');
    out.write_all(h.as_bytes())?;
    let body = encode_scene(scene);
    write_section(out, TAG_SCENE, &body)?;
    for (tag, data) in extra {
        if *tag == TAG_SCENE || *tag == TAG_END {
            bail!(
                "compiled scene: section tag {:?} is reserved",
                String::from_utf8_lossy(tag)
            );
        }
        write_section(out, *tag, data)?;
    }
    write_section(out, TAG_END, &[])?;
    Ok(())
}

fn write_section(out: &mut impl std::io::Write, tag: [u8; 4], data: &[u8]) -> Result<()> {
    out.write_all(&tag)?;
    out.write_all(&(data.len() as u64).to_le_bytes())?;
    out.write_all(data)?;
    Ok(())
}

/// Reads a compiled scene file.
pub fn read_file(path: &str) -> Result<Compiled> {
    let bytes =
        std::fs::read(path).with_context(|| format!("cannot open compiled scene '{path}'"))?;
    read(&bytes).with_context(|| path.to_string())
}

/// Decodes a compiled scene from its bytes.
pub fn read(bytes: &[u8]) -> Result<Compiled> {
    if is_radiance_octree(bytes) {
        bail!("this is an octree written by Radiance's oconv, which fenestra cannot read; pass the .rad files instead");
    }
    if !is_compiled(bytes) {
        bail!("not a fenestra compiled scene (no #?FENESTRA_SCENE header)");
    }
    let end = bytes
        .windows(2)
        .position(|w| w == b"\n\n")
        .ok_or_else(|| anyhow!("compiled scene header is not terminated"))?;
    let header = std::str::from_utf8(&bytes[..end])
        .map_err(|_| anyhow!("compiled scene header is not text"))?;
    let mut inputs = Vec::new();
    let mut other = Vec::new();
    let mut version = None;
    for line in header.lines().skip(1) {
        if let Some(v) = line.strip_prefix("VERSION=") {
            version = v.trim().parse::<u32>().ok();
        } else if let Some(i) = line.strip_prefix("INPUT=") {
            inputs.push(i.to_string());
        } else if line.starts_with("FORMAT=") {
            if line != "FORMAT=fenestra_scene" {
                bail!("unexpected {line} in a compiled scene");
            }
        } else {
            other.push(line.to_string());
        }
    }
    match version {
        Some(VERSION) => {}
        Some(v) => bail!(
            "compiled scene version {v}; this fenestra reads version {VERSION}: run oconv again"
        ),
        None => bail!("compiled scene header has no VERSION line"),
    }
    let mut r = Reader {
        b: bytes,
        pos: end + 2,
    };
    let mut scene = None;
    let mut sections = Vec::new();
    loop {
        let tag: [u8; 4] = r.take(4)?.try_into().expect("4 bytes");
        let len = r.u64()? as usize;
        let data = r.take(len)?;
        match tag {
            TAG_END => break,
            TAG_SCENE => scene = Some(decode_scene(data)?),
            _ => sections.push((tag, data.to_vec())),
        }
    }
    let scene = scene.ok_or_else(|| anyhow!("compiled scene has no PRIM section"))?;
    Ok(Compiled {
        scene,
        inputs,
        header: other,
        sections,
    })
}

struct Reader<'a> {
    b: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        if self.pos + n > self.b.len() {
            bail!("compiled scene is truncated (at byte {})", self.pos);
        }
        let s = &self.b[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    fn string(&mut self) -> Result<String> {
        let n = self.u32()? as usize;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|_| anyhow!("compiled scene: bad string"))
    }
    fn strings(&mut self) -> Result<Vec<String>> {
        let n = self.u32()? as usize;
        (0..n).map(|_| self.string()).collect()
    }
}

fn put_str(v: &mut Vec<u8>, s: &str) {
    v.extend_from_slice(&(s.len() as u32).to_le_bytes());
    v.extend_from_slice(s.as_bytes());
}

/// Encodes a scene: u32 file count and names; u32 primitive count; per primitive: modifier
/// (u32, `u32::MAX` = void), modifier name, type, name, strings, integers (u32 count +
/// length-prefixed UTF-8 each), reals (u32 count + f64 LE each), file index and line (u32).
pub fn encode_scene(scene: &Scene) -> Vec<u8> {
    let mut files: Vec<Arc<str>> = Vec::new();
    let mut v = Vec::new();
    let mut body = Vec::new();
    body.extend_from_slice(&(scene.prims.len() as u32).to_le_bytes());
    for p in &scene.prims {
        let m = p.modifier.map(|m| m as u32).unwrap_or(u32::MAX);
        body.extend_from_slice(&m.to_le_bytes());
        put_str(&mut body, &p.modifier_name);
        put_str(&mut body, &p.ptype);
        put_str(&mut body, &p.name);
        for list in [&p.sargs, &p.iargs] {
            body.extend_from_slice(&(list.len() as u32).to_le_bytes());
            for s in list {
                put_str(&mut body, s);
            }
        }
        body.extend_from_slice(&(p.rargs.len() as u32).to_le_bytes());
        for r in &p.rargs {
            body.extend_from_slice(&r.to_le_bytes());
        }
        let fi = match files
            .iter()
            .position(|f| Arc::ptr_eq(f, &p.loc.file) || **f == *p.loc.file)
        {
            Some(i) => i,
            None => {
                files.push(p.loc.file.clone());
                files.len() - 1
            }
        };
        body.extend_from_slice(&(fi as u32).to_le_bytes());
        body.extend_from_slice(&p.loc.line.to_le_bytes());
    }
    v.extend_from_slice(&(files.len() as u32).to_le_bytes());
    for f in &files {
        put_str(&mut v, f);
    }
    v.extend_from_slice(&body);
    v
}

/// Decodes a scene written by [`encode_scene`], checking modifier indices.
pub fn decode_scene(data: &[u8]) -> Result<Scene> {
    let mut r = Reader { b: data, pos: 0 };
    let files: Vec<Arc<str>> = r.strings()?.into_iter().map(Arc::from).collect();
    let n = r.u32()? as usize;
    let mut prims = Vec::with_capacity(n.min(1 << 24));
    for i in 0..n {
        let m = r.u32()?;
        let modifier = if m == u32::MAX {
            None
        } else if (m as usize) < i {
            Some(m as usize)
        } else {
            bail!("compiled scene: primitive {i} has a bad modifier index {m}");
        };
        let modifier_name = r.string()?;
        let ptype = r.string()?;
        let name = r.string()?;
        let sargs = r.strings()?;
        let iargs = r.strings()?;
        let nr = r.u32()? as usize;
        let rargs = (0..nr).map(|_| r.f64()).collect::<Result<Vec<_>>>()?;
        let fi = r.u32()? as usize;
        let line = r.u32()?;
        let file = files
            .get(fi)
            .cloned()
            .ok_or_else(|| anyhow!("compiled scene: bad file index {fi}"))?;
        prims.push(Primitive {
            modifier,
            modifier_name,
            ptype,
            name,
            sargs,
            iargs,
            rargs,
            loc: Loc { file, line },
        });
    }
    Ok(Scene { prims })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_with_extra_sections() {
        let s = crate::parse_str(
            "void plastic m 0 0 5 .1 .2 .3 0 0\nm polygon p 0 0 9 0 0 0 1 0 0 0.1 1e-300 0\nm alias n m\n",
            "a.rad",
        )
        .unwrap();
        let mut buf = Vec::new();
        let extra = vec![(*b"BVH1", vec![1, 2, 3])];
        write(&mut buf, &s, &["a.rad".into()], "oconv a.rad", &extra).unwrap();
        let c = read(&buf).unwrap();
        assert_eq!(c.scene, s);
        assert_eq!(c.inputs, vec!["a.rad"]);
        assert_eq!(c.header, vec!["oconv a.rad"]);
        assert_eq!(c.sections, extra);
        for cut in [20, buf.len() / 2, buf.len() - 1] {
            assert!(read(&buf[..cut]).is_err());
        }
    }

    #[test]
    fn radiance_octree_is_refused_clearly() {
        let e = read(b"#?RADIANCE\noconv a.rad\nFORMAT=Radiance_octree\n\n\x01\x1f").unwrap_err();
        assert!(e.to_string().contains("pass the .rad files instead"), "{e}");
    }
}
