//! Trowbridge–Reitz (GGX) microfacet distribution.
//!
//! The anisotropic GGX normal distribution [Walter et al. 2007, eq. 33;
//! pbrt-v4 §9.6] is
//! D(ωm) = 1 / (π αx αy cos⁴θm (1 + e)²), e = tan²θm (cos²φm/αx² + sin²φm/αy²).
//! Masking uses Smith's model with
//! Λ(ω) = (√(1 + α²(ω) tan²θ) − 1)/2, α²(ω) = αx² cos²φ + αy² sin²φ
//! [Heitz 2014, §5; pbrt-v4 §9.6], G1 = 1/(1 + Λ) and the joint
//! masking-shadowing G = 1/(1 + Λ(ωo) + Λ(ωi)) (height-correlated form,
//! [Heitz 2014, §6; pbrt-v4 §9.6]).
//!
//! Sampling draws only the normals visible from ω, with density
//! D_ω(ωm) = G1(ω) max(0, ω·ωm) D(ωm) / cos θ [Heitz 2018, eq. 1;
//! pbrt-v4 §9.6]: the view is stretched to the unit-roughness
//! configuration, a point is drawn on the projected hemisphere (a disk whose
//! lower half is squashed by (1 + cos θh)/2), lifted, and un-stretched
//! [Heitz 2018, §4].

use crate::math::{lerp, local, safe_sqrt, sqr, Vec2, Vec3, PI};
use crate::sampling::sample_uniform_disk_polar;

/// Anisotropic Trowbridge–Reitz distribution of microfacet normals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrowbridgeReitz {
    alpha_x: f32,
    alpha_y: f32,
}

impl TrowbridgeReitz {
    /// Distribution with roughness `alpha_x` along the tangent and `alpha_y` along the bitangent.
    pub fn new(alpha_x: f32, alpha_y: f32) -> Self {
        let d = Self { alpha_x, alpha_y };
        if d.effectively_smooth() {
            return d;
        }
        // Very small but not smooth α under- or overflows D: clamp as pbrt-v4 does.
        Self {
            alpha_x: alpha_x.max(1e-4),
            alpha_y: alpha_y.max(1e-4),
        }
    }

    /// pbrt-v4's mapping from user roughness to α: √roughness.
    pub fn roughness_to_alpha(roughness: f32) -> f32 {
        roughness.max(0.0).sqrt()
    }

    /// α along x.
    pub fn alpha_x(&self) -> f32 {
        self.alpha_x
    }

    /// α along y.
    pub fn alpha_y(&self) -> f32 {
        self.alpha_y
    }

    /// Narrow enough to be treated as a perfect mirror (max α < 10⁻³).
    #[inline]
    pub fn effectively_smooth(&self) -> bool {
        self.alpha_x.max(self.alpha_y) < 1e-3
    }

    /// Widens narrow lobes for path regularisation [pbrt-v4 §13.4]:
    /// α < 0.3 becomes clamp(2α, 0.1, 0.3).
    pub fn regularize(&mut self) {
        if self.alpha_x < 0.3 {
            self.alpha_x = (2.0 * self.alpha_x).clamp(0.1, 0.3);
        }
        if self.alpha_y < 0.3 {
            self.alpha_y = (2.0 * self.alpha_y).clamp(0.1, 0.3);
        }
    }

    /// Normal distribution D(ωm) [Walter et al. 2007, eq. 33].
    ///
    /// tan²θ (cos²φ/α_x² + sin²φ/α_y²) is written (x²/α_x² + y²/α_y²)/z²,
    /// and likewise in [`Self::lambda`]: no sin θ, no division for cos φ and
    /// sin φ (D and Λ are evaluated several times per rough scattering, and
    /// many times in a coated surface's walk).
    #[inline]
    pub fn d(&self, wm: Vec3) -> f32 {
        let z2 = wm.z * wm.z;
        let cos4 = z2 * z2;
        if cos4 < 1e-16 {
            return 0.0;
        }
        let e = (sqr(wm.x / self.alpha_x) + sqr(wm.y / self.alpha_y)) / z2;
        if !e.is_finite() {
            return 0.0;
        }
        1.0 / (PI * self.alpha_x * self.alpha_y * cos4 * sqr(1.0 + e))
    }

