//! The coated materials, `coateddiffuse` and `coatedconductor`, with pbrt-v4's
//! parameter names and defaults (pbrt-v4 `materials.cpp`).

use super::check::{Check, Domain};
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
    for (name, t) in [
        ("uroughness", &u),
        ("vroughness", &v),
        ("roughness", &Some(common.clone())),
    ] {
        if let Some(t) = t {
            constant_in(src, &format!("{prefix}{name}"), t, Domain::NonNegative)?;
        }
    }
    Ok(Roughness {
        u: u.unwrap_or_else(|| common.clone()),
        v: v.unwrap_or(common),
        remap: src.params.get_bool("remaproughness", true)?,
    })
}

/// Checks of a material's parameters.
fn check<'a>(src: &'a Source) -> Check<'a> {
    Check::new(src.params, src.loc, src.what)
}

/// A non-negative integer parameter that must be at least `min`.
fn count(src: &Source, name: &str, default: i32, min: i32) -> Result<u32, BuildError> {
    Ok(check(src).int(name, default, min)? as u32)
}

/// Fails when texture parameter `name` is a constant outside `d` (textures
/// that vary are evaluated per hit and cannot be checked here).
pub fn constant_in(
    src: &Source,
    name: &str,
    t: &FloatTexture,
    d: Domain,
) -> Result<(), BuildError> {
    if let FloatTexture::Constant(x) = t {
        check(src).domain(name, *x, d)?;
    }
    Ok(())
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
        let eta = v.first().copied().unwrap_or(1.5);
        return Ok(Spectrum::Constant(check(src).domain(
            name,
            eta,
            Domain::Positive,
        )?));
    }
    Ok(
        spectrum_param(src.params, name, SpectrumKind::Unbounded, src.cs)?
            .unwrap_or(Spectrum::Constant(1.5)),
    )
}

/// The coating and medium shared by both materials; `interface` is the
/// parameter prefix of the coating's roughness and index ("" or "interface.").
fn coating(src: &Source, tex: &mut Textures, interface: &str) -> Result<Coating, BuildError> {
    let thickness = tex.float(src, "thickness", 0.01)?;
    constant_in(src, "thickness", &thickness, Domain::Positive)?;
    let g = tex.float(src, "g", 0.0)?;
    constant_in(src, "g", &g, Domain::Open(-1.0, 1.0))?;
    Ok(Coating {
        eta: eta_param(src, &format!("{interface}eta"))?,
        roughness: roughness(src, tex, interface)?,
        thickness,
        albedo: tex.spectrum(src, "albedo", SpectrumKind::Albedo, 0.0)?,
        g,
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
