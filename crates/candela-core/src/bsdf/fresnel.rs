//! Fresnel reflectance and Snell refraction.
//!
//! For a smooth interface between media of real indices the unpolarised
//! reflectance is the mean of the squared amplitude coefficients
//! r∥ = (η cos θi − cos θt)/(η cos θi + cos θt) and
//! r⊥ = (cos θi − η cos θt)/(cos θi + η cos θt) [pbrt-v4 §9.3],
//! with η = ηt/ηi the relative index and cos θt from Snell's law. Conductors use
//! the same formulas with the complex index η + ik [pbrt-v4 §9.3]. Throughout,
//! `eta` is the index of the side *below* the surface (−z) over the side above
//! (+z); a cosine below zero means the ray arrives from below and η is inverted.

use crate::math::Vec3;
use crate::spectrum::SampledSpectrum;
use std::ops::{Add, Div, Mul, Sub};

/// Minimal complex number for conductor Fresnel terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Complex {
    /// Real part.
    pub re: f32,
    /// Imaginary part.
    pub im: f32,
}

impl Complex {
    /// `re + i·im`.
    #[inline]
    pub const fn new(re: f32, im: f32) -> Self {
        Self { re, im }
    }
    /// Squared magnitude |z|².
    #[inline]
    pub fn norm(self) -> f32 {
        self.re * self.re + self.im * self.im
    }
    /// Principal square root (branch cut on the negative real axis).
    pub fn sqrt(self) -> Self {
        let n = self.norm().sqrt();
        if n == 0.0 {
            return Self::new(0.0, 0.0);
        }
        // sqrt(z) = t1 + i·t2 with t1 = √((|z| + |re|)/2), t2 = im/(2 t1).
        let t1 = (0.5 * (n + self.re.abs())).sqrt();
        let t2 = 0.5 * self.im / t1;
        if self.re >= 0.0 {
            Self::new(t1, t2)
        } else {
            Self::new(t2.abs(), t1.copysign(self.im))
        }
    }
}

impl Add for Complex {
    type Output = Self;
    #[inline]
    fn add(self, o: Self) -> Self {
        Self::new(self.re + o.re, self.im + o.im)
    }
}

impl Sub for Complex {
    type Output = Self;
    #[inline]
    fn sub(self, o: Self) -> Self {
        Self::new(self.re - o.re, self.im - o.im)
    }
}

impl Mul for Complex {
    type Output = Self;
    #[inline]
    fn mul(self, o: Self) -> Self {
        Self::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}

impl Div for Complex {
    type Output = Self;
    #[inline]
    fn div(self, o: Self) -> Self {
        let s = 1.0 / o.norm();
        Self::new(
            s * (self.re * o.re + self.im * o.im),
            s * (self.im * o.re - self.re * o.im),
        )
    }
}

impl From<f32> for Complex {
    #[inline]
    fn from(re: f32) -> Self {
        Self::new(re, 0.0)
    }
}

/// Unpolarised Fresnel reflectance of a dielectric interface [pbrt-v4 §9.3].
///
/// `cos_theta_i` is signed: negative means incidence from below, which inverts
/// `eta`. Returns 1 under total internal reflection.
pub fn fr_dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    let mut cos_i = cos_theta_i.clamp(-1.0, 1.0);
    let mut eta = eta;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    // Snell: sin θt = sin θi / η.
    let sin2_i = 1.0 - cos_i * cos_i;
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// Dielectric transmittance 1 − F without the cancellation of `1 − fr_dielectric`
/// near grazing incidence: with 1 − r² = (1 − r)(1 + r),
/// T = 2η cos θi cos θt [1/(η cos θi + cos θt)² + 1/(cos θi + η cos θt)²].
/// Same conventions as [`fr_dielectric`]; 0 under total internal reflection.
pub fn ft_dielectric(cos_theta_i: f32, eta: f32) -> f32 {
    let mut cos_i = cos_theta_i.clamp(-1.0, 1.0);
    let mut eta = eta;
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
    }
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 0.0;
    }
    ft_dielectric_pair(cos_i, (1.0 - sin2_t).max(0.0).sqrt(), eta)
}

/// Dielectric transmittance from both cosines of a refraction pair (unsigned,
/// measured against the same normal) and the relative index `eta` = ηt/ηi.
///
/// The formula of [`ft_dielectric`] with cos θt taken from the geometry
/// instead of Snell's law. It is exactly symmetric under (cos θi, cos θt, η) ↔
/// (cos θt, cos θi, 1/η), so a rough BTDF built on it is reciprocal to
/// round-off even near the critical angle, where √(1 − sin²θt) loses digits.
pub fn ft_dielectric_pair(cos_i: f32, cos_t: f32, eta: f32) -> f32 {
    let a = eta * cos_i + cos_t;
    let b = cos_i + eta * cos_t;
    2.0 * eta * cos_i * cos_t * (1.0 / (a * a) + 1.0 / (b * b))
}

