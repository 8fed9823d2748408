//! Projection light: a point light that projects an RGB image through a
//! perspective frustum, like a slide projector [pbrt-v4 `ProjectionLight`,
//! §12.2.4].
//!
//! In the light frame the light looks along +z. A direction ω = (x, y, z)
//! with z ≥ `hither` meets the screen plane at (s_x, s_y) = (x, y)/(z·t),
//! t = tan(fov/2); the screen window is [−a, a]×[−1, 1] for an image of
//! aspect a = width/height > 1 and [−1, 1]×[−1/a, 1/a] otherwise, so `fov`
//! spans the shorter side. Inside the window, the texel at
//! (u, v) = ((s_x, s_y) − min)/(max − min) (nearest lookup, row 0 at s_y =
//! −1) gives an RGB, lifted as an illuminant spectrum of the image's colour
//! space; `I(ω) = scale·spectrum(rgb)`, and zero outside the window. pbrt-v4
//! composes the user's transform with a flip of y so that the image's top
//! row points along the user's +y.
//!
//! **Solid angle of a texel.** On the plane z = 1 (X, Y) = t·(s_x, s_y) and
//! dω = dX dY/(1 + X² + Y²)^{3/2} = t²·cos³θ dA_screen. The solid angle of
//! the rectangle [0, X]×[0, Y] is F(X, Y) = atan(XY/√(1 + X² + Y²))
//! [Van Oosterom & Strackee 1983, for the two triangles of the rectangle],
//! so a texel's solid angle Ω_p follows by inclusion–exclusion of its
//! corners, exactly.
//!
//! **Power.** I is constant on each texel's solid angle, so
//! Φ = scale·Σ_p spectrum(rgb_p)·Ω_p exactly. pbrt-v4's `Phi` instead takes
//! the Jacobian cos³θ at texel centres (A·mean(spectrum·cos³θ), A = t²·area
//! of the window), which is close for fine images but off by ~2× for a 1×1
//! image at 90°; candela's Φ is the exact one, because the power light
//! sampler and β₀ = Φ_total rely on it. (The `power` normalisation in
//! `create` keeps pbrt-v4's formula so scenes render alike.)
//!
//! **Emission sampling.** A texel is chosen with probability
//! ∝ avg(rgb_p)·Ω_p (pbrt-v4 weights texels by avg(rgb)·cos³θ at the centre,
//! `GetSamplingDistribution`), then a direction uniformly in the texel's
//! solid angle: X from the marginal CDF G(X) = Σ±F(X, Y_corner) by
//! safeguarded Newton, then Y in closed form from the conditional CDF
//! ∝ Y/√(1 + X² + Y²). So p_dir(ω) = avg(rgb)/Σ_p avg(rgb_p)·Ω_p, exactly
//! proportional to I(ω) for grey images (β₀ = Φ for every sample), and
//! pbrt-v4's p_dir = p_screen/(t²·cos³θ) with its piecewise-constant screen
//! density is replaced by the exact one.

use super::bounds::{isotropic_point, preserves_angles, scalar, LightBounds};
use super::{delta_position_li, LightLeSample, LightLiSample, LightSampleContext};
use crate::image::MapImage;
use crate::math::{Bounds3, DirectionCone, Ray, Transform, Vec2, Vec3};
use crate::sampling::{Distribution2D, PdfArea, PdfSolidAngle};
use crate::spectrum::{
    ColorSpace, Rgb, SampledSpectrum, SampledWavelengths, SpectrumKind, N_SPECTRUM_SAMPLES,
};
use std::sync::Arc;

/// pbrt-v4's near plane: directions with light-frame z below it emit nothing.
const HITHER: f32 = 1e-3;

/// A projector at the light-frame origin looking along +z.
#[derive(Clone, Debug)]
pub struct ProjectionLight {
    render_from_light: Transform,
    light_from_render: Transform,
    image: Arc<MapImage>,
    color_space: &'static ColorSpace,
    scale: f32,
    tan_half_fov: f32,
    /// Screen window [x0, y0, x1, y1].
    window: [f32; 4],
    /// Solid angle of each texel (row-major).
    omega: Arc<Vec<f32>>,
    /// Texel choice ∝ avg(rgb)·Ω (row, then column: no single CDF over
    /// millions of texels in f32).
    distribution: Arc<Distribution2D>,
}

/// Solid angle of [0, X]×[0, Y] on the plane z = 1 (signed by XY).
fn rect_corner(x: f64, y: f64) -> f64 {
    (x * y / (1.0 + x * x + y * y).sqrt()).atan()
}

/// Solid angle of [xa, xb]×[ya, yb] on the plane z = 1.
pub(crate) fn rect_solid_angle(xa: f64, xb: f64, ya: f64, yb: f64) -> f64 {
    rect_corner(xb, yb) - rect_corner(xa, yb) - rect_corner(xb, ya) + rect_corner(xa, ya)
}

