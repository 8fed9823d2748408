//! ZSobol sampler, pbrt-v4's default [Ahmed & Wonka 2020, "Screen-Space
//! Blue-Noise Diffusion of Monte Carlo Sampling Error via Hierarchical
//! Ordering of Pixels"; pbrt-v4 §8.7.7].
//!
//! Every pixel sample of the image is one point of a single Sobol sequence
//! over the first two Sobol dimensions (the same two, and the same
//! scrambles, as [`super::PaddedSobolSampler`]; no direction-number table).
//! The pixels are visited in Morton (Z) order and each takes a block of
//! 2^m consecutive indices, 2^m ≥ spp: the Morton index of pixel (x, y)
//! shifted left by m, plus the sample number. So the samples of one pixel
//! are an aligned block of the sequence, and so are those of every aligned
//! 2×2, 4×4, … square of pixels: each 2D request is a (0, 2)-net over a
//! pixel and over every such square at once, which spreads the error of
//! neighbouring pixels apart (blue noise) instead of repeating one pattern
//! in each pixel.
//!
//! Each request ("dimension" d) needs its own ordering, or all dimensions
//! would share one set of points. Before the Sobol point is looked up, the
//! index is permuted base-4 digit by base-4 digit, from the most
//! significant down: each digit goes through one of the 24 permutations of
//! {0, 1, 2, 3}, chosen by a hash of d and of the digits above it. That
//! permutes pixels (and samples) among the blocks of each square level by
//! level, so every aligned block stays an aligned block and the nets
//! survive. With m odd the lowest digit is binary and is flipped by a
//! hashed bit. Then the coordinate is scrambled ([`ZSobolRandomize`]).
//!
//! Passes beyond 2^m (a time-limited or merged render asking for more
//! samples than the scene's `pixelsamples`) start a new epoch: the same
//! construction with its own hashes, so every group of 2^m passes is a
//! fresh ZSobol point set.

use super::sample_from_bits;
use super::sobol::{owen_scramble, sobol_bits};
use crate::math::{UVec2, Vec2};
use crate::sampling::{hash_u64s, mix_bits};

/// How each coordinate is randomised (pbrt-v4's `"string randomization"`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ZSobolRandomize {
    /// The plain sequence (only the index permutation).
    None,
    /// Every binary digit flipped by a hashed bit per dimension (a random
    /// digital shift in base 2).
    PermuteDigits,
    /// A nested uniform scramble by the hash of `owen_scramble` (the default).
    FastOwen,
    /// Owen's scramble bit by bit: each bit flipped by a hash of the bits
    /// above it.
    Owen,
}

impl ZSobolRandomize {
    /// The names pbrt-v4 accepts, for error messages.
    pub const NAMES: &'static str = "none, permutedigits, fastowen, owen";

    /// From pbrt-v4's `"string randomization"` value.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "none" => Some(Self::None),
            "permutedigits" => Some(Self::PermuteDigits),
            "fastowen" => Some(Self::FastOwen),
            "owen" => Some(Self::Owen),
            _ => None,
        }
    }

    /// Randomises the 32 fraction bits `v` with `seed`.
    #[inline]
    fn apply(self, v: u32, seed: u32) -> u32 {
        match self {
            Self::None => v,
            Self::PermuteDigits => v ^ seed,
            Self::FastOwen => owen_scramble(v, seed),
            Self::Owen => owen_bitwise(v, seed),
        }
    }
}

/// Owen scrambling one bit at a time: bit 31 − b flips when a hash of the b
/// bits above it (and the seed) says so [Owen 1995].
fn owen_bitwise(mut v: u32, seed: u32) -> u32 {
    if seed & 1 != 0 {
        v ^= 1 << 31;
    }
    for b in 1..32 {
        let above = v & (u32::MAX << (32 - b));
        if mix_bits(u64::from(above) ^ (u64::from(seed) << 32) ^ b as u64) & 1 != 0 {
            v ^= 1 << (31 - b);
        }
    }
    v
}

/// The 24 permutations of {0, 1, 2, 3}, in lexicographic order.
const PERMUTATIONS: [[u8; 4]; 24] = permutations4();

const fn permutations4() -> [[u8; 4]; 24] {
    let mut out = [[0u8; 4]; 24];
    let mut n = 0;
    let mut a = 0;
    while a < 4 {
        let mut b = 0;
        while b < 4 {
            let mut c = 0;
            while c < 4 {
                if a != b && b != c && a != c {
                    out[n] = [a, b, c, 6 - a - b - c];
                    n += 1;
                }
                c += 1;
            }
            b += 1;
        }
        a += 1;
    }
    out
}

/// Interleaves the bits of x (even positions) and y (odd positions).
#[inline]
fn morton2(x: u32, y: u32) -> u64 {
    fn spread(v: u32) -> u64 {
        let mut v = u64::from(v);
        v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
        v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        (v | (v << 1)) & 0x5555_5555_5555_5555
    }
    spread(x) | (spread(y) << 1)
}

/// ZSobol sampler; see the module docs.
#[derive(Clone, Debug)]
pub struct ZSobolSampler {
    spp: u32,
    seed: u64,
    randomize: ZSobolRandomize,
    /// m: log2 of the samples per pixel rounded up to a power of two.
    log2_spp: u32,
    /// Base-4 digits of a Morton index with its sample bits.
    base4_digits: u32,
    /// Morton index of the current pixel sample (pixel bits, then m sample bits).
    morton: u64,
    /// Hash of (epoch, seed) of the current pass.
    epoch_hash: u64,
    dimension: u32,
}

