//! Shapes and area lights (instances are flattened into world space).

use super::lights::area_light;
use super::materials::MaterialNames;
use super::shapes::build_shape;
use super::textures::{Source, Textures};
use super::BuildError;
use crate::interaction::{LightId, MaterialId};
use crate::light::Light;
use crate::math::Transform;
use crate::scene::Primitive;
use crate::texture::FloatTexture;
use candela_scene::{MaterialRef, SceneDescription, ShapeDesc};

/// Primitives, their area lights, and the `Texture` directives alpha used.
pub type Built = (Vec<Primitive>, Vec<Light>, Vec<bool>);

/// All primitives (instances flattened), the area lights they carry, and
/// which `Texture` directives their `alpha` parameters used. Shapes and
/// instances under a singular CTM are left out with a warning.
pub fn primitives(
    desc: &SceneDescription,
    names: &MaterialNames,
    warnings: &mut Vec<String>,
) -> Result<Built, BuildError> {
    let mut prims = Vec::new();
    let mut lights = Vec::new();
    let mut tex = Textures::new(&desc.textures);
    let tex = &mut tex;
    for s in &desc.shapes {
        add_shape(
            s,
            &Transform::IDENTITY,
            names,
            tex,
            &mut prims,
            &mut lights,
            warnings,
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
        let Some(t) = Transform::from_rows_f64(inst.render_from_instance.m) else {
            warnings.push(singular(&inst.loc, "object instance"));
            def.shapes.iter().for_each(|s| s.params.mark_all_used());
            continue;
        };
        for s in &def.shapes {
            if let Some(a) = &s.area_light {
                return Err(BuildError::at(&a.loc, "area lights inside object instances are not supported (pbrt-v4 rejects them too)"));
            }
            add_shape(s, &t, names, tex, &mut prims, &mut lights, warnings)?;
        }
    }
    let used = tex.used().to_vec();
    Ok((prims, lights, used))
}

fn add_shape(
    s: &ShapeDesc,
    parent: &Transform,
    names: &MaterialNames,
    tex: &mut Textures,
    prims: &mut Vec<Primitive>,
    lights: &mut Vec<Light>,
    warnings: &mut Vec<String>,
) -> Result<(), BuildError> {
    let material = match &s.material {
        MaterialRef::Index(i) => Some(MaterialId(*i as u32)),
        MaterialRef::Named(n) => Some(*names.0.get(n).ok_or_else(|| {
            BuildError::at(&s.loc, format!("named material \"{n}\" is not defined"))
        })?),
        MaterialRef::None => Some(names.1),
    };
    let Some(object) = Transform::from_rows_f64(s.render_from_object.m) else {
        warnings.push(singular(&s.loc, "shape"));
        s.params.mark_all_used();
        if let Some(a) = &s.area_light {
            a.params.mark_all_used();
        }
        return Ok(());
    };
    let alpha = alpha(s, tex)?;
    let render_from_object = parent.then_after(&object);
    let shapes = build_shape(s, &render_from_object)?;
    let alpha = match alpha {
        // pbrt-v4 masks the emission by alpha and skips alpha-0 hits: the
        // emitter neither shows nor lights anything, so it is left out
        // (after its shape and light were checked like any other).
        Alpha::Off => {
            if let (Some(a), Some(shape)) = (&s.area_light, shapes.first()) {
                area_light(a, shape, &s.loc)?;
            }
            return Ok(());
        }
        Alpha::Mask(a) => a,
    };
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
            alpha: alpha.clone(),
        });
    }
    Ok(())
}

/// The warning for an entity left out because its CTM is singular (pbrt-v4
/// accepts such transforms and flattens the shape; exporters use a zero
/// scale to hide objects).
fn singular(loc: &candela_scene::Loc, what: &str) -> String {
    format!("{loc}: {what} under a singular (zero-scale) transform is left out; pbrt-v4 would render it flattened")
}

/// A shape's alpha: a mask (`None` when fully opaque), or `Off` for an
/// emitter whose constant alpha is 0.
enum Alpha {
    Mask(Option<FloatTexture>),
    Off,
}

/// pbrt-v4's `alpha` (float or float texture). Emitters with other cut-outs
/// are rejected (their emission would have to be masked too).
fn alpha(s: &ShapeDesc, tex: &mut Textures) -> Result<Alpha, BuildError> {
    let src = Source::new(&s.params, &s.loc, "srgb")?;
    let alpha = match tex.float_opt(&src, "alpha")? {
        Some(FloatTexture::Constant(a)) if a >= 1.0 => None,
        other => other,
    };
    match (&alpha, &s.area_light) {
        (Some(FloatTexture::Constant(a)), Some(_)) if *a <= 0.0 => Ok(Alpha::Off),
        (Some(_), Some(_)) => Err(BuildError::at(
            s.params.param_loc("alpha").unwrap_or(&s.loc),
            "\"alpha\" on an area light is not supported yet (only 0, which switches it off)",
        )),
        _ => Ok(Alpha::Mask(alpha)),
    }
}
