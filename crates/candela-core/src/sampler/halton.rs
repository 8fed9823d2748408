//! Halton sampler [pbrt-v4 §8.6 `HaltonSampler`].
//!
//! Dimension d of sample a is the radical inverse of a in the d-th prime
//! base, Φ_b(a) = Σ_k d_k(a) b^(−k−1) with d_k the base-b digits of a
//! [Halton 1960]. The first two dimensions (bases 2 and 3) are spread over
//! the film: with scales 2^j ≥ min(width, 128) and 3^k ≥ min(height, 128),
//! the point (Φ₂(a)·2^j, Φ₃(a)·3^k) lies in pixel (x mod 128, y mod 128)
//! exactly when a ≡ a_p (mod 2^j·3^k), and a_p comes from the two pixel
//! coordinates' inverse radical inverses by the Chinese remainder theorem
//! (the scales are coprime). Sample i of a pixel is a = a_p + i·2^j·3^k, so
//! a pixel's samples are a stratified subsequence of one Halton sequence;
//! [`HaltonSampler::get_pixel_2d`] returns the digits of (Φ₂(a), Φ₃(a))
//! beyond the pixel's, its offset inside the pixel.
//!
//! **Randomisation** (`"string randomization"`): `permutedigits` (the
//! default) applies to each digit position of each base a random
//! permutation of the digits [Faure & Lemieux 2009], all digit positions a
//! 32-bit float resolves, so trailing zero digits are permuted too and
//! every point gets a random offset; `owen` permutes each digit by a hash of
//! the digits above it (a nested, Owen-style scramble); `none` is the plain
//! sequence. Permutations preserve the stratification of every prefix of
//! digits, so a pixel's samples stay stratified in every dimension. The
//! digit permutations are uniformly random (Fisher–Yates from a stream
//! seeded by base, digit position and seed), Owen's per-digit ones
//! Kensler's hashed permutation, so the values are not pbrt-v4's, only their
//! distribution; unlike pbrt-v4, the `owen` scramble depends on the seed. The film dimensions are never
//! randomised (pbrt-v4's rule), so the samples stay in their pixels.
//!
//! After the first 1000 primes the dimension wraps to 2, as in pbrt-v4.

use super::radical::{bases, for_each_digit, radical_inverse, to_unit, ScrambledHalton};
use crate::math::{UVec2, Vec2};
use crate::sampling::{hash_u64s, mix_bits};
use std::sync::Arc;

pub use super::radical::PRIME_TABLE_SIZE;

/// Film resolution beyond which the pixel pattern repeats [pbrt-v4].
const MAX_RESOLUTION: u32 = 128;

/// How the Halton points are randomised (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HaltonRandomize {
    /// The plain sequence.
    None,
    /// A random permutation per digit position and base (the default).
    PermuteDigits,
    /// Each digit permuted by a hash of the digits above it.
    Owen,
}

impl HaltonRandomize {
    /// The names pbrt-v4 accepts, for error messages.
    pub const NAMES: &'static str = "none, permutedigits, owen";

    /// From pbrt-v4's `"string randomization"` value.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "none" => Some(Self::None),
            "permutedigits" => Some(Self::PermuteDigits),
            "owen" => Some(Self::Owen),
            _ => None,
        }
    }
}

/// The index whose first `n` base-`b` digits, reversed, are `inverse`'s.
fn inverse_radical_inverse(mut inverse: u64, b: u64, n: u32) -> u64 {
    let mut index = 0;
    for _ in 0..n {
        index = index * b + inverse % b;
        inverse /= b;
    }
    index
}

/// x with a·x ≡ 1 (mod n), for coprime a and n ≥ 1.
fn multiplicative_inverse(a: i64, n: i64) -> u64 {
    // Extended Euclid on (a, n): old_s·a ≡ gcd (mod n).
    let (mut r0, mut r1, mut s0, mut s1) = (a, n, 1i64, 0i64);
    while r1 != 0 {
        let q = r0 / r1;
        (r0, r1) = (r1, r0 - q * r1);
        (s0, s1) = (s1, s0 - q * s1);
    }
    s0.rem_euclid(n) as u64
}

