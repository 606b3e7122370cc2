//! Antimatter clip sets: the modifiers a ray is blind to while inside antimatter volumes.
//!
//! Radiance's `antimatter` (`void antimatter name N mod1 … modN 0 0`): a ray entering an
//! antimatter surface (from its front) stops seeing surfaces whose direct modifier is one of
//! `mod1 … modN` until it leaves an antimatter surface naming them. Where a ray leaves the
//! antimatter inside a volume bounded by `mod1` surfaces, the antimatter surface is shaded
//! with `mod1` (normal reversed), and rays leaving that point keep the clip set. Inside-ness
//! is tracked by counting the `mod1` surfaces the ray passed while blind to them (+1 entering
//! through a front face, −1 leaving through a back face); found by experiment against the
//! reference rtrace: a recess ending inside a wall is shaded, a hole through it and an
//! antimatter box in free space are not, nor is one entered from inside the wall.

/// Largest number of modifiers a ray can be blind to at once.
pub const MAX_CLIP: usize = 8;

/// A small set of modifiers (scene indices) with a crossing count each.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ClipSet {
    len: u8,
    mods: [(u32, i32); MAX_CLIP],
}

impl ClipSet {
    /// True when the ray sees every surface.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    fn find(&self, m: usize) -> Option<usize> {
        self.mods[..self.len as usize]
            .iter()
            .position(|&(k, _)| k as usize == m)
    }

    /// Whether surfaces with direct modifier `m` are invisible.
    pub fn contains(&self, m: usize) -> bool {
        self.find(m).is_some()
    }

    /// Adds `m` (kept with its count if present); false when the set is full.
    pub fn insert(&mut self, m: usize) -> bool {
        if self.contains(m) {
            return true;
        }
        if self.len as usize == MAX_CLIP {
            return false;
        }
        self.mods[self.len as usize] = (m as u32, 0);
        self.len += 1;
        true
    }

    /// Removes `m` if present.
    pub fn remove(&mut self, m: usize) {
        if let Some(i) = self.find(m) {
            let n = self.len as usize;
            self.mods.copy_within(i + 1..n, i);
            self.len -= 1;
        }
    }

    /// Records that the ray passed a surface of `m` through its front (`front`) or back.
    pub fn cross(&mut self, m: usize, front: bool) {
        if let Some(i) = self.find(m) {
            self.mods[i].1 += if front { 1 } else { -1 };
        }
    }

    /// Whether the ray is inside a volume bounded by `m` surfaces it passed while blind.
    pub fn inside(&self, m: usize) -> bool {
        self.find(m).is_some_and(|i| self.mods[i].1 > 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn insert_cross_remove() {
        let mut c = ClipSet::default();
        assert!(c.is_empty());
        assert!(c.insert(7) && c.insert(3) && c.insert(7));
        assert!(c.contains(7) && c.contains(3) && !c.contains(4));
        assert!(!c.inside(7));
        c.cross(7, true);
        assert!(c.inside(7));
        c.cross(7, false);
        c.cross(7, false);
        assert!(!c.inside(7));
        c.remove(7);
        assert!(!c.contains(7) && c.contains(3));
        for k in 10..17 {
            assert!(c.insert(k));
        }
        assert!(!c.insert(99), "a full set refuses a ninth modifier");
    }
}
