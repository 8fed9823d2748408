//! Materials: textures → a BSDF at each hit.
//!
//! Each variant mirrors the pbrt-v4 material of the same name and evaluates
//! its textures at the hit for the path's wavelengths. Spectrally varying
//! indices of refraction make the path's secondary wavelengths meaningless
//! after refraction, so the dielectric terminates them (keeping only the hero
//! wavelength, [Wilkie et al. 2014]). The coated materials put a
//! [`Coating`] over a Lambertian or conductor base and evaluate to the
//! stochastic layered BxDF of pbrt-v4 §14.3.
//!
//! The scene resolves a [`Material::Mix`] to one of its materials per hit
//! ([`mix_choice`]) and applies a material's `displacement` or `normalmap` ([`Bump::apply`])
//! before asking it for a BSDF, as pbrt-v4's `SurfaceInteraction::GetBSDF`.

mod bump;
mod mix;

pub use bump::{apply_bump, bump_map, normal_map, Bump};
pub use mix::mix_choice;

use crate::bsdf::{
    Bsdf, Bxdf, ConductorBxdf, DielectricBxdf, DiffuseBxdf, DiffuseTransmissionBxdf, LayerParams,
    LayeredBxdf, ThinDielectricBxdf, TrowbridgeReitz,
};
use crate::interaction::{MaterialId, SurfaceInteraction};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};
use crate::texture::{FloatTexture, SpectrumTexture, TextureEvalContext};

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
    fn distribution(&self, ctx: &TextureEvalContext) -> TrowbridgeReitz {
        let (mut u, mut v) = (self.u.evaluate(ctx), self.v.evaluate(ctx));
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

/// The dielectric coating and in-between medium of the coated materials
/// (pbrt-v4 `coateddiffuse` / `coatedconductor` parameters).
#[derive(Clone, Debug)]
pub struct Coating {
    /// Index of refraction of the coating (`eta` / `interface.eta`, default 1.5).
    pub eta: Spectrum,
    /// Coating roughness (`roughness` / `interface.roughness`, default 0).
    pub roughness: Roughness,
    /// Slab thickness (`thickness`, default 0.01).
    pub thickness: FloatTexture,
    /// Medium single-scattering albedo (`albedo`, default 0: no scattering medium).
    pub albedo: SpectrumTexture,
    /// Medium Henyey–Greenstein asymmetry (`g`, default 0).
    pub g: FloatTexture,
    /// Maximum scattering events of one walk (`maxdepth`, default 10).
    pub max_depth: u32,
    /// Walks averaged per evaluation (`nsamples`, default 1).
    pub n_samples: u32,
}

impl Coating {
    /// The coating BxDF and the layer parameters at a hit; a spectrally
    /// varying index terminates the secondary wavelengths, as for dielectrics.
    fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &mut SampledWavelengths,
    ) -> (DielectricBxdf, LayerParams) {
        let top = DielectricBxdf::new(
            hero_eta(&self.eta, lambda),
            self.roughness.distribution(ctx),
        );
        let params = LayerParams {
            thickness: self.thickness.evaluate(ctx),
            albedo: self.albedo.evaluate(ctx, lambda).clamp(0.0, 1.0),
            g: self.g.evaluate(ctx).clamp(-1.0, 1.0),
            max_depth: self.max_depth,
            n_samples: self.n_samples,
        };
        (top, params)
    }
}

/// The closed set of materials.
#[derive(Clone, Debug)]
pub enum Material {
    /// Lambertian.
    Diffuse {
        /// Albedo.
        reflectance: SpectrumTexture,
        /// Bump map.
        bump: Option<Bump>,
    },
    /// Metal.
    Conductor {
        /// Optical constants.
        spec: ConductorSpec,
        /// Microfacet roughness.
        roughness: Roughness,
        /// Bump map.
        bump: Option<Bump>,
    },
    /// Glass-like boundary.
    Dielectric {
        /// Index of refraction (spectral or constant).
        eta: Spectrum,
        /// Microfacet roughness.
        roughness: Roughness,
        /// Bump map.
        bump: Option<Bump>,
    },
    /// Thin dielectric sheet.
    ThinDielectric {
        /// Index of refraction.
        eta: Spectrum,
        /// Bump map.
        bump: Option<Bump>,
    },
    /// Lambertian reflection and transmission.
    DiffuseTransmission {
        /// Reflectance (scaled by `scale`).
        reflectance: SpectrumTexture,
        /// Transmittance (scaled by `scale`).
        transmittance: SpectrumTexture,
        /// Factor on both.
        scale: f32,
        /// Bump map.
        bump: Option<Bump>,
    },
    /// Dielectric coating over a Lambertian base.
    CoatedDiffuse {
        /// Albedo of the base.
        reflectance: SpectrumTexture,
        /// Coating and medium.
        coating: Coating,
        /// Bump map.
        bump: Option<Bump>,
    },
    /// Dielectric coating over a metal.
    CoatedConductor {
        /// Optical constants of the metal (relative to vacuum).
        spec: ConductorSpec,
        /// Microfacet roughness of the metal.
        roughness: Roughness,
        /// Coating and medium.
        coating: Coating,
        /// Bump map.
        bump: Option<Bump>,
    },
    /// Marks a boundary without scattering (media transitions).
    Interface,
    /// One of two materials per hit, the second with probability `amount`.
    Mix {
        /// The two materials.
        materials: [MaterialId; 2],
        /// Probability of the second.
        amount: FloatTexture,
    },
}

