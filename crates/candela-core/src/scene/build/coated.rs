//! The coated materials, `coateddiffuse` and `coatedconductor`, with pbrt-v4's
//! parameter names and defaults (pbrt-v4 `materials.cpp`).

use super::geometry::{eta_param, float_tex, spectrum_tex};
use super::spectra::SpectrumKind;
use super::BuildError;
use crate::material::{Coating, ConductorSpec, Material, Roughness};
use crate::spectrum::{named_spectrum, Spectrum};
use crate::texture::SpectrumTexture;
use candela_scene::MaterialDesc;

/// `{prefix}roughness`, `{prefix}uroughness`, `{prefix}vroughness` (default 0) and `remaproughness`.
fn roughness(m: &MaterialDesc, prefix: &str) -> Result<Roughness, BuildError> {
    let r = m.params.get_float(&format!("{prefix}roughness"), 0.0)?;
    Ok(Roughness {
        u: float_tex(m, &format!("{prefix}uroughness"), r)?,
        v: float_tex(m, &format!("{prefix}vroughness"), r)?,
        remap: m.params.get_bool("remaproughness", true)?,
    })
}

/// A non-negative integer parameter that must be at least `min`.
fn count(m: &MaterialDesc, name: &str, default: i32, min: i32) -> Result<u32, BuildError> {
    let v = m.params.get_int(name, default)?;
    if v < min {
        return Err(BuildError::at(
            &m.loc,
            format!("\"{name}\" must be at least {min}, found {v}"),
        ));
    }
    Ok(v as u32)
}

/// The coating and medium shared by both materials; `interface` is the
/// parameter prefix of the coating's roughness and index ("" or "interface.").
fn coating(m: &MaterialDesc, interface: &str) -> Result<Coating, BuildError> {
    Ok(Coating {
        eta: eta_param(m, &format!("{interface}eta"))?,
        roughness: roughness(m, interface)?,
        thickness: float_tex(m, "thickness", 0.01)?,
        albedo: spectrum_tex(m, "albedo", SpectrumKind::Albedo)?
            .unwrap_or(SpectrumTexture::Constant(Spectrum::Constant(0.0))),
        g: float_tex(m, "g", 0.0)?,
        max_depth: count(m, "maxdepth", 10, 0)?,
        n_samples: count(m, "nsamples", 1, 1)?,
    })
}

/// A metal's optical constants: `reflectance`, or the complex index
/// `eta_name` + i·`k_name` (default copper); giving both is an error, as in pbrt-v4.
pub fn conductor_spec(
    m: &MaterialDesc,
    eta_name: &str,
    k_name: &str,
) -> Result<ConductorSpec, BuildError> {
    let reflectance = spectrum_tex(m, "reflectance", SpectrumKind::Albedo)?;
    let eta = spectrum_tex(m, eta_name, SpectrumKind::Unbounded)?;
    let k = spectrum_tex(m, k_name, SpectrumKind::Unbounded)?;
    let copper = |n: &str| {
        named_spectrum(n)
            .map(SpectrumTexture::Constant)
            .ok_or_else(|| BuildError::Other(format!("missing built-in spectrum {n}")))
    };
    match (reflectance, eta, k) {
        (Some(_), Some(_), _) | (Some(_), _, Some(_)) => Err(BuildError::at(
            &m.loc,
            format!("give either \"reflectance\" or \"{eta_name}\"/\"{k_name}\", not both"),
        )),
        (Some(r), None, None) => Ok(ConductorSpec::Reflectance(r)),
        (None, eta, k) => Ok(ConductorSpec::EtaK {
            eta: eta.map_or_else(|| copper("metal-Cu-eta"), Ok)?,
            k: k.map_or_else(|| copper("metal-Cu-k"), Ok)?,
        }),
    }
}

/// `Material "coateddiffuse"`: a dielectric coating over a Lambertian base.
pub fn coated_diffuse(m: &MaterialDesc) -> Result<Material, BuildError> {
    Ok(Material::CoatedDiffuse {
        reflectance: spectrum_tex(m, "reflectance", SpectrumKind::Albedo)?
            .unwrap_or(SpectrumTexture::Constant(Spectrum::Constant(0.5))),
        coating: coating(m, "")?,
    })
}

/// `Material "coatedconductor"`: a dielectric coating over a metal.
pub fn coated_conductor(m: &MaterialDesc) -> Result<Material, BuildError> {
    Ok(Material::CoatedConductor {
        spec: conductor_spec(m, "conductor.eta", "conductor.k")?,
        roughness: roughness(m, "conductor.")?,
        coating: coating(m, "interface.")?,
    })
}
