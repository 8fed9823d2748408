//! Shapes and area lights (instances are flattened into world space).

use super::lights::area_light;
use super::materials::MaterialNames;
use super::shapes::build_shape;
use super::BuildError;
use crate::interaction::{LightId, MaterialId};
use crate::light::Light;
use crate::math::Transform;
use crate::scene::Primitive;
use candela_scene::{MaterialRef, SceneDescription, ShapeDesc};

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
    prims.reserve(shapes.len());
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
