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
//!
//! **Image emission** [pbrt-v4 `DiffuseAreaLight::L`, `filename`]. With an
//! RGB image instead of a spectrum, the radiance at a point of surface
//! coordinates (u, v) is `scale·spectrum(rgb)`, where rgb is the bilinear
//! lookup of the image at (u, 1 − v) (edge texels extended, so row 0 is at
//! v = 1 as for image textures) with negative components clamped to zero,
//! lifted as an RGB illuminant spectrum of the image's colour space. The
//! sampling above is unchanged (uniform by area, cosine in direction), so
//! it stays unbiased; β₀ = L·cos θ/(p_pos·p_dir) then varies with the texel.
//!
//! **Power of an image emitter.** The exact power is
//! Φ = π·(2 if two-sided)·scale·∫_A spectrum(rgb(uv(p))) dA. Like pbrt-v4's
//! `Phi`, candela takes `A·mean over texels of spectrum(texel)`, which is
//! that integral when the shape's (u, v) covers the unit square uniformly
//! by area (a bilinear patch, or the sum over the two triangles of a quad
//! with uv = the unit square) and the image's colours differ only in
//! brightness (the lift is then linear in rgb). A single triangle of such a
//! quad gets the whole image's mean rather than that of the half it covers.
//! Φ only weights light selection (the power light sampler), so this costs
//! variance, never bias.
//!
//! **Alpha** [pbrt-v4 `DiffuseAreaLight::AlphaMasked`]. An emitter whose
//! shape has an `alpha` texture emits nothing where it is masked: α ≥ 1 is
//! never masked, α ≤ 0 always, and 0 < α < 1 is masked when pbrt-v4's
//! `HashFloat` of the point's bytes exceeds α. The texture sees only the
//! point and its (u, v), as in pbrt-v4. Hits on the shape are alpha-tested
//! separately with a hash of the ray ([`crate::scene::Primitive`]), so a
//! camera ray sees a fractional α with expected emission α² (hit test ×
//! emission mask, independent hashes), while light sampling and emission
//! sampling see α: as in pbrt-v4, whose renders candela follows here, the
//! strategies then disagree, and only 0/1 alpha is consistent. Φ ignores
//! alpha, as pbrt-v4's does.

use super::bounds::{scalar, LightBounds};
use super::{LightLeSample, LightLiSample, LightSampleContext, LightSpectrum};
use crate::image::{MapImage, WrapMode};
use crate::interaction::Interaction;
use crate::math::{Frame, Vec2, Vec3, PI};
use crate::sampling::{
    cosine_hemisphere_pdf, murmur_hash64a, sample_cosine_hemisphere, PdfArea, PdfSolidAngle,
    ONE_MINUS_EPSILON,
};
use crate::shape::{
    area_sample_to_solid_angle, Shape, ShapeSample, ShapeSampleContext, ShapeSampleSa,
    TriangleSampler,
};
use crate::spectrum::{ColorSpace, Rgb, SampledSpectrum, SampledWavelengths, SpectrumKind};
use crate::texture::{FloatTexture, TextureEvalContext};
use std::sync::Arc;

/// What a diffuse area light emits before `scale`.
#[derive(Clone, Debug)]
enum Emission {
    /// The same spectrum everywhere.
    Spectrum(LightSpectrum),
    /// An RGB image over the surface's (u, v), in `color_space`.
    Image {
        image: Arc<MapImage>,
        color_space: &'static ColorSpace,
    },
}

/// A Lambertian emitter on a shape given in render space.
#[derive(Clone, Debug)]
pub struct DiffuseAreaLight {
    shape: Shape,
    /// The triangle's sampling data gathered once, when the shape is a triangle.
    triangle: Option<TriangleSampler>,
    area: f32,
    emission: Emission,
    scale: f32,
    two_sided: bool,
    /// The shape's cut-out mask (`None`: emits everywhere).
    alpha: Option<FloatTexture>,
    /// pbrt-v4's invisible light: a shape with constant `alpha` 0 is never
    /// hit, yet its light still shines through light sampling.
    invisible: bool,
}

