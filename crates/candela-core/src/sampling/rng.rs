//! Random numbers: the PCG32 generator [O'Neill 2014] and [`PathRng`], the
//! one interface through which every path walk draws its uniform numbers.
//!
//! A walk is served either by the [`Sampler`] (camera-driven estimators:
//! values are functions of pixel, sample index and dimension) or by a
//! [`StreamRng`], a counter-based stream: PCG32 seeded by a hash of
//! (seed, pass, index), so light path or photon `index` of `pass` draws the
//! same numbers whatever thread traces it and in whatever order.

use super::hash_u64s;
use crate::math::Vec2;
use crate::sampler::Sampler;

/// Uniform numbers in [0, 1) for a path walk, one or two at a time.
pub trait PathRng {
    /// The next number.
    fn u1(&mut self) -> f32;
    /// The next two numbers (a 2D sample of the sampler).
    fn u2(&mut self) -> Vec2;
}

impl PathRng for Sampler {
    #[inline]
    fn u1(&mut self) -> f32 {
        self.get_1d()
    }
    #[inline]
    fn u2(&mut self) -> Vec2 {
        self.get_2d()
    }
}

/// The numbers of path `index` of `pass`: PCG32 seeded by hash(seed, pass, index).
#[derive(Clone, Debug)]
pub struct StreamRng(Pcg32);

impl StreamRng {
    /// The stream of path `index` of `pass` under `seed`.
    pub fn new(seed: u64, pass: u64, index: u64) -> Self {
        Self(Pcg32::new(hash_u64s(&[seed, pass, index]), 0))
    }
    /// TEMPORARY: a stream from a precomputed hash.
    pub fn with_hash(h: u64) -> Self {
        Self(Pcg32::new(h, 0))
    }
}

impl PathRng for StreamRng {
    #[inline]
    fn u1(&mut self) -> f32 {
        self.0.uniform_f32()
    }
    #[inline]
    fn u2(&mut self) -> Vec2 {
        let x = self.0.uniform_f32();
        Vec2::new(x, self.0.uniform_f32())
    }
}

/// PCG-XSH-RR 64/32: small state, good statistics, seekable streams.
#[derive(Clone, Debug)]
pub struct Pcg32 {
    state: u64,
    inc: u64,
}

const MULT: u64 = 0x5851_f42d_4c95_7f2d;

impl Pcg32 {
    /// Generator for `(seed_index, stream)`; distinct streams are independent.
    pub fn new(seed_index: u64, stream: u64) -> Self {
        let mut r = Self {
            state: 0,
            inc: (stream << 1) | 1,
        };
        r.next_u32();
        r.state = r.state.wrapping_add(seed_index);
        r.next_u32();
        r
    }

    /// Next 32 random bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(MULT).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform float in [0, 1).
    #[inline]
    pub fn uniform_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// Uniform double in [0, 1).
    #[inline]
    pub fn uniform_f64(&mut self) -> f64 {
        let hi = (self.next_u32() as u64) << 21;
        let lo = (self.next_u32() >> 11) as u64;
        (hi | lo) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Skips `delta` outputs in O(log delta) [Brown 1994].
    pub fn advance(&mut self, delta: u64) {
        let (mut cur_mult, mut cur_plus) = (MULT, self.inc);
        let (mut acc_mult, mut acc_plus) = (1u64, 0u64);
        let mut d = delta;
        while d > 0 {
            if d & 1 == 1 {
                acc_mult = acc_mult.wrapping_mul(cur_mult);
                acc_plus = acc_plus.wrapping_mul(cur_mult).wrapping_add(cur_plus);
            }
            cur_plus = cur_mult.wrapping_add(1).wrapping_mul(cur_plus);
            cur_mult = cur_mult.wrapping_mul(cur_mult);
            d >>= 1;
        }
        self.state = acc_mult.wrapping_mul(self.state).wrapping_add(acc_plus);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advance_equals_stepping() {
        let mut a = Pcg32::new(7, 3);
        let mut b = a.clone();
        for _ in 0..1000 {
            a.next_u32();
        }
        b.advance(1000);
        assert_eq!(a.next_u32(), b.next_u32());
    }

    #[test]
    fn uniform_mean_within_5_sigma() {
        // mean of U(0,1) is 1/2 with σ = 1/√12 per sample.
        let mut r = Pcg32::new(1, 0);
        let n = 1_000_000;
        let m: f64 = (0..n).map(|_| r.uniform_f32() as f64).sum::<f64>() / n as f64;
        assert!((m - 0.5).abs() < 5.0 * (1.0f64 / 12.0).sqrt() / (n as f64).sqrt());
    }
}
