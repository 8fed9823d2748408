//! Lights from already-typed scene parameters, with pbrt-v4's photometric
//! conventions (`lights.cpp`, the `Create` functions).
//!
//! **Convention.** A light stores a spectrum `s` and a scalar `scale`; it
//! emits `scale·s(λ)`. As in pbrt-v4, the user's `scale` is first divided by
//! `SpectrumToPhotometric(s)` = ∫ȳ(λ)s(λ)dλ ([`spectrum_photometric`]; for an
//! RGB illuminant spectrum only its illuminant counts), so that `s` carries
//! only the spectral shape and `scale = 1` means a luminance-equivalent of
//! one nit (one cd for intensities). Then, when given:
//!
//! | light | parameter | extra factor on `scale` |
//! |---|---|---|
//! | point | `power` Φ_v > 0 | Φ_v / (4π) |
//! | spot | `power` Φ_v > 0 | Φ_v / (2π[(1 − cos θ_s) + (cos θ_s − cos θ_e)/2]), θ_e = coneangle, θ_s = coneangle − conedelta |
//! | goniometric | `power` Φ_v > 0 | Φ_v / (4π·mean Y), Y = (R + G + B)/3 of the map |
//! | projection | `power` Φ_v > 0 | Φ_v / (A·mean_p(Y_lum(rgb_p)·cos³θ_p)), A = 4·tan²(fov/2)·max(a, 1/a) |
//! | diffuse area | `power` Φ_v > 0 | Φ_v / (π·A·(2 if two-sided else 1)) |
//! | diffuse area, image | `power` Φ_v > 0 | Φ_v / (π·A·(2 if two-sided else 1)·mean Y_lum(rgb)) |
//! | distant | `illuminance` E_v > 0 | E_v (pbrt-v4 after issue #130; was E_v/(−w.y)) |
//! | uniform infinite | `illuminance` E_v > 0 | E_v / π (illuminance on an upward patch) |
//! | image infinite | `illuminance` E_v > 0 | E_v / k, k = (2π/N)·Σ_{texels with z > 0} Y(rgb)·cos θ |
//!
//! Non-positive `power`/`illuminance` (pbrt's default −1) means "not given":
//! pass `None` or a value ≤ 0. pbrt-v4's area-light `k_e` is left
//! uninitialised when `L` is a spectrum rather than an image; we use its
//! evident intent, k_e = 1 before the geometric factor. Renders with these
//! values reproduce pbrt-v4's pixel values.
//!
//! For the projection light, `Y_lum` is the luminance row of the image's
//! colour space, θ_p the angle of texel p's centre from the axis and a the
//! image's aspect ratio: pbrt-v4's midpoint estimate of the luminous power
//! (`ProjectionLight::Create`), which candela keeps so that `power` renders
//! as in pbrt-v4, although its own Φ integrates cos³θ over each texel
//! exactly (see `projection`): the two differ by the midpoint rule's error,
//! below 10⁻³ for images of more than ~30 texels across. Projection and
//! goniometric lights normalise by the photometric value of the image's
//! colour-space illuminant and of `I` respectively, as pbrt-v4 does.
//!
//! A diffuse area light with an image normalises by the illuminant of the
//! scene's current colour space (not the image's), as pbrt-v4's
//! `DiffuseAreaLight::Create` does; for `power`, its k_e is the mean over
//! texels of Y_lum(rgb) (the image colour space's luminance row, texels
//! unclamped) times the shape's own area: each triangle of a mesh is one
//! light and receives the whole `power`, as in pbrt-v4.
//!
//! An image infinite light normalises by its colour space's illuminant (its
//! texels are RGB illuminant spectra) and, for `illuminance`, by pbrt-v4's
//! estimate k of the map's illuminance on a patch facing light-space +z:
//! N texels of 4π/N sr each, Y the luminance row of the colour space. The
//! true Riemann sum has 4π/N where pbrt-v4 (`lights.cpp`, `Light::Create`)
//! has 2π/N, so k is half the map's illuminance and the light renders 2·E_v
//! on that patch; candela keeps pbrt-v4's factor so scenes render alike.

