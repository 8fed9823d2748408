//! Textures: float and spectrum values that vary over surfaces.
//!
//! The set and semantics follow pbrt-v4 (`textures.h`, `textures.cpp`,
//! `util/noise.cpp`; book §10.2–10.6): `constant`, `scale`, `mix`,
//! `directionmix`, `checkerboard` (2D and 3D), `bilerp`, `dots`, `fbm`,
//! `wrinkled`, `windy` (float only), `marble` (spectrum only) and `imagemap`
//! ([`ImageTexture`], PNG and EXR files).
//!
//! A texture is evaluated at a [`TextureEvalContext`] taken from the hit:
//! position, normal, (u, v) and their screen-space derivatives. A mapping
//! ([`TextureMapping2D`], [`TextureMapping3D`]) turns the context into
//! texture coordinates; procedural patterns are functions of those.
//! The derivatives come from the camera's pixel footprint at every hit
//! ([`crate::camera::PixelFootprint`], pbrt-v4's `Approximate_dp_dxy`); they
//! size the checkerboard's box filter, fbm's octave count and the image
//! textures' MIP level. Without a footprint (hand-built scenes, the alpha
//! test during traversal) they are zero.
//!
//! Both texture kinds are closed enums. Leaves (constants) are stored
//! inline; composite nodes hold their children behind an `Arc` built once
//! at scene load, so evaluation never allocates. Spectrum textures carry
//! spectra already lifted from RGB with the meaning their use requires
//! (reflectance or unbounded, pbrt-v4's `SpectrumType`); the scene builder
//! builds a texture once per meaning it is used with.

mod image;
mod mapping;
mod marble;
mod nodes;
mod noise;
mod perm;
#[cfg(test)]
mod tests;

pub use image::{ImageFilter, ImageTexture, SpectrumImageTexture};
pub use mapping::{TexCoord2D, TexCoord3D, TextureMapping2D, TextureMapping3D};
pub use marble::{marble_rgb, marble_spectrum, Marble};
pub use nodes::{
    checkerboard_weight, inside_polka_dot, Bilerp, CheckerMap, Checkerboard, DirectionMix, Dots,
    Mix, NoiseSum, Scale, TexValue,
};
pub use noise::{fbm, noise, noise_at, octave_count, turbulence};

use crate::interaction::SurfaceInteraction;
use crate::math::{Vec2, Vec3};
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};
use std::sync::Arc;

/// What a texture sees of a hit [pbrt-v4 `TextureEvalContext`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TextureEvalContext {
    /// Position (render space).
    pub p: Vec3,
    /// ∂p/∂x on the image plane (zero where no footprint is known).
    pub dpdx: Vec3,
    /// ∂p/∂y on the image plane.
    pub dpdy: Vec3,
    /// Geometric normal (pbrt-v4 takes `si.n`, not the shading normal).
    pub n: Vec3,
    /// Surface (u, v).
    pub uv: Vec2,
    /// ∂u/∂x.
    pub dudx: f32,
    /// ∂u/∂y.
    pub dudy: f32,
    /// ∂v/∂x.
    pub dvdx: f32,
    /// ∂v/∂y.
    pub dvdy: f32,
    /// Face index within the mesh.
    pub face_index: i32,
}

impl TextureEvalContext {
    /// The context of a surface hit.
    pub fn from_si(si: &SurfaceInteraction) -> Self {
        let d = &si.diff;
        Self {
            p: si.p(),
            dpdx: d.dpdx,
            dpdy: d.dpdy,
            n: si.n(),
            uv: si.it.uv,
            dudx: d.dudx,
            dudy: d.dudy,
            dvdx: d.dvdx,
            dvdy: d.dvdy,
            face_index: si.face_index,
        }
    }
}

/// A scalar texture.
#[derive(Clone, Debug)]
pub enum FloatTexture {
    /// The same value everywhere.
    Constant(f32),
    /// `scale`.
    Scale(Arc<Scale<FloatTexture>>),
    /// `mix`.
    Mix(Arc<Mix<FloatTexture>>),
    /// `directionmix`.
    DirectionMix(Arc<DirectionMix<FloatTexture>>),
    /// `checkerboard`.
    Checkerboard(Arc<Checkerboard<FloatTexture>>),
    /// `bilerp`.
    Bilerp(Arc<Bilerp<f32>>),
    /// `dots`.
    Dots(Arc<Dots<FloatTexture>>),
    /// `fbm`.
    Fbm(Arc<NoiseSum>),
    /// `wrinkled` (turbulence).
    Wrinkled(Arc<NoiseSum>),
    /// `windy`.
    Windy(Arc<TextureMapping3D>),
    /// `imagemap`.
    Image(Arc<ImageTexture>),
}

impl FloatTexture {
    /// Value at a hit.
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> f32 {
        let f = |t: &FloatTexture| t.evaluate(ctx);
        match self {
            FloatTexture::Constant(v) => *v,
            FloatTexture::Scale(n) => n.eval(ctx, f),
            FloatTexture::Mix(n) => n.eval(ctx, f),
            FloatTexture::DirectionMix(n) => n.eval(ctx, f),
            FloatTexture::Checkerboard(n) => n.eval(ctx, f),
            FloatTexture::Bilerp(n) => n.eval(ctx, |v| *v),
            FloatTexture::Dots(n) => n.eval(ctx, f),
            FloatTexture::Fbm(n) => n.fbm(ctx),
            FloatTexture::Wrinkled(n) => n.turbulence(ctx),
            FloatTexture::Windy(m) => nodes::windy(m, ctx),
            FloatTexture::Image(t) => t.evaluate_float(ctx),
        }
    }

    /// The value if the texture is a constant.
    pub fn as_constant(&self) -> Option<f32> {
        match self {
            FloatTexture::Constant(v) => Some(*v),
            _ => None,
        }
    }
}

/// A spectral texture.
#[derive(Clone, Debug)]
pub enum SpectrumTexture {
    /// The same spectrum everywhere.
    Constant(Spectrum),
    /// `scale` (by a float texture).
    Scale(Arc<Scale<SpectrumTexture>>),
    /// `mix` (by a float texture).
    Mix(Arc<Mix<SpectrumTexture>>),
    /// `directionmix`.
    DirectionMix(Arc<DirectionMix<SpectrumTexture>>),
    /// `checkerboard`.
    Checkerboard(Arc<Checkerboard<SpectrumTexture>>),
    /// `bilerp` of four spectra.
    Bilerp(Arc<Bilerp<Spectrum>>),
    /// `dots`.
    Dots(Arc<Dots<SpectrumTexture>>),
    /// `marble`.
    Marble(Arc<Marble>),
    /// `imagemap`.
    Image(Arc<SpectrumImageTexture>),
}

impl SpectrumTexture {
    /// Value at a hit for the path's wavelengths.
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let f = |t: &SpectrumTexture| t.evaluate(ctx, lambda);
        match self {
            SpectrumTexture::Constant(s) => s.sample(lambda),
            SpectrumTexture::Scale(n) => n.eval(ctx, f),
            SpectrumTexture::Mix(n) => n.eval(ctx, f),
            SpectrumTexture::DirectionMix(n) => n.eval(ctx, f),
            SpectrumTexture::Checkerboard(n) => n.eval(ctx, f),
            SpectrumTexture::Bilerp(n) => n.eval(ctx, |s| s.sample(lambda)),
            SpectrumTexture::Dots(n) => n.eval(ctx, f),
            SpectrumTexture::Marble(n) => n.eval(ctx, lambda),
            SpectrumTexture::Image(t) => t.evaluate(ctx, lambda),
        }
    }
}
