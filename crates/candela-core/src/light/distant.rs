//! Distant (directional) light [pbrt-v4 §12.4].
//!
//! Radiance `L` arriving from a single direction: a delta in direction. The
//! incident "radiance" returned by `sample_li` is the irradiance on a surface
//! perpendicular to the light. Its power is only meaningful relative to the
//! scene: the light is treated as a disk of the scene's bounding radius R
//! perpendicular to the direction, Φ = πR²·L, and emission sampling picks a
//! uniform point on that disk (p_pos = 1/(πR²), p_dir = 1 for the delta), so
//! `β₀ = L·πR² = Φ` exactly.

use super::{LightLeSample, LightLiSample, LightSampleContext, LightSpectrum};
use crate::interaction::Interaction;
use crate::math::{Bounds3, Frame, Ray, Transform, Vec2, Vec3, PI};
use crate::sampling::{sample_uniform_disk_concentric, PdfArea, PdfSolidAngle};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Light arriving from light-frame direction +z (i.e. travelling along −z).
#[derive(Clone, Debug)]
pub struct DistantLight {
    render_from_light: Transform,
    lemit: LightSpectrum,
    scale: f32,
    scene_center: Vec3,
    scene_radius: f32,
}

impl DistantLight {
    /// Distant light of radiance `scale·lemit` from `render_from_light(+z)`;
    /// call `preprocess` before use.
    pub fn new(render_from_light: Transform, lemit: LightSpectrum, scale: f32) -> Self {
        Self {
            render_from_light,
            lemit,
            scale,
            scene_center: Vec3::ZERO,
            scene_radius: 0.0,
        }
    }

    /// Records the scene's bounding sphere.
    pub fn preprocess(&mut self, scene_bounds: &Bounds3) {
        let (c, r) = scene_bounds.bounding_sphere();
        self.scene_center = c;
        self.scene_radius = r;
    }

    /// Unit direction towards the light (render space).
    pub fn direction(&self) -> Vec3 {
        self.render_from_light.vector(Vec3::Z).normalize()
    }

    /// Incident radiance from the light's direction; density 1 (delta).
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLiSample> {
        let wi = self.direction();
        let p_outside = ctx.p + wi * (2.0 * self.scene_radius);
        Some(LightLiSample {
            l: self.lemit.sample(lambda) * self.scale,
            wi,
            pdf: PdfSolidAngle(1.0),
            p_light: Interaction::at_point(p_outside),
        })
    }

    /// Ray from a uniform point on the scene-radius disk facing the light.
    pub fn sample_le(
        &self,
        u1: Vec2,
        _u2: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let r = self.scene_radius;
        if r <= 0.0 {
            return None;
        }
        let w = self.direction();
        let cd = sample_uniform_disk_concentric(u1);
        let p_disk =
            self.scene_center + r * Frame::from_z(w).from_local(Vec3::new(cd.x, cd.y, 0.0));
        Some(LightLeSample {
            l: self.lemit.sample(lambda) * self.scale,
            ray: Ray::new(p_disk + r * w, -w),
            intr: None,
            pdf_pos: PdfArea(1.0 / (PI * r * r)),
            pdf_dir: PdfSolidAngle(1.0),
        })
    }

    /// Densities of [`sample_le`](Self::sample_le): (1/(πR²), 1 (delta)).
    pub fn pdf_le(&self, _ray: &Ray) -> (PdfArea, PdfSolidAngle) {
        let r = self.scene_radius;
        (PdfArea(1.0 / (PI * r * r)), PdfSolidAngle(1.0))
    }

    /// Φ = πR²·L (power through the scene's cross-section).
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let r = self.scene_radius;
        self.lemit.sample(lambda) * (self.scale * PI * r * r)
    }
}