use super::projection::screen_window;
use super::{
    spectrum_photometric, DiffuseAreaLight, DistantLight, GoniometricLight, IesWeb,
    ImageInfiniteLight, LightSpectrum, PointLight, ProjectionLight, SpotLight,
    UniformInfiniteLight,
};
use crate::image::{MapImage, PixelFormat};
use crate::math::{Frame, Mat4, Transform, Vec2, Vec3, PI};
use crate::sampling::equal_area_square_to_sphere;
use crate::shape::Shape;
use crate::spectrum::{ColorSpace, K_M};
use std::sync::Arc;

/// `scale / SpectrumToPhotometric(s)`: normalises `s` to one nit [pbrt-v4].
fn nit_scale(scale: f32, s: &LightSpectrum) -> f32 {
    let y = spectrum_photometric(s);
    if y > 0.0 {
        scale / y
    } else {
        scale
    }
}

/// The target value when it is given (> 0), pbrt-v4's `-1` default otherwise.
fn given(v: Option<f32>) -> Option<f32> {
    v.filter(|&x| x > 0.0)
}

/// Rotation taking light-frame (x, y, z) to `frame`'s axes.
fn frame_to_render(frame: &Frame) -> Transform {
    let m = Mat4::from_cols(
        frame.x.extend(0.0),
        frame.y.extend(0.0),
        frame.z.extend(0.0),
        glam::Vec4::W,
    );
    Transform::new(m, m.transpose())
}

/// pbrt-v4 `"point"`: intensity `I`, `scale`, optional `power` (lm), `from`.
pub fn point_light(
    render_from_light: &Transform,
    i: LightSpectrum,
    scale: f32,
    power: Option<f32>,
    from: Vec3,
) -> PointLight {
    let mut sc = nit_scale(scale, &i);
    if let Some(phi_v) = given(power) {
        sc *= phi_v / (4.0 * PI);
    }
    let t = render_from_light.then_after(&Transform::translate(from));
    PointLight::new(t, i, sc)
}

/// pbrt-v4 `"spot"`: `coneangle` θ_e and `conedeltaangle` (degrees), aimed
/// from `from` to `to`; optional `power` (lm).
pub fn spot_light(
    render_from_light: &Transform,
    i: LightSpectrum,
    scale: f32,
    coneangle: f32,
    conedelta: f32,
    power: Option<f32>,
    from: Vec3,
    to: Vec3,
) -> SpotLight {
    let mut sc = nit_scale(scale, &i);
    if let Some(phi_v) = given(power) {
        let cos_end = coneangle.to_radians().cos();
        let cos_start = (coneangle - conedelta).to_radians().cos();
        let k_e = 2.0 * PI * ((1.0 - cos_start) + (cos_start - cos_end) / 2.0);
        sc *= phi_v / k_e;
    }
    let dir_frame = Frame::from_z((to - from).normalize());
    let t = render_from_light
        .then_after(&Transform::translate(from))
        .then_after(&frame_to_render(&dir_frame));
    SpotLight::new(t, i, sc, coneangle, coneangle - conedelta)
}

/// pbrt-v4 `"distant"`: radiance `L` arriving from `from − to`; optional
/// `illuminance` (lx) on a surface facing the light.
pub fn distant_light(
    render_from_light: &Transform,
    l: LightSpectrum,
    scale: f32,
    illuminance: Option<f32>,
    from: Vec3,
    to: Vec3,
) -> DistantLight {
    let mut sc = nit_scale(scale, &l);
    if let Some(e_v) = given(illuminance) {
        sc *= e_v;
    }
    let w = (from - to).normalize();
    let t = render_from_light.then_after(&frame_to_render(&Frame::from_z(w)));
    DistantLight::new(t, l, sc)
}

/// pbrt-v4 `"diffuse"` area light on `shape` (render space): radiance `L`,
/// `twosided`, optional `power` (lm).
pub fn diffuse_area_light(
    shape: Shape,
    l: LightSpectrum,
    scale: f32,
    two_sided: bool,
    power: Option<f32>,
) -> DiffuseAreaLight {
    let mut sc = nit_scale(scale, &l);
    if let Some(phi_v) = given(power) {
        let sides = if two_sided { 2.0 } else { 1.0 };
        let k_e = sides * shape.area() * PI;
        sc *= phi_v / k_e;
    }
    DiffuseAreaLight::new(shape, l, sc, two_sided)
}

