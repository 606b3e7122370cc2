//! Errors of the .cal language, located by source, line and column.

use std::fmt;

/// What went wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorKind {
    /// The text is not valid .cal syntax.
    Syntax,
    /// A variable is referenced but never defined.
    UndefinedVariable,
    /// A function is called but never defined.
    UndefinedFunction,
    /// A function is called with fewer arguments than it has parameters.
    TooFewArguments,
    /// Definitions call each other too deeply (usually recursion without a base case).
    Recursion,
    /// A file cannot be read.
    Io,
    /// Anything else (misuse of the host interface).
    Other,
}

/// A location in a .cal source.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Location {
    /// File name, or a label such as `-e` for command-line strings.
    pub source: String,
    /// Line number, from 1.
    pub line: usize,
    /// Column number (characters), from 1.
    pub column: usize,
    /// The text of that line.
    pub text: String,
}

/// An error with its location.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CalcError {
    /// The class of the error.
    pub kind: ErrorKind,
    /// The message (without location).
    pub message: String,
    /// Where it happened, if known.
    pub location: Option<Location>,
}

impl CalcError {
    /// An error without a location.
    pub fn new(kind: ErrorKind, message: impl Into<String>) -> Self {
        CalcError {
            kind,
            message: message.into(),
            location: None,
        }
    }

    /// An error at a location.
    pub fn at(kind: ErrorKind, message: impl Into<String>, loc: Location) -> Self {
        CalcError {
            kind,
            message: message.into(),
            location: Some(loc),
        }
    }
}

impl fmt::Display for CalcError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.location {
            None => write!(f, "{}", self.message),
            Some(l) => {
                write!(
                    f,
                    "{}, line {}, column {}: {}",
                    l.source, l.line, l.column, self.message
                )?;
                if !l.text.is_empty() {
                    // at most WINDOW characters of the line, around the column
                    const WINDOW: usize = 100;
                    let chars: Vec<char> = l.text.chars().collect();
                    let col = l.column.saturating_sub(1).min(chars.len());
                    let start = col.saturating_sub(WINDOW / 2);
                    let end = (start + WINDOW).min(chars.len());
                    let shown: String = chars[start..end].iter().collect();
                    let caret: String = chars[start..col]
                        .iter()
                        .map(|&c| if c == '\t' { '\t' } else { ' ' })
                        .collect();
                    let (pre, post) = (
                        if start > 0 { "…" } else { "" },
                        if end < chars.len() { "…" } else { "" },
                    );
                    let pad = if start > 0 { " " } else { "" };
                    write!(f, "\n  {pre}{shown}{post}\n  {pad}{caret}^")?;
                }
                Ok(())
            }
        }
    }
}

impl std::error::Error for CalcError {}
