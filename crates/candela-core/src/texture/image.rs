//! `imagemap`: textures looked up in an image [pbrt-v4 `FloatImageTexture`,
//! `SpectrumImageTexture`, `MIPMap::Filter`; book §10.4].
//!
//! The 2D mapping gives (s, t); t is flipped (t′ = 1 − t) because texture
//! space has its origin at the lower left and images at the upper left. The
//! image is read at level 0 of pbrt-v4's pyramid (the file resized to
//! power-of-two sides, `image::resize_to_power_of_two`). With the zero
//! footprint candela has (no ray differentials), pbrt-v4's `bilinear`,
//! `trilinear` and `ewa` filters all reduce to bilinear interpolation at
//! level 0, and `point` to the texel whose centre is nearest. Then the value
//! is scaled, optionally inverted (1 − v), and clamped at 0.
//!
//! A float texture reads the first channel. A spectrum texture lifts the
//! RGB (a grey image's value repeated) in the image's colour space with the
//! meaning its use requires (albedo: clamped to [0, 1]; unbounded;
//! illuminant), through the colour space's precomputed table
//! ([`ColorSpace::sample_rgb`]), once per lookup as pbrt-v4 does.

use super::{TextureEvalContext, TextureMapping2D};
use crate::image::{MapImage, WrapMode};
use crate::math::Vec2;
use crate::spectrum::{ColorSpace, Rgb, SampledSpectrum, SampledWavelengths, SpectrumKind};
use std::sync::Arc;

/// How texels are combined at a lookup.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFilter {
    /// The texel whose centre is nearest.
    Point,
    /// Bilinear interpolation of the four nearest texel centres.
    Bilinear,
}

/// An image texture's lookup: mapping, image, filter and value transform.
#[derive(Clone, Debug)]
pub struct ImageTexture {
    /// The (s, t) mapping.
    pub map: TextureMapping2D,
    /// Level 0 of the pyramid (power-of-two sides).
    pub image: Arc<MapImage>,
    /// Addressing outside [0, 1]².
    pub wrap: WrapMode,
    /// Texel filter.
    pub filter: ImageFilter,
    /// Factor on looked-up values.
    pub scale: f32,
    /// Whether values become 1 − value.
    pub invert: bool,
    /// Colour space of the image's RGB.
    pub color_space: &'static ColorSpace,
}

impl ImageTexture {
    /// Image coordinates of a hit (t flipped).
    fn st(&self, ctx: &TextureEvalContext) -> Vec2 {
        let st = self.map.map(ctx).st;
        Vec2::new(st.x, 1.0 - st.y)
    }

    /// Filtered RGB (grey replicated) before scaling.
    fn lookup_rgb(&self, st: Vec2) -> [f32; 3] {
        match self.filter {
            ImageFilter::Bilinear => self.image.bilerp_rgb(st, self.wrap),
            ImageFilter::Point => {
                let (x, y) = self.image.point_texel(st);
                self.image.texel_rgb(x, y, self.wrap)
            }
        }
    }

    /// Float value at a hit: first channel, scaled, inverted as 1 − v clamped at 0.
    pub fn evaluate_float(&self, ctx: &TextureEvalContext) -> f32 {
        let st = self.st(ctx);
        let raw = match self.filter {
            ImageFilter::Bilinear => self.image.bilerp(st, 0, self.wrap),
            ImageFilter::Point => {
                let (x, y) = self.image.point_texel(st);
                self.image.texel(x, y, 0, self.wrap)
            }
        };
        let v = self.scale * raw;
        if self.invert {
            (1.0 - v).max(0.0)
        } else {
            v
        }
    }

    /// RGB at a hit: scaled, optionally inverted, clamped at 0.
    pub fn evaluate_rgb(&self, ctx: &TextureEvalContext) -> Rgb {
        let rgb = self.lookup_rgb(self.st(ctx)).map(|c| {
            let v = self.scale * c;
            let v = if self.invert { 1.0 - v } else { v };
            v.max(0.0)
        });
        Rgb::new(rgb[0], rgb[1], rgb[2])
    }
}

/// A spectrum image texture: the lookup and the meaning of its RGB.
#[derive(Clone, Debug)]
pub struct SpectrumImageTexture {
    /// The lookup.
    pub tex: ImageTexture,
    /// How RGB becomes a spectrum.
    pub kind: SpectrumKind,
}

impl SpectrumImageTexture {
    /// Spectrum at a hit for the path's wavelengths.
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let rgb = self.tex.evaluate_rgb(ctx);
        self.tex.color_space.sample_rgb(rgb, self.kind, lambda)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::PixelFormat;

    /// 2×2 grey image: top row 0, 1; bottom row 2, 3.
    fn tex(filter: ImageFilter, wrap: WrapMode) -> ImageTexture {
        ImageTexture {
            map: TextureMapping2D::UV,
            image: Arc::new(MapImage::new(
                2,
                2,
                1,
                vec![0.0, 1.0, 2.0, 3.0],
                PixelFormat::Float,
            )),
            wrap,
            filter,
            scale: 1.0,
            invert: false,
            color_space: ColorSpace::srgb(),
        }
    }

    fn at(u: f32, v: f32) -> TextureEvalContext {
        TextureEvalContext {
            uv: Vec2::new(u, v),
            ..Default::default()
        }
    }

    #[test]
    fn v_is_flipped_and_filters_address_texels() {
        let p = tex(ImageFilter::Point, WrapMode::Clamp);
        // v near 1 is the image's top row.
        assert_eq!(p.evaluate_float(&at(0.1, 0.9)), 0.0);
        assert_eq!(p.evaluate_float(&at(0.9, 0.1)), 3.0);
        let b = tex(ImageFilter::Bilinear, WrapMode::Clamp);
        // The image centre averages all four texels.
        assert!((b.evaluate_float(&at(0.5, 0.5)) - 1.5).abs() < 1e-6);
        // Repeat wraps u = 1.25 to 0.25 (texel centre of column 0).
        let r = tex(ImageFilter::Bilinear, WrapMode::Repeat);
        assert!((r.evaluate_float(&at(1.25, 0.75)) - 0.0).abs() < 1e-6);
        let mut inv = tex(ImageFilter::Point, WrapMode::Clamp);
        (inv.scale, inv.invert) = (0.5, true);
        // 1 − 0.5·3 clamps at 0; 1 − 0.5·1 = 0.5.
        assert_eq!(inv.evaluate_float(&at(0.9, 0.1)), 0.0);
        assert_eq!(inv.evaluate_float(&at(0.9, 0.9)), 0.5);
        let rgb = inv.evaluate_rgb(&at(0.9, 0.9));
        assert_eq!((rgb.r, rgb.g, rgb.b), (0.5, 0.5, 0.5));
    }
}