impl Material {
    /// The BSDF at a hit, or `None` for [`Material::Interface`]. A
    /// [`Material::Mix`] must have been resolved by the caller (it gives `None`).
    pub fn bsdf(&self, si: &SurfaceInteraction, lambda: &mut SampledWavelengths) -> Option<Bsdf> {
        let ctx = TextureEvalContext::from_si(si);
        let bxdf = match self {
            Material::Diffuse { reflectance, .. } => Bxdf::Diffuse(DiffuseBxdf::new(
                reflectance.evaluate(&ctx, lambda).clamp(0.0, 1.0),
            )),
            Material::Conductor {
                spec, roughness, ..
            } => {
                let (eta, k) = conductor_constants(spec, &ctx, lambda);
                Bxdf::Conductor(ConductorBxdf::new(roughness.distribution(&ctx), eta, k))
            }
            Material::Dielectric { eta, roughness, .. } => Bxdf::Dielectric(DielectricBxdf::new(
                hero_eta(eta, lambda),
                roughness.distribution(&ctx),
            )),
            Material::ThinDielectric { eta, .. } => {
                Bxdf::ThinDielectric(ThinDielectricBxdf::new(hero_eta(eta, lambda)))
            }
            Material::DiffuseTransmission {
                reflectance,
                transmittance,
                scale,
                ..
            } => Bxdf::DiffuseTransmission(DiffuseTransmissionBxdf::new(
                (reflectance.evaluate(&ctx, lambda) * *scale).clamp(0.0, 1.0),
                (transmittance.evaluate(&ctx, lambda) * *scale).clamp(0.0, 1.0),
            )),
            Material::CoatedDiffuse {
                reflectance,
                coating,
                ..
            } => {
                let r = reflectance.evaluate(&ctx, lambda).clamp(0.0, 1.0);
                let (top, params) = coating.evaluate(&ctx, lambda);
                Bxdf::CoatedDiffuse(LayeredBxdf::new(top, DiffuseBxdf::new(r), params))
            }
            Material::CoatedConductor {
                spec,
                roughness,
                coating,
                ..
            } => {
                let (eta, k) = conductor_constants(spec, &ctx, lambda);
                let (top, params) = coating.evaluate(&ctx, lambda);
                // The metal lies under the coating: its index is relative to the
                // coating's [pbrt-v4 `CoatedConductorMaterial::GetBxDF`].
                let base =
                    ConductorBxdf::new(roughness.distribution(&ctx), eta / top.eta, k / top.eta);
                Bxdf::CoatedConductor(LayeredBxdf::new(top, base, params))
            }
            Material::Interface => return None,
            Material::Mix { .. } => {
                debug_assert!(false, "mix materials are resolved before bsdf()");
                return None;
            }
        };
        Some(Bsdf::new(si.shading.n, si.shading.dpdu, bxdf))
    }

    /// The bump or normal map, if any.
    pub fn bump(&self) -> Option<&Bump> {
        match self {
            Material::Diffuse { bump, .. }
            | Material::Conductor { bump, .. }
            | Material::Dielectric { bump, .. }
            | Material::ThinDielectric { bump, .. }
            | Material::DiffuseTransmission { bump, .. }
            | Material::CoatedDiffuse { bump, .. }
            | Material::CoatedConductor { bump, .. } => bump.as_ref(),
            Material::Interface | Material::Mix { .. } => None,
        }
    }
}

fn conductor_constants(
    spec: &ConductorSpec,
    ctx: &TextureEvalContext,
    lambda: &SampledWavelengths,
) -> (SampledSpectrum, SampledSpectrum) {
    match spec {
        ConductorSpec::EtaK { eta, k } => (eta.evaluate(ctx, lambda), k.evaluate(ctx, lambda)),
        ConductorSpec::Reflectance(r) => {
            // η = 1, k = 2√r / √(1 − r) reproduces reflectance r at normal incidence [pbrt-v4 §10.5].
            let r = r.evaluate(ctx, lambda).clamp(0.0, 0.9999);
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
