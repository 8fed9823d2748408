//! `LightSource` and `AreaLightSource` directives.
//!
//! `"infinite"` follows pbrt-v4's `Light::Create`: without `L` and
//! `filename`, a uniform sky of the colour space's illuminant; with `L`, a
//! uniform sky of that spectrum; with `filename`, an equal-area square RGB
//! image (PNG or EXR, relative to the scene file); both is an error. A
//! `portal` is ignored with a warning: pbrt-v4's `PortalImageInfiniteLight`
//! samples only directions through the portal and shows the sky only there,
//! which renders the same wherever the portal is the scene's only opening.
//!
//! `AreaLightSource "diffuse"` follows pbrt-v4's `DiffuseAreaLight::Create`:
//! `L` (default: the colour space's illuminant) or an RGB `filename` image
//! (PNG or EXR, finite texels) looked up by the shape's (u, v), not both;
//! `scale`, `twosided` and `power`. The directive is read once per `Shape`
//! (one image for all the triangles of a mesh) and then gives one light
//! per shape, carrying the shape's `alpha` texture.
//!
//! `"goniometric"` and `"projection"` follow their pbrt-v4 `Create`
//! functions: `filename` (PNG or EXR) is required for a projector and
//! optional for a goniometric light (isotropic without it, with a warning;
//! pbrt-v4 only warns and then divides by the empty image's size), the
//! goniometric map must be square, the projector's image RGB, and neither
//! may hold infinite or NaN texels. A projector's `fov` must lie in
//! (0°, 180°).
//!
//! `"goniometric"` with a `filename` ending in `.ies` reads an IES LM-63
//! file instead (`candela_scene::ies`, `light::IesWeb`): photometric nadir
//! along `to − from` (default +z), horizontal angle 0 along light-space +x;
//! `I` then only sets the colour. `TILT` other than `NONE` is refused.
//!
//! Photometric units (`candela`, `luminance`, `lumens`, `lux`) are read by
//! [`super::photometric`] for every light.
//!
//! Every light's `scale` is ≥ 0 (a negative one would emit negative
//! radiance); a spot light's `coneangle` lies in (0°, 180°] and its
//! `conedeltaangle` in [0°, `coneangle`]. A `power` or `illuminance` ≤ 0
//! means "not given", as in pbrt-v4.

use super::check::{Check, Domain};
use super::photometric::{units, Units, UnitsOf};
use super::spectra::{spectrum_param, SpectrumKind};
use super::BuildError;
use crate::image::{read_map, ColorEncoding, MapImage};
use crate::light::{self as create, IesWeb, Light};
use crate::math::{Transform, Vec3};
use crate::shape::Shape;
use crate::spectrum::{ColorSpace, Spectrum};
use crate::texture::FloatTexture;
use candela_scene::{Entity, LightDesc, Loc, SceneDescription};
use std::path::Path;
use std::sync::Arc;

fn cs(name: &str, loc: &Loc) -> Result<&'static ColorSpace, BuildError> {
    ColorSpace::by_name(name)
        .ok_or_else(|| BuildError::at(loc, format!("unknown color space \"{name}\"")))
}

