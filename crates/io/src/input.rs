//! Opening inputs the Radiance way: a file, `-` for standard input, or `!command`.

use std::io::{BufRead, BufReader, Read};
use std::process::{Child, Stdio};

use anyhow::{Context, Result};

/// Opens `name` for reading: `-` (or empty) is stdin, `!cmd` runs `sh -c cmd` and reads
/// its output (a failing command is reported when its output ends), anything else a file.
pub fn open(name: &str) -> Result<Box<dyn BufRead + Send>> {
    if name.is_empty() || name == "-" {
        return Ok(Box::new(BufReader::with_capacity(
            1 << 16,
            std::io::stdin(),
        )));
    }
    if let Some(cmd) = name.strip_prefix('!') {
        let mut child = fenestra_cfmt::sh_c(cmd)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .spawn()
            .with_context(|| format!("cannot run command '{cmd}'"))?;
        let out = child.stdout.take().context("no output pipe from command")?;
        return Ok(Box::new(BufReader::with_capacity(
            1 << 16,
            CommandOutput {
                out,
                child: Some(child),
                cmd: cmd.to_string(),
            },
        )));
    }
    if std::path::Path::new(name).is_dir() {
        anyhow::bail!("cannot open input file '{name}': it is a directory");
    }
    let f =
        std::fs::File::open(name).with_context(|| format!("cannot open input file '{name}'"))?;
    Ok(Box::new(BufReader::with_capacity(1 << 16, f)))
}

/// Output of a child command; at end of data the exit status is checked.
struct CommandOutput {
    out: std::process::ChildStdout,
    child: Option<Child>,
    cmd: String,
}

impl Read for CommandOutput {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.out.read(buf)?;
        if n == 0 && !buf.is_empty() {
            if let Some(mut c) = self.child.take() {
                let st = c.wait()?;
                if !st.success() {
                    return Err(std::io::Error::other(format!(
                        "command '{}' failed ({st})",
                        self.cmd
                    )));
                }
            }
        }
        Ok(n)
    }
}

impl Drop for CommandOutput {
    fn drop(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn command_input_is_read() {
        let mut s = String::new();
        open("!printf 'a b\\n'")
            .unwrap()
            .read_to_string(&mut s)
            .unwrap();
        assert_eq!(s, "a b\n");
    }

    #[test]
    fn failing_command_is_reported() {
        let mut s = String::new();
        let e = open("!exit 3").unwrap().read_to_string(&mut s).unwrap_err();
        assert!(e.to_string().contains("failed"), "{e}");
    }

    #[test]
    fn missing_file_names_it() {
        let e = open("no/such/file.mtx").err().unwrap();
        assert!(format!("{e:#}").contains("no/such/file.mtx"));
    }
}
