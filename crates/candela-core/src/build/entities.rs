//! Camera, film, pixel filter, sampler and integrator from their directives.

use super::{BuildError, Overrides};
use crate::camera::{Camera, CameraParams, SphericalCamera, SphericalMapping};
use crate::film::filter::{Filter, FilterKind, FilterParams};
use crate::film::{Buckets, Film, FilmKind, FilmLayout, FilmSettings, SurfaceAov, SurfaceSpace};
use crate::math::{Transform, UVec2, Vec2};
use crate::sampler::{Sampler, SamplerKind};
use crate::spectrum::{ColorSpace, PixelSensor, LAMBDA_MAX, LAMBDA_MIN};
use candela_scene::SceneDescription;
use std::path::PathBuf;

fn transform(
    rows: &candela_scene::Mat4d,
    loc: &candela_scene::Loc,
) -> Result<Transform, BuildError> {
    Transform::from_rows_f64(rows.m)
        .ok_or_else(|| BuildError::at(loc, "singular transformation matrix"))
}

/// The film and the output path (`--outfile` over `"string filename"`).
pub fn film(desc: &SceneDescription, ov: &Overrides) -> Result<(Film, PathBuf), BuildError> {
    let empty = super::default_entity("rgb");
    let e = desc.film.as_ref().unwrap_or(&empty);
    let p = &e.params;
    let (layout, kind, space) = film_layers(e, ov)?;
    let res = UVec2::new(
        p.get_int("xresolution", 1280)?.max(1) as u32,
        p.get_int("yresolution", 720)?.max(1) as u32,
    );
    let filename = p.get_string("filename", "pbrt.exr")?;
    let outfile = ov
        .outfile
        .clone()
        .unwrap_or_else(|| PathBuf::from(filename));
    let pixel_bounds = match ov.cropwindow {
        Some(cw) => {
            let _ = (p.get_ints("pixelbounds")?, p.get_floats("cropwindow")?);
            crop_bounds(cw, res)
        }
        None => pixel_bounds(p, res, &e.loc)?,
    };
    let max_component_value = p.get_float("maxcomponentvalue", f32::INFINITY)?;
    let _ = p.get_bool("savefp16", true)?; // candela always writes 32-bit float EXR.
    let iso = p.get_float("iso", 100.0)?;
    let exposure_time = camera_exposure(desc)?;
    let sensor_name = p.get_string("sensor", "cie1931")?;
    let white_balance = p.get_float("whitebalance", 0.0)?;
    if !(white_balance >= 0.0 && white_balance.is_finite()) {
        return Err(BuildError::at(
            &e.loc,
            format!("\"whitebalance\" must be a temperature in K (0: none), found {white_balance}"),
        ));
    }
    if !(iso >= 0.0 && iso.is_finite()) {
        return Err(BuildError::at(
            &e.loc,
            format!("\"iso\" must be non-negative, found {iso}"),
        ));
    }
    let cs = ColorSpace::by_name(&e.color_space).ok_or_else(|| {
        BuildError::at(&e.loc, format!("unknown color space \"{}\"", e.color_space))
    })?;
    let sensor =
        PixelSensor::from_name(&sensor_name, cs, white_balance, exposure_time * iso / 100.0)
            .map_err(|err| BuildError::at(&e.loc, err.to_string()))?;
    let output_from_sensor = cs.rgb_from_xyz * sensor.xyz_from_sensor_rgb();
    let filter = filter(desc)?;
    let settings = FilmSettings {
        resolution: res,
        pixel_bounds,
        max_component_value,
    };
    let film = Film::new(settings, filter, sensor, output_from_sensor)
        .with_layers(layout, kind, space)
        .with_color_space(cs);
    Ok((film, outfile))
}

/// Longest list of spectral buckets (each costs two sums per pixel).
const MAX_BUCKETS: i32 = 1024;

