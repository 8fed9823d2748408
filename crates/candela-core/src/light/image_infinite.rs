//! Image infinite (environment) light [pbrt-v4 `ImageInfiniteLight`, §12.5.2].
//!
//! Radiance arriving from direction ω is read from a square RGB image in the
//! equal-area octahedral parameterisation [Clarberg 2008]: ω is taken to the
//! light's frame and mapped to (u, v) ∈ [0, 1]² by
//! [`equal_area_sphere_to_square`]; the texel containing (u, v) (nearest
//! lookup, octahedral wrap) gives an RGB, lifted as an illuminant spectrum in
//! the image's colour space and multiplied by `scale`. Radiance is thus
//! piecewise constant over texels, and every texel covers 4π/N steradians.
//!
//! **Sampling.** A piecewise-constant 2D distribution over the texels, each
//! weighted by the average of its R, G and B (pbrt-v4's
//! `Image::GetSamplingDistribution`), samples (u, v) with density p(u, v);
//! because the map is equal-area, the density per steradian is p/(4π) with
//! no Jacobian [pbrt-v4 `ImageInfiniteLight::SampleLi`, `PDF_Li`]. The same
//! distribution drives MIS: pbrt-v4 additionally uses a "compensated"
//! distribution (weights minus their mean, clamped at 0) for NEE when MIS
//! with BSDF sampling follows [Karlík et al. 2019], which lowers variance
//! but not the expectation; candela uses the plain one everywhere.
//!
//! **Emission** [pbrt-v4 `SampleLe`, `PDF_Le`]: the direction the light
//! travels is minus a direction sampled as above (p_dir = p/(4π)), the origin
//! a uniform point on the disk of the scene's bounding radius R perpendicular
//! to it, R upstream of the centre (p_pos = 1/(πR²)), as for the uniform sky.
//!
//! **Power** [pbrt-v4 `Phi`]: Φ = 4π²R²·scale·(mean texel radiance), the
//! flux through that disk from every direction; E[β₀] = Φ for `sample_le`.

use super::{LightLeSample, LightLiSample, LightSampleContext};
use crate::image::{MapImage, WrapMode};
use crate::interaction::Interaction;
use crate::math::{Bounds3, Frame, Ray, Transform, Vec2, Vec3, PI};
use crate::sampling::{
    equal_area_sphere_to_square, equal_area_square_to_sphere, sample_uniform_disk_concentric,
    Distribution2D, PdfArea, PdfSolidAngle,
};
use crate::spectrum::{ColorSpace, Rgb, SampledSpectrum, SampledWavelengths, SpectrumKind};
use std::sync::Arc;

/// Environment light from an equal-area square RGB image.
#[derive(Clone, Debug)]
pub struct ImageInfiniteLight {
    render_from_light: Transform,
    light_from_render: Transform,
    image: Arc<MapImage>,
    color_space: &'static ColorSpace,
    scale: f32,
    distribution: Arc<Distribution2D>,
    scene_center: Vec3,
    scene_radius: f32,
}

