//! `Material` and `MakeNamedMaterial` directives → materials.
//!
//! Texture-valued parameters (reflectance, roughness, η, k, displacement,
//! the mix amount) are resolved by [`Textures`]. A `mix` material names two
//! named materials; its material ids are known before any material is
//! built (anonymous materials first, then named ones in declaration
//! order), and mixes that contain themselves are rejected.

use super::check::Domain;
use super::coated::{coated_conductor, coated_diffuse, conductor_spec, constant_in, eta_param};
use super::spectra::SpectrumKind;
use super::textures::{Source, Textures};
use super::BuildError;
use crate::interaction::MaterialId;
use crate::material::{Bump, Material, Roughness};
use crate::spectrum::Spectrum;
use crate::texture::{FloatTexture, SpectrumTexture};
use candela_scene::{MaterialDesc, SceneDescription};
use std::collections::HashMap;

/// Named material → id, and the default material's id.
pub type MaterialNames = (HashMap<String, MaterialId>, MaterialId);

/// The scene's materials, their names, which `Texture` directives they
/// use, and which materials read a texture (so that their hits need the
/// camera footprint's differentials).
pub struct BuiltMaterials {
    /// Every material, by [`MaterialId`]; the default one last.
    pub materials: Vec<Material>,
    /// Named materials and the default.
    pub names: MaterialNames,
    /// Per `Texture` directive: used by some material.
    pub textures_used: Vec<bool>,
    /// Per material: it reads a texture (a mix: its amount or any material
    /// it can become), so a hit on it needs its screen-space differentials.
    pub reads_textures: Vec<bool>,
}

/// All materials, the name table, and which `Texture` directives and
/// materials read textures.
pub fn materials(
    desc: &SceneDescription,
    warnings: &mut Vec<String>,
) -> Result<BuiltMaterials, BuildError> {
    let first_named = desc.materials.len();
    let names: HashMap<String, MaterialId> = desc
        .named_materials
        .iter()
        .enumerate()
        .map(|(j, (name, _))| (name.clone(), MaterialId((first_named + j) as u32)))
        .collect();
    let all: Vec<&MaterialDesc> = desc
        .materials
        .iter()
        .chain(desc.named_materials.iter().map(|(_, m)| m))
        .collect();
    let mut textures = Textures::new(&desc.textures);
    let mut out = Vec::with_capacity(all.len() + 1);
    let mut reads_textures = Vec::with_capacity(all.len() + 1);
    for m in &all {
        let before = textures.lookups();
        out.push(material(m, &mut textures, &names)?);
        reads_textures.push(textures.lookups() != before);
    }
    check_mix_cycles(&out, &all)?;
    // pbrt-v4's default material: diffuse, reflectance 0.5.
    let default = MaterialId(out.len() as u32);
    out.push(Material::Diffuse {
        reflectance: SpectrumTexture::Constant(Spectrum::Constant(0.5)),
        bump: None,
    });
    reads_textures.push(false);
    mixes_read_their_materials(&out, &mut reads_textures);
    let used = textures.used().to_vec();
    warnings.extend_from_slice(textures.warnings());
    Ok(BuiltMaterials {
        materials: out,
        names: (names, default),
        textures_used: used,
        reads_textures,
    })
}

/// A mix reads the textures of every material it can become (it is
/// resolved after the differentials are set). Mixes form no cycle
/// (`check_mix_cycles`), so as many rounds as materials settle it.
fn mixes_read_their_materials(materials: &[Material], reads: &mut [bool]) {
    for _ in 0..materials.len() {
        let mut changed = false;
        for (i, m) in materials.iter().enumerate() {
            if let Material::Mix {
                materials: parts, ..
            } = m
            {
                if !reads[i] && parts.iter().any(|p| reads[p.0 as usize]) {
                    reads[i] = true;
                    changed = true;
                }
            }
        }
        if !changed {
            return;
        }
    }
}

/// Roughness: `uroughness`/`vroughness`, each defaulting to `roughness` (0).
fn roughness(src: &Source, tex: &mut Textures) -> Result<Roughness, BuildError> {
    let u = tex.float_opt(src, "uroughness")?;
    let v = tex.float_opt(src, "vroughness")?;
    let common = match (&u, &v) {
        (Some(_), Some(_)) => FloatTexture::Constant(0.0),
        _ => tex.float(src, "roughness", 0.0)?,
    };
    for (name, t) in [
        ("uroughness", &u),
        ("vroughness", &v),
        ("roughness", &Some(common.clone())),
    ] {
        if let Some(t) = t {
            constant_in(src, name, t, Domain::NonNegative)?;
        }
    }
    Ok(Roughness {
        u: u.unwrap_or_else(|| common.clone()),
        v: v.unwrap_or(common),
        remap: src.params.get_bool("remaproughness", true)?,
    })
}

