//! Lambertian reflection and transmission (pbrt-v4 `DiffuseTransmissionBxDF`):
//! f = R/π towards wo's side and T/π through the surface. One lobe is chosen
//! with probability proportional to max(R) and max(T), then a cosine-weighted
//! direction on that side.

use super::{BsdfSample, BxdfFlags, SampleFlags, TransportMode};
use crate::math::{local, Vec2, Vec3, INV_PI};
use crate::sampling::{cosine_hemisphere_pdf, sample_cosine_hemisphere, PdfSolidAngle};
use crate::spectrum::SampledSpectrum;

/// Lambertian reflector and transmitter (symmetric: both modes agree).
#[derive(Clone, Copy, Debug)]
pub struct DiffuseTransmissionBxdf {
    /// Reflectance ∈ \[0,1\].
    pub r: SampledSpectrum,
    /// Transmittance ∈ \[0,1\].
    pub t: SampledSpectrum,
}

impl DiffuseTransmissionBxdf {
    /// New BxDF; R + T ≤ 1 keeps it energy conserving.
    pub fn new(r: SampledSpectrum, t: SampledSpectrum) -> Self {
        Self { r, t }
    }

    /// Probabilities of choosing reflection and transmission under `allowed`.
    fn lobe_probs(&self, allowed: SampleFlags) -> Option<(f32, f32)> {
        let pr = if allowed.contains(SampleFlags::REFLECTION) {
            self.r.max_component()
        } else {
            0.0
        };
        let pt = if allowed.contains(SampleFlags::TRANSMISSION) {
            self.t.max_component()
        } else {
            0.0
        };
        let sum = pr + pt;
        (sum > 0.0).then(|| (pr / sum, pt / sum))
    }

    /// R/π on wo's side, T/π on the other.
    pub fn f(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> SampledSpectrum {
        if local::same_hemisphere(wo, wi) {
            self.r * INV_PI
        } else {
            self.t * INV_PI
        }
    }

    /// Chooses a lobe with `uc`, then a cosine-weighted direction with `u`.
    pub fn sample_f(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        allowed: SampleFlags,
    ) -> Option<BsdfSample> {
        let (pr, pt) = self.lobe_probs(allowed)?;
        let mut wi = sample_cosine_hemisphere(u);
        let reflect = uc < pr;
        // Reflection stays on wo's side, transmission goes to the other.
        if (wo.z < 0.0) == reflect {
            wi.z = -wi.z;
        }
        let p = if reflect { pr } else { pt };
        Some(BsdfSample {
            f: self.f(wo, wi, mode),
            wi,
            pdf: PdfSolidAngle(p * cosine_hemisphere_pdf(local::abs_cos_theta(wi))),
            flags: if reflect {
                BxdfFlags::DIFFUSE_REFLECTION
            } else {
                BxdfFlags::DIFFUSE_TRANSMISSION
            },
            eta: 1.0,
            pdf_is_proportional: false,
        })
    }

    /// Lobe probability × cos θ/π.
    pub fn pdf(
        &self,
        wo: Vec3,
        wi: Vec3,
        _mode: TransportMode,
        allowed: SampleFlags,
    ) -> PdfSolidAngle {
        let Some((pr, pt)) = self.lobe_probs(allowed) else {
            return PdfSolidAngle(0.0);
        };
        let p = if local::same_hemisphere(wo, wi) {
            pr
        } else {
            pt
        };
        PdfSolidAngle(p * cosine_hemisphere_pdf(local::abs_cos_theta(wi)))
    }

    /// Diffuse reflection and/or transmission.
    pub fn flags(&self) -> BxdfFlags {
        let mut f = BxdfFlags::empty();
        if !self.r.is_black() {
            f |= BxdfFlags::DIFFUSE_REFLECTION;
        }
        if !self.t.is_black() {
            f |= BxdfFlags::DIFFUSE_TRANSMISSION;
        }
        f
    }

    /// Nothing to regularise.
    pub fn regularize(&mut self) {}
}
