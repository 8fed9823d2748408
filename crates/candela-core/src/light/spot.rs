//! Spot light: a point light whose intensity falls off smoothly over a cone
//! [pbrt-v4 §12.2.2].
//!
//! `I(ω) = I₀·smoothstep(cos θ; cos θ_end, cos θ_start)` with θ measured from
//! the light's +z axis: full intensity inside θ_start, zero beyond θ_end
//! (pbrt-v4's `coneangle` = θ_end, `coneangle − conedelta` = θ_start), and
//! smoothstep(x; a, b) = t²(3 − 2t), t = (x − a)/(b − a) clamped to [0, 1].
//! Integrating over the sphere, ∫ smoothstep d(cos θ) over [cos θ_end,
//! cos θ_start] is (cos θ_start − cos θ_end)/2, so
//! Φ = 2π·I₀·[(1 − cos θ_start) + (cos θ_start − cos θ_end)/2].
//!
//! Emission sampling picks the inner cone or the falloff band with
//! probability proportional to those two power terms, then samples the cone
//! uniformly or the band proportionally to the smoothstep; p_dir is therefore
//! exactly proportional to I(ω), and `β₀ = Φ` for every sample.

use super::bounds::{isotropic_point, preserves_angles, scalar, LightBounds};
use super::{delta_position_li, LightLeSample, LightLiSample, LightSampleContext, LightSpectrum};
use crate::math::{
    next_float_down, safe_sqrt, spherical_direction, Bounds3, DirectionCone, Ray, Transform, Vec2,
    Vec3, PI,
};
use crate::sampling::{sample_uniform_cone, uniform_cone_pdf, PdfArea, PdfSolidAngle};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// A spot light at the light-frame origin, pointing along light-frame +z.
#[derive(Clone, Debug)]
pub struct SpotLight {
    render_from_light: Transform,
    i: LightSpectrum,
    scale: f32,
    cos_falloff_start: f32,
    cos_falloff_end: f32,
}

