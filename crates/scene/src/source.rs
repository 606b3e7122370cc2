//! Where scene text comes from: files (bytes as Radiance reads them: UTF-8, or one byte
//! per character), standard input, and `!command` lines (plain `xform …` run in-process,
//! anything else through `sh -c`); and writing such text back byte for byte.

use std::process::Stdio;

use anyhow::{bail, Context, Result};

/// Runs `cmd` through `sh -c` and returns its standard output; a failing command is an error.
pub(crate) fn command_output(cmd: &str) -> Result<String> {
    if let Some(out) = crate::xform::run_inline(cmd)? {
        return Ok(out);
    }
    let out = fenestra_cfmt::sh_c(cmd)
        .stdin(Stdio::null())
        .stderr(Stdio::inherit())
        .output()
        .context("cannot run sh")?;
    if !out.status.success() {
        bail!("command failed ({})", out.status);
    }
    Ok(decode_text(out.stdout))
}

/// The bytes of a scene text file, with an error naming it (an octree or compiled scene
/// gets a specific message).
pub(crate) fn read_text_bytes(path: &str) -> Result<Vec<u8>> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot open scene file '{path}'"))?;
    if crate::compiled::is_radiance_octree(&bytes) {
        bail!("{path}: this is an octree written by Radiance's oconv, which fenestra cannot read; pass the .rad files instead");
    }
    if crate::compiled::is_compiled(&bytes) {
        bail!("{path}: this is a compiled scene (fenestra oconv output), not scene text");
    }
    Ok(bytes)
}

/// Scene text from bytes: UTF-8 when valid, otherwise one character per byte (Latin-1),
/// as Radiance reads bytes; names and numbers are ASCII either way.
pub fn decode_text(bytes: Vec<u8>) -> String {
    String::from_utf8(bytes)
        .unwrap_or_else(|e| e.into_bytes().iter().map(|&b| char::from(b)).collect())
}

/// Text read as [`decode_text`] does, and whether it was read one byte per character
/// (not valid UTF-8), so output made from it can be written back byte for byte.
pub fn decode_text_latin1(bytes: Vec<u8>) -> (String, bool) {
    match String::from_utf8(bytes) {
        Ok(s) => (s, false),
        Err(e) => (
            e.into_bytes().iter().map(|&b| char::from(b)).collect(),
            true,
        ),
    }
}

/// Bytes of text: one byte per character when `latin1` (text that
/// [`decode_text_latin1`] read byte for byte, plus ASCII), UTF-8 otherwise.
pub fn encode_text(text: &str, latin1: bool) -> Vec<u8> {
    if latin1 && text.chars().all(|c| u32::from(c) <= 0xFF) {
        return text.chars().map(|c| u32::from(c) as u8).collect();
    }
    text.as_bytes().to_vec()
}
