//! Tests of the lights against closed forms (validation.md T1–T3) and of
//! their sampling routines against their densities (χ², pdf agreement).
//!
//! Stochastic assertions follow validation.md: fixed seeds, and pass when
//! |mean − expected| ≤ 5·s/√n + b, with s measured in the same run and b a
//! stated round-off allowance.

mod area_image;
mod chi2;
mod fixtures;
mod image_infinite;
mod irradiance;
pub(super) mod power;
mod punctual_maps;

use super::*;
use crate::math::Vec2;
use crate::sampling::Pcg32;
pub(super) use fixtures::Geo;

/// Constant emission spectrum (the one place tests build spectra).
pub(super) fn constant(v: f32) -> LightSpectrum {
    crate::spectrum::Spectrum::Constant(v)
}

/// Fixed wavelengths for tests.
pub(super) fn lambda() -> SampledWavelengths {
    SampledWavelengths::sample_visible(0.37)
}

/// Next 2D uniform sample.
pub(super) fn u2(r: &mut Pcg32) -> Vec2 {
    Vec2::new(r.uniform_f32(), r.uniform_f32())
}

/// Running mean and standard deviation of the samples (f64).
#[derive(Default)]
pub(super) struct Stats {
    n: u64,
    sum: f64,
    sum2: f64,
}

impl Stats {
    /// Adds one sample.
    pub(super) fn add(&mut self, x: f64) {
        self.n += 1;
        self.sum += x;
        self.sum2 += x * x;
    }
    /// Sample mean.
    pub(super) fn mean(&self) -> f64 {
        self.sum / self.n as f64
    }
    /// Standard error of the mean: s/√n.
    pub(super) fn sem(&self) -> f64 {
        let m = self.mean();
        let var =
            (self.sum2 / self.n as f64 - m * m).max(0.0) * self.n as f64 / (self.n - 1) as f64;
        (var / self.n as f64).sqrt()
    }
    /// Asserts |mean − expected| ≤ 5·s/√n + b.
    pub(super) fn assert_mean(&self, expected: f64, b: f64, what: &str) {
        let (m, e) = (self.mean(), self.sem());
        assert!(
            (m - expected).abs() <= 5.0 * e + b,
            "{what}: mean {m} expected {expected} (5σ = {}, b = {b})",
            5.0 * e
        );
    }
}

/// Axis-aligned square of side `s` centred at `c`, normal ±z (`down` = −z).
pub(super) fn square(c: Vec3, s: f32, down: bool) -> Geo {
    let (e1, e2) = if down {
        (Vec3::new(0.0, s, 0.0), Vec3::new(s, 0.0, 0.0))
    } else {
        (Vec3::new(s, 0.0, 0.0), Vec3::new(0.0, s, 0.0))
    };
    Geo::Quad {
        p0: c - 0.5 * (e1 + e2),
        e1,
        e2,
    }
}

/// Scene bounds used for lights at infinity: a box of bounding radius √3.
pub(super) fn unit_scene() -> crate::math::Bounds3 {
    crate::math::Bounds3::from_points(Vec3::splat(-1.0), Vec3::splat(1.0))
}
