//! Recognising compiled scene files: fenestra's own (written by `oconv`) and Radiance octrees.

/// First bytes of a fenestra compiled scene.
pub const MAGIC: &[u8] = b"#?FENESTRA_SCENE";

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