/// pbrt-v4's `HashFloat(p)`: MurmurHash64A of the coordinates' bytes, low
/// 32 bits scaled to [0, 1).
fn hash_float(p: Vec3) -> f32 {
    let mut bytes = [0u8; 12];
    for (i, v) in [p.x, p.y, p.z].iter().enumerate() {
        bytes[4 * i..4 * i + 4].copy_from_slice(&v.to_le_bytes());
    }
    (murmur_hash64a(&bytes, 0) as u32) as f32 * (1.0 / 4_294_967_296.0)
}

impl DiffuseAreaLight {
    /// Emitter of radiance `scale·lemit` on `shape` (already in render
    /// space); one-sided lights emit on the side of the shape's normal.
    pub fn new(shape: Shape, lemit: LightSpectrum, scale: f32, two_sided: bool) -> Self {
        Self::with_emission(shape, Emission::Spectrum(lemit), scale, two_sided)
    }

    /// Emitter of radiance `scale·spectrum(rgb)`, rgb looked up in the RGB
    /// `image` (colour space `color_space`) at (u, 1 − v); see the module doc.
    pub fn new_image(
        shape: Shape,
        image: Arc<MapImage>,
        color_space: &'static ColorSpace,
        scale: f32,
        two_sided: bool,
    ) -> Self {
        assert_eq!(image.channels, 3, "area light images are RGB");
        let emission = Emission::Image { image, color_space };
        Self::with_emission(shape, emission, scale, two_sided)
    }

    fn with_emission(shape: Shape, emission: Emission, scale: f32, two_sided: bool) -> Self {
        let area = shape.area();
        let triangle = match &shape {
            Shape::Triangle(t) => Some(t.sampler()),
            _ => None,
        };
        Self {
            shape,
            triangle,
            area,
            emission,
            scale,
            two_sided,
            alpha: None,
            invisible: false,
        }
    }

    /// The same light with its emission masked by the shape's `alpha` texture.
    pub fn with_alpha(mut self, alpha: Option<FloatTexture>) -> Self {
        self.alpha = alpha;
        self
    }

    /// Makes the light invisible: rays never hit it (its shape has constant
    /// alpha 0), but it emits everywhere and is reached by light sampling
    /// and emission sampling only [pbrt-v4 `DiffuseAreaLight::Create`, whose
    /// "invisible area light" drops the alpha and excludes it from MIS].
    pub fn invisible(mut self) -> Self {
        self.invisible = true;
        self.alpha = None;
        self
    }

    /// True for an invisible light (see [`DiffuseAreaLight::invisible`]).
    pub fn is_invisible(&self) -> bool {
        self.invisible
    }

    /// True when the emission comes from an image.
    pub fn has_image(&self) -> bool {
        matches!(self.emission, Emission::Image { .. })
    }

    /// True when an alpha texture cuts the emission.
    pub fn has_alpha(&self) -> bool {
        self.alpha.is_some()
    }

    /// pbrt-v4's stochastic alpha test of point `p` with coordinates `uv`.
    fn alpha_masked(&self, p: Vec3, uv: Vec2) -> bool {
        let Some(alpha) = &self.alpha else {
            return false;
        };
        let ctx = TextureEvalContext {
            p,
            uv,
            ..TextureEvalContext::default()
        };
        let a = alpha.evaluate(&ctx);
        if a >= 1.0 {
            return false;
        }
        if a <= 0.0 {
            return true;
        }
        hash_float(p) > a
    }

    /// `spectrum(rgb)` of one RGB triple clamped at zero, before `scale`.
    fn rgb_spectrum(
        cs: &ColorSpace,
        rgb: [f32; 3],
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let rgb = Rgb::new(rgb[0].max(0.0), rgb[1].max(0.0), rgb[2].max(0.0));
        cs.sample_rgb(rgb, SpectrumKind::Illuminant, lambda)
    }

    /// The emitting shape.
    pub fn shape(&self) -> &Shape {
        &self.shape
    }

    /// True when both sides emit.
    pub fn two_sided(&self) -> bool {
        self.two_sided
    }

    fn shape_ctx(&self, ctx: &LightSampleContext) -> ShapeSampleContext {
        ShapeSampleContext {
            p: ctx.p,
            p_error: ctx.p_error,
            n: ctx.n,
            ns: ctx.ns,
            need_uv: self.alpha.is_some() || matches!(self.emission, Emission::Image { .. }),
        }
    }

