//! The coated materials, `coateddiffuse` and `coatedconductor`, with pbrt-v4's
//! parameter names and defaults (pbrt-v4 `materials.cpp`).

use super::spectra::{spectrum_param, SpectrumKind};
use super::textures::{Source, Textures};
use super::BuildError;
use crate::material::{Bump, Coating, ConductorSpec, Material, Roughness};
use crate::spectrum::{named_spectrum, Spectrum};
use crate::texture::{FloatTexture, SpectrumTexture};
use candela_scene::ParamType;

/// `{prefix}roughness`, `{prefix}uroughness`, `{prefix}vroughness` (default 0) and `remaproughness`.
fn roughness(src: &Source, tex: &mut Textures, prefix: &str) -> Result<Roughness, BuildError> {
    let u = tex.float_opt(src, &format!("{prefix}uroughness"))?;
    let v = tex.float_opt(src, &format!("{prefix}vroughness"))?;
    let common = match (&u, &v) {
        (Some(_), Some(_)) => FloatTexture::Constant(0.0),
        _ => tex.float(src, &format!("{prefix}roughness"), 0.0)?,
    };
    Ok(Roughness {
        u: u.unwrap_or_else(|| common.clone()),
        v: v.unwrap_or(common),
        remap: src.params.get_bool("remaproughness", true)?,
    })
}

/// A non-negative integer parameter that must be at least `min`.
fn count(src: &Source, name: &str, default: i32, min: i32) -> Result<u32, BuildError> {
    let v = src.params.get_int(name, default)?;
    if v < min {
        return Err(BuildError::at(
            src.loc,
            format!("\"{name}\" must be at least {min}, found {v}"),
        ));
    }
    Ok(v as u32)
}

/// Index of refraction `name`: a float or a spectrum (pbrt-v4 accepts both), default 1.5.
pub fn eta_param(src: &Source, name: &str) -> Result<Spectrum, BuildError> {
    // Ask for floats only when the parameter is one: `get_floats` rejects a spectrum.
    let is_float = src
        .params
        .get(name)
        .is_some_and(|p| p.ty == ParamType::Float);
    if let Some(v) = is_float
        .then(|| src.params.get_floats(name))
        .transpose()?
        .flatten()
    {
        return Ok(Spectrum::Constant(v.first().copied().unwrap_or(1.5)));
    }
    Ok(
        spectrum_param(src.params, name, SpectrumKind::Unbounded, src.cs)?
            .unwrap_or(Spectrum::Constant(1.5)),
    )
}

/// The coating and medium shared by both materials; `interface` is the
/// parameter prefix of the coating's roughness and index ("" or "interface.").
fn coating(src: &Source, tex: &mut Textures, interface: &str) -> Result<Coating, BuildError> {
    Ok(Coating {
        eta: eta_param(src, &format!("{interface}eta"))?,
        roughness: roughness(src, tex, interface)?,
        thickness: tex.float(src, "thickness", 0.01)?,
        albedo: tex.spectrum(src, "albedo", SpectrumKind::Albedo, 0.0)?,
        g: tex.float(src, "g", 0.0)?,
        max_depth: count(src, "maxdepth", 10, 0)?,
        n_samples: count(src, "nsamples", 1, 1)?,
    })
}

/// A metal's optical constants: `reflectance`, or the complex index
/// `eta_name` + i·`k_name` (default copper); giving both is an error, as in pbrt-v4.
pub fn conductor_spec(
    src: &Source,
    tex: &mut Textures,
    eta_name: &str,
    k_name: &str,
) -> Result<ConductorSpec, BuildError> {
    let reflectance = tex.spectrum_opt(src, "reflectance", SpectrumKind::Albedo)?;
    let eta = tex.spectrum_opt(src, eta_name, SpectrumKind::Unbounded)?;
    let k = tex.spectrum_opt(src, k_name, SpectrumKind::Unbounded)?;
    let copper = |n: &str| {
        named_spectrum(n)
            .map(SpectrumTexture::Constant)
            .ok_or_else(|| BuildError::Other(format!("missing built-in spectrum {n}")))
    };
    match (reflectance, eta, k) {
        (Some(_), Some(_), _) | (Some(_), _, Some(_)) => Err(BuildError::at(
            src.loc,
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
pub fn coated_diffuse(
    src: &Source,
    tex: &mut Textures,
    bump: Option<Bump>,
) -> Result<Material, BuildError> {
    Ok(Material::CoatedDiffuse {
        reflectance: tex.spectrum(src, "reflectance", SpectrumKind::Albedo, 0.5)?,
        coating: coating(src, tex, "")?,
        bump,
    })
}

/// `Material "coatedconductor"`: a dielectric coating over a metal.
pub fn coated_conductor(
    src: &Source,
    tex: &mut Textures,
    bump: Option<Bump>,
) -> Result<Material, BuildError> {
    Ok(Material::CoatedConductor {
        spec: conductor_spec(src, tex, "conductor.eta", "conductor.k")?,
        roughness: roughness(src, tex, "conductor.")?,
        coating: coating(src, tex, "interface.")?,
        bump,
    })
}