/// pbrt-v4 `"diffuse"` area light with a `filename` RGB `image` in colour
/// space `image_cs`, in a scene whose current colour space is `scene_cs`:
/// `scale`, `twosided`, optional `power` (lm).
pub fn diffuse_area_image_light(
    shape: Shape,
    image: Arc<MapImage>,
    image_cs: &'static ColorSpace,
    scene_cs: &ColorSpace,
    scale: f32,
    two_sided: bool,
    power: Option<f32>,
) -> DiffuseAreaLight {
    let mut sc = nit_scale(scale, &scene_cs.illuminant);
    if let Some(phi_v) = given(power) {
        let lum = image_cs.xyz_from_rgb.row(1);
        let sum: f64 = image
            .data
            .chunks_exact(3)
            .map(|t| lum.dot(Vec3::new(t[0], t[1], t[2])) as f64)
            .sum();
        let mean_y = (sum / (image.width * image.height) as f64) as f32;
        let sides = if two_sided { 2.0 } else { 1.0 };
        let k_e = mean_y * sides * shape.area() * PI;
        if k_e > 0.0 {
            sc *= phi_v / k_e;
        }
    }
    DiffuseAreaLight::new_image(shape, image, image_cs, sc, two_sided)
}

/// pbrt-v4 `"infinite"` with a constant `L`: optional `illuminance` (lx) on
/// an upward-facing patch (E = πL for a uniform sky).
pub fn uniform_infinite_light(
    l: LightSpectrum,
    scale: f32,
    illuminance: Option<f32>,
) -> UniformInfiniteLight {
    let mut sc = nit_scale(scale, &l);
    if let Some(e_v) = given(illuminance) {
        sc *= e_v / PI;
    }
    UniformInfiniteLight::new(l, sc)
}

/// pbrt-v4 `"infinite"` with an equal-area `filename` image (square, RGB) in
/// colour space `cs`; optional `illuminance` (lx) on a light-space +z patch,
/// with pbrt-v4's normalisation (see the module doc).
pub fn image_infinite_light(
    render_from_light: &Transform,
    image: Arc<MapImage>,
    cs: &'static ColorSpace,
    scale: f32,
    illuminance: Option<f32>,
) -> ImageInfiniteLight {
    let mut sc = nit_scale(scale, &cs.illuminant);
    if let Some(e_v) = given(illuminance) {
        let k = map_illuminance_pbrt(&image, cs);
        if k > 0.0 {
            sc *= e_v / k;
        }
    }
    ImageInfiniteLight::new(*render_from_light, image, cs, sc)
}

/// pbrt-v4's illuminance estimate of an equal-area map on a +z patch:
/// (2π/N)·Σ_{z > 0} Y(rgb)·z over texel centres.
fn map_illuminance_pbrt(image: &MapImage, cs: &ColorSpace) -> f32 {
    let lum = cs.xyz_from_rgb.row(1);
    let (w, h) = (image.width, image.height);
    let mut sum = 0.0f64;
    for y in 0..h {
        for x in 0..w {
            let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
            let d = equal_area_square_to_sphere(uv);
            if d.z <= 0.0 {
                continue;
            }
            let t = &image.data[(y * w + x) * 3..][..3];
            sum += (lum.dot(Vec3::new(t[0], t[1], t[2])) * d.z) as f64;
        }
    }
    (sum * 2.0 * std::f64::consts::PI / (w * h) as f64) as f32
}

/// pbrt-v4 `"goniometric"`: intensity `I`, `scale`, optional `power` (lm),
/// and the equal-area square map `image` (one channel, or RGB averaged to
/// one as pbrt-v4 does; negative values count as 0). Without an image the
/// light is isotropic (a 1×1 map of 1), where pbrt-v4 divides by an empty
/// image's texel count.
pub fn goniometric_light(
    render_from_light: &Transform,
    i: LightSpectrum,
    scale: f32,
    power: Option<f32>,
    image: Option<&MapImage>,
) -> GoniometricLight {
    let y_map = match image {
        Some(im) => {
            let y: Vec<f32> = im
                .data
                .chunks_exact(im.channels)
                .map(|t| (t.iter().sum::<f32>() / im.channels as f32).max(0.0))
                .collect();
            MapImage::new(im.width, im.height, 1, y, im.format)
        }
        None => MapImage::new(1, 1, 1, vec![1.0], PixelFormat::Float),
    };
    let mut sc = nit_scale(scale, &i);
    if let Some(phi_v) = given(power) {
        let sum: f64 = y_map.data.iter().map(|&v| v as f64).sum();
        let k_e = 4.0 * PI * (sum / y_map.data.len() as f64) as f32;
        if k_e > 0.0 {
            sc *= phi_v / k_e;
        }
    }
    // pbrt-v4 swaps y and z: the map's centre (+z) points along the user's +y.
    let swap_yz = Mat4::from_cols(glam::Vec4::X, glam::Vec4::Z, glam::Vec4::Y, glam::Vec4::W);
    let t = render_from_light.then_after(&Transform::new(swap_yz, swap_yz));
    GoniometricLight::new(t, i, sc, Arc::new(y_map))
}

