//! Materials, shapes and area lights (instances are flattened into world space).

use super::coated::{coated_conductor, coated_diffuse, conductor_spec};
use super::lights::area_light;
use super::spectra::{spectrum_param, SpectrumKind};
use super::BuildError;
use crate::interaction::{LightId, MaterialId};
use crate::light::Light;
use crate::material::{Material, Roughness};
use crate::math::{Transform, Vec2, Vec3};
use crate::scene::Primitive;
use crate::shape::{Disk, Shape, Sphere, Triangle, TriangleMesh};
use crate::spectrum::{ColorSpace, Spectrum};
use crate::texture::{FloatTexture, SpectrumTexture};
use candela_scene::{Loc, MaterialDesc, MaterialRef, ParamType, SceneDescription, ShapeDesc};
use std::collections::HashMap;
use std::sync::Arc;

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

pub(super) fn float_tex(
    m: &MaterialDesc,
    name: &str,
    default: f32,
) -> Result<FloatTexture, BuildError> {
    if let Some(t) = m.params.get_texture(name) {
        return Err(BuildError::at(
            &m.loc,
            format!("texture \"{t}\" for \"{name}\": textures are not supported yet"),
        ));
    }
    Ok(FloatTexture::Constant(m.params.get_float(name, default)?))
}

pub(super) fn spectrum_tex(
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

/// Index of refraction `eta`.
fn eta(m: &MaterialDesc) -> Result<Spectrum, BuildError> {
    eta_param(m, "eta")
}

/// Index of refraction `name`: a float or a spectrum (pbrt-v4 accepts both), default 1.5.
pub(super) fn eta_param(m: &MaterialDesc, name: &str) -> Result<Spectrum, BuildError> {
    // Ask for floats only when the parameter is one: `get_floats` rejects a spectrum.
    let is_float = m.params.get(name).is_some_and(|p| p.ty == ParamType::Float);
    if let Some(v) = is_float
        .then(|| m.params.get_floats(name))
        .transpose()?
        .flatten()
    {
        return Ok(Spectrum::Constant(v.first().copied().unwrap_or(1.5)));
    }
    let cs = color_space(&m.color_space, &m.loc)?;
    Ok(
        spectrum_param(&m.params, name, SpectrumKind::Unbounded, cs)?
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
        "conductor" => Material::Conductor { spec: conductor_spec(m, "eta", "k")?, roughness: roughness(m)? },
        "coateddiffuse" => coated_diffuse(m)?,
        "coatedconductor" => coated_conductor(m)?,
        "dielectric" => Material::Dielectric { eta: eta(m)?, roughness: roughness(m)? },
        "thindielectric" => Material::ThinDielectric { eta: eta(m)? },
        "interface" | "" | "none" => Material::Interface,
        other => return Err(BuildError::at(&m.loc, format!("material \"{other}\" is not supported yet (supported: diffuse, conductor, coateddiffuse, coatedconductor, dielectric, thindielectric, interface)"))),
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
        add_shape(
            desc,
            s,
            &Transform::IDENTITY,
            names,
            &mut prims,
            &mut lights,
        )?;
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
            add_shape(desc, s, &t, names, &mut prims, &mut lights)?;
        }
    }
    Ok((prims, lights))
}

