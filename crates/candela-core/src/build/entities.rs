//! Camera, film, pixel filter, sampler and integrator from their directives.

use super::budget::Budget;
use super::check::{Check, Domain};
use super::{BuildError, Overrides};
use crate::camera::{Camera, CameraParams, SphericalCamera, SphericalMapping};
use crate::film::filter::{Filter, FilterKind, FilterParams};
use crate::film::{Buckets, Film, FilmKind, FilmLayout, FilmSettings, SurfaceAov, SurfaceSpace};
use crate::math::{Transform, UVec2, Vec2};
use crate::sampler::{
    HaltonRandomize, HaltonSampler, Sampler, SamplerKind, ZSobolRandomize, ZSobolSampler,
};
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
pub fn film(
    desc: &SceneDescription,
    ov: &Overrides,
    budget: &mut Budget,
) -> Result<(Film, PathBuf), BuildError> {
    let empty = super::default_entity("rgb");
    let e = desc.film.as_ref().unwrap_or(&empty);
    let p = &e.params;
    let what = format!("Film \"{}\"", e.name);
    let ck = Check::new(p, &e.loc, &what);
    let (layout, kind, space) = film_layers(e, ov)?;
    let res = UVec2::new(
        ck.int("xresolution", 1280, 1)? as u32,
        ck.int("yresolution", 720, 1)? as u32,
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
    let max_component_value = ck.float("maxcomponentvalue", f32::INFINITY, Domain::Positive)?;
    let _ = p.get_bool("savefp16", true)?; // candela always writes 32-bit float EXR.
    let iso = ck.float("iso", 100.0, Domain::Positive)?;
    let exposure_time = camera_exposure(desc)?;
    let sensor_name = p.get_string("sensor", "cie1931")?;
    // A temperature in K; 0 means no white balance.
    let white_balance = ck.float("whitebalance", 0.0, Domain::NonNegative)?;
    let cs = ColorSpace::by_name(&e.color_space).ok_or_else(|| {
        BuildError::at(&e.loc, format!("unknown color space \"{}\"", e.color_space))
    })?;
    let sensor =
        PixelSensor::from_name(&sensor_name, cs, white_balance, exposure_time * iso / 100.0)
            .map_err(|err| BuildError::at(&e.loc, err.to_string()))?;
    let output_from_sensor = cs.rgb_from_xyz * sensor.xyz_from_sensor_rgb();
    let filter = filter(desc, budget)?;
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
    let mut layout = layout.with_aovs(&ov.aovs);
    layout.photometric = ov.photometric;
    Ok((layout, kind, space))
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
    // The exposure time scales the sensor's response (pbrt-v4 refuses it
    // too, scene.cpp): a shutter that never opens gives a black image.
    if close == open {
        return Err(BuildError::at(
            &c.loc,
            format!("\"shutteropen\" and \"shutterclose\" are both {open}: the shutter never opens, so the exposure time is 0 and the image would be black"),
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
                p.param_loc("pixelbounds").unwrap_or(loc),
                format!(
                    "Film \"pixelbounds\" must be 4 integers x0 x1 y0 y1 inside the {}×{} image with x0 < x1, y0 < y1, found {pb:?}",
                    res.x, res.y
                ),
            ));
        }
        return Ok((
            UVec2::new(pb[0] as u32, pb[2] as u32),
            UVec2::new(pb[1] as u32, pb[3] as u32),
        ));
    }
    if let Some(cw) = p.get_floats("cropwindow")? {
        let unit = |x: &f32| (0.0..=1.0).contains(x);
        if cw.len() != 4 || !cw.iter().all(unit) || cw[0] >= cw[1] || cw[2] >= cw[3] {
            return Err(BuildError::at(
                p.param_loc("cropwindow").unwrap_or(loc),
                format!("Film \"cropwindow\" must be 4 floats x0 x1 y0 y1 in [0, 1] with x0 < x1, y0 < y1, found {cw:?}"),
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
fn filter(desc: &SceneDescription, budget: &mut Budget) -> Result<Filter, BuildError> {
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
    let what = format!("PixelFilter \"{}\"", e.name);
    let ck = Check::new(p, &e.loc, &what);
    let any = Domain::AtLeast(f32::NEG_INFINITY);
    let (xr, yr) = (
        ck.float_opt("xradius", Domain::Positive)?,
        ck.float_opt("yradius", Domain::Positive)?,
    );
    let mut fp = FilterParams {
        sigma: ck.float_opt("sigma", Domain::Positive)?,
        b: ck.float_opt("B", any)?,
        c: ck.float_opt("C", any)?,
        tau: ck.float_opt("tau", Domain::Positive)?,
        ..Default::default()
    };
    if xr.is_some() || yr.is_some() {
        let def = Filter::default_radius(kind);
        fp.radius = Some(Vec2::new(xr.unwrap_or(def.x), yr.unwrap_or(def.y)));
    }
    // The tabulated filters allocate 32² cells per square pixel of radius.
    let table = Filter::table_bytes(kind, &fp);
    budget
        .claim(
            table,
            &format!("the {} filter's sampling table", e.name),
            "lower \"xradius\"/\"yradius\" of the PixelFilter",
        )
        .map_err(|m| ck.error(if xr.is_some() { "xradius" } else { "yradius" }, m))?;
    Ok(Filter::new(kind, &fp))
}

/// The camera.
pub fn camera(desc: &SceneDescription, film: &Film) -> Result<Camera, BuildError> {
    let Some(c) = &desc.camera else {
        let params = CameraParams::new(Transform::IDENTITY, film.resolution());
        return Camera::perspective(&params).map_err(|e| BuildError::Other(e.to_string()));
    };
    let p = &c.params;
    let what = format!("Camera \"{}\"", c.name);
    let ck = Check::new(p, &c.loc, &what);
    let mut params = CameraParams::new(transform(&c.camera_from_world, &c.loc)?, film.resolution());
    params.lens_radius = ck.float("lensradius", 0.0, Domain::NonNegative)?;
    params.focal_distance = ck.float("focaldistance", 1e6, Domain::Positive)?;
    if let Some(sw) = p.get_floats("screenwindow")? {
        if sw.len() != 4 || sw[0] >= sw[1] || sw[2] >= sw[3] {
            return Err(ck.error(
                "screenwindow",
                "needs 4 values x0 x1 y0 y1 with x0 < x1 and y0 < y1",
            ));
        }
        params.screen_window = Some([sw[0], sw[1], sw[2], sw[3]]);
    }
    params.filter_radius = film.filter().radius();
    let cam = match c.name.as_str() {
        "perspective" => {
            params.fov_deg = ck.float("fov", 90.0, Domain::Open(0.0, 180.0))?;
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

/// The sampler for a film of `resolution` pixels; unknown pbrt samplers
/// are substituted with a warning.
pub fn sampler(
    desc: &SceneDescription,
    ov: &Overrides,
    resolution: UVec2,
    warnings: &mut Vec<String>,
) -> Result<Sampler, BuildError> {
    let empty = super::default_entity("zsobol");
    let e = desc.sampler.as_ref().unwrap_or(&empty);
    let what = format!("Sampler \"{}\"", e.name);
    let ck = Check::new(&e.params, &e.loc, &what);
    let mut spp = ck.int("pixelsamples", 16, 1)? as u32;
    if e.name == "stratified" {
        // pbrt-v4's stratified sampler takes x/y counts instead of pixelsamples.
        let (x, y) = (ck.int("xsamples", 4, 1)?, ck.int("ysamples", 4, 1)?);
        let _ = e.params.get_bool("jitter", true)?;
        spp = (x as u32).checked_mul(y as u32).ok_or_else(|| {
            ck.error(
                "ysamples",
                format!("times \"xsamples\" ({x}) overflows the sample count"),
            )
        })?;
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
    match kind {
        SamplerKind::Halton => Ok(Sampler::Halton(HaltonSampler::new(
            spp,
            seed,
            resolution,
            randomization(
                &ck,
                "Halton",
                "permutedigits",
                HaltonRandomize::from_name,
                HaltonRandomize::NAMES,
            )?,
        ))),
        SamplerKind::ZSobol => Ok(Sampler::ZSobol(ZSobolSampler::new(
            spp,
            seed,
            resolution,
            randomization(
                &ck,
                "ZSobol",
                "fastowen",
                ZSobolRandomize::from_name,
                ZSobolRandomize::NAMES,
            )?,
        ))),
        _ => Ok(Sampler::new(kind, spp, seed)),
    }
}

/// A sampler's `"string randomization"` parsed by `from_name` (pbrt-v4's
/// names and defaults: `permutedigits` for Halton, which refuses
/// `fastowen` as pbrt-v4 does, `fastowen` for ZSobol); an error naming the
/// parameter and the supported `names` otherwise.
fn randomization<T>(
    ck: &Check<'_>,
    sampler: &str,
    default: &str,
    from_name: fn(&str) -> Option<T>,
    names: &str,
) -> Result<T, BuildError> {
    let name = ck.params.get_string("randomization", default)?;
    from_name(&name).ok_or_else(|| {
        ck.error(
            "randomization",
            format!("\"{name}\" is not supported by the {sampler} sampler (supported: {names})"),
        )
    })
}
