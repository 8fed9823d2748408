//! Materials: textures → a BSDF at each hit.
//!
//! Each variant mirrors the pbrt-v4 material of the same name and evaluates
//! its textures at the hit for the path's wavelengths. Spectrally varying
//! indices of refraction make the path's secondary wavelengths meaningless
//! after refraction, so the dielectric terminates them (keeping only the hero
//! wavelength, [Wilkie et al. 2014]).

use crate::bsdf::{
    Bsdf, Bxdf, ConductorBxdf, DielectricBxdf, DiffuseBxdf, ThinDielectricBxdf, TrowbridgeReitz,
};
use crate::interaction::SurfaceInteraction;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};
use crate::texture::{FloatTexture, SpectrumTexture};

/// Microfacet roughness parameters shared by conductors and dielectrics.
#[derive(Clone, Debug)]
pub struct Roughness {
    /// Roughness along u.
    pub u: FloatTexture,
    /// Roughness along v.
    pub v: FloatTexture,
    /// Map perceptual roughness to α (pbrt-v4 `remaproughness`, default true).
    pub remap: bool,
}

impl Roughness {
    fn distribution(&self, si: &SurfaceInteraction) -> TrowbridgeReitz {
        let (mut u, mut v) = (self.u.evaluate(si), self.v.evaluate(si));
        if self.remap {
            u = TrowbridgeReitz::roughness_to_alpha(u);
            v = TrowbridgeReitz::roughness_to_alpha(v);
        }
        TrowbridgeReitz::new(u, v)
    }
}

/// How a conductor's optical constants are given.
#[derive(Clone, Debug)]
pub enum ConductorSpec {
    /// Complex index of refraction η + ik.
    EtaK {
        /// Real part.
        eta: SpectrumTexture,
        /// Absorption.
        k: SpectrumTexture,
    },
    /// Normal-incidence reflectance (pbrt-v4 maps it to k with η = 1).
    Reflectance(SpectrumTexture),
}

/// The closed set of materials.
#[derive(Clone, Debug)]
pub enum Material {
    /// Lambertian.
    Diffuse {
        /// Albedo.
        reflectance: SpectrumTexture,
    },
    /// Metal.
    Conductor {
        /// Optical constants.
        spec: ConductorSpec,
        /// Microfacet roughness.
        roughness: Roughness,
    },
    /// Glass-like boundary.
    Dielectric {
        /// Index of refraction (spectral or constant).
        eta: Spectrum,
        /// Microfacet roughness.
        roughness: Roughness,
    },
    /// Thin dielectric sheet.
    ThinDielectric {
        /// Index of refraction.
        eta: Spectrum,
    },
    /// Marks a boundary without scattering (media transitions).
    Interface,
}

impl Material {
    /// The BSDF at a hit, or `None` for [`Material::Interface`].
    pub fn bsdf(&self, si: &SurfaceInteraction, lambda: &mut SampledWavelengths) -> Option<Bsdf> {
        let bxdf = match self {
            Material::Diffuse { reflectance } => Bxdf::Diffuse(DiffuseBxdf::new(
                reflectance.evaluate(si, lambda).clamp(0.0, 1.0),
            )),
            Material::Conductor { spec, roughness } => {
                let (eta, k) = conductor_constants(spec, si, lambda);
                Bxdf::Conductor(ConductorBxdf::new(roughness.distribution(si), eta, k))
            }
            Material::Dielectric { eta, roughness } => Bxdf::Dielectric(DielectricBxdf::new(
                hero_eta(eta, lambda),
                roughness.distribution(si),
            )),
            Material::ThinDielectric { eta } => {
                Bxdf::ThinDielectric(ThinDielectricBxdf::new(hero_eta(eta, lambda)))
            }
            Material::Interface => return None,
        };
        Some(Bsdf::new(si.shading.n, si.shading.dpdu, bxdf))
    }
}

fn conductor_constants(
    spec: &ConductorSpec,
    si: &SurfaceInteraction,
    lambda: &SampledWavelengths,
) -> (SampledSpectrum, SampledSpectrum) {
    match spec {
        ConductorSpec::EtaK { eta, k } => (eta.evaluate(si, lambda), k.evaluate(si, lambda)),
        ConductorSpec::Reflectance(r) => {
            // η = 1, k = 2√r / √(1 − r) reproduces reflectance r at normal incidence [pbrt-v4 §10.5].
            let r = r.evaluate(si, lambda).clamp(0.0, 0.9999);
            (
                SampledSpectrum::one(),
                2.0 * r.sqrt() / (SampledSpectrum::one() - r).sqrt(),
            )
        }
    }
}

/// η at the hero wavelength; a non-constant η terminates the secondary wavelengths.
fn hero_eta(eta: &Spectrum, lambda: &mut SampledWavelengths) -> f32 {
    let e = match eta {
        Spectrum::Constant(c) => *c,
        other => {
            let e = other.eval(lambda.lambda(0));
            lambda.terminate_secondary();
            e
        }
    };
    if e == 0.0 {
        1.0
    } else {
        e
    }
}