/// Fresnel reflectance of a conductor with complex index `eta` (= η + ik)
/// [pbrt-v4 §9.3]; `cos_theta_i` is clamped to [0, 1].
pub fn fr_complex(cos_theta_i: f32, eta: Complex) -> f32 {
    let cos_i = cos_theta_i.clamp(0.0, 1.0);
    let sin2_i = 1.0 - cos_i * cos_i;
    // Complex Snell's law: sin²θt = sin²θi / η², cos θt = √(1 − sin²θt).
    let sin2_t = Complex::from(sin2_i) / (eta * eta);
    let cos_t = (Complex::from(1.0) - sin2_t).sqrt();
    let ci = Complex::from(cos_i);
    let r_parl = (eta * ci - cos_t) / (eta * ci + cos_t);
    let r_perp = (ci - eta * cos_t) / (ci + eta * cos_t);
    0.5 * (r_parl.norm() + r_perp.norm())
}

/// [`fr_complex`] for every wavelength of a sampled spectrum (η + ik per λ).
pub fn fr_complex_spectral(
    cos_theta_i: f32,
    eta: SampledSpectrum,
    k: SampledSpectrum,
) -> SampledSpectrum {
    SampledSpectrum::from_fn(|i| fr_complex(cos_theta_i, Complex::new(eta[i], k[i])))
}

/// Refracts `wi` through the interface with normal `n` and relative index `eta`
/// (index on the side opposite `n` over the side of `n`) [pbrt-v4 §9.3].
///
/// Both directions point away from the surface. Returns the transmitted
/// direction and the relative index actually crossed (`eta` or `1/eta` when
/// `wi` lies below `n`), or `None` under total internal reflection.
pub fn refract(wi: Vec3, n: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let mut cos_i = n.dot(wi);
    let (mut eta, mut n) = (eta, n);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        n = -n;
    }
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let wt = -wi / eta + (cos_i / eta - cos_t) * n;
    Some((wt, eta))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dielectric_limits() {
        for eta in [1.33f32, 1.5, 2.4] {
            // Normal incidence: ((η − 1)/(η + 1))², the same from either side.
            let r0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
            assert!((fr_dielectric(1.0, eta) - r0).abs() < 1e-6);
            assert!((fr_dielectric(-1.0, eta) - r0).abs() < 1e-6);
            // Grazing incidence reflects everything.
            assert!((fr_dielectric(0.0, eta) - 1.0).abs() < 1e-6);
            // Beyond the critical angle from the dense side: total internal reflection.
            let cos_crit = (1.0 - 1.0 / (eta * eta)).sqrt();
            assert_eq!(fr_dielectric(-(cos_crit - 1e-3), eta), 1.0);
            assert!(fr_dielectric(-(cos_crit + 1e-3), eta) < 1.0);
        }
        assert!(fr_dielectric(0.3, 1.0) < 1e-12);
    }

    #[test]
    fn transmittance_complements_reflectance() {
        for eta in [1.5f32, 1.0 / 1.5, 1.0] {
            for i in 0..=200 {
                let c = -1.0 + i as f32 / 100.0;
                let (r, t) = (fr_dielectric(c, eta), ft_dielectric(c, eta));
                assert!((r + t - 1.0).abs() < 1e-6, "η={eta} cos={c}: {r} + {t}");
            }
        }
        // Near grazing, T is accurate where 1 − R has lost most digits:
        // T ≈ 4η cos θi/(η² − 1)^{1/2}·… is linear in cos θi, so halving cos halves T.
        let (t1, t2) = (ft_dielectric(2e-6, 1.5), ft_dielectric(1e-6, 1.5));
        assert!((t1 / t2 - 2.0).abs() < 1e-4, "{t1} {t2}");
        // The two-cosine form agrees with Snell's and is symmetric.
        let (ci, eta) = (0.4f32, 1.5f32);
        let ct = (1.0 - (1.0 - ci * ci) / (eta * eta)).sqrt();
        let t = ft_dielectric_pair(ci, ct, eta);
        assert!((t - ft_dielectric(ci, eta)).abs() < 1e-6);
        assert!((t - ft_dielectric_pair(ct, ci, 1.0 / eta)).abs() < 1e-6);
    }

    #[test]
    fn complex_reduces_to_dielectric_for_k_zero() {
        for &c in &[1.0f32, 0.8, 0.4, 0.1] {
            let a = fr_complex(c, Complex::new(1.5, 0.0));
            assert!((a - fr_dielectric(c, 1.5)).abs() < 1e-5, "{c}: {a}");
        }
        // Gold-like index at normal incidence: ((n−1)² + k²)/((n+1)² + k²).
        let (n, k) = (0.2f32, 3.0f32);
        let r0 = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        assert!((fr_complex(1.0, Complex::new(n, k)) - r0).abs() < 1e-5);
    }

    #[test]
    fn refraction_obeys_snell_and_reverses() {
        let n = Vec3::Z;
        let wi = Vec3::new(0.6, 0.0, 0.8);
        let (wt, etap) = refract(wi, n, 1.5).unwrap();
        assert_eq!(etap, 1.5);
        assert!((wt.length() - 1.0).abs() < 1e-6 && wt.z < 0.0);
        // η_i sin θi = η_t sin θt.
        assert!((0.6 - 1.5 * wt.x.abs()).abs() < 1e-6);
        let (back, etap2) = refract(wt, n, 1.5).unwrap();
        assert!((back - wi).length() < 1e-5 && (etap2 - 1.0 / 1.5).abs() < 1e-7);
        // Past the critical angle from inside: nothing is transmitted.
        assert!(refract(Vec3::new(0.9, 0.0, -0.436).normalize(), n, 1.5).is_none());
    }
}
