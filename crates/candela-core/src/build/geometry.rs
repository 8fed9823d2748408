//! Shapes and area lights (instances are flattened into world space).
//!
//! A shape whose transform differs at the start and end of `TransformTimes`
//! (or that belongs to a moving instance) is built in object space and
//! placed in a [`MovingGroup`] with its [`AnimatedTransform`].

use super::budget::Budget;
use super::lights::area_light_spec;
use super::materials::MaterialNames;
use super::shapes::build_shape;
use super::textures::{Source, Textures};
use super::BuildError;
use crate::interaction::{LightId, MaterialId};
use crate::light::Light;
use crate::math::{AnimatedTransform, Bounds3, Transform};
use crate::scene::{MovingGroup, Primitive};
use crate::shape::Shape;
use crate::texture::FloatTexture;
use candela_scene::{MaterialRef, SceneDescription, ShapeDesc};

/// Static primitives, moving groups, their area lights, and the `Texture`
/// directives alpha used.
pub struct Built {
    /// Static primitives in world space.
    pub prims: Vec<Primitive>,
    /// Moving shapes.
    pub movers: Vec<MovingGroup>,
    /// Area lights of the static primitives.
    pub lights: Vec<Light>,
    /// Which `Texture` directives `alpha` parameters used.
    pub textures_used: Vec<bool>,
}

/// Where a shape's parent places it: at the start time and, when moving, at
/// the end time.
struct Placement {
    start: Transform,
    end: Option<Transform>,
    times: [f32; 2],
}

/// Shapes being collected, and the memory budget refined meshes claim.
struct Sink<'a> {
    prims: Vec<Primitive>,
    movers: Vec<MovingGroup>,
    lights: Vec<Light>,
    budget: &'a mut Budget,
}

fn transform(
    m: &candela_scene::Mat4d,
    loc: &candela_scene::Loc,
    what: &str,
) -> Result<Transform, BuildError> {
    Transform::from_rows_f64(m.m)
        .ok_or_else(|| BuildError::at(loc, format!("singular {what} transform")))
}

/// All primitives (instances flattened), the area lights they carry, and
/// which `Texture` directives their `alpha` parameters used. Shapes and
/// instances under a singular CTM are left out with a warning.
pub fn primitives(
    desc: &SceneDescription,
    names: &MaterialNames,
    budget: &mut Budget,
    warnings: &mut Vec<String>,
) -> Result<Built, BuildError> {
    let mut sink = Sink {
        prims: Vec::new(),
        movers: Vec::new(),
        lights: Vec::new(),
        budget,
    };
    let mut tex = Textures::new(&desc.textures);
    let tex = &mut tex;
    let times = desc.transform_times;
    let world = Placement {
        start: Transform::IDENTITY,
        end: None,
        times,
    };
    for s in &desc.shapes {
        add_shape(s, &world, names, tex, &mut sink, warnings)?;
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
        let Some(start) = Transform::from_rows_f64(inst.render_from_instance.m) else {
            warnings.push(singular(&inst.loc, "object instance"));
            def.shapes.iter().for_each(|s| s.params.mark_all_used());
            continue;
        };
        let placement = Placement {
            start,
            end: inst
                .render_from_instance_end
                .as_ref()
                .map(|m| transform(m, &inst.loc, "instance"))
                .transpose()?,
            times,
        };
        for s in &def.shapes {
            if let Some(a) = &s.area_light {
                return Err(BuildError::at(&a.loc, "area lights inside object instances are not supported (pbrt-v4 rejects them too)"));
            }
            add_shape(s, &placement, names, tex, &mut sink, warnings)?;
        }
    }
    Ok(Built {
        prims: sink.prims,
        movers: sink.movers,
        lights: sink.lights,
        textures_used: tex.used().to_vec(),
    })
}

/// The material a shape refers to (named ones must be defined).
fn material_of(s: &ShapeDesc, names: &MaterialNames) -> Result<MaterialId, BuildError> {
    Ok(match &s.material {
        MaterialRef::Index(i) => MaterialId(*i as u32),
        MaterialRef::Named(n) => *names.0.get(n).ok_or_else(|| {
            BuildError::at(&s.loc, format!("named material \"{n}\" is not defined"))
        })?,
        MaterialRef::None => names.1,
    })
}

