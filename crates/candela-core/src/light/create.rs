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
//! | diffuse area | `power` Φ_v > 0 | Φ_v / (π·A·(2 if two-sided else 1)) |
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
//! An image infinite light normalises by its colour space's illuminant (its
//! texels are RGB illuminant spectra) and, for `illuminance`, by pbrt-v4's
//! estimate k of the map's illuminance on a patch facing light-space +z:
//! N texels of 4π/N sr each, Y the luminance row of the colour space. The
//! true Riemann sum has 4π/N where pbrt-v4 (`lights.cpp`, `Light::Create`)
//! has 2π/N, so k is half the map's illuminance and the light renders 2·E_v
//! on that patch; candela keeps pbrt-v4's factor so scenes render alike.

use super::{
    spectrum_photometric, DiffuseAreaLight, DistantLight, ImageInfiniteLight, LightSpectrum,
    PointLight, SpotLight, UniformInfiniteLight,
};
use crate::image::MapImage;
use crate::math::{Frame, Mat4, Transform, Vec2, Vec3, PI};
use crate::sampling::equal_area_square_to_sphere;
use crate::shape::Shape;
use crate::spectrum::ColorSpace;
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