    /// Smith auxiliary function Λ(ω) [Heitz 2014, §5]; 0 where tan θ is
    /// infinite (pbrt-v4's convention).
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let alpha2_tan2 = (sqr(self.alpha_x * w.x) + sqr(self.alpha_y * w.y)) / (w.z * w.z);
        if !alpha2_tan2.is_finite() {
            return 0.0;
        }
        ((1.0 + alpha2_tan2).sqrt() - 1.0) / 2.0
    }

    /// Masking G1(ω) = 1/(1 + Λ(ω)).
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking-shadowing G(ωo, ωi) = 1/(1 + Λ(ωo) + Λ(ωi)).
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// Visible-normal distribution D_ω(ωm) = G1(ω)/|cos θ| · D(ωm) · |ω·ωm| [Heitz 2018, eq. 1].
    #[inline]
    pub fn d_visible(&self, w: Vec3, wm: Vec3) -> f32 {
        self.g1(w) / local::abs_cos_theta(w) * self.d(wm) * w.dot(wm).abs()
    }

    /// Density of [`Self::sample_wm`] per unit solid angle of ωm.
    #[inline]
    pub fn pdf(&self, w: Vec3, wm: Vec3) -> f32 {
        self.d_visible(w, wm)
    }

    /// Samples a normal visible from `w` (either hemisphere) [Heitz 2018, §4];
    /// the result always lies in the +z hemisphere.
    pub fn sample_wm(&self, w: Vec3, u: Vec2) -> Vec3 {
        // Stretch to the α = 1 configuration.
        let mut wh = Vec3::new(self.alpha_x * w.x, self.alpha_y * w.y, w.z).normalize();
        if wh.z < 0.0 {
            wh = -wh;
        }
        // Orthonormal basis around the stretched view.
        let t1 = if wh.z < 0.99999 {
            Vec3::Z.cross(wh).normalize()
        } else {
            Vec3::X
        };
        let t2 = wh.cross(t1);
        // Uniform disk point, squashed on the half hidden by the view [Heitz 2018, eq. 8].
        let mut p = sample_uniform_disk_polar(u);
        let h = (1.0 - p.x * p.x).sqrt();
        p.y = lerp((1.0 + wh.z) / 2.0, h, p.y);
        // Lift to the hemisphere and unstretch the normal.
        let pz = safe_sqrt(1.0 - p.length_squared());
        let nh = p.x * t1 + p.y * t2 + pz * wh;
        Vec3::new(self.alpha_x * nh.x, self.alpha_y * nh.y, nh.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{sample_uniform_sphere, uniform_sphere_pdf, Pcg32};

    fn u2(r: &mut Pcg32) -> Vec2 {
        Vec2::new(r.uniform_f32(), r.uniform_f32())
    }

    #[test]
    fn projected_area_is_one_and_visible_normals_normalise() {
        // ∫ D(ωm) cos θm dωm = 1 and ∫ D_ω(ωm) dωm = 1 [Heitz 2014, §2–3].
        // Uniform-sphere Monte Carlo with n samples; 5σ bound from the measured spread.
        let n = 400_000;
        for (ax, ay) in [(0.3f32, 0.3f32), (0.1, 0.4), (0.7, 0.5)] {
            let d = TrowbridgeReitz::new(ax, ay);
            let w = Vec3::new(0.5, 0.3, 0.2).normalize();
            let mut r = Pcg32::new(5, 1);
            let (mut s1, mut s1q, mut s2, mut s2q) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
            for _ in 0..n {
                let wm = sample_uniform_sphere(u2(&mut r));
                let inv = 1.0 / uniform_sphere_pdf() as f64;
                let a = if wm.z > 0.0 {
                    d.d(wm) as f64 * wm.z as f64 * inv
                } else {
                    0.0
                };
                let b = if wm.z > 0.0 && w.dot(wm) > 0.0 {
                    d.d_visible(w, wm) as f64 * inv
                } else {
                    0.0
                };
                s1 += a;
                s1q += a * a;
                s2 += b;
                s2q += b * b;
            }
            let nf = n as f64;
            for (s, sq) in [(s1, s1q), (s2, s2q)] {
                let m = s / nf;
                let sd = ((sq / nf - m * m).max(0.0) / nf).sqrt();
                assert!((m - 1.0).abs() < 5.0 * sd, "α=({ax},{ay}): {m} ± {sd}");
            }
        }
    }

    #[test]
    fn sampled_normals_face_the_view_and_regularize_widens() {
        let d = TrowbridgeReitz::new(0.2, 0.6);
        let mut r = Pcg32::new(9, 2);
        for _ in 0..10_000 {
            let w = sample_uniform_sphere(u2(&mut r));
            let wm = d.sample_wm(w, u2(&mut r));
            assert!(wm.z > 0.0 && (wm.length() - 1.0).abs() < 1e-5);
        }
        let mut s = TrowbridgeReitz::new(1e-4, 1e-4);
        assert!(s.effectively_smooth());
        s.regularize();
        assert!(!s.effectively_smooth() && s.alpha_x() == 0.1);
        assert!((TrowbridgeReitz::roughness_to_alpha(0.25) - 0.5).abs() < 1e-7);
    }
}