/// Element `i` of a hashed permutation of `0..l` chosen by `p` [Kensler
/// 2013, "Correlated Multi-Jittered Sampling", §3, `permute`], for the
/// Owen scramble's per-digit permutations. The hashed index permutation
/// padded Sobol used until stop 38 was not used in this module: its
/// few rounds reach a small family of the permutations of a handful of
/// elements, and as the digit tables it gave killeroo-simple (16 spp,
/// relMSE without the worst 0.1 % of pixels, seeds 0–2) 0.0044, 0.0058,
/// 0.0073 against 0.0040, 0.0042, 0.0049 with the uniform permutations of
/// [`shuffled`] (pbrt-v4's Halton: 0.0048, 0.0038, 0.0047). For the Owen
/// scramble the two measured alike (0.0046, 0.0044, 0.0077 against 0.0072,
/// 0.0043, 0.0042); Kensler's is kept as the better-mixed of the two.
fn kensler_permute(mut i: u32, l: u32, p: u32) -> u32 {
    let mut w = l - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    loop {
        i ^= p;
        i = i.wrapping_mul(0xe170_893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929_eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | p >> 27);
        i = i.wrapping_mul(0x6935_fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dc_b303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e50_1cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860_a3df);
        i &= w;
        i ^= i >> 5;
        if i < l {
            break;
        }
    }
    ((u64::from(i) + u64::from(p)) % u64::from(l)) as u32
}

/// The Halton sampler; see the module docs.
#[derive(Clone, Debug)]
pub struct HaltonSampler {
    spp: u32,
    seed: u64,
    randomize: HaltonRandomize,
    resolution: UVec2,
    /// 2^j and 3^k.
    scales: [u64; 2],
    /// j and k.
    exponents: [u32; 2],
    /// (3^k)⁻¹ mod 2^j and (2^j)⁻¹ mod 3^k.
    inverses: [u64; 2],
    permutations: Arc<ScrambledHalton>,
    index: u64,
    dimension: u32,
}

impl HaltonSampler {
    /// `spp` samples per pixel on a film of `resolution` pixels.
    pub fn new(spp: u32, seed: u64, resolution: UVec2, randomize: HaltonRandomize) -> Self {
        let mut scales = [1u64; 2];
        let mut exponents = [0u32; 2];
        for (i, base) in [2u64, 3].into_iter().enumerate() {
            let target = u64::from(resolution[i].clamp(1, MAX_RESOLUTION));
            while scales[i] < target {
                scales[i] *= base;
                exponents[i] += 1;
            }
        }
        let inverses = [
            multiplicative_inverse(scales[1] as i64, scales[0] as i64),
            multiplicative_inverse(scales[0] as i64, scales[1] as i64),
        ];
        Self {
            spp: spp.max(1),
            seed,
            randomize,
            resolution,
            scales,
            exponents,
            inverses,
            permutations: Arc::new(ScrambledHalton::new(seed)),
            index: 0,
            dimension: 2,
        }
    }

    /// Samples per pixel.
    pub fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    /// Same sampler with a different seed.
    pub fn with_seed(&self, seed: u64) -> Self {
        Self::new(self.spp, seed, self.resolution, self.randomize)
    }

    /// Positions the sampler at (pixel, sample index, dimension ≥ 2).
    pub fn start_pixel_sample(&mut self, pixel: UVec2, sample_index: u32, dimension: u32) {
        let stride = self.scales[0] * self.scales[1];
        let mut index = 0;
        if stride > 1 {
            for (i, base) in [2, 3].into_iter().enumerate() {
                let p = u64::from(pixel[i] % MAX_RESOLUTION);
                let offset = inverse_radical_inverse(p, base, self.exponents[i]);
                index += offset * (stride / self.scales[i]) * self.inverses[i];
            }
            index %= stride;
        }
        self.index = index + u64::from(sample_index) * stride;
        self.dimension = dimension.max(2);
    }

    /// The next dimension's value.
    pub fn get_1d(&mut self) -> f32 {
        if self.dimension as usize >= PRIME_TABLE_SIZE {
            self.dimension = 2;
        }
        let d = self.dimension;
        self.dimension += 1;
        self.sample_dimension(d as usize)
    }