/// A point of [xa, xb]×[ya, yb] on the plane z = 1 distributed uniformly
/// in solid angle as seen from the origin (see the module doc).
pub(crate) fn sample_rect_solid_angle(xa: f64, xb: f64, ya: f64, yb: f64, u: Vec2) -> (f64, f64) {
    let omega = rect_solid_angle(xa, xb, ya, yb);
    let target = u.x as f64 * omega;
    // G(X) − target and its derivative, the marginal density ∫ dY/(1+X²+Y²)^{3/2}.
    let g = |x: f64| rect_solid_angle(xa, x, ya, yb) - target;
    let dg = |x: f64| {
        let a2 = 1.0 + x * x;
        (yb / (a2 + yb * yb).sqrt() - ya / (a2 + ya * ya).sqrt()) / a2
    };
    let (mut lo, mut hi) = (xa, xb);
    let mut x = xa + u.x as f64 * (xb - xa);
    for _ in 0..60 {
        let gx = g(x);
        if gx.abs() <= 1e-13 * omega {
            break;
        }
        if gx > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let d = dg(x);
        let xn = x - gx / d;
        x = if d > 0.0 && xn > lo && xn < hi {
            xn
        } else {
            0.5 * (lo + hi)
        };
    }
    // Conditional CDF in Y ∝ H(Y) = Y/√(a² + Y²), inverted in closed form.
    let a = (1.0 + x * x).sqrt();
    let hy = |y: f64| y / (a * a + y * y).sqrt();
    let h = hy(ya) + u.y as f64 * (hy(yb) - hy(ya));
    let y = (h * a / (1.0 - h * h).max(1e-300).sqrt()).clamp(ya, yb);
    (x, y)
}

impl ProjectionLight {
    /// Projector of `scale`·image (RGB, non-negative, in colour space `cs`)
    /// with field of view `fov_deg` ∈ (0°, 180°) across the image's shorter
    /// side, at `render_from_light` (the y flip belongs to the caller).
    pub fn new(
        render_from_light: Transform,
        image: Arc<MapImage>,
        color_space: &'static ColorSpace,
        scale: f32,
        fov_deg: f32,
    ) -> Self {
        assert_eq!(image.channels, 3, "projection images are RGB");
        debug_assert!(fov_deg > 0.0 && fov_deg < 180.0);
        let window = screen_window(image.width, image.height);
        let t = (fov_deg.to_radians() / 2.0).tan();
        let (w, h) = (image.width, image.height);
        let mut omega = Vec::with_capacity(w * h);
        let mut weight = Vec::with_capacity(w * h);
        let (dx, dy) = (
            (window[2] - window[0]) as f64 / w as f64,
            (window[3] - window[1]) as f64 / h as f64,
        );
        for y in 0..h {
            for x in 0..w {
                let xa = (window[0] as f64 + x as f64 * dx) * t as f64;
                let ya = (window[1] as f64 + y as f64 * dy) * t as f64;
                let o = rect_solid_angle(xa, xa + dx * t as f64, ya, ya + dy * t as f64);
                let rgb = &image.data[(y * w + x) * 3..][..3];
                omega.push(o as f32);
                weight.push(((rgb[0] + rgb[1] + rgb[2]) as f64 / 3.0 * o) as f32);
            }
        }
        Self {
            light_from_render: render_from_light.inverse(),
            render_from_light,
            image,
            color_space,
            scale,
            tan_half_fov: t,
            window,
            omega: Arc::new(omega),
            distribution: Arc::new(Distribution2D::new(&weight, w, h)),
        }
    }

    /// Position in render space.
    pub fn position(&self) -> Vec3 {
        self.render_from_light.point(Vec3::ZERO)
    }

    /// Texel (x, y) hit by light-frame unit direction `wl`, if inside the window.
    fn texel_of(&self, wl: Vec3) -> Option<(usize, usize)> {
        if wl.z < HITHER {
            return None;
        }
        let s = Vec2::new(wl.x, wl.y) / (wl.z * self.tan_half_fov);
        let [x0, y0, x1, y1] = self.window;
        if !(x0..=x1).contains(&s.x) || !(y0..=y1).contains(&s.y) {
            return None;
        }
        let uv = Vec2::new((s.x - x0) / (x1 - x0), (s.y - y0) / (y1 - y0));
        let (w, h) = (self.image.width, self.image.height);
        let x = ((uv.x * w as f32) as usize).min(w - 1);
        let y = ((uv.y * h as f32) as usize).min(h - 1);
        Some((x, y))
    }

    /// Spectrum of texel `i` (row-major) times `scale`.
    fn texel_spectrum(&self, i: usize, lambda: &SampledWavelengths) -> SampledSpectrum {
        let t = &self.image.data[i * 3..][..3];
        self.color_space
            .sample_rgb(Rgb::new(t[0], t[1], t[2]), SpectrumKind::Illuminant, lambda)
            * self.scale
    }