/// The layers of the `Film` directive's kind [pbrt-v4 `GBufferFilm`,
/// `SpectralFilm`] and of `--aov`.
fn film_layers(
    e: &candela_scene::Entity,
    ov: &Overrides,
) -> Result<(FilmLayout, FilmKind, SurfaceSpace), BuildError> {
    let p = &e.params;
    let (layout, kind, space) = match e.name.as_str() {
        "rgb" => (FilmLayout::default(), FilmKind::Rgb, SurfaceSpace::World),
        "gbuffer" => {
            let space = match p.get_string("coordinatesystem", "camera")?.as_str() {
                "camera" => SurfaceSpace::Camera,
                "world" => SurfaceSpace::World,
                other => {
                    let loc = p.param_loc("coordinatesystem").unwrap_or(&e.loc);
                    return Err(BuildError::at(
                        loc,
                        format!("\"coordinatesystem\" must be \"camera\" or \"world\", found \"{other}\""),
                    ));
                }
            };
            use SurfaceAov::*;
            let layout = FilmLayout {
                surface: vec![Albedo, Position, DepthGradient, Normal, ShadingNormal, Uv],
                variance: true,
                ..FilmLayout::default()
            };
            (layout, FilmKind::GBuffer, space)
        }
        "spectral" => {
            let n = p.get_int("nbuckets", 16)?;
            let (lo, hi) = (
                p.get_float("lambdamin", 360.0)?,
                p.get_float("lambdamax", 830.0)?,
            );
            if !(1..=MAX_BUCKETS).contains(&n) {
                let loc = p.param_loc("nbuckets").unwrap_or(&e.loc);
                return Err(BuildError::at(
                    loc,
                    format!("\"nbuckets\" must be between 1 and {MAX_BUCKETS}, found {n}"),
                ));
            }
            if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lo)
                || !(LAMBDA_MIN..=LAMBDA_MAX).contains(&hi)
                || lo >= hi
            {
                return Err(BuildError::at(
                    &e.loc,
                    format!("\"lambdamin\" {lo} and \"lambdamax\" {hi} must satisfy {LAMBDA_MIN} ≤ lambdamin < lambdamax ≤ {LAMBDA_MAX} nm (the wavelengths candela samples)"),
                ));
            }
            let layout = FilmLayout {
                spectral: Some(Buckets {
                    n: n as usize,
                    lambda_min: lo,
                    lambda_max: hi,
                }),
                ..FilmLayout::default()
            };
            (layout, FilmKind::Spectral, SurfaceSpace::World)
        }
        other => {
            return Err(BuildError::at(
                &e.loc,
                format!(
                "film \"{other}\" is not supported (supported: \"rgb\", \"gbuffer\", \"spectral\")"
            ),
            ))
        }
    };
    Ok((layout.with_aovs(&ov.aovs), kind, space))
}

fn camera_exposure(desc: &SceneDescription) -> Result<f32, BuildError> {
    let (open, close) = shutter(desc)?;
    Ok(close - open)
}

/// The camera's shutter interval (`shutteropen`, `shutterclose`; pbrt-v4's
/// defaults 0 and 1): moving shapes are sampled over it.
pub fn shutter(desc: &SceneDescription) -> Result<(f32, f32), BuildError> {
    let Some(c) = &desc.camera else {
        return Ok((0.0, 1.0));
    };
    let open = c.params.get_float("shutteropen", 0.0)?;
    let close = c.params.get_float("shutterclose", 1.0)?;
    if close < open {
        return Err(BuildError::at(
            &c.loc,
            "\"shutterclose\" is before \"shutteropen\"",
        ));
    }
    Ok((open, close))
}

/// Crop window / pixel bounds as pbrt-v4 computes them (half-open pixel range).
fn pixel_bounds(
    p: &candela_scene::ParamSet,
    res: UVec2,
    loc: &candela_scene::Loc,
) -> Result<(UVec2, UVec2), BuildError> {
    if let Some(pb) = p.get_ints("pixelbounds")? {
        if pb.len() != 4
            || pb[0] < 0
            || pb[2] < 0
            || pb[1] <= pb[0]
            || pb[3] <= pb[2]
            || pb[1] as u32 > res.x
            || pb[3] as u32 > res.y
        {
            return Err(BuildError::at(
                loc,
                "\"pixelbounds\" must be 4 integers x0 x1 y0 y1 inside the image",
            ));
        }
        return Ok((
            UVec2::new(pb[0] as u32, pb[2] as u32),
            UVec2::new(pb[1] as u32, pb[3] as u32),
        ));
    }
    if let Some(cw) = p.get_floats("cropwindow")? {
        if cw.len() != 4 || cw[0] >= cw[1] || cw[2] >= cw[3] {
            return Err(BuildError::at(
                loc,
                "\"cropwindow\" must be 4 floats x0 x1 y0 y1 with x0 < x1, y0 < y1",
            ));
        }
        return Ok(crop_bounds([cw[0], cw[1], cw[2], cw[3]], res));
    }
    Ok((UVec2::ZERO, res))
}

/// Pixel bounds of crop window `[x0, x1, y0, y1]` (fractions of the film,
/// pbrt-v4's rounding up), at least one pixel wide and tall.
fn crop_bounds(cw: [f32; 4], res: UVec2) -> (UVec2, UVec2) {
    let c = |v: f32, r: u32| ((v.clamp(0.0, 1.0) * r as f32).ceil() as u32).min(r);
    let lo = UVec2::new(c(cw[0], res.x), c(cw[2], res.y)).min(res - UVec2::ONE);
    let hi = UVec2::new(c(cw[1], res.x), c(cw[3], res.y))
        .max(lo + UVec2::ONE)
        .min(res);
    (lo, hi)
}

