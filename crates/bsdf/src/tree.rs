//! Tensor-tree BSDF data (`TensorTree3` / `TensorTree4`): parse and evaluate.
//!
//! A node is `{ child × 2^rank }` (a branch; child `n` covers the upper half of dimension `i`
//! when bit `i` of `n` is set) or `{ value × 2^(rank·g) }` (a grid with `2^g` cells per
//! dimension, dimension 0 varying slowest). Lookup is nearest cell, as in Radiance.

use std::f64::consts::FRAC_PI_4;

/// A tensor tree of rank 3 (isotropic) or 4 (anisotropic).
#[derive(Clone, Debug, PartialEq)]
pub struct TensorTree {
    rank: usize,
    root: Node,
}

/// A tree node: a branch of `2^rank` children or a grid of `2^(rank·log2)` values.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Node {
    Branch(Vec<Node>),
    Grid { log2: u32, values: Vec<f32> },
}

/// Edge of the smallest leaf of `node` along one dimension (1/2^depth, a grid's cells counted
/// as one level of `log2` halvings).
pub(crate) fn smallest_leaf_edge(node: &Node) -> f64 {
    match node {
        Node::Branch(ch) => 0.5 * ch.iter().map(smallest_leaf_edge).fold(1.0, f64::min),
        Node::Grid { log2, .. } => 1.0 / (1u64 << log2) as f64,
    }
}

/// A leaf found by a lookup: its value and its hypercube (lower corner, edge).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Leaf {
    pub(crate) value: f32,
    pub(crate) corner: [f64; 4],
    pub(crate) edge: f64,
}

/// The leaf of `node` (a tree of rank `rank`) holding `pos` (each coordinate in [0, 1]; 1 falls
/// in the last cell). A branch halves every dimension (child bit `i` set: upper half of
/// dimension `i`); a grid picks the cell by truncation.
pub(crate) fn leaf_at(node: &Node, rank: usize, pos: &[f64; 4]) -> Leaf {
    let mut p = *pos;
    let mut corner = [0.0; 4];
    let mut edge = 1.0;
    let mut node = node;
    loop {
        match node {
            Node::Branch(ch) => {
                edge *= 0.5;
                let mut n = 0;
                for i in (0..rank).rev() {
                    let s = 2.0 * p[i];
                    let t = usize::from(s >= 1.0);
                    n |= t << i;
                    p[i] = s - t as f64;
                    corner[i] += t as f64 * edge;
                }
                node = &ch[n];
            }
            Node::Grid { log2, values } => {
                if *log2 == 0 {
                    return Leaf {
                        value: values[0],
                        corner,
                        edge,
                    };
                }
                let cells = (1u64 << log2) as f64;
                let top = (1usize << log2) - 1;
                let mut n = 0usize;
                for v in &p[..rank] {
                    n = (n << log2) + ((cells * v) as usize).min(top);
                }
                edge /= cells;
                for i in (0..rank).rev() {
                    corner[i] += (cells * p[i]).floor().min(top as f64) * edge;
                }
                return Leaf {
                    value: values[n],
                    corner,
                    edge,
                };
            }
        }
    }
}

/// Finest leaf edge accepted in a tree: leaves smaller than 1/2^16 per dimension (branch levels
/// plus a grid's levels) are rejected. The reciprocity sampling walks one radius per smallest
/// leaf and the slice sizes are rounded to 1/65536, so deeper trees would only cost time (and,
/// below 2^-53, never end); the limit also bounds the parser's recursion.
pub const MAX_TREE_LEVELS: u32 = 16;

/// A check on every value of a tree (`Err` with what is wrong).
pub type ValueCheck<'a> = &'a dyn Fn(f64) -> Result<(), String>;

/// A tree parse error: message and byte offset inside the parsed text.
#[derive(Debug, PartialEq)]
pub struct TreeError {
    /// What is wrong.
    pub message: String,
    /// Byte offset in the text.
    pub offset: usize,
}