    /// Intensity towards light-frame unit direction `wl` [W/sr].
    pub fn intensity(&self, wl: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        match self.texel_of(wl) {
            Some((x, y)) => self.texel_spectrum(y * self.image.width + x, lambda),
            None => SampledSpectrum::zero(),
        }
    }

    /// Incident radiance I(ω)/d² towards the light; density 1 (delta).
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLiSample> {
        delta_position_li(self.position(), &self.light_from_render, ctx, |wl| {
            self.intensity(wl, lambda)
        })
    }

    /// Texel by `u1` (∝ avg(rgb)·Ω), direction uniform in its solid angle by `u2`.
    pub fn sample_le(
        &self,
        u1: Vec2,
        u2: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let ((ix, iy), pmf) = self.distribution.sample_discrete(u1);
        let w = self.image.width;
        let i = iy * w + ix;
        let omega = self.omega[i];
        if pmf == 0.0 || omega <= 0.0 {
            return None;
        }
        let (x, y) = (ix as f64, iy as f64);
        let [x0, y0, x1, y1] = self.window.map(|v| v as f64);
        let t = self.tan_half_fov as f64;
        let (dx, dy) = ((x1 - x0) / w as f64, (y1 - y0) / self.image.height as f64);
        let (xa, ya) = ((x0 + x * dx) * t, (y0 + y * dy) * t);
        let (px, py) = sample_rect_solid_angle(xa, xa + dx * t, ya, ya + dy * t, u2);
        let wl = Vec3::new(px as f32, py as f32, 1.0).normalize();
        let d = self.render_from_light.vector(wl).normalize();
        Some(LightLeSample {
            l: self.texel_spectrum(i, lambda),
            ray: Ray::new(self.position(), d),
            intr: None,
            pdf_pos: PdfArea(1.0),
            pdf_dir: PdfSolidAngle(pmf / omega),
        })
    }

    /// Densities of [`sample_le`](Self::sample_le) for `ray`: (1 (delta), P(texel)/Ω_texel).
    pub fn pdf_le(&self, ray: &Ray) -> (PdfArea, PdfSolidAngle) {
        let wl = self.light_from_render.vector(ray.d).normalize();
        let pdf = match self.texel_of(wl) {
            Some((x, y)) => {
                let i = y * self.image.width + x;
                let omega = self.omega[i];
                if omega > 0.0 {
                    self.distribution.discrete_pmf(x, y) / omega
                } else {
                    0.0
                }
            }
            None => 0.0,
        };
        (PdfArea(1.0), PdfSolidAngle(pdf))
    }

    /// Φ = scale·Σ_texels spectrum(rgb)·Ω_texel.
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let mut sum = [0.0f64; N_SPECTRUM_SAMPLES];
        for (i, &o) in self.omega.iter().enumerate() {
            let s = self.texel_spectrum(i, lambda);
            for (k, acc) in sum.iter_mut().enumerate() {
                *acc += s[k] as f64 * o as f64;
            }
        }
        SampledSpectrum::from_fn(|k| sum[k] as f32)
    }

    /// Emission bounds [pbrt-v4 `ProjectionLight::Bounds`]: the axis, with
    /// emission reaching the frustum's corner direction; power 4π times the
    /// mean intensity over the frustum (Φ/Ω). A light frame that distorts
    /// angles gets the isotropic bound.
    pub(super) fn bounds(&self) -> LightBounds {
        let p = self.position();
        let omega: f64 = self.omega.iter().map(|&o| o as f64).sum();
        let phi = if omega > 0.0 {
            scalar(|l| self.phi(l)) * (4.0 * std::f64::consts::PI / omega) as f32
        } else {
            0.0
        };
        if !preserves_angles(&self.render_from_light) {
            return isotropic_point(p, phi);
        }
        let [x0, y0, x1, y1] = self.window;
        let t = self.tan_half_fov;
        let corner = Vec3::new(x0.abs().max(x1.abs()) * t, y0.abs().max(y1.abs()) * t, 1.0);
        let cos_e = corner.normalize().z;
        let cone = DirectionCone::from_direction(self.render_from_light.vector(Vec3::Z));
        LightBounds::new(Bounds3::from_point(p), cone, phi, cos_e, false)
    }
}

/// pbrt-v4's screen window for a `w`×`h` image: [x0, y0, x1, y1].
pub(crate) fn screen_window(w: usize, h: usize) -> [f32; 4] {
    let aspect = w as f32 / h as f32;
    if aspect > 1.0 {
        [-aspect, -1.0, aspect, 1.0]
    } else {
        [-1.0, -1.0 / aspect, 1.0, 1.0 / aspect]
    }
}
