//! Scattering functions.
//!
//! A [`Bsdf`] is a shading frame plus one [`Bxdf`] that works in the local
//! frame (z = shading normal). Conventions [pbrt-v4 §9.1]: `wo` points back
//! along the path, `wi` is the sampled direction, both away from the surface;
//! `f` excludes the cosine; `sample_f` returns a [`BsdfSample`] record;
//! densities are per unit solid angle. The adjoint of non-symmetric BSDFs is
//! selected by [`TransportMode`].

mod conductor;
mod dielectric;
mod diffuse;
mod diffuse_transmission;
pub mod fresnel;
pub mod layered;
pub mod microfacet;
mod thin_dielectric;

#[cfg(test)]
mod tests;

pub use conductor::ConductorBxdf;
pub use dielectric::DielectricBxdf;
pub use diffuse::DiffuseBxdf;
pub use diffuse_transmission::DiffuseTransmissionBxdf;
pub use layered::{CoatedConductorBxdf, CoatedDiffuseBxdf, LayerParams, LayeredBxdf};
pub use microfacet::TrowbridgeReitz;
pub use thin_dielectric::ThinDielectricBxdf;

use crate::math::{FrameA, Vec2, Vec3, Vec3A};
use crate::sampling::PdfSolidAngle;
use crate::spectrum::SampledSpectrum;
use bitflags::bitflags;

/// Which quantity a path carries: radiance (camera paths) or importance
/// (light paths, photons). Refraction scales radiance by 1/η² but not
/// importance [Veach 1997, §5.2].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransportMode {
    /// Camera subpaths: radiance flows towards the camera.
    Radiance,
    /// Light subpaths and photons: importance flows towards the light.
    Importance,
}

impl TransportMode {
    /// The other mode: what a path traced from the opposite end carries.
    #[inline]
    pub fn adjoint(self) -> Self {
        match self {
            Self::Radiance => Self::Importance,
            Self::Importance => Self::Radiance,
        }
    }
}

bitflags! {
    /// Lobe classification of a BxDF or of one sample.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    pub struct BxdfFlags: u8 {
        /// Reflects.
        const REFLECTION = 1;
        /// Transmits.
        const TRANSMISSION = 1 << 1;
        /// Lambertian-like.
        const DIFFUSE = 1 << 2;
        /// Glossy lobe.
        const GLOSSY = 1 << 3;
        /// Dirac delta lobe.
        const SPECULAR = 1 << 4;
        /// Diffuse reflection.
        const DIFFUSE_REFLECTION = Self::DIFFUSE.bits() | Self::REFLECTION.bits();
        /// Diffuse transmission.
        const DIFFUSE_TRANSMISSION = Self::DIFFUSE.bits() | Self::TRANSMISSION.bits();
        /// Glossy reflection.
        const GLOSSY_REFLECTION = Self::GLOSSY.bits() | Self::REFLECTION.bits();
        /// Glossy transmission.
        const GLOSSY_TRANSMISSION = Self::GLOSSY.bits() | Self::TRANSMISSION.bits();
        /// Specular reflection.
        const SPECULAR_REFLECTION = Self::SPECULAR.bits() | Self::REFLECTION.bits();
        /// Specular transmission.
        const SPECULAR_TRANSMISSION = Self::SPECULAR.bits() | Self::TRANSMISSION.bits();
        /// Everything.
        const ALL = Self::DIFFUSE.bits() | Self::GLOSSY.bits() | Self::SPECULAR.bits() | Self::REFLECTION.bits() | Self::TRANSMISSION.bits();
    }
}

impl BxdfFlags {
    /// Has a non-delta lobe (can be evaluated for an arbitrary `wi`).
    #[inline]
    pub fn is_non_specular(self) -> bool {
        self.intersects(Self::DIFFUSE | Self::GLOSSY)
    }
    /// Is (or has) a delta lobe.
    #[inline]
    pub fn is_specular(self) -> bool {
        self.contains(Self::SPECULAR)
    }
    /// Reflects.
    #[inline]
    pub fn is_reflective(self) -> bool {
        self.contains(Self::REFLECTION)
    }
    /// Transmits.
    #[inline]
    pub fn is_transmissive(self) -> bool {
        self.contains(Self::TRANSMISSION)
    }
}

