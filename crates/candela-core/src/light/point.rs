//! Isotropic point light [pbrt-v4 §12.2.1].
//!
//! Radiant intensity `I` [W/sr] in every direction from one point, so the
//! incident radiance at distance d is `I/d²` along a single direction (a
//! delta in position) and the power is Φ = 4πI (seed eq. 二.5). Emission
//! sampling draws a uniform direction on the sphere, p_dir = 1/(4π), so
//! `β₀ = I/(1/(4π)) = Φ` exactly.

use super::bounds::{isotropic_point, scalar, LightBounds};
use super::{delta_position_li, LightLeSample, LightLiSample, LightSampleContext, LightSpectrum};
use crate::math::{Ray, Transform, Vec2, Vec3, PI};
use crate::sampling::{sample_uniform_sphere, uniform_sphere_pdf, PdfArea, PdfSolidAngle};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// A point light at the origin of its light frame.
#[derive(Clone, Debug)]
pub struct PointLight {
    render_from_light: Transform,
    i: LightSpectrum,
    scale: f32,
}

impl PointLight {
    /// Point light at `render_from_light(0,0,0)` with intensity `scale·i` [W/sr].
    pub fn new(render_from_light: Transform, i: LightSpectrum, scale: f32) -> Self {
        Self {
            render_from_light,
            i,
            scale,
        }
    }

    /// Position in render space.
    pub fn position(&self) -> Vec3 {
        self.render_from_light.point(Vec3::ZERO)
    }

    /// Intensity at the sampled wavelengths.
    pub fn intensity(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.i.sample(lambda) * self.scale
    }

    /// Incident radiance I/d² towards the light; density 1 (delta).
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLiSample> {
        // Isotropic: the direction in the light's frame does not matter.
        delta_position_li(self.position(), &Transform::IDENTITY, ctx, |_| {
            self.intensity(lambda)
        })
    }

    /// Uniform direction on the sphere from the light's position.
    pub fn sample_le(
        &self,
        u1: Vec2,
        _u2: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let p = self.position();
        Some(LightLeSample {
            l: self.intensity(lambda),
            ray: Ray::new(p, sample_uniform_sphere(u1)),
            intr: None,
            pdf_pos: PdfArea(1.0),
            pdf_dir: PdfSolidAngle(uniform_sphere_pdf()),
        })
    }

    /// Densities of [`sample_le`](Self::sample_le): (1 (delta), 1/(4π)).
    pub fn pdf_le(&self, _ray: &Ray) -> (PdfArea, PdfSolidAngle) {
        (PdfArea(1.0), PdfSolidAngle(uniform_sphere_pdf()))
    }

    /// Φ = 4π·I (seed eq. 二.5).
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.intensity(lambda) * (4.0 * PI)
    }

    /// Emission bounds: the point, every direction, power Φ = 4πI.
    pub(super) fn bounds(&self) -> LightBounds {
        isotropic_point(self.position(), scalar(|l| self.phi(l)))
    }
}
