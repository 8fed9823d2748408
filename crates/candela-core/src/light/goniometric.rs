//! Goniometric light: a point light whose intensity varies with direction as
//! a measured goniophotometric diagram [pbrt-v4 `GoniometricLight`, §12.2.3].
//!
//! `I(ω) = scale·I_e(λ)·Y(ω)`, where `Y` is a single-channel square image in
//! the equal-area octahedral parameterisation [Clarberg 2008]: ω, in the
//! light's frame, maps to (u, v) = [`equal_area_sphere_to_square`]`(ω)` and
//! the texel containing (u, v) gives `Y` (nearest lookup). pbrt-v4's
//! `Create` turns an RGB image into `Y` by the plain average (R + G + B)/3,
//! and composes the user's light transform with a swap of y and z, so the
//! image centre (light-frame +z here) points along the user's +y.
//!
//! **Power.** Every texel covers 4π/N steradians, so
//! Φ = ∫ I dω = 4π·scale·I_e·mean(Y) exactly [pbrt-v4 `Phi`].
//!
//! **Emission sampling.** A piecewise-constant 2D distribution over the
//! texels weighted by `Y` samples (u, v) with density p(u, v); the map is
//! equal-area, so p_dir = p/(4π) without a Jacobian [pbrt-v4 `SampleLe`].
//! Then p_dir(ω) = Y(ω)/(4π·mean Y) is proportional to I(ω) and
//! `β₀ = I/p_dir = Φ` for every sample.
//!
//! **IES webs.** The same light may instead carry an [`IesWeb`] (an IES
//! LM-63 file): `Y(ω)` is then the web's bilinear intensity \[cd\] in the
//! light frame (nadir +z, horizontal angle 0 +x), emission sampling is the
//! web's own ∝ I(ω), and Φ = scale·I_e·∫I dω with the web's exact flux.

use super::bounds::{isotropic_point, scalar, LightBounds};
use super::{
    delta_position_li, IesWeb, LightLeSample, LightLiSample, LightSampleContext, LightSpectrum,
};
use crate::image::{MapImage, WrapMode};
use crate::math::{Ray, Transform, Vec2, Vec3, PI};
use crate::sampling::{
    equal_area_sphere_to_square, equal_area_square_to_sphere, Distribution2D, PdfArea,
    PdfSolidAngle,
};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use std::sync::Arc;

/// A point light at the light-frame origin with an equal-area intensity map.
#[derive(Clone, Debug)]
pub struct GoniometricLight {
    render_from_light: Transform,
    light_from_render: Transform,
    i: LightSpectrum,
    scale: f32,
    pattern: Pattern,
}

/// The directional factor Y(ω) of a goniometric light.
#[derive(Clone, Debug)]
enum Pattern {
    /// pbrt-v4's equal-area image, its texel distribution and mean.
    Map {
        image: Arc<MapImage>,
        distribution: Arc<Distribution2D>,
        mean_y: f32,
    },
    /// An IES photometric web \[cd\].
    Web(Arc<IesWeb>),
}

impl GoniometricLight {
    /// Light of intensity `scale·i·Y(ω)`, `Y` a square one-channel image of
    /// non-negative values in the equal-area parameterisation of the light
    /// frame (pbrt-v4's constructor; the y/z swap belongs to the caller).
    pub fn new(
        render_from_light: Transform,
        i: LightSpectrum,
        scale: f32,
        image: Arc<MapImage>,
    ) -> Self {
        assert_eq!(image.width, image.height, "equal-area maps are square");
        assert_eq!(image.channels, 1, "goniometric maps have one channel");
        debug_assert!(image.data.iter().all(|v| *v >= 0.0 && v.is_finite()));
        let distribution = Arc::new(Distribution2D::new(&image.data, image.width, image.height));
        let sum: f64 = image.data.iter().map(|&v| v as f64).sum();
        let mean_y = (sum / image.data.len() as f64) as f32;
        Self {
            light_from_render: render_from_light.inverse(),
            render_from_light,
            i,
            scale,
            pattern: Pattern::Map {
                image,
                distribution,
                mean_y,
            },
        }
    }

    /// Light of intensity `scale·i·I_web(ω)` with `web` in the light frame.
    pub fn from_web(
        render_from_light: Transform,
        i: LightSpectrum,
        scale: f32,
        web: Arc<IesWeb>,
    ) -> Self {
        Self {
            light_from_render: render_from_light.inverse(),
            render_from_light,
            i,
            scale,
            pattern: Pattern::Web(web),
        }
    }

    /// Y(ω) towards light-frame unit direction `wl`.
    fn pattern(&self, wl: Vec3) -> f32 {
        match &self.pattern {
            Pattern::Map { image, .. } => {
                let uv = equal_area_sphere_to_square(wl);
                image.nearest_rgb(uv, WrapMode::Clamp)[0]
            }
            Pattern::Web(web) => web.intensity(wl),
        }
    }

    /// ∫ Y dω over the sphere.
    fn pattern_integral(&self) -> f32 {
        match &self.pattern {
            Pattern::Map { mean_y, .. } => 4.0 * PI * mean_y,
            Pattern::Web(web) => web.flux() as f32,
        }
    }

    /// Position in render space.
    pub fn position(&self) -> Vec3 {
        self.render_from_light.point(Vec3::ZERO)
    }

    /// Intensity towards light-frame unit direction `wl` [W/sr].
    pub fn intensity(&self, wl: Vec3, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.i.sample(lambda) * (self.scale * self.pattern(wl))
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

    /// A direction drawn ∝ Y(ω) (`u1`): the texel distribution or the web's.
    pub fn sample_le(
        &self,
        u1: Vec2,
        _u2: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let (wl, pdf) = match &self.pattern {
            Pattern::Map { distribution, .. } => {
                let (uv, map_pdf) = distribution.sample(u1);
                (equal_area_square_to_sphere(uv), map_pdf / (4.0 * PI))
            }
            Pattern::Web(web) => {
                let s = web.sample(u1)?;
                (s.w, s.pdf.0)
            }
        };
        if pdf == 0.0 {
            return None;
        }
        let d = self.render_from_light.vector(wl).normalize();
        Some(LightLeSample {
            l: self.intensity(wl, lambda),
            ray: Ray::new(self.position(), d),
            intr: None,
            pdf_pos: PdfArea(1.0),
            pdf_dir: PdfSolidAngle(pdf),
        })
    }

    /// Densities of [`sample_le`](Self::sample_le) for `ray`: (1 (delta),
    /// p(u, v)/(4π) or the web's density).
    pub fn pdf_le(&self, ray: &Ray) -> (PdfArea, PdfSolidAngle) {
        let wl = self.light_from_render.vector(ray.d).normalize();
        let pdf = match &self.pattern {
            Pattern::Map { distribution, .. } => {
                distribution.pdf(equal_area_sphere_to_square(wl)) / (4.0 * PI)
            }
            Pattern::Web(web) => web.pdf(wl).0,
        };
        (PdfArea(1.0), PdfSolidAngle(pdf))
    }

    /// Φ = scale·I_e·∫Y dω (4π·mean(Y) for a map, the web's flux for IES).
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.i.sample(lambda) * (self.scale * self.pattern_integral())
    }

    /// Emission bounds: bounded as an isotropic point light of the same
    /// power Φ, as pbrt-v4 does (the map may light any direction).
    pub(super) fn bounds(&self) -> LightBounds {
        isotropic_point(self.position(), scalar(|l| self.phi(l)))
    }
}