/// Index of refraction `eta`: a float or a spectrum (pbrt-v4 accepts both).
fn eta(src: &Source) -> Result<Spectrum, BuildError> {
    eta_param(src, "eta")
}

/// The material's `normalmap` (an RGB image file, read linearly) or, without
/// one, its `displacement` texture; pbrt-v4 prefers the normal map.
fn bump(src: &Source, tex: &mut Textures) -> Result<Option<Bump>, BuildError> {
    let displacement = tex.float_opt(src, "displacement")?;
    let Some(path) = src.params.get_filename("normalmap")? else {
        return Ok(displacement.map(Bump::Displacement));
    };
    let loc = src.params.param_loc("normalmap").unwrap_or(src.loc);
    Ok(Some(Bump::NormalMap(tex.normal_map(path, loc)?)))
}

fn material(
    m: &MaterialDesc,
    tex: &mut Textures,
    names: &HashMap<String, MaterialId>,
) -> Result<Material, BuildError> {
    let what = format!("Material \"{}\"", m.ty);
    let src = Source {
        what: &what,
        ..Source::new(&m.params, &m.loc, &m.color_space)?
    };
    let bump = match m.ty.as_str() {
        "mix" | "interface" | "" | "none" => None,
        _ => bump(&src, tex)?,
    };
    Ok(match m.ty.as_str() {
        "diffuse" => Material::Diffuse {
            reflectance: tex.spectrum(&src, "reflectance", SpectrumKind::Albedo, 0.5)?,
            bump,
        },
        "conductor" => Material::Conductor {
            spec: conductor_spec(&src, tex, "eta", "k")?,
            roughness: roughness(&src, tex)?,
            bump,
        },
        "dielectric" => Material::Dielectric {
            eta: eta(&src)?,
            roughness: roughness(&src, tex)?,
            bump,
        },
        "thindielectric" => Material::ThinDielectric {
            eta: eta(&src)?,
            bump,
        },
        "diffusetransmission" => Material::DiffuseTransmission {
            reflectance: tex.spectrum(&src, "reflectance", SpectrumKind::Albedo, 0.25)?,
            transmittance: tex.spectrum(&src, "transmittance", SpectrumKind::Albedo, 0.25)?,
            scale: super::check::Check::new(src.params, src.loc, src.what).float(
                "scale",
                1.0,
                Domain::NonNegative,
            )?,
            bump,
        },
        "coateddiffuse" => coated_diffuse(&src, tex, bump)?,
        "coatedconductor" => coated_conductor(&src, tex, bump)?,
        "mix" => mix(&src, tex, names)?,
        "interface" | "" | "none" => Material::Interface,
        other => return Err(BuildError::at(&m.loc, format!("material \"{other}\" is not supported yet (supported: diffuse, diffusetransmission, conductor, coateddiffuse, coatedconductor, dielectric, thindielectric, mix, interface)"))),
    })
}

/// `mix`: `"string materials" [a b]` (named materials) and `amount` (0.5).
fn mix(
    src: &Source,
    tex: &mut Textures,
    names: &HashMap<String, MaterialId>,
) -> Result<Material, BuildError> {
    let loc = src.params.param_loc("materials").unwrap_or(src.loc);
    let list = src.params.get_strings("materials")?.unwrap_or_default();
    let [a, b] = list.as_slice() else {
        return Err(BuildError::at(
            loc,
            format!(
                "mix material needs \"string materials\" with two named materials, found {}",
                list.len()
            ),
        ));
    };
    let id = |n: &String| {
        names.get(n).copied().ok_or_else(|| {
            BuildError::at(
                loc,
                format!("mix material: named material \"{n}\" is not defined"),
            )
        })
    };
    let amount = tex.float(src, "amount", 0.5)?;
    constant_in(src, "amount", &amount, Domain::Closed(0.0, 1.0))?;
    Ok(Material::Mix {
        materials: [id(a)?, id(b)?],
        amount,
    })
}

/// Rejects mix materials that reach themselves through their components.
fn check_mix_cycles(materials: &[Material], descs: &[&MaterialDesc]) -> Result<(), BuildError> {
    // 0 = unvisited, 1 = on the current path, 2 = done (depth-first search).
    let mut state = vec![0u8; materials.len()];
    fn visit(i: usize, m: &[Material], state: &mut [u8]) -> bool {
        match state[i] {
            1 => return false,
            2 => return true,
            _ => {}
        }
        state[i] = 1;
        if let Material::Mix { materials, .. } = &m[i] {
            if !materials.iter().all(|c| visit(c.0 as usize, m, state)) {
                return false;
            }
        }
        state[i] = 2;
        true
    }
    for (i, d) in descs.iter().enumerate() {
        if !visit(i, materials, &mut state) {
            return Err(BuildError::at(
                &d.loc,
                "mix materials form a cycle through their \"materials\"",
            ));
        }
    }
    Ok(())
}
