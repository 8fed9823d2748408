//! Diffuse (Lambertian) area light [pbrt-v4 §12.3.1].
//!
//! Every point of a shape emits constant radiance `L` into the hemisphere of
//! its surface normal (both hemispheres when two-sided). Power:
//! Φ = A·∫ L cos θ dω = πAL (seed eq. 二.7), 2πAL two-sided.
//!
//! Incident sampling delegates to the shape's solid-angle sampling (cone
//! sampling for spheres seen from outside, area sampling converted by
//! d²/|cos θ'| otherwise) [pbrt-v4 §6.1]. Emission sampling [Veach 1997,
//! §8.2; pbrt-v3 `DiffuseAreaLight::Sample_Le`] picks a point by area
//! (p_pos = 1/A for uniformly sampled shapes, else the shape's density) and
//! a cosine-weighted direction about the normal (p_dir = cos θ/π); a
//! two-sided light first picks a side with probability 1/2, so
//! p_dir = cos θ/(2π). Then `β₀ = L·cos θ·A·π/cos θ = πAL = Φ` (2πAL
//! two-sided) for every uniform-area sample.

use super::{LightLeSample, LightLiSample, LightSampleContext, LightSpectrum};
use crate::interaction::Interaction;
use crate::math::{Frame, Vec2, Vec3, PI};
use crate::sampling::{
    cosine_hemisphere_pdf, sample_cosine_hemisphere, PdfArea, PdfSolidAngle, ONE_MINUS_EPSILON,
};
use crate::shape::{Shape, ShapeSampleContext};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// A Lambertian emitter on a shape given in render space.
#[derive(Clone, Debug)]
pub struct DiffuseAreaLight {
    shape: Shape,
    area: f32,
    lemit: LightSpectrum,
    scale: f32,
    two_sided: bool,
}

impl DiffuseAreaLight {
    /// Emitter of radiance `scale·lemit` on `shape` (already in render
    /// space); one-sided lights emit on the side of the shape's normal.
    pub fn new(shape: Shape, lemit: LightSpectrum, scale: f32, two_sided: bool) -> Self {
        let area = shape.area();
        Self {
            shape,
            area,
            lemit,
            scale,
            two_sided,
        }
    }

    /// The emitting shape.
    pub fn shape(&self) -> &Shape {
        &self.shape
    }

    /// True when both sides emit.
    pub fn two_sided(&self) -> bool {
        self.two_sided
    }

    fn shape_ctx(ctx: &LightSampleContext) -> ShapeSampleContext {
        ShapeSampleContext {
            p: ctx.p,
            p_error: ctx.p_error,
            n: ctx.n,
            ns: ctx.ns,
        }
    }

    /// Radiance leaving surface point `p` (normal `n`) towards `w`; zero on
    /// the back side of a one-sided light.
    pub fn l(
        &self,
        _p: Vec3,
        n: Vec3,
        _uv: Vec2,
        w: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        if !self.two_sided && n.dot(w) < 0.0 {
            return SampledSpectrum::zero();
        }
        self.lemit.sample(lambda) * self.scale
    }

    /// Samples a point on the shape as seen from `ctx`.
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLiSample> {
        let ss = self.shape.sample_from(&Self::shape_ctx(ctx), u)?;
        let d = ss.intr.p - ctx.p;
        if ss.pdf.0 == 0.0 || d.length_squared() == 0.0 {
            return None;
        }
        let wi = d.normalize();
        let l = self.l(ss.intr.p, ss.intr.n, ss.intr.uv, -wi, lambda);
        if l.is_black() {
            return None;
        }
        Some(LightLiSample {
            l,
            wi,
            pdf: ss.pdf,
            p_light: ss.intr,
        })
    }

    /// Density of [`sample_li`](Self::sample_li) for direction `wi`.
    pub fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> PdfSolidAngle {
        self.shape.pdf_from(&Self::shape_ctx(ctx), wi)
    }

    /// Point by area (`u1`), cosine-weighted direction (`u2`; `u2.x` also
    /// picks the side of a two-sided light).
    pub fn sample_le(
        &self,
        u1: Vec2,
        u2: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let ss = self.shape.sample_area(u1)?;
        let (w_local, pdf_dir) = if self.two_sided {
            let front = u2.x < 0.5;
            let ux = if front {
                u2.x * 2.0
            } else {
                (u2.x - 0.5) * 2.0
            };
            let mut w = sample_cosine_hemisphere(Vec2::new(ux.min(ONE_MINUS_EPSILON), u2.y));
            if !front {
                w.z = -w.z;
            }
            (w, 0.5 * cosine_hemisphere_pdf(w.z.abs()))
        } else {
            let w = sample_cosine_hemisphere(u2);
            (w, cosine_hemisphere_pdf(w.z))
        };
        if pdf_dir <= 0.0 {
            return None;
        }
        let it = ss.intr;
        let w = Frame::from_z(it.n).from_local(w_local);
        Some(LightLeSample {
            l: self.l(it.p, it.n, it.uv, w, lambda),
            ray: it.spawn_ray(w),
            intr: Some(it),
            pdf_pos: ss.pdf,
            pdf_dir: PdfSolidAngle(pdf_dir),
        })
    }

    /// Densities of [`sample_le`](Self::sample_le) leaving `intr` towards `w`.
    /// The position density is the shape's area density at `intr` (1/A for
    /// uniformly sampled shapes).
    pub fn pdf_le_area(&self, intr: &Interaction, w: Vec3) -> (PdfArea, PdfSolidAngle) {
        debug_assert!(intr.is_surface());
        let cos = intr.n.dot(w);
        let pdf_dir = if self.two_sided {
            0.5 * cosine_hemisphere_pdf(cos.abs())
        } else if cos > 0.0 {
            cosine_hemisphere_pdf(cos)
        } else {
            0.0
        };
        (self.shape.pdf_area(intr), PdfSolidAngle(pdf_dir))
    }

    /// Φ = πAL, doubled when two-sided (seed eq. 二.7).
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let sides = if self.two_sided { 2.0 } else { 1.0 };
        self.lemit.sample(lambda) * (sides * self.scale * self.area * PI)
    }
}
