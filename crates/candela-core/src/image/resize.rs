//! Resampling a texture to power-of-two resolution, as pbrt-v4 does before
//! building a MIP pyramid (`Image::GeneratePyramid`, `FloatResizeUp`,
//! `resampleWeights`; book §10.4.3).
//!
//! pbrt-v4 image textures always read level 0 of a pyramid whose base has
//! power-of-two sides, so a texture of another size is first magnified:
//! separably, each output texel centre (i + ½)·old/new is reconstructed
//! from the 4 nearest input texels weighted by a Lanczos windowed sinc
//! (radius 2, τ = 2) normalised to sum 1, reading beyond the edges through
//! the texture's wrap mode; negative results (ringing) are clamped to 0.
//! The result is stored back in the source's pixel format (8-bit values
//! re-encoded, halves rounded), so candela quantises the same way to read
//! the same texels. Ray differentials would select coarser levels; candela
//! has none, so only level 0 is built.

use super::map::{MapImage, PixelFormat, WrapMode};
use exr::prelude::f16;

/// sin(πx)/(πx).
fn sinc(x: f32) -> f32 {
    if x.abs() < 1e-5 {
        return 1.0;
    }
    let px = std::f32::consts::PI * x;
    px.sin() / px
}

/// Lanczos window of radius `r` and period τ: sinc(x)·sinc(x/τ) [pbrt-v4 `WindowedSinc`].
fn windowed_sinc(x: f32, r: f32, tau: f32) -> f32 {
    if x.abs() > r {
        return 0.0;
    }
    sinc(x) * sinc(x / tau)
}

/// First input texel and the 4 normalised weights of every output texel.
fn resample_weights(old: usize, new: usize) -> Vec<(i64, [f32; 4])> {
    const WIDTH: f32 = 2.0;
    (0..new)
        .map(|i| {
            let center = (i as f32 + 0.5) * old as f32 / new as f32;
            let first = ((center - WIDTH) + 0.5).floor();
            let mut w = [0.0f32; 4];
            for (j, wj) in w.iter_mut().enumerate() {
                let pos = first + j as f32 + 0.5;
                *wj = windowed_sinc(pos - center, WIDTH, 2.0);
            }
            let inv = 1.0 / w.iter().sum::<f32>();
            (first as i64, w.map(|v| v * inv))
        })
        .collect()
}

/// The image at the next power of two in each dimension (itself if both
/// already are), quantised like its source format.
pub fn resize_to_power_of_two(im: &MapImage, wrap: WrapMode) -> MapImage {
    let (nw, nh) = (im.width.next_power_of_two(), im.height.next_power_of_two());
    if (nw, nh) == (im.width, im.height) {
        return im.clone();
    }
    let nc = im.channels;
    let (xw, yw) = (
        resample_weights(im.width, nw),
        resample_weights(im.height, nh),
    );
    let mut out = vec![0.0f32; nw * nh * nc];
    for (y, (fy, wy)) in yw.iter().enumerate() {
        for (x, (fx, wx)) in xw.iter().enumerate() {
            for c in 0..nc {
                // x first, then y, each tap wrapped in 2D as pbrt-v4 copies
                // the source rectangle (octahedral folds couple the axes).
                let v: f32 = (0..4)
                    .map(|j| {
                        let row: f32 = (0..4)
                            .map(|i| wx[i] * im.texel(fx + i as i64, fy + j as i64, c, wrap))
                            .sum();
                        wy[j] * row
                    })
                    .sum();
                out[(y * nw + x) * nc + c] = quantise(v.max(0.0), im.format);
            }
        }
    }
    MapImage::new(nw, nh, nc, out, im.format)
}

/// `v` after a round trip through the storage format.
pub(super) fn quantise(v: f32, format: PixelFormat) -> f32 {
    match format {
        PixelFormat::U8(enc) => enc.to_linear(enc.to_u8(v) as f32 / 255.0),
        PixelFormat::Half => f16::from_f32(v).to_f32(),
        PixelFormat::Float => v,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_are_normalised_and_symmetric() {
        for (old, new) in [(3, 4), (5, 8), (100, 128)] {
            for (_, w) in resample_weights(old, new) {
                assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-6);
            }
        }
        // Upsampling 1 → 2: the two outputs mirror each other.
        let w = resample_weights(1, 2);
        assert!((w[0].1[1] - w[1].1[2]).abs() < 1e-6, "{w:?}");
    }

    #[test]
    fn constant_images_stay_constant_and_sizes_round_up() {
        let im = MapImage::new(3, 5, 3, vec![0.25; 45], PixelFormat::Float);
        let r = resize_to_power_of_two(&im, WrapMode::Clamp);
        assert_eq!((r.width, r.height), (4, 8));
        assert!(r.data.iter().all(|&v| (v - 0.25).abs() < 1e-6));
        let p = MapImage::new(4, 2, 1, vec![1.0; 8], PixelFormat::Float);
        assert_eq!(resize_to_power_of_two(&p, WrapMode::Repeat), p);
    }
}
