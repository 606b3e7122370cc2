//! Random numbers keyed by a seed and the input ray's index: the samples drawn for ray
//! `i` do not depend on which thread traces it or in what order, so output is the same
//! for any `-n`.

/// A small counter-free generator (SplitMix64 stream) started from `(seed, index)`.
#[derive(Debug, Clone)]
pub struct Rng {
    state: u64,
}

fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Rng {
    /// The stream for input ray `index` under `seed`.
    pub fn for_ray(seed: u64, index: u64) -> Rng {
        Rng {
            state: mix(seed ^ mix(index.wrapping_add(0x9e37_79b9_7f4a_7c15))),
        }
    }

    /// Next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix(self.state)
    }

    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// Order of the Hilbert curve that spreads one stratified number over a square (4096²).
const CURVE_ORDER: u32 = 12;

/// (x, y) of cell `d` along a Hilbert curve over a 2^order square.
pub fn hilbert_cell(order: u32, mut d: u64) -> (u64, u64) {
    let (mut x, mut y) = (0u64, 0u64);
    let mut s = 1u64;
    while s < (1u64 << order) {
        let rx = 1 & (d / 2);
        let ry = 1 & (d ^ rx);
        if ry == 0 {
            if rx == 1 {
                x = s - 1 - x;
                y = s - 1 - y;
            }
            std::mem::swap(&mut x, &mut y);
        }
        x += s * rx;
        y += s * ry;
        d /= 4;
        s *= 2;
    }
    (x, y)
}

/// Two numbers in [0,1)² from one: `t` picks a cell along the Hilbert curve (so numbers
/// stratified in [0,1) give points stratified over the square), `rng` places the point in it.
pub fn spread2(t: f64, rng: &mut Rng) -> (f64, f64) {
    let side = 1u64 << CURVE_ORDER;
    let cells = side * side;
    let d = ((t.clamp(0.0, 1.0) * cells as f64) as u64).min(cells - 1);
    let (x, y) = hilbert_cell(CURVE_ORDER, d);
    (
        (x as f64 + rng.next_f64()) / side as f64,
        (y as f64 + rng.next_f64()) / side as f64,
    )
}

/// Two numbers in [0, 1) for sample `i` of `s`: the first stratified (drawn in the
/// sample's 1/`s` of the range), both then spread over the square by [`spread2`].
pub fn stratified2(i: usize, s: usize, rng: &mut Rng) -> (f64, f64) {
    let t = (i as f64 + rng.next_f64()) / s as f64;
    spread2(t, rng)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hilbert_cells_cover_the_square_once() {
        let mut seen = [false; 64];
        for d in 0..64 {
            let (x, y) = hilbert_cell(3, d);
            assert!(!seen[(y * 8 + x) as usize]);
            seen[(y * 8 + x) as usize] = true;
            if d > 0 {
                let (px, py) = hilbert_cell(3, d - 1);
                assert_eq!(
                    px.abs_diff(x) + py.abs_diff(y),
                    1,
                    "neighbours along the curve"
                );
            }
        }
    }

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<u64> = (0..4).map(|_| Rng::for_ray(1, 7).next_u64()).collect();
        assert!(a.iter().all(|&x| x == a[0]));
        assert_ne!(Rng::for_ray(1, 7).next_u64(), Rng::for_ray(1, 8).next_u64());
        let mut r = Rng::for_ray(3, 3);
        let mean: f64 = (0..10000).map(|_| r.next_f64()).sum::<f64>() / 10000.0;
        assert!((mean - 0.5).abs() < 0.01);
    }
}