bitflags! {
    /// Which hemispheres a sampling call may return.
    #[derive(Clone, Copy, Debug, PartialEq, Eq)]
    pub struct SampleFlags: u8 {
        /// Reflection allowed.
        const REFLECTION = 1;
        /// Transmission allowed.
        const TRANSMISSION = 2;
        /// Both.
        const ALL = 3;
    }
}

/// One sampled scattering direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// BSDF value f(wo, wi) (cosine excluded).
    pub f: SampledSpectrum,
    /// Sampled direction.
    pub wi: Vec3,
    /// Density of `wi` (for a delta lobe: the discrete lobe probability).
    pub pdf: PdfSolidAngle,
    /// Lobe of the sample.
    pub flags: BxdfFlags,
    /// Relative index of refraction across the boundary (1 for reflection).
    pub eta: f32,
    /// The pdf is only proportional to the true density (stochastic layered BSDFs).
    pub pdf_is_proportional: bool,
}

impl BsdfSample {
    /// Came from a delta lobe.
    #[inline]
    pub fn is_specular(&self) -> bool {
        self.flags.is_specular()
    }
    /// Is a transmission.
    #[inline]
    pub fn is_transmission(&self) -> bool {
        self.flags.is_transmissive()
    }
    /// Is a reflection.
    #[inline]
    pub fn is_reflection(&self) -> bool {
        self.flags.is_reflective()
    }
}

/// A pair of world directions taken into a BSDF's local frame once
/// ([`Bsdf::local_pair`]), so f and both densities of the pair are
/// evaluated without repeating the frame change: what a bidirectional join
/// needs at each end.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalPair {
    wo: Vec3,
    wi: Vec3,
}

/// The closed set of local-frame scattering models.
#[derive(Clone, Copy, Debug)]
pub enum Bxdf {
    /// Lambertian reflection.
    Diffuse(DiffuseBxdf),
    /// Lambertian reflection and transmission.
    DiffuseTransmission(DiffuseTransmissionBxdf),
    /// Metal: mirror or Torrance–Sparrow reflection.
    Conductor(ConductorBxdf),
    /// Dielectric interface: smooth or rough reflection and refraction.
    Dielectric(DielectricBxdf),
    /// Thin dielectric sheet: delta reflection and straight transmission.
    ThinDielectric(ThinDielectricBxdf),
    /// Dielectric coating over a Lambertian base (stochastic layered model).
    CoatedDiffuse(CoatedDiffuseBxdf),
    /// Dielectric coating over a conductor (stochastic layered model).
    CoatedConductor(CoatedConductorBxdf),
}

/// Writes a `match` over every [`Bxdf`] variant that forwards to the inner model.
macro_rules! dispatch_bxdf {
    ($self:expr, $b:ident => $e:expr) => {
        match $self {
            Bxdf::Diffuse($b) => $e,
            Bxdf::DiffuseTransmission($b) => $e,
            Bxdf::Conductor($b) => $e,
            Bxdf::Dielectric($b) => $e,
            Bxdf::ThinDielectric($b) => $e,
            Bxdf::CoatedDiffuse($b) => $e,
            Bxdf::CoatedConductor($b) => $e,
        }
    };
}

impl Bxdf {
    /// True when f and the sampling densities are the same at every
    /// wavelength: the dielectric interfaces, whose Fresnel terms take one
    /// scalar η (a spectrally varying η terminates the secondary
    /// wavelengths instead). A path scattered only by these keeps a β that
    /// holds at any wavelengths.
    pub fn is_wavelength_independent(&self) -> bool {
        matches!(self, Bxdf::Dielectric(_) | Bxdf::ThinDielectric(_))
    }

