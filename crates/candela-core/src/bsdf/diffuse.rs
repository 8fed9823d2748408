//! Lambertian reflection: f = R/π, sampled by the cosine-weighted hemisphere.

use super::{BsdfSample, BxdfFlags, SampleFlags, TransportMode};
use crate::math::{local, Vec2, Vec3, INV_PI};
use crate::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere, PdfSolidAngle};
use crate::spectrum::SampledSpectrum;

/// Lambertian reflector with albedo `r` (symmetric, so both transport modes agree).
#[derive(Clone, Copy, Debug)]
pub struct DiffuseBxdf {
    /// Albedo ∈ \[0,1\] per wavelength.
    pub r: SampledSpectrum,
}

impl DiffuseBxdf {
    /// New Lambertian BxDF.
    pub fn new(r: SampledSpectrum) -> Self {
        Self { r }
    }
    /// f = R/π on the same hemisphere, 0 otherwise.
    pub fn f(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> SampledSpectrum {
        if !local::same_hemisphere(wo, wi) {
            return SampledSpectrum::zero();
        }
        self.r * INV_PI
    }
    /// Cosine-weighted sample on wo's side.
    pub fn sample_f(
        &self,
        wo: Vec3,
        _uc: f32,
        u: Vec2,
        mode: TransportMode,
        allowed: SampleFlags,
    ) -> Option<BsdfSample> {
        if !allowed.contains(SampleFlags::REFLECTION) {
            return None;
        }
        let mut wi = sample_cosine_hemisphere(u);
        if wo.z < 0.0 {
            wi.z = -wi.z;
        }
        let pdf = cosine_hemisphere_pdf(local::abs_cos_theta(wi));
        Some(BsdfSample {
            f: self.f(wo, wi, mode),
            wi,
            pdf: PdfSolidAngle(pdf),
            flags: BxdfFlags::DIFFUSE_REFLECTION,
            eta: 1.0,
            pdf_is_proportional: false,
        })
    }
    /// cos θ/π on wo's side.
    pub fn pdf(
        &self,
        wo: Vec3,
        wi: Vec3,
        _mode: TransportMode,
        allowed: SampleFlags,
    ) -> PdfSolidAngle {
        if !allowed.contains(SampleFlags::REFLECTION) || !local::same_hemisphere(wo, wi) {
            return PdfSolidAngle(0.0);
        }
        PdfSolidAngle(cosine_hemisphere_pdf(local::abs_cos_theta(wi)))
    }
    /// Diffuse reflection, or nothing for a black albedo.
    pub fn flags(&self) -> BxdfFlags {
        if self.r.is_black() {
            BxdfFlags::empty()
        } else {
            BxdfFlags::DIFFUSE_REFLECTION
        }
    }
    /// Nothing to regularise.
    pub fn regularize(&mut self) {}
}
