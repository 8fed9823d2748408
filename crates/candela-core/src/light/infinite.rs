//! Uniform infinite (environment) light [pbrt-v4 §12.5.1].
//!
//! Constant radiance `L` arrives from every direction at infinity. Incident
//! sampling picks a uniform direction on the sphere (p = 1/(4π)); a
//! cosine-weighted choice would be better for surfaces but this one is also
//! valid for points in media and matches pbrt-v4's densities.
//!
//! Emission [pbrt-v3 `InfiniteAreaLight::Sample_Le`; Veach 1997, §8.3.2]:
//! choose the direction ω the light travels uniformly (p_dir = 1/(4π)), then
//! a uniform point on the disk of the scene's bounding radius R perpendicular
//! to ω, placed R upstream of the centre (p_pos = 1/(πR²)). The flux crossing
//! that disk is Φ = ∫ L·πR² dω = 4π²R²·L, and `β₀ = Φ` for every sample.

use super::{LightLeSample, LightLiSample, LightSampleContext, LightSpectrum};
use crate::interaction::Interaction;
use crate::math::{Bounds3, Frame, Ray, Vec2, Vec3, PI};
use crate::sampling::{
    sample_uniform_disk_concentric, sample_uniform_sphere, uniform_sphere_pdf, PdfArea,
    PdfSolidAngle,
};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Constant-radiance environment.
#[derive(Clone, Debug)]
pub struct UniformInfiniteLight {
    lemit: LightSpectrum,
    scale: f32,
    scene_center: Vec3,
    scene_radius: f32,
}

impl UniformInfiniteLight {
    /// Environment of radiance `scale·lemit`; call `preprocess` before use.
    pub fn new(lemit: LightSpectrum, scale: f32) -> Self {
        Self {
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

    /// Radiance seen along any escaped ray.
    pub fn le(&self, _ray: &Ray, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.lemit.sample(lambda) * self.scale
    }

    /// Uniform direction on the sphere; the light point lies 2R away.
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLiSample> {
        let wi = sample_uniform_sphere(u);
        Some(LightLiSample {
            l: self.lemit.sample(lambda) * self.scale,
            wi,
            pdf: PdfSolidAngle(uniform_sphere_pdf()),
            p_light: Interaction::at_point(ctx.p + wi * (2.0 * self.scene_radius)),
        })
    }

    /// Density of [`sample_li`](Self::sample_li): 1/(4π).
    pub fn pdf_li(&self, _ctx: &LightSampleContext, _wi: Vec3) -> PdfSolidAngle {
        PdfSolidAngle(uniform_sphere_pdf())
    }

    /// Uniform travel direction (`u1`), uniform point on the upstream disk (`u2`).
    pub fn sample_le(
        &self,
        u1: Vec2,
        u2: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let r = self.scene_radius;
        if r <= 0.0 {
            return None;
        }
        let w = sample_uniform_sphere(u1);
        let cd = sample_uniform_disk_concentric(u2);
        let frame = Frame::from_z(-w);
        let p_disk = self.scene_center + r * frame.from_local(Vec3::new(cd.x, cd.y, 0.0));
        Some(LightLeSample {
            l: self.lemit.sample(lambda) * self.scale,
            ray: Ray::new(p_disk - r * w, w),
            intr: None,
            pdf_pos: PdfArea(1.0 / (PI * r * r)),
            pdf_dir: PdfSolidAngle(uniform_sphere_pdf()),
        })
    }

    /// Densities of [`sample_le`](Self::sample_le): (1/(πR²), 1/(4π)).
    pub fn pdf_le(&self, _ray: &Ray) -> (PdfArea, PdfSolidAngle) {
        let r = self.scene_radius;
        (
            PdfArea(1.0 / (PI * r * r)),
            PdfSolidAngle(uniform_sphere_pdf()),
        )
    }

    /// Φ = 4π²R²·L.
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let r = self.scene_radius;
        self.lemit.sample(lambda) * (self.scale * 4.0 * PI * PI * r * r)
    }
}
