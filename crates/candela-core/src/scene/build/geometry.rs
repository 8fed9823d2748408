//! Materials, shapes and area lights (instances are flattened into world space).

use super::lights::area_light;
use super::shapes::build_shape;
use super::spectra::{spectrum_param, SpectrumKind};
use super::BuildError;
use crate::interaction::{LightId, MaterialId};
use crate::light::Light;
use crate::material::{ConductorSpec, Material, Roughness};
use crate::math::Transform;
use crate::scene::Primitive;
use crate::spectrum::{named_spectrum, ColorSpace, Spectrum};
use crate::texture::{FloatTexture, SpectrumTexture};
use candela_scene::{Loc, MaterialDesc, MaterialRef, SceneDescription, ShapeDesc};
use std::collections::HashMap;

/// Named material → id.
pub type MaterialNames = (HashMap<String, MaterialId>, MaterialId);

fn color_space(name: &str, loc: &Loc) -> Result<&'static ColorSpace, BuildError> {
    ColorSpace::by_name(name)
        .ok_or_else(|| BuildError::at(loc, format!("unknown color space \"{name}\"")))
}

/// All materials; returns them with the name table and the default material's id.
pub fn materials(desc: &SceneDescription) -> Result<(Vec<Material>, MaterialNames), BuildError> {
    let mut out = Vec::new();
    for m in &desc.materials {
        out.push(material(m)?);
    }
    let mut names = HashMap::new();
    for (name, m) in &desc.named_materials {
        names.insert(name.clone(), MaterialId(out.len() as u32));
        out.push(material(m)?);
    }
    // pbrt-v4's default material: diffuse, reflectance 0.5.
    let default = MaterialId(out.len() as u32);
    out.push(Material::Diffuse {
        reflectance: SpectrumTexture::Constant(Spectrum::Constant(0.5)),
    });
    Ok((out, (names, default)))
}

fn float_tex(m: &MaterialDesc, name: &str, default: f32) -> Result<FloatTexture, BuildError> {
    if let Some(t) = m.params.get_texture(name) {
        return Err(BuildError::at(
            &m.loc,
            format!("texture \"{t}\" for \"{name}\": textures are not supported yet"),
        ));
    }
    Ok(FloatTexture::Constant(m.params.get_float(name, default)?))
}

fn spectrum_tex(
    m: &MaterialDesc,
    name: &str,
    kind: SpectrumKind,
) -> Result<Option<SpectrumTexture>, BuildError> {
    if let Some(t) = m.params.get_texture(name) {
        return Err(BuildError::at(
            &m.loc,
            format!("texture \"{t}\" for \"{name}\": textures are not supported yet"),
        ));
    }
    let cs = color_space(&m.color_space, &m.loc)?;
    Ok(spectrum_param(&m.params, name, kind, cs)?.map(SpectrumTexture::Constant))
}

fn roughness(m: &MaterialDesc) -> Result<Roughness, BuildError> {
    let r = m.params.get_float("roughness", 0.0)?;
    let u = float_tex(m, "uroughness", r)?;
    let v = float_tex(m, "vroughness", r)?;
    Ok(Roughness {
        u,
        v,
        remap: m.params.get_bool("remaproughness", true)?,
    })
}

/// Index of refraction: a float or a spectrum (pbrt-v4 accepts both).
fn eta(m: &MaterialDesc) -> Result<Spectrum, BuildError> {
    if let Some(v) = m.params.get_floats("eta")? {
        return Ok(Spectrum::Constant(v.first().copied().unwrap_or(1.5)));
    }
    let cs = color_space(&m.color_space, &m.loc)?;
    Ok(
        spectrum_param(&m.params, "eta", SpectrumKind::Unbounded, cs)?
            .unwrap_or(Spectrum::Constant(1.5)),
    )
}