/// What a diffuse area light emits: a spectrum, or an RGB image and its
/// colour space.
enum AreaEmission {
    Spectrum(Spectrum),
    Image(Arc<MapImage>, &'static ColorSpace),
}

/// A `Shape`'s `AreaLightSource`, read once and then instantiated for each
/// shape (triangle) the directive makes.
pub struct AreaLightSpec {
    emission: AreaEmission,
    scene_cs: &'static ColorSpace,
    scale: f32,
    two_sided: bool,
    power: Option<f32>,
    /// `power` came from `lumens`: it is the whole shape's, shared by area.
    shared: bool,
    /// Total area of the shape's triangles (for `shared`).
    total_area: f32,
}

impl AreaLightSpec {
    /// The light on `shape` (render space), its emission cut by `alpha`.
    pub fn light(&self, shape: &Shape, alpha: Option<FloatTexture>) -> Light {
        let power = match self.power {
            Some(p) if self.shared && self.total_area > 0.0 => {
                Some(p * shape.area() / self.total_area)
            }
            p => p,
        };
        let (shape, scale, two) = (shape.clone(), self.scale, self.two_sided);
        let light = match &self.emission {
            AreaEmission::Spectrum(l) => {
                create::diffuse_area_light(shape, l.clone(), scale, two, power)
            }
            AreaEmission::Image(im, cs) => create::diffuse_area_image_light(
                shape,
                im.clone(),
                cs,
                self.scene_cs,
                scale,
                two,
                power,
            ),
        };
        Light::DiffuseArea(light.with_alpha(alpha))
    }
}

/// Reads a shape's `AreaLightSource` (pbrt-v4 has only `"diffuse"`);
/// `total_area` is the shape's, over which a flux in `lumens` is shared.
pub fn area_light_spec(
    a: &Entity,
    total_area: f32,
    warnings: &mut Vec<String>,
) -> Result<AreaLightSpec, BuildError> {
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
    let scene_cs = cs(&a.color_space, &a.loc)?;
    let l = spectrum_param(p, "L", SpectrumKind::Illuminant, scene_cs)?;
    let emission = match (p.get_filename("filename")?, l) {
        (Some(_), Some(_)) => {
            return Err(BuildError::at(
                &a.loc,
                "both \"L\" and \"filename\" specified for a \"diffuse\" area light",
            ))
        }
        (Some(path), None) => {
            let loc = p.param_loc("filename").unwrap_or(&a.loc);
            let (im, image_cs) = light_image(&path, loc, warnings)?;
            if im.channels != 3 {
                return Err(BuildError::at(
                    loc,
                    format!(
                        "{}: image provided to \"diffuse\" area light must have R, G, and B channels",
                        path.display()
                    ),
                ));
            }
            AreaEmission::Image(Arc::new(im), image_cs)
        }
        (None, l) => AreaEmission::Spectrum(l.unwrap_or_else(|| scene_cs.illuminant.clone())),
    };
    let what = format!("AreaLightSource \"{}\"", a.name);
    let ck = Check::new(p, &a.loc, &what);
    let u = units(&ck, UnitsOf::Area)?;
    let u = match &emission {
        AreaEmission::Spectrum(s) => u.colour_only(s),
        AreaEmission::Image(..) => u,
    };
    Ok(AreaLightSpec {
        emission,
        scene_cs,
        scale: u.scale,
        two_sided: p.get_bool("twosided", false)?,
        power: u.target,
        shared: u.from_lumens,
        total_area,
    })
}

/// All `LightSource` lights.
pub fn lights(
    desc: &SceneDescription,
    warnings: &mut Vec<String>,
) -> Result<Vec<Light>, BuildError> {
    desc.lights.iter().map(|d| light(d, warnings)).collect()
}

fn light(d: &LightDesc, warnings: &mut Vec<String>) -> Result<Light, BuildError> {
    let p = &d.params;
    let t = Transform::from_rows_f64(d.render_from_light.m)
        .ok_or_else(|| BuildError::at(&d.loc, "singular light transform"))?;
    let space = cs(&d.color_space, &d.loc)?;
    let illum = |name: &str| -> Result<Spectrum, BuildError> {
        Ok(spectrum_param(p, name, SpectrumKind::Illuminant, space)?
            .unwrap_or_else(|| space.illuminant.clone()))
    };
    let what = format!("LightSource \"{}\"", d.name);
    let ck = Check::new(p, &d.loc, &what);
    let v3 = |name: &str, def: Vec3| -> Result<Vec3, BuildError> {
        Ok(p.get_point3(name, def.to_array())?.into())
    };
    let (from, to) = (v3("from", Vec3::ZERO)?, v3("to", Vec3::Z)?);
    if matches!(d.name.as_str(), "spot" | "distant" | "goniometric") && from == to {
        return Err(ck.error(
            "to",
            "must differ from \"from\": together they give the light's direction",
        ));
    }
    let u = |of| units(&ck, of);
    Ok(match d.name.as_str() {
        "point" => {
            let i = illum("I")?;
            let u = u(UnitsOf::Intensity)?.colour_only(&i);
            Light::Point(create::point_light(&t, i, u.scale, u.target, from))
        }
        "spot" => {
            let i = illum("I")?;
            let u = u(UnitsOf::Intensity)?.colour_only(&i);
            let cone = ck.float("coneangle", 30.0, Domain::LeftOpen(0.0, 180.0))?;
            let delta = ck.float("conedeltaangle", 5.0, Domain::Closed(0.0, cone))?;
            Light::Spot(create::spot_light(&t, i, u.scale, cone, delta, u.target, from, to))
        }
        "distant" => {
            let l = illum("L")?;
            let u = u(UnitsOf::Distant)?.colour_only(&l);
            Light::Distant(create::distant_light(&t, l, u.scale, u.target, from, to))
        }
        "infinite" => infinite(d, &ck, &t, space, warnings)?,
        "goniometric" if is_ies(p)? => ies(d, &ck, &t, illum("I")?, (from, to), warnings)?,
        "goniometric" => goniometric(d, &t, illum("I")?, u(UnitsOf::Intensity)?, warnings)?,
        "projection" => projection(d, &t, u(UnitsOf::Intensity)?, warnings)?,
        other => return Err(BuildError::at(&d.loc, format!("light \"{other}\" is not supported (supported: point, spot, goniometric, projection, distant, infinite)"))),
    })
}

/// pbrt-v4 `"infinite"`: uniform (`L` or the illuminant) or image (`filename`).
fn infinite(
    d: &LightDesc,
    ck: &Check<'_>,
    t: &Transform,
    space: &'static ColorSpace,
    warnings: &mut Vec<String>,
) -> Result<Light, BuildError> {
    let p = &d.params;
    let l = spectrum_param(p, "L", SpectrumKind::Illuminant, space)?;
    let file = p.get_filename("filename")?;
    let of = match file {
        Some(_) => UnitsOf::ImageSky,
        None => UnitsOf::UniformSky,
    };
    let Units {
        scale,
        target: illuminance,
        photometric,
        ..
    } = units(ck, of)?;
    if p.get_point3s("portal")?.is_some() {
        warnings.push(format!(
            "{}: \"portal\" ignored: candela samples the environment over the whole sphere and shows it in every direction (the same image where the portal is the only opening)",
            p.param_loc("portal").unwrap_or(&d.loc)
        ));
    }
    let Some(path) = file else {
        let l = l.unwrap_or_else(|| space.illuminant.clone());
        let u = Units {
            scale,
            target: illuminance,
            from_lumens: false,
            photometric,
        }
        .colour_only(&l);
        return Ok(Light::UniformInfinite(create::uniform_infinite_light(
            l, u.scale, u.target,
        )));
    };
    if l.is_some() {
        return Err(BuildError::at(
            &d.loc,
            "can't specify both emission \"L\" and \"filename\" for an \"infinite\" light",
        ));
    }
    let loc = p.param_loc("filename").unwrap_or(&d.loc);
    let (im, color_space) = env_map(&path, loc, warnings)?;
    Ok(Light::ImageInfinite(create::image_infinite_light(
        t,
        Arc::new(im),
        color_space,
        scale,
        illuminance,
    )))
}

/// pbrt-v4 `"goniometric"`: `I`, `scale`, `power` and an optional map.
fn goniometric(
    d: &LightDesc,
    t: &Transform,
    i: Spectrum,
    u: Units,
    warnings: &mut Vec<String>,
) -> Result<Light, BuildError> {
    let p = &d.params;
    let (scale, power) = (u.scale, u.target);
    let image = match p.get_filename("filename")? {
        Some(path) => {
            let loc = p.param_loc("filename").unwrap_or(&d.loc);
            let (im, _) = light_image(&path, loc, warnings)?;
            if im.width != im.height {
                return Err(BuildError::at(
                    loc,
                    format!(
                        "{}: image resolution ({}, {}) is non-square; it is unlikely to be an equal-area map",
                        path.display(),
                        im.width,
                        im.height
                    ),
                ));
            }
            Some(im)
        }
        None => {
            warnings.push(format!(
                "{}: no \"filename\" parameter provided for goniometric light; it emits isotropically",
                d.loc
            ));
            None
        }
    };
    Ok(Light::Goniometric(create::goniometric_light(
        t,
        i,
        scale,
        power,
        image.as_ref(),
    )))
}

/// pbrt-v4 `"projection"`: RGB `filename` (required), `fov`, `scale`, `power`.
fn projection(
    d: &LightDesc,
    t: &Transform,
    u: Units,
    warnings: &mut Vec<String>,
) -> Result<Light, BuildError> {
    let p = &d.params;
    let (scale, power) = (u.scale, u.target);
    let fov = p.get_float("fov", 90.0)?;
    if !(fov > 0.0 && fov < 180.0) {
        return Err(BuildError::at(
            p.param_loc("fov").unwrap_or(&d.loc),
            format!("\"fov\" of a \"projection\" light must lie in (0, 180) degrees, not {fov}"),
        ));
    }
    let Some(path) = p.get_filename("filename")? else {
        return Err(BuildError::at(
            &d.loc,
            "must provide \"filename\" to \"projection\" light source",
        ));
    };
    let loc = p.param_loc("filename").unwrap_or(&d.loc);
    let (im, color_space) = light_image(&path, loc, warnings)?;
    if im.channels != 3 {
        return Err(BuildError::at(
            loc,
            format!(
                "{}: image provided to \"projection\" light must have R, G, and B channels",
                path.display()
            ),
        ));
    }
    Ok(Light::Projection(create::projection_light(
        t,
        &im,
        color_space,
        scale,
        power,
        fov,
    )))
}

/// True when `filename` names an IES LM-63 file (extension `.ies`, any case).
fn is_ies(p: &candela_scene::ParamSet) -> Result<bool, BuildError> {
    Ok(p.get_filename("filename")?
        .is_some_and(|f| f.extension().is_some_and(|e| e.eq_ignore_ascii_case("ies"))))
}

/// `"goniometric"` from an IES file: `I` (colour), `scale`, `power` or
/// `lumens`, `from`/`to` (the photometric nadir).
fn ies(
    d: &LightDesc,
    ck: &Check<'_>,
    t: &Transform,
    i: Spectrum,
    (from, to): (Vec3, Vec3),
    warnings: &mut Vec<String>,
) -> Result<Light, BuildError> {
    // The file is in candela: `I` sets only the colour, photometric
    // parameter or not.
    let u = Units {
        photometric: true,
        ..units(ck, UnitsOf::IesWeb)?
    }
    .colour_only(&i);
    let path = d.params.get_filename("filename")?.unwrap_or_default();
    let loc = ck.loc_of("filename");
    if !path.is_file() {
        let name = path.display();
        return Err(BuildError::at(
            loc,
            format!("IES file \"{name}\" not found"),
        ));
    }
    let file = candela_scene::ies::read_ies(&path)?;
    warnings.extend(
        file.warnings
            .iter()
            .map(|w| format!("{}: {}", w.loc, w.message)),
    );
    if !matches!(file.tilt, candela_scene::ies::IesTilt::None) {
        return Err(BuildError::at(
            loc,
            format!("{}: TILT other than NONE is not supported", path.display()),
        ));
    }
    let web =
        IesWeb::new(&file).map_err(|e| BuildError::at(loc, format!("{}: {e}", path.display())))?;
    Ok(Light::Goniometric(create::ies_light(
        t,
        i,
        u.scale,
        u.target,
        Arc::new(web),
        from,
        to,
    )))
}

/// An image read for a light: it exists, decodes, and every texel is finite.
fn light_image(
    path: &Path,
    loc: &Loc,
    warnings: &mut Vec<String>,
) -> Result<(MapImage, &'static ColorSpace), BuildError> {
    let name = path.display();
    if !path.is_file() {
        return Err(BuildError::at(
            loc,
            format!("image file \"{name}\" not found"),
        ));
    }
    let file =
        read_map(path, ColorEncoding::Srgb).map_err(|e| BuildError::at(loc, e.to_string()))?;
    if let Some(w) = file.warning {
        warnings.push(format!("{loc}: {w}"));
    }
    if file.image.data.iter().any(|v| !v.is_finite()) {
        return Err(BuildError::at(
            loc,
            format!("{name}: image has infinite or not-a-number pixel values and so is not suitable as a light"),
        ));
    }
    // Fit the RGB table now rather than on the first lookup, mid-render.
    file.color_space.rgb_table();
    Ok((file.image, file.color_space))
}

/// An equal-area environment map: a square, finite RGB image.
fn env_map(
    path: &Path,
    loc: &Loc,
    warnings: &mut Vec<String>,
) -> Result<(MapImage, &'static ColorSpace), BuildError> {
    let name = path.display();
    let (im, color_space) = light_image(path, loc, warnings)?;
    let fail = |msg: String| Err(BuildError::at(loc, format!("{name}: {msg}")));
    if im.channels != 3 {
        return fail("image provided to \"infinite\" light must have R, G, and B channels".into());
    }
    if im.width != im.height {
        return fail(format!(
            "image resolution ({}, {}) is non-square; it is unlikely to be an equal-area environment map",
            im.width, im.height
        ));
    }
    Ok((im, color_space))
}