/// The pixel filter (pbrt-v4's default is a Gaussian of radius 1.5, σ 0.5).
fn filter(desc: &SceneDescription) -> Result<Filter, BuildError> {
    let Some(e) = &desc.filter else {
        return Ok(Filter::default());
    };
    let p = &e.params;
    let kind = FilterKind::from_name(&e.name).ok_or_else(|| {
        BuildError::at(
            &e.loc,
            format!(
                "unknown pixel filter \"{}\" (known: box, gaussian, mitchell, sinc, triangle)",
                e.name
            ),
        )
    })?;
    let opt = |name: &str| -> Result<Option<f32>, BuildError> {
        Ok(p.get_floats(name)?.and_then(|v| v.first().copied()))
    };
    let (xr, yr) = (opt("xradius")?, opt("yradius")?);
    let mut fp = FilterParams {
        sigma: opt("sigma")?,
        b: opt("B")?,
        c: opt("C")?,
        tau: opt("tau")?,
        ..Default::default()
    };
    if xr.is_some() || yr.is_some() {
        let def = Filter::new(kind, &FilterParams::default()).radius();
        fp.radius = Some(Vec2::new(xr.unwrap_or(def.x), yr.unwrap_or(def.y)));
    }
    Ok(Filter::new(kind, &fp))
}

/// The camera.
pub fn camera(desc: &SceneDescription, film: &Film) -> Result<Camera, BuildError> {
    let Some(c) = &desc.camera else {
        let params = CameraParams::new(Transform::IDENTITY, film.resolution());
        return Camera::perspective(&params).map_err(|e| BuildError::Other(e.to_string()));
    };
    let p = &c.params;
    let mut params = CameraParams::new(transform(&c.camera_from_world, &c.loc)?, film.resolution());
    params.lens_radius = p.get_float("lensradius", 0.0)?;
    params.focal_distance = p.get_float("focaldistance", 1e6)?;
    if let Some(sw) = p.get_floats("screenwindow")? {
        if sw.len() != 4 {
            return Err(BuildError::at(&c.loc, "\"screenwindow\" needs 4 values"));
        }
        params.screen_window = Some([sw[0], sw[1], sw[2], sw[3]]);
    }
    params.filter_radius = film.filter().radius();
    let cam = match c.name.as_str() {
        "perspective" => {
            params.fov_deg = p.get_float("fov", 90.0)?;
            Camera::perspective(&params)
        }
        "orthographic" => Camera::orthographic(&params),
        "spherical" => {
            let mapping = match p.get_string("mapping", "equalarea")?.as_str() {
                "equalarea" => SphericalMapping::EqualArea,
                "equirectangular" => SphericalMapping::Equirectangular,
                other => {
                    return Err(BuildError::at(
                        p.param_loc("mapping").unwrap_or(&c.loc),
                        format!("unknown spherical mapping \"{other}\" (expected \"equalarea\" or \"equirectangular\")"),
                    ))
                }
            };
            let res = film.resolution();
            if mapping == SphericalMapping::EqualArea && res.x != res.y {
                return Err(BuildError::at(
                    &c.loc,
                    format!("the equal-area spherical camera needs a square film, found {}×{}", res.x, res.y),
                ));
            }
            Ok(Camera::Spherical(SphericalCamera::new(
                params.camera_from_world,
                res,
                mapping,
            )))
        }
        other => {
            return Err(BuildError::at(
                &c.loc,
                format!(
                "camera \"{other}\" is not supported yet (supported: perspective, orthographic, spherical)"
            ),
            ))
        }
    };
    cam.map_err(|e| BuildError::at(&c.loc, e.to_string()))
}

/// The sampler; unknown pbrt samplers are substituted with a warning.
pub fn sampler(
    desc: &SceneDescription,
    ov: &Overrides,
    warnings: &mut Vec<String>,
) -> Result<Sampler, BuildError> {
    let empty = super::default_entity("zsobol");
    let e = desc.sampler.as_ref().unwrap_or(&empty);
    let mut spp = e.params.get_int("pixelsamples", 16)?.max(1) as u32;
    if e.name == "stratified" {
        // pbrt-v4's stratified sampler takes x/y counts instead of pixelsamples.
        let (x, y) = (
            e.params.get_int("xsamples", 4)?,
            e.params.get_int("ysamples", 4)?,
        );
        let _ = e.params.get_bool("jitter", true)?;
        spp = (x * y).max(1) as u32;
    }
    let spp = ov.spp.unwrap_or(spp);
    let seed = match ov.seed {
        Some(s) => s,
        None => e.params.get_int("seed", 0)? as u64,
    };
    let (kind, exact) = SamplerKind::from_name(&e.name)
        .ok_or_else(|| BuildError::at(&e.loc, format!("unknown sampler \"{}\"", e.name)))?;
    if !exact {
        warnings.push(format!(
            "{}: sampler \"{}\" is not implemented; using {:?} (same expectation, different noise)",
            e.loc, e.name, kind
        ));
    }
    Ok(Sampler::new(kind, spp, seed))
}
