//! The scene model: primitives in file order with resolved modifiers.

use std::fmt;
use std::sync::Arc;

/// Where a primitive (or an error) comes from: file name (or `!command`, `-` for stdin) and line.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Loc {
    /// File name as given, `-` for standard input, `!command` for a command's output.
    pub file: Arc<str>,
    /// 1-based line number of the primitive's first word.
    pub line: u32,
}

impl fmt::Display for Loc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.file, self.line)
    }
}

/// One Radiance primitive (surface, material, pattern, texture, mixture …).
#[derive(Debug, Clone, PartialEq)]
pub struct Primitive {
    /// Index into [`Scene::prims`] of the modifier; `None` for `void`.
    pub modifier: Option<usize>,
    /// The modifier's name as written (`void` when none).
    pub modifier_name: String,
    /// The primitive type (`polygon`, `plastic`, `brightfunc` …).
    pub ptype: String,
    /// The identifier.
    pub name: String,
    /// String arguments.
    pub sargs: Vec<String>,
    /// Integer arguments (always empty for the types Radiance defines).
    pub iargs: Vec<String>,
    /// Real arguments.
    pub rargs: Vec<f64>,
    /// Where the primitive was defined.
    pub loc: Loc,
}

impl Primitive {
    /// True for surfaces (geometry), false for modifiers (materials, patterns …).
    pub fn is_surface(&self) -> bool {
        crate::types::is_surface(&self.ptype)
    }
}

/// A parsed scene: primitives in input order, modifiers resolved.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scene {
    /// All primitives in the order read.
    pub prims: Vec<Primitive>,
}

impl Scene {
    /// The most recent modifier (non-surface primitive) named `name` among the first `before`
    /// primitives, as Radiance resolves modifier names.
    pub fn find_modifier(&self, name: &str, before: usize) -> Option<usize> {
        self.prims[..before.min(self.prims.len())]
            .iter()
            .rposition(|p| p.name == name && !p.is_surface())
    }

    /// The chain of modifiers of primitive `i`, nearest first (its material, then that
    /// material's pattern, …).
    pub fn modifier_chain(&self, i: usize) -> Vec<usize> {
        let mut out = Vec::new();
        let mut m = self.prims[i].modifier;
        while let Some(k) = m {
            out.push(k);
            m = self.prims[k].modifier;
        }
        out
    }

    /// Writes the scene in Radiance syntax (one primitive per block, reals in `%g` style).
    pub fn to_rad(&self) -> String {
        let mut s = String::new();
        for p in &self.prims {
            crate::rad::write_primitive(&mut s, p);
        }
        s
    }
}