/// smoothstep(x; a, b) = t²(3 − 2t) with t = clamp((x − a)/(b − a)).
pub(crate) fn smooth_step(x: f32, a: f32, b: f32) -> f32 {
    if a == b {
        return if x < a { 0.0 } else { 1.0 };
    }
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Density on [a, b] proportional to smoothstep: 2·smoothstep(x)/(b − a).
fn smooth_step_pdf(x: f32, a: f32, b: f32) -> f32 {
    if x < a || x > b || a >= b {
        return 0.0;
    }
    2.0 * smooth_step(x, a, b) / (b - a)
}

/// Inverts the CDF of [`smooth_step_pdf`], F(t) = 2t³ − t⁴, by safeguarded Newton.
fn sample_smooth_step(u: f32, a: f32, b: f32) -> f32 {
    let (mut lo, mut hi, mut t) = (0.0f64, 1.0f64, 0.5f64);
    let u = u as f64;
    for _ in 0..40 {
        let f = 2.0 * t * t * t - t * t * t * t - u;
        if f.abs() < 1e-9 {
            break;
        }
        if f > 0.0 {
            hi = t;
        } else {
            lo = t;
        }
        let df = 6.0 * t * t - 4.0 * t * t * t;
        let tn = t - f / df;
        t = if df > 0.0 && tn > lo && tn < hi {
            tn
        } else {
            0.5 * (lo + hi)
        };
    }
    (a as f64 + t * (b - a) as f64) as f32
}

impl SpotLight {
    /// Spot light with intensity `scale·i` on its axis; `total_width_deg` is
    /// the cone half-angle where emission ends, `falloff_start_deg` where the
    /// falloff begins (pbrt-v4's constructor arguments).
    pub fn new(
        render_from_light: Transform,
        i: LightSpectrum,
        scale: f32,
        total_width_deg: f32,
        falloff_start_deg: f32,
    ) -> Self {
        debug_assert!(falloff_start_deg <= total_width_deg);
        Self {
            render_from_light,
            i,
            scale,
            cos_falloff_start: falloff_start_deg.to_radians().cos(),
            cos_falloff_end: total_width_deg.to_radians().cos(),
        }
    }

    /// Position in render space.
    pub fn position(&self) -> Vec3 {
        self.render_from_light.point(Vec3::ZERO)
    }

    /// Intensity towards light-frame direction `wl` (unit).
    pub fn intensity(&self, wl: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        let f = smooth_step(wl.z, self.cos_falloff_end, self.cos_falloff_start);
        self.i.sample(lambda) * (f * self.scale)
    }

    /// Unnormalised probabilities of the inner cone and the falloff band
    /// (their solid-angle-weighted intensities over 2π·I₀).
    fn section_weights(&self) -> [f32; 2] {
        [
            1.0 - self.cos_falloff_start,
            (self.cos_falloff_start - self.cos_falloff_end) / 2.0,
        ]
    }

    /// Incident radiance I(ω)/d² towards the light; density 1 (delta).
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLiSample> {
        let to_light = self.render_from_light.inverse();
        delta_position_li(self.position(), &to_light, ctx, |wl| {
            self.intensity(wl, lambda)
        })
    }

    /// Samples a direction ∝ I(ω): `u2.x` picks cone or band, `u1` the direction.
    pub fn sample_le(
        &self,
        u1: Vec2,
        u2: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let p = self.section_weights();
        let total = p[0] + p[1];
        if total <= 0.0 {
            return None;
        }
        let (wl, pdf_dir) = if u2.x * total < p[0] {
            let wl = sample_uniform_cone(u1, self.cos_falloff_start);
            (wl, uniform_cone_pdf(self.cos_falloff_start) * p[0] / total)
        } else {
            let (a, b) = (self.cos_falloff_end, self.cos_falloff_start);
            let cos_t = sample_smooth_step(u1.x, a, b);
            let sin_t = safe_sqrt(1.0 - cos_t * cos_t);
            let wl = spherical_direction(sin_t, cos_t, 2.0 * PI * u1.y);
            (wl, smooth_step_pdf(cos_t, a, b) * p[1] / (total * 2.0 * PI))
        };
        if pdf_dir <= 0.0 {
            return None;
        }
        let d = self.render_from_light.vector(wl).normalize();
        Some(LightLeSample {
            l: self.intensity(wl, lambda),
            ray: Ray::new(self.position(), d),
            intr: None,
            pdf_pos: PdfArea(1.0),
            pdf_dir: PdfSolidAngle(pdf_dir),
        })
    }

    /// Densities of [`sample_le`](Self::sample_le) for `ray`: (1 (delta), p_dir).
    pub fn pdf_le(&self, ray: &Ray) -> (PdfArea, PdfSolidAngle) {
        let p = self.section_weights();
        let total = p[0] + p[1];
        let cos_t = self.render_from_light.inverse().vector(ray.d).normalize().z;
        let pdf = if total <= 0.0 {
            0.0
        } else if cos_t >= self.cos_falloff_start {
            if p[0] > 0.0 {
                uniform_cone_pdf(self.cos_falloff_start) * p[0] / total
            } else {
                0.0
            }
        } else {
            let (a, b) = (self.cos_falloff_end, self.cos_falloff_start);
            smooth_step_pdf(cos_t, a, b) * p[1] / (total * 2.0 * PI)
        };
        (PdfArea(1.0), PdfSolidAngle(pdf))
    }

    /// Φ = 2π·I₀·[(1 − cos θ_start) + (cos θ_start − cos θ_end)/2].
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let p = self.section_weights();
        self.i.sample(lambda) * (self.scale * 2.0 * PI * (p[0] + p[1]))
    }

    /// Emission bounds [pbrt-v4 `SpotLight::Bounds`]: normals within θ_start
    /// of the axis, spreading θ_end − θ_start further, power 4π·I₀. With no
    /// falloff band (θ_end = θ_start) the spread is the smallest angle above
    /// zero, so that the cone's own directions (θ' = 0) keep their
    /// importance. A light frame that distorts angles gets the isotropic bound.
    pub(super) fn bounds(&self) -> LightBounds {
        let p = self.position();
        let phi = scalar(|l| self.i.sample(l) * (self.scale * 4.0 * PI));
        if !preserves_angles(&self.render_from_light) {
            return isotropic_point(p, phi);
        }
        let w = self.render_from_light.vector(Vec3::Z);
        let theta_e = self.cos_falloff_end.clamp(-1.0, 1.0).acos()
            - self.cos_falloff_start.clamp(-1.0, 1.0).acos();
        let cos_e = theta_e.max(0.0).cos().min(next_float_down(1.0));
        let cone = DirectionCone::new(w, self.cos_falloff_start);
        LightBounds::new(Bounds3::from_point(p), cone, phi, cos_e, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_step_sampling_inverts_cdf() {
        // F(x) = ∫_a^x pdf must return u; checked by midpoint quadrature (error ~1e-6).
        let (a, b) = (0.8f32, 0.95f32);
        for &u in &[0.01f32, 0.2, 0.5, 0.77, 0.99] {
            let x = sample_smooth_step(u, a, b);
            let n = 20_000;
            let h = (x - a) as f64 / n as f64;
            let cdf: f64 = (0..n)
                .map(|i| smooth_step_pdf(a + ((i as f64 + 0.5) * h) as f32, a, b) as f64 * h)
                .sum();
            assert!((cdf - u as f64).abs() < 1e-4, "u={u} cdf={cdf}");
        }
    }
}
