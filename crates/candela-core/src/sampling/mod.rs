//! Random numbers, hashing, warps from [0,1)² to common domains, tabulated
//! distributions, and densities tagged with their measure.

/// χ² goodness-of-fit harness for direction samplers (test support).
pub mod chi2;
mod distribution;
mod equal_area;
mod hash;
mod pdf;
mod rng;
mod warp;

pub use distribution::{Distribution1D, Distribution2D};
pub use equal_area::{equal_area_sphere_to_square, equal_area_square_to_sphere};
pub use hash::{hash_u64s, hash_u64s_from, mix_bits, murmur_hash64a};
pub use pdf::{pdf_area_to_solid_angle, pdf_solid_angle_to_area, PdfArea, PdfSolidAngle};
pub use rng::{PathRng, Pcg32, StreamRng};
pub use warp::*;

/// Largest float below 1: samples are clamped to `[0, ONE_MINUS_EPSILON]`.
pub const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

/// Power heuristic with β = 2 for `nf` samples of density `f_pdf` against
/// `ng` of `g_pdf` [Veach 1997, eq. 9.13]. The squares are taken in f64:
/// in f32 a density above ~1.8·10¹⁹ (a light sampled at grazing angle from
/// a point in its own plane) squares to ∞ and the weight to ∞/∞ = NaN.
#[inline]
pub fn power_heuristic(nf: f32, f_pdf: f32, ng: f32, g_pdf: f32) -> f32 {
    let f = nf as f64 * f_pdf as f64;
    let g = ng as f64 * g_pdf as f64;
    if f.is_infinite() {
        return 1.0;
    }
    if f == 0.0 && g == 0.0 {
        return 0.0;
    }
    ((f * f) / (f * f + g * g)) as f32
}

#[cfg(test)]
mod heuristic_tests {
    use super::power_heuristic;

    #[test]
    fn power_heuristic_survives_huge_densities() {
        assert_eq!(power_heuristic(1.0, 3.8e19, 1.0, 0.3), 1.0);
        assert!(power_heuristic(1.0, 0.3, 1.0, 3.8e19) < 1e-38);
        let w = power_heuristic(1.0, 3e19, 1.0, 4e19);
        assert!((w - 9.0 / 25.0).abs() < 1e-6, "{w}");
        assert_eq!(power_heuristic(1.0, f32::INFINITY, 1.0, 1.0), 1.0);
        assert_eq!(power_heuristic(1.0, 0.0, 1.0, 0.0), 0.0);
    }
}