    /// The next two dimensions' values.
    pub fn get_2d(&mut self) -> Vec2 {
        if self.dimension as usize + 1 >= PRIME_TABLE_SIZE {
            self.dimension = 2;
        }
        let d = self.dimension as usize;
        self.dimension += 2;
        Vec2::new(self.sample_dimension(d), self.sample_dimension(d + 1))
    }

    /// The offset inside the pixel: the film dimensions' digits beyond the
    /// pixel's, unrandomised (module docs).
    pub fn get_pixel_2d(&self) -> Vec2 {
        Vec2::new(
            radical_inverse(2, self.index >> self.exponents[0]),
            radical_inverse(3, self.index / self.scales[1]),
        )
    }

    fn sample_dimension(&self, d: usize) -> f32 {
        let base = &bases()[d];
        let reversed = match self.randomize {
            HaltonRandomize::None => return radical_inverse(base.b as u32, self.index),
            HaltonRandomize::PermuteDigits => self.permutations.table(d).reversed(base, self.index),
            HaltonRandomize::Owen => {
                let hash = hash_u64s(&[d as u64, self.seed, 0x6f77_656e]);
                let mut reversed = 0u64;
                for_each_digit(base, self.index, |v| {
                    let p = mix_bits(hash ^ reversed) as u32;
                    let v = kensler_permute(v as u32, base.b as u32, p);
                    reversed = reversed * base.b + u64::from(v);
                });
                reversed
            }
        };
        to_unit(reversed, base.inv_scale)
    }
}

#[cfg(test)]
mod tests {
    use super::super::radical::{digits, PRIMES};
    use super::*;

    #[test]
    fn primes_and_inverses() {
        assert_eq!(&PRIMES[..6], &[2, 3, 5, 7, 11, 13]);
        assert_eq!(PRIMES[PRIME_TABLE_SIZE - 1], 7919);
        for (a, n) in [(27i64, 128i64), (128, 243), (9, 8), (1, 1), (5, 3)] {
            assert_eq!(
                (a as u64 * multiplicative_inverse(a, n)) % n as u64,
                1 % n as u64
            );
        }
        assert_eq!(radical_inverse(2, 1), 0.5);
        assert_eq!(radical_inverse(3, 5), 7.0 / 9.0); // 5 = 12₃ → 0.21₃
        assert_eq!(digits(2), 25); // 1 − 2^−24 < 1 in f32, 1 − 2^−25 rounds to 1
    }

    /// Each pixel's samples lie in that pixel of the film's Halton points,
    /// and `get_pixel_2d` is their offset inside it.
    #[test]
    fn samples_land_in_their_pixel() {
        for res in [UVec2::new(8, 6), UVec2::new(37, 21), UVec2::new(300, 200)] {
            let s = HaltonSampler::new(4, 0, res, HaltonRandomize::PermuteDigits);
            let mut s = s.clone();
            for (x, y) in [(0, 0), (5, 3), (7, 5), (36, 20), (299, 199), (130, 3)] {
                if x >= res.x || y >= res.y {
                    continue;
                }
                for i in 0..4 {
                    s.start_pixel_sample(UVec2::new(x, y), i, 0);
                    let film = [radical_inverse(2, s.index), radical_inverse(3, s.index)];
                    let off = s.get_pixel_2d();
                    for (c, (f, o)) in film.into_iter().zip([off.x, off.y]).enumerate() {
                        let at = f as f64 * s.scales[c] as f64;
                        let want = [x, y][c] % MAX_RESOLUTION;
                        assert_eq!(at.floor() as u32, want, "{res:?} ({x}, {y}) {i} axis {c}");
                        assert!((at.fract() - o as f64).abs() < 1e-4, "{at} vs {o}");
                    }
                }
            }
        }
    }