fn material(m: &MaterialDesc) -> Result<Material, BuildError> {
    if m.params.get_texture("displacement").is_some()
        || m.params.get_floats("displacement")?.is_some()
    {
        return Err(BuildError::at(
            &m.loc,
            "bump mapping (\"displacement\") is not supported yet",
        ));
    }
    if m.params.get_texture("normalmap").is_some()
        || !m.params.get_string("normalmap", "")?.is_empty()
    {
        return Err(BuildError::at(&m.loc, "\"normalmap\" is not supported yet"));
    }
    Ok(match m.ty.as_str() {
        "diffuse" => Material::Diffuse {
            reflectance: spectrum_tex(m, "reflectance", SpectrumKind::Albedo)?
                .unwrap_or(SpectrumTexture::Constant(Spectrum::Constant(0.5))),
        },
        "conductor" => {
            let spec = match spectrum_tex(m, "reflectance", SpectrumKind::Albedo)? {
                Some(r) => ConductorSpec::Reflectance(r),
                None => {
                    let cu = |n: &str| named_spectrum(n).map(SpectrumTexture::Constant).ok_or_else(|| BuildError::Other(format!("missing built-in spectrum {n}")));
                    let eta = match spectrum_tex(m, "eta", SpectrumKind::Unbounded)? {
                        Some(e) => e,
                        None => cu("metal-Cu-eta")?,
                    };
                    let k = match spectrum_tex(m, "k", SpectrumKind::Unbounded)? {
                        Some(k) => k,
                        None => cu("metal-Cu-k")?,
                    };
                    ConductorSpec::EtaK { eta, k }
                }
            };
            Material::Conductor { spec, roughness: roughness(m)? }
        }
        "dielectric" => Material::Dielectric { eta: eta(m)?, roughness: roughness(m)? },
        "thindielectric" => Material::ThinDielectric { eta: eta(m)? },
        "interface" | "" | "none" => Material::Interface,
        other => return Err(BuildError::at(&m.loc, format!("material \"{other}\" is not supported yet (supported: diffuse, conductor, dielectric, thindielectric, interface)"))),
    })
}

/// All primitives (instances flattened) and the area lights they carry.
pub fn primitives(
    desc: &SceneDescription,
    names: &MaterialNames,
) -> Result<(Vec<Primitive>, Vec<Light>), BuildError> {
    let mut prims = Vec::new();
    let mut lights = Vec::new();
    for s in &desc.shapes {
        add_shape(s, &Transform::IDENTITY, names, &mut prims, &mut lights)?;
    }
    for inst in &desc.instances {
        let def = desc
            .instance_definitions
            .iter()
            .find(|d| d.name == inst.name)
            .ok_or_else(|| {
                BuildError::at(
                    &inst.loc,
                    format!("object instance \"{}\" was never defined", inst.name),
                )
            })?;
        let t = Transform::from_rows_f64(inst.render_from_instance.m)
            .ok_or_else(|| BuildError::at(&inst.loc, "singular instance transform"))?;
        for s in &def.shapes {
            if let Some(a) = &s.area_light {
                return Err(BuildError::at(&a.loc, "area lights inside object instances are not supported (pbrt-v4 rejects them too)"));
            }
            add_shape(s, &t, names, &mut prims, &mut lights)?;
        }
    }
    Ok((prims, lights))
}

fn add_shape(
    s: &ShapeDesc,
    parent: &Transform,
    names: &MaterialNames,
    prims: &mut Vec<Primitive>,
    lights: &mut Vec<Light>,
) -> Result<(), BuildError> {
    let material = match &s.material {
        MaterialRef::Index(i) => Some(MaterialId(*i as u32)),
        MaterialRef::Named(n) => Some(*names.0.get(n).ok_or_else(|| {
            BuildError::at(&s.loc, format!("named material \"{n}\" is not defined"))
        })?),
        MaterialRef::None => Some(names.1),
    };
    if let Some(a) = s.params.get_floats("alpha")? {
        if a.first().is_some_and(|&v| v != 1.0) {
            return Err(BuildError::at(
                &s.loc,
                "\"alpha\" cut-outs are not supported yet",
            ));
        }
    }
    if let Some(t) = s.params.get_texture("alpha") {
        return Err(BuildError::at(
            &s.loc,
            format!("alpha texture \"{t}\" is not supported yet"),
        ));
    }
    let object = Transform::from_rows_f64(s.render_from_object.m)
        .ok_or_else(|| BuildError::at(&s.loc, "singular shape transform"))?;
    let render_from_object = parent.then_after(&object);
    let shapes = build_shape(s, &render_from_object)?;
    for shape in shapes {
        let area_light = match &s.area_light {
            Some(a) => {
                lights.push(area_light(a, &shape, &s.loc)?);
                Some(LightId(lights.len() as u32 - 1))
            }
            None => None,
        };
        prims.push(Primitive {
            shape,
            material,
            area_light,
        });
    }
    Ok(())
}