    /// f(wo, wi) in the local frame.
    #[inline]
    pub fn f(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> SampledSpectrum {
        dispatch_bxdf!(self, b => b.f(wo, wi, mode))
    }
    /// Samples wi given wo; `uc` picks a lobe, `u` the direction.
    #[inline]
    pub fn sample_f(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        allowed: SampleFlags,
    ) -> Option<BsdfSample> {
        dispatch_bxdf!(self, b => b.sample_f(wo, uc, u, mode, allowed))
    }
    /// Density of sampling wi given wo.
    #[inline]
    pub fn pdf(
        &self,
        wo: Vec3,
        wi: Vec3,
        mode: TransportMode,
        allowed: SampleFlags,
    ) -> PdfSolidAngle {
        dispatch_bxdf!(self, b => b.pdf(wo, wi, mode, allowed))
    }
    /// Lobe classification.
    #[inline]
    pub fn flags(&self) -> BxdfFlags {
        dispatch_bxdf!(self, b => b.flags())
    }
    /// Makes near-specular lobes rougher (path regularisation) [pbrt-v4 §13.4].
    #[inline]
    pub fn regularize(&mut self) {
        dispatch_bxdf!(self, b => b.regularize())
    }
    /// Monte Carlo estimate of the directional albedo ρ(wo) = ∫ f |cos θi| dωi
    /// from one sample per pair of `uc[j]`, `u[j]` [pbrt-v4 §9.1.1]; delta lobes included.
    pub fn rho(&self, wo: Vec3, uc: &[f32], u: &[Vec2], mode: TransportMode) -> SampledSpectrum {
        debug_assert_eq!(uc.len(), u.len());
        let mut sum = SampledSpectrum::zero();
        for (&c, &u2) in uc.iter().zip(u) {
            if let Some(bs) = self.sample_f(wo, c, u2, mode, SampleFlags::ALL) {
                if bs.pdf.0 > 0.0 {
                    sum += bs.f * (bs.wi.z.abs() / bs.pdf.0);
                }
            }
        }
        sum / uc.len().max(1) as f32
    }
}

impl From<DiffuseTransmissionBxdf> for Bxdf {
    fn from(b: DiffuseTransmissionBxdf) -> Self {
        Self::DiffuseTransmission(b)
    }
}

impl From<DiffuseBxdf> for Bxdf {
    fn from(b: DiffuseBxdf) -> Self {
        Self::Diffuse(b)
    }
}

impl From<ConductorBxdf> for Bxdf {
    fn from(b: ConductorBxdf) -> Self {
        Self::Conductor(b)
    }
}

impl From<DielectricBxdf> for Bxdf {
    fn from(b: DielectricBxdf) -> Self {
        Self::Dielectric(b)
    }
}

impl From<ThinDielectricBxdf> for Bxdf {
    fn from(b: ThinDielectricBxdf) -> Self {
        Self::ThinDielectric(b)
    }
}

impl From<CoatedDiffuseBxdf> for Bxdf {
    fn from(b: CoatedDiffuseBxdf) -> Self {
        Self::CoatedDiffuse(b)
    }
}

impl From<CoatedConductorBxdf> for Bxdf {
    fn from(b: CoatedConductorBxdf) -> Self {
        Self::CoatedConductor(b)
    }
}

/// A BxDF placed in a shading frame.
#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    frame: FrameA,
    /// The local scattering model.
    pub bxdf: Bxdf,
}