impl TensorTree {
    /// The tree as `ScatteringData` text (values in their shortest exact form).
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        self.write_text(&mut out);
        out
    }

    /// [`TensorTree::to_text`] appended to `out` (no copy of a large tree's text).
    pub fn write_text(&self, out: &mut String) {
        use std::fmt::Write as _;
        fn node(out: &mut String, n: &Node, depth: usize) {
            for _ in 0..depth {
                out.push_str("    ");
            }
            match n {
                Node::Grid { values, .. } => {
                    out.push('{');
                    for v in values {
                        let _ = write!(out, " {v:e}");
                    }
                    out.push_str(" }\n");
                }
                Node::Branch(ch) => {
                    out.push_str("{\n");
                    for c in ch {
                        node(out, c, depth + 1);
                    }
                    for _ in 0..depth {
                        out.push_str("    ");
                    }
                    out.push_str("}\n");
                }
            }
        }
        node(out, &self.root, 0);
    }

    /// Parses `ScatteringData` text of a tree of the given rank (3 or 4).
    pub fn parse(rank: usize, text: &str) -> Result<Self, TreeError> {
        Self::parse_checked(rank, text, &|_| Ok(()))
    }

    /// [`TensorTree::parse`] with every value passed through `check` (an error names the value's
    /// offset).
    pub fn parse_checked(rank: usize, text: &str, check: ValueCheck) -> Result<Self, TreeError> {
        let mut p = Parser {
            s: text.as_bytes(),
            i: 0,
            rank,
            check,
        };
        p.skip();
        let root = p.node(0)?;
        p.skip();
        if p.i < p.s.len() {
            return Err(p.err("extra characters after the tree's root node"));
        }
        Ok(TensorTree { rank, root })
    }

    /// The rank (3 or 4).
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// The root node.
    pub(crate) fn root(&self) -> &Node {
        &self.root
    }

    /// Value at a position in the unit hypercube (`pos.len() == rank`, each clamped to [0,1]).
    pub fn lookup(&self, pos: &[f64]) -> f64 {
        let mut p = [0.0; 4];
        for (q, v) in p.iter_mut().zip(pos.iter().take(self.rank)) {
            *q = v.clamp(0.0, 1.0);
        }
        f64::from(leaf_at(&self.root, self.rank, &p).value)
    }

    /// BSDF (sr⁻¹) for an incident and an outgoing direction, both unit vectors pointing away
    /// from the surface in the component's frame (the frame Radiance's tree lookups use).
    pub fn eval(&self, inc: [f64; 3], out: [f64; 3]) -> f64 {
        if self.rank == 4 {
            let a = disk_to_square(-inc[0], -inc[1]);
            let b = disk_to_square(out[0], out[1]);
            self.lookup(&[a.0, a.1, b.0, b.1])
        } else {
            let r = (inc[0] * inc[0] + inc[1] * inc[1]).sqrt();
            let p0 = (0.5 - 1e-6) - 0.5 * r;
            let ang = -(-inc[1]).atan2(-inc[0]);
            let (s, c) = ang.sin_cos();
            let rot = [out[0] * c - out[1] * s, out[0] * s + out[1] * c];
            let b = disk_to_square(rot[0], rot[1]);
            self.lookup(&[p0.max(0.0), b.0, b.1])
        }
    }
}

/// Shirley–Chiu concentric map from the unit disk to the unit square.
pub fn disk_to_square(x: f64, y: f64) -> (f64, f64) {
    let r = (x * x + y * y).sqrt();
    let mut phi = y.atan2(x);
    if phi < -FRAC_PI_4 {
        phi += 2.0 * std::f64::consts::PI;
    }
    let (a, b) = if phi < FRAC_PI_4 {
        (r, phi * r / FRAC_PI_4)
    } else if phi < 3.0 * FRAC_PI_4 {
        (-(phi - 2.0 * FRAC_PI_4) * r / FRAC_PI_4, r)
    } else if phi < 5.0 * FRAC_PI_4 {
        (-r, (phi - 4.0 * FRAC_PI_4) * -r / FRAC_PI_4)
    } else {
        (-(phi - 6.0 * FRAC_PI_4) * -r / FRAC_PI_4, -r)
    };
    const S: f64 = 0.5 / 0.9999999999999;
    (a * S + 0.5, b * S + 0.5)
}