fn add_shape(
    desc: &SceneDescription,
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
    let shapes = build_shape(desc, s, &render_from_object)?;
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

fn build_shape(
    desc: &SceneDescription,
    s: &ShapeDesc,
    t: &Transform,
) -> Result<Vec<Shape>, BuildError> {
    let p = &s.params;
    let ro = s.reverse_orientation;
    Ok(match s.name.as_str() {
        "sphere" => {
            let r = p.get_float("radius", 1.0)?;
            let (zmin, zmax, phimax) = (
                p.get_float("zmin", -r)?,
                p.get_float("zmax", r)?,
                p.get_float("phimax", 360.0)?,
            );
            vec![Shape::Sphere(Sphere::new(
                Arc::new(*t),
                ro,
                r,
                zmin,
                zmax,
                phimax,
            ))]
        }
        "disk" => {
            let (h, r, ri, phimax) = (
                p.get_float("height", 0.0)?,
                p.get_float("radius", 1.0)?,
                p.get_float("innerradius", 0.0)?,
                p.get_float("phimax", 360.0)?,
            );
            vec![Shape::Disk(Disk::new(Arc::new(*t), ro, h, r, ri, phimax))]
        }
        "trianglemesh" => {
            let pos = p
                .get_point3s("P")?
                .ok_or_else(|| BuildError::at(&s.loc, "trianglemesh needs \"point3 P\""))?;
            let indices =
                match p.get_ints("indices")? {
                    Some(i) => i,
                    None if pos.len() == 3 => vec![0, 1, 2],
                    None => return Err(BuildError::at(
                        &s.loc,
                        "trianglemesh needs \"integer indices\" unless it has exactly 3 vertices",
                    )),
                };
            let n = p.get_normals("N")?;
            let uv = p.get_point2s("uv")?;
            let face = p.get_ints("faceIndices")?;
            mesh_shapes(s, t, pos, indices, n, uv, face)?
        }
        "plymesh" => {
            let file = p
                .get_filename("filename")?
                .ok_or_else(|| BuildError::at(&s.loc, "plymesh needs \"string filename\""))?;
            if p.get_texture("displacement").is_some() {
                return Err(BuildError::at(
                    &s.loc,
                    "plymesh \"displacement\" is not supported yet",
                ));
            }
            let m = candela_scene::read_ply(&file)
                .map_err(|e| BuildError::at(&s.loc, format!("{e}")))?;
            let idx = m.indices.iter().map(|&i| i as i32).collect();
            mesh_shapes(s, t, m.positions, idx, m.normals, m.uvs, m.face_indices)?
        }
        other => {
            let _ = desc;
            return Err(BuildError::at(&s.loc, format!("shape \"{other}\" is not supported yet (supported: trianglemesh, plymesh, sphere, disk)")));
        }
    })
}

fn mesh_shapes(
    s: &ShapeDesc,
    t: &Transform,
    pos: Vec<[f32; 3]>,
    indices: Vec<i32>,
    n: Option<Vec<[f32; 3]>>,
    uv: Option<Vec<[f32; 2]>>,
    face: Option<Vec<i32>>,
) -> Result<Vec<Shape>, BuildError> {
    if !indices.len().is_multiple_of(3) {
        return Err(BuildError::at(
            &s.loc,
            format!(
                "triangle mesh has {} indices, not a multiple of 3",
                indices.len()
            ),
        ));
    }
    if let Some(bad) = indices.iter().find(|&&i| i < 0 || i as usize >= pos.len()) {
        return Err(BuildError::at(
            &s.loc,
            format!(
                "vertex index {bad} out of range (mesh has {} vertices)",
                pos.len()
            ),
        ));
    }
    if n.as_ref().is_some_and(|n| n.len() != pos.len())
        || uv.as_ref().is_some_and(|u| u.len() != pos.len())
    {
        return Err(BuildError::at(
            &s.loc,
            "\"N\" and \"uv\" must have one entry per vertex of \"P\"",
        ));
    }
    let mesh = TriangleMesh::new(
        t,
        s.reverse_orientation,
        indices.iter().map(|&i| i as u32).collect(),
        pos.iter().map(|p| Vec3::from_array(*p)).collect(),
        n.map(|n| n.iter().map(|v| Vec3::from_array(*v)).collect()),
        uv.map(|u| u.iter().map(|v| Vec2::from_array(*v)).collect()),
        face,
    )
    .map_err(|e| BuildError::at(&s.loc, format!("invalid triangle mesh: {e}")))?;
    Ok(Triangle::all(&Arc::new(mesh))
        .into_iter()
        .map(Shape::Triangle)
        .collect())
}
