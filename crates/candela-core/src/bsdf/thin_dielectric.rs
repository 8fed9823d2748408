//! Thin dielectric sheet (window pane, soap film without interference).
//!
//! Two parallel smooth interfaces with infinitely many internal bounces summed
//! in closed form [pbrt-v4 §9.5]: with single-interface reflectance R and
//! T = 1 − R, the sheet reflects R′ = R + T²R/(1 − R²) (a geometric series) and
//! transmits T′ = 1 − R′. Transmitted light leaves parallel to the incident
//! direction (ωi = −ωo), so no η′² factor applies and both transport modes
//! agree. Both lobes are deltas; absorption inside the sheet is ignored.

use super::fresnel::fr_dielectric;
use super::{BsdfSample, BxdfFlags, SampleFlags, TransportMode};
use crate::math::{local, Vec2, Vec3};
use crate::sampling::PdfSolidAngle;
use crate::spectrum::SampledSpectrum;

/// Thin sheet of a dielectric with index `eta` relative to its surroundings.
#[derive(Clone, Copy, Debug)]
pub struct ThinDielectricBxdf {
    /// Index of the sheet relative to the surrounding medium.
    pub eta: f32,
}

impl ThinDielectricBxdf {
    /// New thin sheet.
    pub fn new(eta: f32) -> Self {
        Self { eta }
    }

    /// Sheet reflectance R′ and transmittance T′ = 1 − R′ at |cos θ|.
    pub fn reflectance_transmittance(&self, abs_cos_theta: f32) -> (f32, f32) {
        let mut r = fr_dielectric(abs_cos_theta, self.eta);
        let t = 1.0 - r;
        // Sum over internal bounces: R′ = R + T² R / (1 − R²) [pbrt-v4 §9.5].
        if r < 1.0 {
            r += t * t * r / (1.0 - r * r);
        }
        (r, 1.0 - r)
    }

    /// Always zero: both lobes are deltas.
    pub fn f(&self, _wo: Vec3, _wi: Vec3, _mode: TransportMode) -> SampledSpectrum {
        SampledSpectrum::zero()
    }

    /// Mirror reflection with probability R′, straight transmission otherwise.
    pub fn sample_f(
        &self,
        wo: Vec3,
        uc: f32,
        _u: Vec2,
        _mode: TransportMode,
        allowed: SampleFlags,
    ) -> Option<BsdfSample> {
        let (r, t) = self.reflectance_transmittance(local::abs_cos_theta(wo));
        let pr = if allowed.contains(SampleFlags::REFLECTION) {
            r
        } else {
            0.0
        };
        let pt = if allowed.contains(SampleFlags::TRANSMISSION) {
            t
        } else {
            0.0
        };
        if pr == 0.0 && pt == 0.0 {
            return None;
        }
        let (wi, value, prob, flags) = if uc < pr / (pr + pt) {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            (wi, r, pr / (pr + pt), BxdfFlags::SPECULAR_REFLECTION)
        } else {
            (-wo, t, pt / (pr + pt), BxdfFlags::SPECULAR_TRANSMISSION)
        };
        Some(BsdfSample {
            f: SampledSpectrum::splat(value / local::abs_cos_theta(wi)),
            wi,
            pdf: PdfSolidAngle(prob),
            flags,
            eta: 1.0,
            pdf_is_proportional: false,
        })
    }

    /// Always zero: both lobes are deltas.
    pub fn pdf(
        &self,
        _wo: Vec3,
        _wi: Vec3,
        _mode: TransportMode,
        _allowed: SampleFlags,
    ) -> PdfSolidAngle {
        PdfSolidAngle(0.0)
    }

    /// Specular reflection and transmission.
    pub fn flags(&self) -> BxdfFlags {
        BxdfFlags::SPECULAR_REFLECTION | BxdfFlags::SPECULAR_TRANSMISSION
    }

    /// Delta lobes stay deltas: nothing to widen.
    pub fn regularize(&mut self) {}
}