/// Shirley–Chiu concentric map from the unit square to the unit disk (inverse of
/// [`disk_to_square`]; radius scaled by 1 − 1e-13). The centre takes the last branch and maps to
/// (−0, −0), which a rank-3 lookup turns by π where (+0, +0) is not turned; which of the two
/// Radiance gives was not tested (checkBSDF's sampling draws the centre with probability 2^-48).
pub fn square_to_disk(u: f64, v: f64) -> (f64, f64) {
    let a = 2.0 * u - 1.0;
    let b = 2.0 * v - 1.0;
    let (r, phi) = if a > -b {
        if a > b {
            (a, FRAC_PI_4 * (b / a))
        } else {
            (b, FRAC_PI_4 * (2.0 - a / b))
        }
    } else if a < b {
        (-a, FRAC_PI_4 * (4.0 + b / a))
    } else {
        (
            -b,
            if b != 0.0 {
                FRAC_PI_4 * (6.0 - a / b)
            } else {
                0.0
            },
        )
    };
    let r = r * 0.9999999999999;
    (r * phi.cos(), r * phi.sin())
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    rank: usize,
    check: ValueCheck<'a>,
}

impl Parser<'_> {
    fn err(&self, m: &str) -> TreeError {
        TreeError {
            message: m.to_string(),
            offset: self.i,
        }
    }

    fn skip(&mut self) {
        while self.i < self.s.len()
            && (self.s[self.i].is_ascii_whitespace() || self.s[self.i] == b',')
        {
            self.i += 1;
        }
    }

    /// One node `levels` branch levels below the root.
    fn node(&mut self, levels: u32) -> Result<Node, TreeError> {
        if self.s.get(self.i) != Some(&b'{') {
            return Err(self.err("expected '{'"));
        }
        let open = self.i;
        self.i += 1;
        self.skip();
        if self.s.get(self.i) == Some(&b'{') {
            if levels >= MAX_TREE_LEVELS {
                return Err(TreeError {
                    message: format!(
                        "tree nested deeper than {MAX_TREE_LEVELS} levels (leaves smaller than \
                         1/{} are not supported)",
                        1u64 << MAX_TREE_LEVELS
                    ),
                    offset: open,
                });
            }
            let n = 1 << self.rank;
            let mut ch = Vec::with_capacity(n);
            for _ in 0..n {
                ch.push(self.node(levels + 1)?);
                self.skip();
            }
            if self.s.get(self.i) != Some(&b'}') {
                return Err(self.err(&format!("expected '}}' after {n} child nodes")));
            }
            self.i += 1;
            return Ok(Node::Branch(ch));
        }
        let mut values = Vec::new();
        loop {
            self.skip();
            match self.s.get(self.i) {
                Some(b'}') => {
                    self.i += 1;
                    break;
                }
                None => return Err(self.err("unexpected end of data inside a node")),
                _ => {}
            }
            let start = self.i;
            while self.i < self.s.len()
                && !matches!(self.s[self.i], b'}' | b'{' | b',')
                && !self.s[self.i].is_ascii_whitespace()
            {
                self.i += 1;
            }
            let tok = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("?");
            let v: f64 = tok.parse().map_err(|_| TreeError {
                message: format!("bad number '{tok}'"),
                offset: start,
            })?;
            if !v.is_finite() {
                return Err(TreeError {
                    message: format!("non-finite value '{tok}'"),
                    offset: start,
                });
            }
            if v < 0.0 {
                return Err(TreeError {
                    message: format!("negative BSDF value {tok}"),
                    offset: start,
                });
            }
            (self.check)(v).map_err(|m| TreeError {
                message: m,
                offset: start,
            })?;
            values.push(v as f32);
        }
        let mut log2 = 0u32;
        let mut k = 1usize;
        while k < values.len() {
            k <<= self.rank;
            log2 += 1;
        }
        if k != values.len() {
            return Err(self.err(&format!(
                "illegal value count {} in a rank-{} leaf",
                values.len(),
                self.rank
            )));
        }
        if levels + log2 > MAX_TREE_LEVELS {
            return Err(TreeError {
                message: format!(
                    "tree leaves smaller than 1/{} ({levels} branch levels and a grid of {} \
                     per dimension)",
                    1u64 << MAX_TREE_LEVELS,
                    1u64 << log2
                ),
                offset: open,
            });
        }
        Ok(Node::Grid { log2, values })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_and_lookup() {
        // rank 3: root branch of 8; child 0 a 2x2x2 grid, others constants.
        let t =
            TensorTree::parse(3, "{ { 1 2 3 4 5 6 7 8 } {9} {9} {9} {9} {9} {9} {10}, }").unwrap();
        assert_eq!(t.lookup(&[0.1, 0.1, 0.1]), 1.0);
        assert_eq!(t.lookup(&[0.1, 0.1, 0.3]), 2.0);
        assert_eq!(t.lookup(&[0.3, 0.1, 0.1]), 5.0);
        assert_eq!(t.lookup(&[0.9, 0.9, 0.9]), 10.0);
        assert_eq!(t.lookup(&[0.9, 0.1, 0.1]), 9.0);
        assert!(TensorTree::parse(3, "{1 2 3}").is_err());
        assert!(TensorTree::parse(3, "{1} x").is_err());
        assert!(TensorTree::parse(3, "{-1}").is_err());
        assert!(TensorTree::parse(4, "{ {1} }").is_err());
    }

    /// Leaves down to 1/2^16 per dimension parse; one level more, or brace nesting far deeper
    /// (no stack overflow), is an error at the offending node.
    #[test]
    fn depth_limit() {
        fn chain(levels: u32, grid: &str) -> String {
            if levels == 0 {
                return grid.to_string();
            }
            format!("{{ {} {} }}", chain(levels - 1, grid), ["{1}"; 7].join(" "))
        }
        let g2 = format!("{{ {} }}", ["1"; 8].join(" "));
        assert!(TensorTree::parse(3, &chain(15, &g2)).is_ok());
        assert!(TensorTree::parse(3, &chain(16, "{1}")).is_ok());
        let e = TensorTree::parse(3, &chain(16, &g2)).unwrap_err();
        assert!(e.message.contains("smaller than 1/65536"), "{}", e.message);
        let e = TensorTree::parse(3, &chain(17, "{1}")).unwrap_err();
        assert!(e.message.contains("deeper than 16"), "{}", e.message);
        assert_eq!(e.offset, 2 * 16);
        let deep = "{ ".repeat(1_000_000);
        let e = TensorTree::parse(4, &deep).unwrap_err();
        assert_eq!(e.offset, 2 * 16);
    }

    #[test]
    fn value_check() {
        let t = "{ 0.4 0.5 0.7 0.1 0.2 0.3 0.4 0.5 }";
        let check = |v: f64| {
            if v < 0.6 {
                Ok(())
            } else {
                Err(format!("{v} too big"))
            }
        };
        let e = TensorTree::parse_checked(3, t, &check).unwrap_err();
        assert_eq!((e.message.as_str(), e.offset), ("0.7 too big", 10));
    }

    #[test]
    fn disk_square_round_trip() {
        for &(x, y) in &[
            (0.3, 0.2),
            (-0.5, 0.1),
            (-0.2, -0.7),
            (0.1, -0.4),
            (0.0, 0.9),
        ] {
            let (u, v) = disk_to_square(x, y);
            let (x2, y2) = square_to_disk(u, v);
            assert!(
                (x - x2).abs() < 1e-9 && (y - y2).abs() < 1e-9,
                "{x} {y} -> {x2} {y2}"
            );
        }
    }
}
