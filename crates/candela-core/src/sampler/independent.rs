//! Independent uniform random samples [pbrt-v4 §8.3].

use super::pixel_hash;
use crate::math::{UVec2, Vec2};
use crate::sampling::{mix_bits, Pcg32};

/// Uniform samples from a PCG32 stream chosen by (pixel, seed) and advanced to
/// (sample index, dimension), so any sample can be replayed on its own.
#[derive(Clone, Debug)]
pub struct IndependentSampler {
    spp: u32,
    seed: u64,
    rng: Pcg32,
}

impl IndependentSampler {
    /// `spp` samples per pixel.
    pub fn new(spp: u32, seed: u64) -> Self {
        Self {
            spp: spp.max(1),
            seed,
            rng: Pcg32::new(0, 0),
        }
    }

    /// Samples per pixel.
    pub fn samples_per_pixel(&self) -> u32 {
        self.spp
    }

    /// Same sampler with a different seed.
    pub fn with_seed(&self, seed: u64) -> Self {
        Self::new(self.spp, seed)
    }

    /// Selects the stream of `pixel` and skips 2^16 values per sample index.
    pub fn start_pixel_sample(&mut self, pixel: UVec2, sample_index: u32, dimension: u32) {
        let h = pixel_hash(pixel, 0, self.seed);
        self.rng = Pcg32::new(mix_bits(h), h);
        self.rng
            .advance(u64::from(sample_index) * 65536 + u64::from(dimension));
    }

    /// One uniform value in [0, 1).
    pub fn get_1d(&mut self) -> f32 {
        self.rng.uniform_f32()
    }

    /// Two uniform values in [0, 1).
    pub fn get_2d(&mut self) -> Vec2 {
        let x = self.rng.uniform_f32();
        Vec2::new(x, self.rng.uniform_f32())
    }
}
