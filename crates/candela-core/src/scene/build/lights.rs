//! `LightSource` and `AreaLightSource` directives.

use super::spectra::{spectrum_param, SpectrumKind};
use super::BuildError;
use crate::light::{self as create, Light};
use crate::math::{Transform, Vec3};
use crate::shape::Shape;
use crate::spectrum::{ColorSpace, Spectrum};
use candela_scene::{Entity, Loc, SceneDescription};

fn cs(name: &str, loc: &Loc) -> Result<&'static ColorSpace, BuildError> {
    ColorSpace::by_name(name)
        .ok_or_else(|| BuildError::at(loc, format!("unknown color space \"{name}\"")))
}

fn optional_positive(v: f32) -> Option<f32> {
    (v > 0.0).then_some(v)
}

/// The diffuse area light attached to one shape.
pub fn area_light(a: &Entity, shape: &Shape, shape_loc: &Loc) -> Result<Light, BuildError> {
    if a.name != "diffuse" {
        return Err(BuildError::at(
            &a.loc,
            format!(
                "area light \"{}\" is not supported (pbrt-v4 has only \"diffuse\")",
                a.name
            ),
        ));
    }
    let p = &a.params;
    if p.get_filename("filename")?.is_some() {
        return Err(BuildError::at(
            &a.loc,
            "image area lights (\"filename\") are not supported yet",
        ));
    }
    let l = spectrum_param(
        p,
        "L",
        SpectrumKind::Illuminant,
        cs(&a.color_space, &a.loc)?,
    )?
    .unwrap_or_else(|| ColorSpace::srgb().illuminant.clone());
    let _ = shape_loc;
    let (scale, two_sided, power) = (
        p.get_float("scale", 1.0)?,
        p.get_bool("twosided", false)?,
        optional_positive(p.get_float("power", -1.0)?),
    );
    Ok(Light::DiffuseArea(create::diffuse_area_light(
        shape.clone(),
        l,
        scale,
        two_sided,
        power,
    )))
}

/// All `LightSource` lights.
pub fn lights(desc: &SceneDescription) -> Result<Vec<Light>, BuildError> {
    desc.lights.iter().map(light).collect()
}

fn light(d: &candela_scene::LightDesc) -> Result<Light, BuildError> {
    let p = &d.params;
    let t = Transform::from_rows_f64(d.render_from_light.m)
        .ok_or_else(|| BuildError::at(&d.loc, "singular light transform"))?;
    let space = cs(&d.color_space, &d.loc)?;
    let illum = |name: &str| -> Result<Spectrum, BuildError> {
        Ok(spectrum_param(p, name, SpectrumKind::Illuminant, space)?
            .unwrap_or_else(|| space.illuminant.clone()))
    };
    let scale = p.get_float("scale", 1.0)?;
    let v3 = |name: &str, def: Vec3| -> Result<Vec3, BuildError> {
        Ok(p.get_point3(name, def.to_array())?.into())
    };
    Ok(match d.name.as_str() {
        "point" => Light::Point(create::point_light(&t, illum("I")?, scale, optional_positive(p.get_float("power", -1.0)?), v3("from", Vec3::ZERO)?)),
        "spot" => Light::Spot(create::spot_light(
            &t,
            illum("I")?,
            scale,
            p.get_float("coneangle", 30.0)?,
            p.get_float("conedelta", 5.0)?,
            optional_positive(p.get_float("power", -1.0)?),
            v3("from", Vec3::ZERO)?,
            v3("to", Vec3::Z)?,
        )),
        "distant" => Light::Distant(create::distant_light(
            &t,
            illum("L")?,
            scale,
            optional_positive(p.get_float("illuminance", -1.0)?),
            v3("from", Vec3::ZERO)?,
            v3("to", Vec3::Z)?,
        )),
        "infinite" => {
            if p.get_filename("filename")?.is_some() {
                return Err(BuildError::at(&d.loc, "image-based \"infinite\" lights (\"filename\") are not supported yet"));
            }
            if p.get_point3s("portal")?.is_some() {
                return Err(BuildError::at(&d.loc, "\"portal\" is not supported yet"));
            }
            Light::UniformInfinite(create::uniform_infinite_light(illum("L")?, scale, optional_positive(p.get_float("illuminance", -1.0)?)))
        }
        other => return Err(BuildError::at(&d.loc, format!("light \"{other}\" is not supported yet (supported: point, spot, distant, infinite)"))),
    })
}