impl Bsdf {
    /// Places `bxdf` in the frame with normal `ns` and tangent `dpdus`.
    pub fn new(ns: Vec3, dpdus: Vec3, bxdf: Bxdf) -> Self {
        Self {
            frame: FrameA::from_xz(Vec3A::from(dpdus).normalize_or_zero(), ns.into()),
            bxdf,
        }
    }
    /// World → local.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        self.frame.to_local(v)
    }
    /// Local → world.
    #[inline]
    pub fn from_local(&self, v: Vec3) -> Vec3 {
        self.frame.from_local(v)
    }
    /// Shading normal.
    #[inline]
    pub fn ns(&self) -> Vec3 {
        self.frame.z.into()
    }
    /// Lobes present.
    #[inline]
    pub fn flags(&self) -> BxdfFlags {
        self.bxdf.flags()
    }
    /// f(wo, wi) for world-space directions.
    pub fn f(&self, wo_render: Vec3, wi_render: Vec3, mode: TransportMode) -> SampledSpectrum {
        let (wo, wi) = (self.to_local(wo_render), self.to_local(wi_render));
        if wo.z == 0.0 {
            return SampledSpectrum::zero();
        }
        self.bxdf.f(wo, wi, mode)
    }
    /// Samples a world-space direction.
    pub fn sample_f(
        &self,
        wo_render: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        allowed: SampleFlags,
    ) -> Option<BsdfSample> {
        let wo = self.to_local(wo_render);
        if wo.z == 0.0 || !self.bxdf.flags().intersects(allowed_lobes(allowed)) {
            return None;
        }
        let mut bs = self.bxdf.sample_f(wo, uc, u, mode, allowed)?;
        if bs.f.is_black()
            || bs.pdf.0 == 0.0
            || bs.wi.z == 0.0
            || bs.f.has_non_finite()
            || !bs.pdf.0.is_finite()
        {
            return None;
        }
        bs.wi = self.from_local(bs.wi);
        Some(bs)
    }
    /// Density of sampling `wi` given `wo` (world space).
    pub fn pdf(
        &self,
        wo_render: Vec3,
        wi_render: Vec3,
        mode: TransportMode,
        allowed: SampleFlags,
    ) -> PdfSolidAngle {
        let (wo, wi) = (self.to_local(wo_render), self.to_local(wi_render));
        if wo.z == 0.0 {
            return PdfSolidAngle(0.0);
        }
        self.bxdf.pdf(wo, wi, mode, allowed)
    }
    /// `wo` and `wi` (world space) in the local frame.
    #[inline]
    pub fn local_pair(&self, wo_render: Vec3, wi_render: Vec3) -> LocalPair {
        self.local_pair_from(self.to_local(wo_render), wi_render)
    }
    /// [`Self::local_pair`] with `wo` already local ([`Self::to_local`],
    /// made once for the many `wi` of a merge or of the joins at one vertex).
    #[inline]
    pub fn local_pair_from(&self, wo_local: Vec3, wi_render: Vec3) -> LocalPair {
        LocalPair {
            wo: wo_local,
            wi: self.to_local(wi_render),
        }
    }
    /// [`Self::f`] of the pair.
    #[inline]
    pub fn f_pair(&self, d: &LocalPair, mode: TransportMode) -> SampledSpectrum {
        if d.wo.z == 0.0 {
            return SampledSpectrum::zero();
        }
        self.bxdf.f(d.wo, d.wi, mode)
    }
    /// The densities [`Self::pdf`] gives the pair, all lobes: forward,
    /// `pdf(wo, wi, mode)`, and reverse, `pdf(wi, wo, mode.adjoint())`.
    #[inline]
    pub fn pdfs_pair(&self, d: &LocalPair, mode: TransportMode) -> (PdfSolidAngle, PdfSolidAngle) {
        let all = SampleFlags::ALL;
        let fwd = if d.wo.z == 0.0 {
            PdfSolidAngle(0.0)
        } else {
            self.bxdf.pdf(d.wo, d.wi, mode, all)
        };
        let rev = if d.wi.z == 0.0 {
            PdfSolidAngle(0.0)
        } else {
            self.bxdf.pdf(d.wi, d.wo, mode.adjoint(), all)
        };
        (fwd, rev)
    }
    /// Applies path regularisation.
    pub fn regularize(&mut self) {
        self.bxdf.regularize()
    }
    /// Directional albedo ρ(wo) for a world-space `wo` ([`Bxdf::rho`]).
    pub fn rho(
        &self,
        wo_render: Vec3,
        uc: &[f32],
        u: &[Vec2],
        mode: TransportMode,
    ) -> SampledSpectrum {
        let wo = self.to_local(wo_render);
        if wo.z == 0.0 {
            return SampledSpectrum::zero();
        }
        self.bxdf.rho(wo, uc, u, mode)
    }
}

fn allowed_lobes(allowed: SampleFlags) -> BxdfFlags {
    let mut f = BxdfFlags::empty();
    if allowed.contains(SampleFlags::REFLECTION) {
        f |= BxdfFlags::REFLECTION;
    }
    if allowed.contains(SampleFlags::TRANSMISSION) {
        f |= BxdfFlags::TRANSMISSION;
    }
    f
}