impl ZSobolSampler {
    /// `spp` samples per pixel (rounded up to a power of two for the index
    /// blocks) for a film of `resolution` pixels (its full size).
    pub fn new(spp: u32, seed: u64, resolution: UVec2, randomize: ZSobolRandomize) -> Self {
        let spp = spp.max(1);
        let log2_spp = spp
            .checked_next_power_of_two()
            .map_or(31, |n| n.trailing_zeros().min(31));
        // Films up to 65536 pixels a side: with 2^31 samples a pixel the
        // Morton index still fits in 63 bits.
        let side = resolution
            .x
            .max(resolution.y)
            .clamp(1, 1 << 16)
            .next_power_of_two();
        let base4_digits = side.trailing_zeros() + log2_spp.div_ceil(2);
        let mut s = Self {
            spp,
            seed,
            randomize,
            log2_spp,
            base4_digits,
            morton: 0,
            epoch_hash: 0,
            dimension: 0,
        };
        s.start_pixel_sample(UVec2::ZERO, 0, 0);
        s
    }

    /// Samples per pixel.
    pub fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    /// Same sampler with a different seed.
    pub fn with_seed(&self, seed: u64) -> Self {
        let mut s = Self {
            seed,
            ..self.clone()
        };
        s.start_pixel_sample(UVec2::ZERO, 0, 0);
        s
    }

    /// Positions the sampler at (pixel, sample index, first dimension).
    pub fn start_pixel_sample(&mut self, pixel: UVec2, sample_index: u32, dimension: u32) {
        let block = (1u64 << self.log2_spp) - 1;
        let (epoch, index) = (
            u64::from(sample_index) >> self.log2_spp,
            u64::from(sample_index) & block,
        );
        self.morton = (morton2(pixel.x, pixel.y) << self.log2_spp) | index;
        self.epoch_hash = hash_u64s(&[epoch, self.seed, 0x7a73_6f62]);
        self.dimension = dimension;
    }

    /// The Sobol index of the current pixel sample for dimension `d`: the
    /// Morton index with its base-4 digits permuted (module doc).
    fn sample_index(&self, d: u32) -> u64 {
        let h = self.epoch_hash ^ u64::from(d).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        // With m odd, digits sit one bit up and bit 0 is a binary digit.
        let odd = self.log2_spp & 1;
        let mut index = 0;
        for i in (odd..self.base4_digits).rev() {
            let shift = 2 * i - odd;
            let digit = (self.morton >> shift) & 3;
            let above = self.morton >> (shift + 2);
            let p = (mix_bits(above ^ h) >> 40) % 24;
            index |= u64::from(PERMUTATIONS[p as usize][digit as usize]) << shift;
        }
        if odd == 1 {
            let bit = (self.morton & 1) ^ (mix_bits((self.morton >> 1) ^ h ^ 0x5555_5555) & 1);
            index |= bit;
        }
        index
    }

    /// Seeds of the coordinates' scrambles for dimension `d`.
    fn scramble_seeds(&self, d: u32) -> (u32, u32) {
        let h = mix_bits(self.epoch_hash ^ u64::from(d) ^ 0xd1b5_4a32_d192_ed03);
        (h as u32, (h >> 32) as u32)
    }

    /// One coordinate (Sobol dimension 0 of the dimension's point).
    pub fn get_1d(&mut self) -> f32 {
        let d = self.dimension;
        self.dimension += 1;
        let index = self.sample_index(d);
        let (s, _) = self.scramble_seeds(d);
        sample_from_bits(self.randomize.apply(sobol_bits(index, 0), s))
    }

    /// Two coordinates (Sobol dimensions 0 and 1 of the dimension's point).
    pub fn get_2d(&mut self) -> Vec2 {
        let d = self.dimension;
        self.dimension += 2;
        let index = self.sample_index(d);
        let (s0, s1) = self.scramble_seeds(d);
        Vec2::new(
            sample_from_bits(self.randomize.apply(sobol_bits(index, 0), s0)),
            sample_from_bits(self.randomize.apply(sobol_bits(index, 1), s1)),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permutations_and_morton_order() {
        // 24 distinct permutations of 0..4.
        let mut seen = std::collections::HashSet::new();
        for p in PERMUTATIONS {
            let mut s = p;
            s.sort_unstable();
            assert_eq!(s, [0, 1, 2, 3]);
            assert!(seen.insert(p));
        }
        // x = 101, y = 1001: bits y3 x3 y2 x2 y1 x1 y0 x0 = 1 0 0 1 0 0 1 1.
        assert_eq!(morton2(0b101, 0b1001), 0b1001_0011);
    }

    #[test]
    fn owen_bitwise_is_a_bijection_that_keeps_prefix_structure() {
        // Bits 8.. of the output depend only on bits 8.. of the input and
        // the seed: the 256 inputs sharing their top 24 bits map to outputs
        // sharing theirs, all distinct in the low 8.
        for seed in [0u32, 1, 0xdead_beef] {
            let outs: Vec<u32> = (0..256u32)
                .map(|i| owen_bitwise(0xabcd_e100 | i, seed))
                .collect();
            let mut low: Vec<u32> = outs.iter().map(|o| o & 0xff).collect();
            low.sort_unstable();
            assert!(
                low.iter().enumerate().all(|(i, &v)| v == i as u32),
                "{seed:#x}"
            );
            assert!(outs.iter().all(|o| o >> 8 == outs[0] >> 8), "{seed:#x}");
        }
    }
}
