//! Metals: Fresnel-weighted mirror or Torrance–Sparrow microfacet reflection.
//!
//! With an effectively smooth distribution the BxDF is a delta lobe in the
//! mirror direction carrying the conductor Fresnel reflectance
//! F(cos θ) / |cos θi| [pbrt-v4 §9.4]. Otherwise it is the Torrance–Sparrow
//! model f = D(ωm) F(ωo·ωm) G(ωo, ωi) / (4 cos θo cos θi), ωm = ĥ(ωo + ωi)
//! [Torrance & Sparrow 1967; Walter et al. 2007, eq. 20; pbrt-v4 §9.6],
//! sampled by drawing a visible normal and reflecting ωo about it, which gives
//! p(ωi) = D_ωo(ωm) / (4 |ωo·ωm|) [Walter et al. 2007, eq. 14]. Reflection is symmetric,
//! so both transport modes evaluate the same function.

use super::fresnel::fr_complex_spectral;
use super::microfacet::TrowbridgeReitz;
use super::{BsdfSample, BxdfFlags, SampleFlags, TransportMode};
use crate::math::{face_forward, local, Vec2, Vec3};
use crate::sampling::PdfSolidAngle;
use crate::spectrum::SampledSpectrum;

/// Conductor with complex index η + ik per wavelength over a GGX distribution.
#[derive(Clone, Copy, Debug)]
pub struct ConductorBxdf {
    /// Microfacet distribution (smooth → delta mirror).
    pub distrib: TrowbridgeReitz,
    /// Real part of the relative index of refraction per wavelength.
    pub eta: SampledSpectrum,
    /// Absorption coefficient (imaginary part) per wavelength.
    pub k: SampledSpectrum,
}

impl ConductorBxdf {
    /// New conductor.
    pub fn new(distrib: TrowbridgeReitz, eta: SampledSpectrum, k: SampledSpectrum) -> Self {
        Self { distrib, eta, k }
    }

    /// Torrance–Sparrow value; 0 for the smooth (delta) case or opposite hemispheres.
    pub fn f(&self, wo: Vec3, wi: Vec3, _mode: TransportMode) -> SampledSpectrum {
        if !local::same_hemisphere(wo, wi) || self.distrib.effectively_smooth() {
            return SampledSpectrum::zero();
        }
        let (cos_o, cos_i) = (local::abs_cos_theta(wo), local::abs_cos_theta(wi));
        if cos_i == 0.0 || cos_o == 0.0 {
            return SampledSpectrum::zero();
        }
        let wm = wi + wo;
        if wm.length_squared() == 0.0 {
            return SampledSpectrum::zero();
        }
        let wm = wm.normalize();
        let fr = fr_complex_spectral(wo.dot(wm).abs(), self.eta, self.k);
        // [Walter et al. 2007, eq. 20]
        fr * (self.distrib.d(wm) * self.distrib.g(wo, wi) / (4.0 * cos_i * cos_o))
    }

    /// Mirror direction (smooth) or reflection about a visible normal (rough).
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
        if self.distrib.effectively_smooth() {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            let cos_i = local::abs_cos_theta(wi);
            let f = fr_complex_spectral(cos_i, self.eta, self.k) / cos_i;
            return Some(BsdfSample {
                f,
                wi,
                pdf: PdfSolidAngle(1.0),
                flags: BxdfFlags::SPECULAR_REFLECTION,
                eta: 1.0,
                pdf_is_proportional: false,
            });
        }
        if wo.z == 0.0 {
            return None;
        }
        let wm = self.distrib.sample_wm(wo, u);
        let wi = local::reflect(wo, wm);
        if !local::same_hemisphere(wo, wi) {
            return None;
        }
        // Value and density are evaluated from (ωo, ωi) exactly as `f` and `pdf`
        // do, rather than from the sampled ωm: rebuilding ωm = ĥ(ωo + ωi) differs
        // by float round-off that a narrow lobe amplifies, and MIS needs the
        // sampled pdf to equal `pdf()` bit for bit.
        let pdf = self.pdf(wo, wi, mode, allowed).0;
        let f = self.f(wo, wi, mode);
        if pdf == 0.0 {
            return None;
        }
        Some(BsdfSample {
            f,
            wi,
            pdf: PdfSolidAngle(pdf),
            flags: BxdfFlags::GLOSSY_REFLECTION,
            eta: 1.0,
            pdf_is_proportional: false,
        })
    }

    /// Density of [`Self::sample_f`]; 0 for the delta case.
    pub fn pdf(
        &self,
        wo: Vec3,
        wi: Vec3,
        _mode: TransportMode,
        allowed: SampleFlags,
    ) -> PdfSolidAngle {
        if !allowed.contains(SampleFlags::REFLECTION)
            || !local::same_hemisphere(wo, wi)
            || self.distrib.effectively_smooth()
        {
            return PdfSolidAngle(0.0);
        }
        let wm = wo + wi;
        if wm.length_squared() == 0.0 {
            return PdfSolidAngle(0.0);
        }
        let wm = face_forward(wm.normalize(), Vec3::Z);
        PdfSolidAngle(self.distrib.pdf(wo, wm) / (4.0 * wo.dot(wm).abs()))
    }

    /// Specular or glossy reflection.
    pub fn flags(&self) -> BxdfFlags {
        if self.distrib.effectively_smooth() {
            BxdfFlags::SPECULAR_REFLECTION
        } else {
            BxdfFlags::GLOSSY_REFLECTION
        }
    }

    /// Widens the microfacet lobe.
    pub fn regularize(&mut self) {
        self.distrib.regularize()
    }
}