    /// Radiance leaving surface point `p` (normal `n`, coordinates `uv`)
    /// towards `w`; zero on the back side of a one-sided light and where
    /// alpha masks the point.
    pub fn l(
        &self,
        p: Vec3,
        n: Vec3,
        uv: Vec2,
        w: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        if !self.two_sided && n.dot(w) < 0.0 {
            return SampledSpectrum::zero();
        }
        if self.alpha_masked(p, uv) {
            return SampledSpectrum::zero();
        }
        match &self.emission {
            Emission::Spectrum(s) => s.sample(lambda) * self.scale,
            Emission::Image { image, color_space } => {
                // [pbrt-v4 `DiffuseAreaLight::L`]: v flipped, bilinear, edges clamped.
                let st = Vec2::new(uv.x, 1.0 - uv.y);
                let rgb = image.bilerp_rgb(st, WrapMode::Clamp);
                Self::rgb_spectrum(color_space, rgb, lambda) * self.scale
            }
        }
    }

    /// A point on the shape by area ([`Shape::sample_area`], from the
    /// gathered data for a triangle).
    fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        match &self.triangle {
            Some(t) => t.sample_area(u),
            None => self.shape.sample_area(u),
        }
    }

    /// A point on the shape by solid angle at `ctx` ([`Shape::sample_from`],
    /// from the gathered data for a triangle).
    fn sample_from(&self, ctx: &ShapeSampleContext, u: Vec2) -> Option<ShapeSampleSa> {
        match &self.triangle {
            Some(t) => area_sample_to_solid_angle(ctx, t.sample_area(u)?),
            None => self.shape.sample_from(ctx, u),
        }
    }

    /// True unless [`sample_li`](Self::sample_li) samples the shape's
    /// visible cone (spheres) instead of its area.
    pub fn samples_li_by_area(&self) -> bool {
        self.triangle.is_some() || !matches!(self.shape, Shape::Sphere(_))
    }

    /// Samples a point on the shape as seen from `ctx`.
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLiSample> {
        let ss = self.sample_from(&self.shape_ctx(ctx), u)?;
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
        match &self.triangle {
            Some(t) => t.pdf_from(&self.shape_ctx(ctx), wi),
            None => self.shape.pdf_from(&self.shape_ctx(ctx), wi),
        }
    }

    /// Point by area (`u1`), cosine-weighted direction (`u2`; `u2.x` also
    /// picks the side of a two-sided light).
    pub fn sample_le(
        &self,
        u1: Vec2,
        u2: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        let ss = self.sample_area(u1)?;
        if self.alpha_masked(ss.intr.p, ss.intr.uv) {
            return None;
        }
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
        let pdf_pos = match &self.triangle {
            Some(t) => t.pdf_area(),
            None => self.shape.pdf_area(intr),
        };
        (pdf_pos, PdfSolidAngle(pdf_dir))
    }

    /// Φ = πAL, doubled when two-sided (seed eq. 二.7); for an image, L is
    /// the mean of the texels' spectra (pbrt-v4's `Phi`; see the module doc).
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let sides = if self.two_sided { 2.0 } else { 1.0 };
        let l = match &self.emission {
            Emission::Spectrum(s) => s.sample(lambda),
            Emission::Image { image, color_space } => {
                let mut sum = SampledSpectrum::zero();
                for t in image.data.chunks_exact(3) {
                    sum += Self::rgb_spectrum(color_space, [t[0], t[1], t[2]], lambda);
                }
                sum * (1.0 / (image.width * image.height) as f32)
            }
        };
        l * (sides * self.scale * self.area * PI)
    }

    /// Emission bounds [pbrt-v4 `DiffuseAreaLight::Bounds`]: the shape's box
    /// and normal cone, Lambertian spread π/2, power π·A·L of one side.
    pub(super) fn bounds(&self) -> LightBounds {
        let sides = if self.two_sided { 2.0 } else { 1.0 };
        let phi = scalar(|l| self.phi(l)) / sides;
        LightBounds::new(
            self.shape.bounds(),
            self.shape.normal_bounds(),
            phi,
            0.0,
            self.two_sided,
        )
    }
}