    /// A pixel's first b^m samples put one value in each 1/b^m stratum, in
    /// the film dimensions' offsets and in a later dimension, for every
    /// randomisation (and, as a check that the test can fail, not for a
    /// count that is not a power of the base).
    #[test]
    fn a_pixels_samples_are_stratified() {
        let strata = |vals: &[f32], n: usize| {
            let mut seen = vec![false; n];
            vals.iter().all(|&v| {
                let k = (v as f64 * n as f64) as usize;
                !std::mem::replace(&mut seen[k], true)
            })
        };
        for r in [
            HaltonRandomize::None,
            HaltonRandomize::PermuteDigits,
            HaltonRandomize::Owen,
        ] {
            let mut s = HaltonSampler::new(64, 9, UVec2::new(40, 30), r);
            let px = UVec2::new(17, 11);
            let run = |s: &mut HaltonSampler, n: u32, f: &dyn Fn(&mut HaltonSampler) -> f32| {
                (0..n)
                    .map(|i| {
                        s.start_pixel_sample(px, i, 2);
                        f(s)
                    })
                    .collect::<Vec<f32>>()
            };
            let xs = run(&mut s, 16, &|s| s.get_pixel_2d().x);
            let ys = run(&mut s, 9, &|s| s.get_pixel_2d().y);
            let d2 = run(&mut s, 25, &|s| s.get_1d()); // base 5
            assert!(
                strata(&xs, 16) && strata(&ys, 9) && strata(&d2, 25),
                "{r:?}"
            );
            // Every other sample covers half the strata twice.
            let every_other: Vec<f32> = (0..16)
                .map(|i| {
                    s.start_pixel_sample(px, 2 * i, 2);
                    s.get_pixel_2d().x
                })
                .collect();
            assert!(!strata(&every_other, 16), "{r:?}");
        }
    }

    /// Randomisations differ from the plain sequence and from each other,
    /// and the seed changes the permutations.
    #[test]
    fn randomisations_and_seeds_change_the_values() {
        let first = |r, seed| {
            let mut s = HaltonSampler::new(16, seed, UVec2::new(64, 64), r);
            s.start_pixel_sample(UVec2::new(3, 4), 2, 2);
            (0..8).map(|_| s.get_1d()).collect::<Vec<f32>>()
        };
        let none = first(HaltonRandomize::None, 0);
        let perm = first(HaltonRandomize::PermuteDigits, 0);
        let owen = first(HaltonRandomize::Owen, 0);
        assert!(none != perm && perm != owen && none != owen);
        assert_eq!(none, first(HaltonRandomize::None, 5));
        assert_ne!(perm, first(HaltonRandomize::PermuteDigits, 5));
        assert_ne!(owen, first(HaltonRandomize::Owen, 5));
    }

    /// The hashed permutation is a bijection for every size, and over many
    /// seeds puts each element in each place about equally often.
    #[test]
    fn kensler_permutations_are_bijections_and_look_uniform() {
        for l in [1u32, 2, 3, 5, 7, 13, 100] {
            for p in [0u32, 1, 0xdead_beef, 77] {
                let mut seen = vec![false; l as usize];
                for i in 0..l {
                    let j = kensler_permute(i, l, p) as usize;
                    assert!(!std::mem::replace(&mut seen[j], true), "{l} {p}");
                }
            }
        }
        // Where element 0 of a 5-permutation goes over 5000 seeds: each
        // place 1000 ± 5σ (σ = √(5000·0.2·0.8) ≈ 28).
        let mut count = [0u32; 5];
        for p in 0..5000u32 {
            count[kensler_permute(0, 5, mix_bits(u64::from(p)) as u32) as usize] += 1;
        }
        assert!(count.iter().all(|&c| c.abs_diff(1000) < 142), "{count:?}");
    }

    /// After the last prime the dimension wraps to 2.
    #[test]
    fn dimensions_wrap_after_the_prime_table() {
        let mut s = HaltonSampler::new(4, 1, UVec2::new(16, 16), HaltonRandomize::PermuteDigits);
        s.start_pixel_sample(UVec2::new(1, 1), 1, 2);
        let d2 = s.get_1d();
        s.start_pixel_sample(UVec2::new(1, 1), 1, PRIME_TABLE_SIZE as u32);
        assert_eq!(s.get_1d(), d2);
    }
}