impl ImageInfiniteLight {
    /// Environment of radiance `scale`·image (square, RGB) in colour space
    /// `cs`, oriented by `render_from_light`; call `preprocess` before use.
    pub fn new(
        render_from_light: Transform,
        image: Arc<MapImage>,
        color_space: &'static ColorSpace,
        scale: f32,
    ) -> Self {
        assert_eq!(image.width, image.height, "equal-area maps are square");
        assert_eq!(image.channels, 3, "environment maps are RGB");
        let weights: Vec<f32> = image
            .data
            .chunks_exact(3)
            .map(|t| (t[0] + t[1] + t[2]) / 3.0)
            .collect();
        let distribution = Arc::new(Distribution2D::new(&weights, image.width, image.height));
        Self {
            light_from_render: render_from_light.inverse(),
            render_from_light,
            image,
            color_space,
            scale,
            distribution,
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

    /// Radiance of the texel containing (u, v).
    fn image_le(&self, uv: Vec2, lambda: &SampledWavelengths) -> SampledSpectrum {
        let [r, g, b] = self.image.nearest_rgb(uv, WrapMode::OctahedralSphere);
        self.color_space
            .sample_rgb(Rgb::new(r, g, b), SpectrumKind::Illuminant, lambda)
            * self.scale
    }

    /// Equal-area (u, v) of render-space direction `w` (any length).
    fn uv_of(&self, w: Vec3) -> Vec2 {
        equal_area_sphere_to_square(self.light_from_render.vector(w).normalize())
    }

    /// Render-space unit direction of (u, v).
    fn dir_of(&self, uv: Vec2) -> Vec3 {
        self.render_from_light
            .vector(equal_area_square_to_sphere(uv))
            .normalize()
    }

    /// Radiance arriving along an escaped ray (from direction `ray.d`).
    pub fn le(&self, ray: &Ray, lambda: &SampledWavelengths) -> SampledSpectrum {
        self.image_le(self.uv_of(ray.d), lambda)
    }

    /// A direction drawn from the image distribution; the light point lies 2R away.
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLiSample> {
        let (uv, map_pdf) = self.distribution.sample(u);
        if map_pdf == 0.0 {
            return None;
        }
        let wi = self.dir_of(uv);
        Some(LightLiSample {
            l: self.image_le(uv, lambda),
            wi,
            pdf: PdfSolidAngle(map_pdf / (4.0 * PI)),
            p_light: Interaction::at_point(ctx.p + wi * (2.0 * self.scene_radius)),
        })
    }

    /// Density of [`sample_li`](Self::sample_li): p(u, v)/(4π).
    pub fn pdf_li(&self, _ctx: &LightSampleContext, wi: Vec3) -> PdfSolidAngle {
        PdfSolidAngle(self.distribution.pdf(self.uv_of(wi)) / (4.0 * PI))
    }

    /// Travel direction minus an image sample (`u1`), origin on the upstream disk (`u2`).
    pub fn sample_le(
        &self,
        u1: Vec2,
        u2: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let r = self.scene_radius;
        let (uv, map_pdf) = self.distribution.sample(u1);
        if r <= 0.0 || map_pdf == 0.0 {
            return None;
        }
        let w = -self.dir_of(uv);
        let cd = sample_uniform_disk_concentric(u2);
        let frame = Frame::from_z(-w);
        let p_disk = self.scene_center + r * frame.from_local(Vec3::new(cd.x, cd.y, 0.0));
        Some(LightLeSample {
            l: self.image_le(uv, lambda),
            ray: Ray::new(p_disk - r * w, w),
            intr: None,
            pdf_pos: PdfArea(1.0 / (PI * r * r)),
            pdf_dir: PdfSolidAngle(map_pdf / (4.0 * PI)),
        })
    }

    /// Densities of [`sample_le`](Self::sample_le) for a ray travelling along `ray.d`.
    pub fn pdf_le(&self, ray: &Ray) -> (PdfArea, PdfSolidAngle) {
        let r = self.scene_radius;
        let map_pdf = self.distribution.pdf(self.uv_of(-ray.d));
        (
            PdfArea(1.0 / (PI * r * r)),
            PdfSolidAngle(map_pdf / (4.0 * PI)),
        )
    }

    /// Φ = 4π²R²·scale·mean over texels of the texel's radiance spectrum.
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let mut sum = SampledSpectrum::zero();
        for t in self.image.data.chunks_exact(3) {
            let rgb = Rgb::new(t[0], t[1], t[2]);
            sum += self
                .color_space
                .sample_rgb(rgb, SpectrumKind::Illuminant, lambda);
        }
        let n = (self.image.width * self.image.height) as f32;
        let r = self.scene_radius;
        sum * (4.0 * PI * PI * r * r * self.scale / n)
    }
}
