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

/// A small set of modifiers (scene indices) with a crossing count each. Every ray carries
/// one, almost always empty: the empty set is a null pointer, so rays stay small and copying
/// one costs nothing outside antimatter.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClipSet(Option<Box<Mods>>);

#[derive(Debug, Clone, Default, PartialEq)]
struct Mods {
    len: u8,
    mods: [(u32, i32); MAX_CLIP],
}

impl Mods {
    fn find(&self, m: usize) -> Option<usize> {
        self.mods[..self.len as usize]
            .iter()
            .position(|&(k, _)| k as usize == m)
    }
}

impl ClipSet {
    /// True when the ray sees every surface.
    pub fn is_empty(&self) -> bool {
        self.0.is_none()
    }

    fn find(&self, m: usize) -> Option<usize> {
        self.0.as_ref().and_then(|s| s.find(m))
    }

    /// Whether surfaces with direct modifier `m` are invisible.
    pub fn contains(&self, m: usize) -> bool {
        self.find(m).is_some()
    }

    /// Adds `m` (kept with its count if present); false when the set is full.
    pub fn insert(&mut self, m: usize) -> bool {
        let s = self.0.get_or_insert_with(Default::default);
        if s.find(m).is_some() {
            return true;
        }
        if s.len as usize == MAX_CLIP {
            return false;
        }
        s.mods[s.len as usize] = (m as u32, 0);
        s.len += 1;
        true
    }

    /// Removes `m` if present.
    pub fn remove(&mut self, m: usize) {
        let Some(s) = self.0.as_mut() else { return };
        if let Some(i) = s.find(m) {
            let n = s.len as usize;
            s.mods.copy_within(i + 1..n, i);
            s.len -= 1;
        }
        if s.len == 0 {
            self.0 = None;
        }
    }

    /// Records that the ray passed a surface of `m` through its front (`front`) or back.
    pub fn cross(&mut self, m: usize, front: bool) {
        if let Some(s) = self.0.as_mut() {
            if let Some(i) = s.find(m) {
                s.mods[i].1 += if front { 1 } else { -1 };
            }
        }
    }

    /// Whether the ray is inside a volume bounded by `m` surfaces it passed while blind.
    pub fn inside(&self, m: usize) -> bool {
        self.0
            .as_ref()
            .is_some_and(|s| s.find(m).is_some_and(|i| s.mods[i].1 > 0))
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
        for k in [3].into_iter().chain(10..17) {
            c.remove(k);
        }
        assert!(c.is_empty() && c == ClipSet::default());
    }
}