fn add_shape(
    s: &ShapeDesc,
    parent: &Placement,
    names: &MaterialNames,
    tex: &mut Textures,
    sink: &mut Sink<'_>,
    warnings: &mut Vec<String>,
) -> Result<(), BuildError> {
    let material = Some(material_of(s, names)?);
    let Some(object) = Transform::from_rows_f64(s.render_from_object.m) else {
        warnings.push(singular(&s.loc, "shape"));
        s.params.mark_all_used();
        if let Some(a) = &s.area_light {
            a.params.mark_all_used();
        }
        return Ok(());
    };
    let alpha = alpha(s, tex)?;
    let object_end = s
        .render_from_object_end
        .as_ref()
        .map(|m| transform(m, &s.loc, "shape"))
        .transpose()?;
    let render_from_object = parent.start.then_after(&object);
    if parent.end.is_some() || object_end.is_some() {
        let end = parent
            .end
            .unwrap_or(parent.start)
            .then_after(&object_end.unwrap_or(object));
        let motion =
            AnimatedTransform::new(render_from_object, parent.times[0], end, parent.times[1]);
        return add_moving_shape(s, material, alpha, motion, sink);
    }
    let shapes = build_shape(s, &render_from_object, sink.budget)?;
    finite_bounds(s, shapes.iter().map(Shape::bounds))?;
    let spec = s
        .area_light
        .as_ref()
        .map(|a| area_light_spec(a, warnings))
        .transpose()?;
    let alpha = match alpha {
        // pbrt-v4's invisible light: an emitter with constant alpha 0 is
        // never hit (no primitive), yet still lights the scene.
        Alpha::Off => {
            if let Some(spec) = &spec {
                for shape in &shapes {
                    let Light::DiffuseArea(l) = spec.light(shape, None) else {
                        continue;
                    };
                    sink.lights.push(Light::DiffuseArea(l.invisible()));
                }
            }
            return Ok(());
        }
        Alpha::Mask(a) => a,
    };
    let (prims, lights) = (&mut sink.prims, &mut sink.lights);
    prims.reserve(shapes.len());
    for shape in shapes {
        let area_light = match &spec {
            Some(spec) => {
                lights.push(spec.light(&shape, alpha.clone()));
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

/// A shape whose transform changes over the shutter: its primitives in
/// object space in a [`MovingGroup`] that `motion` places.
fn add_moving_shape(
    s: &ShapeDesc,
    material: Option<MaterialId>,
    alpha: Alpha,
    motion: AnimatedTransform,
    sink: &mut Sink<'_>,
) -> Result<(), BuildError> {
    if let Some(a) = &s.area_light {
        return Err(BuildError::at(
            &a.loc,
            "an area light on a moving shape is not supported (pbrt-v4 does not animate area lights either)",
        ));
    }
    let Alpha::Mask(alpha) = alpha else {
        return Ok(()); // Switched off (only emitters, refused above).
    };
    let shapes = build_shape(s, &Transform::IDENTITY, sink.budget)?;
    finite_bounds(
        s,
        shapes.iter().map(|sh| motion.motion_bounds(&sh.bounds())),
    )?;
    let prims = shapes
        .into_iter()
        .map(|shape| Primitive {
            shape,
            material,
            area_light: None,
            alpha: alpha.clone(),
        })
        .collect();
    sink.movers.push(MovingGroup::new(prims, motion));
    Ok(())
}

/// Fails unless every one of `bounds` (a shape's pieces in render space) is
/// finite: a transform or vertex that overflows single precision would
/// otherwise reach the BVH.
fn finite_bounds(
    s: &ShapeDesc,
    mut bounds: impl Iterator<Item = Bounds3>,
) -> Result<(), BuildError> {
    let finite = |b: &Bounds3| b.min.is_finite() && b.max.is_finite();
    match bounds.find(|b| !finite(b)) {
        None => Ok(()),
        Some(b) => Err(BuildError::at(
            &s.loc,
            format!(
                "Shape \"{}\" has non-finite bounds in render space ({:?} to {:?}): its size and transformation overflow single precision",
                s.name,
                b.min.to_array(),
                b.max.to_array()
            ),
        )),
    }
}

/// The warning for an entity left out because its CTM is singular (pbrt-v4
/// accepts such transforms and flattens the shape; exporters use a zero
/// scale to hide objects).
fn singular(loc: &candela_scene::Loc, what: &str) -> String {
    format!("{loc}: {what} under a singular (zero-scale) transform is left out; pbrt-v4 would render it flattened")
}

/// A shape's alpha: a mask (`None` when fully opaque), or `Off` for an
/// emitter whose constant alpha is 0.
///
/// A constant-0 emitter is pbrt-v4's invisible light: never hit, but still
/// emitting through light and emission sampling (pbrt-v4 types it
/// `DeltaPosition` to keep it out of MIS; candela marks it not hittable, see
/// `Light::is_hittable`). Any other alpha on an emitter masks its emission
/// too (`DiffuseAreaLight`).
enum Alpha {
    Mask(Option<FloatTexture>),
    Off,
}

/// pbrt-v4's `alpha` (float or float texture).
fn alpha(s: &ShapeDesc, tex: &mut Textures) -> Result<Alpha, BuildError> {
    let src = Source::new(&s.params, &s.loc, "srgb")?;
    let alpha = match tex.float_opt(&src, "alpha")? {
        Some(FloatTexture::Constant(a)) if a >= 1.0 => None,
        other => other,
    };
    match (&alpha, &s.area_light) {
        (Some(FloatTexture::Constant(a)), Some(_)) if *a <= 0.0 => Ok(Alpha::Off),
        _ => Ok(Alpha::Mask(alpha)),
    }
}
