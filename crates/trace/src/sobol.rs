//! Randomised quasi-Monte Carlo points: the first four dimensions of Sobol's sequence,
//! each scrambled by a seeded, hash-based nested permutation of its binary digits (Owen's
//! scrambling with the permutations drawn from a hash, as Laine and Karras's).
//!
//! Every one-dimensional projection of the first 2^m points is stratified (one point in
//! each of 2^m equal cells) and every pair of dimensions jointly: dimensions 0 and 1 form a
//! (0, m, 2)-net (one point in every elementary rectangle of area 2^-m), the other pairs
//! (t, m, 2)-nets with t ≤ 2 (tested); the scramble keeps that and makes each point
//! uniform on [0,1)^4, so a mean over the points is an unbiased estimate whose error
//! falls faster than independent samples' where the integrand has structure across
//! dimensions (a ray's start point and direction jointly deciding whether it passes
//! between two slats).
//!
//! Direction numbers: the primitive polynomials x+1, x²+x+1, x³+x+1 with initial
//! numbers (1), (1,3), (1,3,1), the standard choice for dimensions 2–4.

/// Binary digits generated per dimension.
const BITS: usize = 32;

/// Generator matrices (as column words, most significant digit first) of dimensions 0–3.
const fn matrices() -> [[u32; BITS]; 4] {
    let mut v = [[0u32; BITS]; 4];
    // dimension 0: the van der Corput sequence
    let mut k = 0;
    while k < BITS {
        v[0][k] = 1u32 << (31 - k);
        k += 1;
    }
    // dimensions 1..3: (degree s, inner coefficients a, initial m values)
    let polys: [(usize, u32, [u32; 3]); 3] =
        [(1, 0, [1, 0, 0]), (2, 1, [1, 3, 0]), (3, 1, [1, 3, 1])];
    let mut d = 0;
    while d < 3 {
        let (s, a, m0) = polys[d];
        let mut m = [0u32; BITS];
        let mut k = 0;
        while k < BITS {
            if k < s {
                m[k] = m0[k];
            } else {
                // m_k = 2 a1 m_{k-1} ^ 4 a2 m_{k-2} ^ … ^ 2^s m_{k-s} ^ m_{k-s}
                let mut x = m[k - s] ^ (m[k - s] << s);
                let mut j = 1;
                while j < s {
                    if (a >> (s - 1 - j)) & 1 == 1 {
                        x ^= m[k - j] << j;
                    }
                    j += 1;
                }
                m[k] = x;
            }
            v[d + 1][k] = m[k] << (31 - k);
            k += 1;
        }
        d += 1;
    }
    v
}

/// The generator matrices, built at compile time.
static MATRICES: [[u32; BITS]; 4] = matrices();

/// Point `index` of the unscrambled sequence in dimension `dim` (0..4), as 32 binary digits.
pub fn sobol_bits(index: u32, dim: usize) -> u32 {
    let m = &MATRICES[dim];
    let mut x = 0u32;
    let mut i = index;
    let mut k = 0;
    while i != 0 {
        if i & 1 == 1 {
            x ^= m[k];
        }
        i >>= 1;
        k += 1;
    }
    x
}

/// A hash-based nested scramble of 32 binary digits under `seed`: each output digit is the
/// input digit flipped or not by a function of the seed and the more significant digits
/// only (so every elementary interval maps onto one of the same size).
pub fn owen_scramble(x: u32, seed: u64) -> u32 {
    // on the reversed digits, every step below lets a bit depend only on the bits below it
    let mut y = x.reverse_bits();
    let s0 = seed as u32;
    let s1 = (seed >> 32) as u32;
    y = y.wrapping_add(s0);
    y ^= y.wrapping_mul(0x6c8e_9cf6); // even multiplier: feeds lower bits upward only
    y = y.wrapping_mul(s1 | 1);
    y ^= y.wrapping_mul(0x9e37_79b8);
    y = y.wrapping_add(s1.rotate_left(13));
    y ^= y.wrapping_mul(0x2c1b_3c6c);
    y = y.wrapping_mul(0xa54f_f53b);
    y.reverse_bits()
}

/// Point `index` of the scrambled sequence: four numbers in [0,1), dimension `d`
/// scrambled with `seeds[d]`; `fill` supplies the digits below the 32nd (uniform in
/// [0,1), e.g. a ray's own random stream), so the values are not confined to a 2^-32 grid.
pub fn point4(index: u32, seeds: [u64; 4], mut fill: impl FnMut() -> f64) -> [f64; 4] {
    let mut out = [0.0; 4];
    for (d, o) in out.iter_mut().enumerate() {
        let bits = owen_scramble(sobol_bits(index, d), seeds[d]);
        *o = ((f64::from(bits) + fill()) / 4_294_967_296.0).min(1.0 - f64::EPSILON / 2.0);
    }
    out
}

