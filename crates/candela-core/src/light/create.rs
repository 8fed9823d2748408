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
//!
//! Non-positive `power`/`illuminance` (pbrt's default −1) means "not given":
//! pass `None` or a value ≤ 0. pbrt-v4's area-light `k_e` is left
//! uninitialised when `L` is a spectrum rather than an image; we use its
//! evident intent, k_e = 1 before the geometric factor. Renders with these
//! values reproduce pbrt-v4's pixel values.

use super::{
    spectrum_photometric, DiffuseAreaLight, DistantLight, LightSpectrum, PointLight, SpotLight,
    UniformInfiniteLight,
};
use crate::math::{Frame, Mat4, Transform, Vec3, PI};
use crate::shape::Shape;

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