/// `"goniometric"` with an IES LM-63 `web` \[cd\]: photometric nadir along
/// `to − from`, horizontal angle 0 along light-space +x projected
/// perpendicular to it (+y when `to − from` is along ±x). The web is
/// absolute, so `scale·I` only sets the colour: I_v(ω) = scale·I_web(ω)
/// (the spectrum normalised to one nit, then ÷ K_M). With `power` (pbrt-v4
/// units, lumens/K_M) the web is rescaled to that flux instead.
pub fn ies_light(
    render_from_light: &Transform,
    i: LightSpectrum,
    scale: f32,
    power: Option<f32>,
    web: Arc<IesWeb>,
    from: Vec3,
    to: Vec3,
) -> GoniometricLight {
    let mut sc = nit_scale(scale, &i);
    match given(power) {
        Some(phi_v) if web.flux() > 0.0 => sc *= phi_v / web.flux() as f32,
        _ => sc /= K_M,
    }
    let z = (to - from).normalize();
    let x_hint = if z.cross(Vec3::X).length() > 1e-3 {
        Vec3::X
    } else {
        Vec3::Y
    };
    let t = render_from_light
        .then_after(&Transform::translate(from))
        .then_after(&frame_to_render(&Frame::from_xz(x_hint, z)));
    GoniometricLight::from_web(t, i, sc, web)
}

/// pbrt-v4 `"projection"`: RGB `image` in colour space `cs` projected with
/// field of view `fov_deg` ∈ (0°, 180°), `scale`, optional `power` (lm)
/// with pbrt-v4's normalisation (see the module doc). Negative texels count
/// as 0, as in pbrt-v4's lookups.
pub fn projection_light(
    render_from_light: &Transform,
    image: &MapImage,
    cs: &'static ColorSpace,
    scale: f32,
    power: Option<f32>,
    fov_deg: f32,
) -> ProjectionLight {
    let data: Vec<f32> = image.data.iter().map(|v| v.max(0.0)).collect();
    let image = MapImage::new(image.width, image.height, 3, data, image.format);
    let mut sc = nit_scale(scale, &cs.illuminant);
    if let Some(phi_v) = given(power) {
        let k = projection_luminous_power_pbrt(&image, cs, fov_deg);
        if k > 0.0 {
            sc *= phi_v / k;
        }
    }
    // pbrt-v4 flips y so that the image's top row points along the user's +y.
    let t = render_from_light.then_after(&Transform::scale(Vec3::new(1.0, -1.0, 1.0)));
    ProjectionLight::new(t, Arc::new(image), cs, sc, fov_deg)
}

/// pbrt-v4's luminous power estimate of a unit-scale projector:
/// A·mean over texels of Y_lum(rgb)·cos³θ at the texel centre.
fn projection_luminous_power_pbrt(image: &MapImage, cs: &ColorSpace, fov_deg: f32) -> f32 {
    let lum = cs.xyz_from_rgb.row(1);
    let (w, h) = (image.width, image.height);
    let [x0, y0, x1, y1] = screen_window(w, h);
    let t = (fov_deg.to_radians() / 2.0).tan();
    let area = t * t * (x1 - x0) * (y1 - y0);
    let mut sum = 0.0f64;
    for y in 0..h {
        for x in 0..w {
            let sx = x0 + (x1 - x0) * (x as f32 + 0.5) / w as f32;
            let sy = y0 + (y1 - y0) * (y as f32 + 0.5) / h as f32;
            let cos = Vec3::new(sx * t, sy * t, 1.0).normalize().z;
            let p = &image.data[(y * w + x) * 3..][..3];
            sum += (lum.dot(Vec3::new(p[0], p[1], p[2])) * cos * cos * cos) as f64;
        }
    }
    (area as f64 * sum / (w * h) as f64) as f32
}