/// Four scramble seeds (one per dimension of [`point4`]) for the point set keyed by `key`
/// under `seed`: each set (an incident direction, a distribution bin) gets its own scramble.
pub fn scramble_seeds(seed: u64, key: u64) -> [u64; 4] {
    let mut keyed = crate::rng::Rng::for_ray(seed, key);
    [0; 4].map(|_: u64| keyed.next_u64())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether the first 2^m points of dimensions `a`, `b` (digits `x`) hold exactly one
    /// point in every elementary rectangle of area 2^(t-m) (a (t, m, 2)-net).
    fn is_net(pts: &[(u32, u32)], m: u32, t: u32) -> bool {
        for kx in 0..=(m - t) {
            let ky = m - t - kx;
            let mut seen = std::collections::HashMap::new();
            for &(x, y) in pts {
                let cx = if kx == 0 { 0 } else { x >> (32 - kx) };
                let cy = if ky == 0 { 0 } else { y >> (32 - ky) };
                *seen.entry((cx, cy)).or_insert(0u32) += 1;
            }
            let want = 1u32 << t;
            if seen.len() as u64 != 1u64 << (m - t) || seen.values().any(|&c| c != want) {
                return false;
            }
        }
        true
    }

    #[test]
    fn the_first_dimensions_are_sobol_s() {
        // the well-known opening of dimensions 1 and 2: 0, 1/2, 3/4, 1/4, ... and 0, 1/2, 1/4, 3/4
        let f = |i: u32, d: usize| f64::from(sobol_bits(i, d)) / 4_294_967_296.0;
        assert_eq!([f(0, 1), f(1, 1), f(2, 1), f(3, 1)], [0.0, 0.5, 0.75, 0.25]);
        assert_eq!([f(0, 0), f(1, 0), f(2, 0), f(3, 0)], [0.0, 0.5, 0.25, 0.75]);
    }

    #[test]
    fn every_pair_of_dimensions_is_a_net_with_small_t() {
        // (0,1) is a (0,m,2)-net; the other pairs of the first four dimensions have t ≤ 2
        for m in 1..=10u32 {
            for a in 0..4 {
                for b in a + 1..4 {
                    let pts: Vec<(u32, u32)> = (0..1u32 << m)
                        .map(|i| (sobol_bits(i, a), sobol_bits(i, b)))
                        .collect();
                    let t = (0..=m).find(|&t| is_net(&pts, m, t)).unwrap();
                    let limit = if (a, b) == (0, 1) { 0 } else { 2 };
                    assert!(t <= limit, "dims {a},{b} m={m}: t={t}");
                }
            }
        }
    }

    #[test]
    fn scrambling_keeps_the_nets_and_varies_with_the_seed() {
        let m = 8u32;
        for seed in [1u64, 0xdead_beef_1234, u64::MAX] {
            for d in 0..4 {
                let s1: Vec<u32> = (0..1u32 << m)
                    .map(|i| owen_scramble(sobol_bits(i, d), seed))
                    .collect();
                let mut cells: Vec<u32> = s1.iter().map(|x| x >> (32 - m)).collect();
                cells.sort_unstable();
                assert_eq!(cells, (0..1u32 << m).collect::<Vec<_>>(), "dim {d}");
            }
            let pts: Vec<(u32, u32)> = (0..1u32 << m)
                .map(|i| {
                    (
                        owen_scramble(sobol_bits(i, 0), seed),
                        owen_scramble(sobol_bits(i, 1), seed ^ 7),
                    )
                })
                .collect();
            assert!(is_net(&pts, m, 0));
        }
        assert_ne!(owen_scramble(12345, 1), owen_scramble(12345, 2));
    }

    #[test]
    fn scrambled_points_are_uniform() {
        // the mean of one scrambled coordinate over many seeds (point 5 of dimension 2) is 1/2
        let n = 20000u64;
        let mean: f64 = (0..n)
            .map(|s| {
                f64::from(owen_scramble(
                    sobol_bits(5, 2),
                    s.wrapping_mul(0x9e37_79b9_7f4a_7c15),
                ))
            })
            .sum::<f64>()
            / n as f64
            / 4_294_967_296.0;
        assert!(
            (mean - 0.5).abs() < 4.0 * (1.0 / 12.0f64 / n as f64).sqrt(),
            "{mean}"
        );
    }
}
