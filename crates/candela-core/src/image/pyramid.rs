//! MIP pyramids of texture images and their filtered lookups [pbrt-v4
//! `Image::GeneratePyramid`, `MIPMap::Filter`, `MIPMap::EWA`; book §10.4.3].
//!
//! Level 0 is the texture resized to power-of-two sides
//! ([`super::resize_to_power_of_two`]); level k + 1 halves each side of
//! level k (down to 1) and each of its texels is the mean of the 2×2 texels
//! below it, a side of 1 texel reusing its texel. The means are taken in
//! `f32` from the unrounded level below, and every level is stored back in
//! the source's pixel format, as pbrt-v4 does. A pyramid may hold level 0
//! only: the `point` and `bilinear` filters read nothing else in candela.
//!
//! **Trilinear.** The filter width is w = 2·max(|∂s/∂x|, |∂s/∂y|, |∂t/∂x|,
//! |∂t/∂y|) and the level ℓ = L − 1 + log₂ w for L levels (a width of one
//! texel of level ℓ). At or beyond the top the single top texel is the
//! value; below level 1 it is level 0 bilinearly (pbrt-v4 does not blend
//! levels 0 and 1); otherwise the bilinear lookups at ⌊ℓ⌋ and ⌊ℓ⌋ + 1 are
//! blended by the fraction of ℓ.
//!
//! **EWA** (elliptically weighted average, [Heckbert 1989]; pbrt-v4's
//! variant). The two screen-space derivative vectors (∂s/∂x, ∂t/∂x) and
//! (∂s/∂y, ∂t/∂y) are the ellipse's axes; the shorter is lengthened so that
//! the ratio is at most `maxanisotropy`. The level follows the shorter axis,
//! ℓ = max(0, L − 1 + log₂|minor|), and two levels are blended. At a level,
//! the implicit ellipse A s² + B s t + C t² < F (with one texel added to both
//! axes so that it always covers a texel) is scanned over its bounding box;
//! each texel inside is weighted by a Gaussian of its scaled squared radius
//! r², e^(−2 r²) − e^(−2), quantised to pbrt-v4's 128 table entries.

use super::map::{MapImage, WrapMode};
use super::resize::quantise;
use crate::math::Vec2;

/// Number of entries in pbrt-v4's EWA weight table (`MIPFilterLUTSize`).
const EWA_LUT_SIZE: usize = 128;

/// The levels of a texture image, finest first.
#[derive(Clone, Debug, PartialEq)]
pub struct MipPyramid {
    levels: Vec<MapImage>,
}

impl MipPyramid {
    /// All levels above `base` (power-of-two sides) by 2×2 box averages.
    pub fn build(base: MapImage) -> Self {
        let mut levels = Vec::new();
        let mut cur = base.data.clone();
        let (mut w, mut h, nc) = (base.width, base.height, base.channels);
        let format = base.format;
        levels.push(base);
        while w > 1 || h > 1 {
            let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
            let mut next = vec![0.0f32; nw * nh * nc];
            for y in 0..nh {
                for x in 0..nw {
                    // A side of one texel uses its texel twice.
                    let (x1, y1) = ((2 * x + 1).min(w - 1), (2 * y + 1).min(h - 1));
                    for c in 0..nc {
                        let at = |xx: usize, yy: usize| cur[(yy * w + xx) * nc + c];
                        next[(y * nw + x) * nc + c] =
                            (at(2 * x, 2 * y) + at(x1, 2 * y) + at(2 * x, y1) + at(x1, y1)) / 4.0;
                    }
                }
            }
            let stored = next.iter().map(|&v| quantise(v, format)).collect();
            levels.push(MapImage::new(nw, nh, nc, stored, format));
            (cur, w, h) = (next, nw, nh);
        }
        Self { levels }
    }

    /// Level 0.
    pub fn base(&self) -> &MapImage {
        &self.levels[0]
    }

    /// All levels, finest first.
    pub fn levels(&self) -> &[MapImage] {
        &self.levels
    }

    /// Trilinear lookup at `st` with screen-space derivative vectors
    /// `dst0` = (∂s/∂x, ∂t/∂x) and `dst1` = (∂s/∂y, ∂t/∂y).
    pub fn trilinear(&self, st: Vec2, dst0: Vec2, dst1: Vec2, wrap: WrapMode) -> [f32; 3] {
        let level = self.footprint_level(dst0, dst1);
        let Some(i) = self.finite_level(level) else {
            return self.top_texel(wrap);
        };
        if i == 0 {
            return self.levels[0].bilerp_rgb(st, wrap);
        }
        let (a, b) = (
            self.levels[i].bilerp_rgb(st, wrap),
            self.levels[i + 1].bilerp_rgb(st, wrap),
        );
        lerp3(level - i as f32, a, b)
    }

    /// pbrt-v4's continuous level ℓ = L − 1 + log₂ w of a footprint of width
    /// w = 2·max(|∂s/∂x|, |∂t/∂x|, |∂s/∂y|, |∂t/∂y|).
    pub fn footprint_level(&self, dst0: Vec2, dst1: Vec2) -> f32 {
        let width = 2.0 * dst0.abs().max_element().max(dst1.abs().max_element());
        (self.levels.len() - 1) as f32 + width.max(1e-8).log2()
    }

    /// ⌊ℓ⌋ clamped at 0, or `None` when the footprint covers the whole
    /// texture (ℓ ≥ L − 1: pbrt-v4 then returns the single top texel).
    pub fn finite_level(&self, level: f32) -> Option<usize> {
        (level < (self.levels.len() - 1) as f32).then(|| level.floor().max(0.0) as usize)
    }

    /// The one texel of the coarsest level.
    pub fn top_texel(&self, wrap: WrapMode) -> [f32; 3] {
        self.levels[self.levels.len() - 1].texel_rgb(0, 0, wrap)
    }

    /// pbrt-v4's `point` and `bilinear` filters: one lookup at level ⌊ℓ⌋
    /// (level 0 whenever the texture is magnified), or the top texel.
    pub fn single_level(
        &self,
        st: Vec2,
        dst0: Vec2,
        dst1: Vec2,
        wrap: WrapMode,
        point: bool,
    ) -> [f32; 3] {
        let Some(i) = self.finite_level(self.footprint_level(dst0, dst1)) else {
            return self.top_texel(wrap);
        };
        let image = &self.levels[i];
        if point {
            let (x, y) = image.point_texel(st);
            image.texel_rgb(x, y, wrap)
        } else {
            image.bilerp_rgb(st, wrap)
        }
    }

    /// EWA lookup (see the module docs); `max_anisotropy` bounds the
    /// ellipse's axis ratio.
    pub fn ewa(
        &self,
        st: Vec2,
        dst0: Vec2,
        dst1: Vec2,
        max_anisotropy: f32,
        wrap: WrapMode,
    ) -> [f32; 3] {
        let (mut major, mut minor) = (dst0, dst1);
        if major.length_squared() < minor.length_squared() {
            std::mem::swap(&mut major, &mut minor);
        }
        let (major_len, mut minor_len) = (major.length(), minor.length());
        if minor_len * max_anisotropy < major_len && minor_len > 0.0 {
            let scale = major_len / (minor_len * max_anisotropy);
            minor *= scale;
            minor_len *= scale;
        }
        if minor_len == 0.0 {
            return self.levels[0].bilerp_rgb(st, wrap);
        }
        let lod = ((self.levels.len() - 1) as f32 + minor_len.log2()).max(0.0);
        let i = lod.floor() as usize;
        let a = self.ewa_level(i, st, major, minor, wrap);
        let b = self.ewa_level(i + 1, st, major, minor, wrap);
        lerp3(lod - i as f32, a, b)
    }

    /// The elliptical weighted average over one level.
    fn ewa_level(&self, level: usize, st: Vec2, d0: Vec2, d1: Vec2, wrap: WrapMode) -> [f32; 3] {
        let Some(im) = self.levels.get(level) else {
            let top = &self.levels[self.levels.len() - 1];
            return top.texel_rgb(0, 0, wrap);
        };
        let res = Vec2::new(im.width as f32, im.height as f32);
        let c = st * res - Vec2::splat(0.5);
        let (d0, d1) = (d0 * res, d1 * res);
        // Implicit ellipse through the axes, widened by a texel, scaled to F = 1.
        let mut a = d0.y * d0.y + d1.y * d1.y + 1.0;
        let mut b = -2.0 * (d0.x * d0.y + d1.x * d1.y);
        let mut cc = d0.x * d0.x + d1.x * d1.x + 1.0;
        let inv_f = 1.0 / (a * cc - b * b * 0.25);
        (a, b, cc) = (a * inv_f, b * inv_f, cc * inv_f);
        // Bounding box of the ellipse.
        let det = 4.0 * a * cc - b * b;
        let inv_det = 1.0 / det;
        let (u_sqrt, v_sqrt) = ((det * cc).max(0.0).sqrt(), (a * det).max(0.0).sqrt());
        let s0 = (c.x - 2.0 * inv_det * u_sqrt).ceil() as i64;
        let s1 = (c.x + 2.0 * inv_det * u_sqrt).floor() as i64;
        let t0 = (c.y - 2.0 * inv_det * v_sqrt).ceil() as i64;
        let t1 = (c.y + 2.0 * inv_det * v_sqrt).floor() as i64;
        let mut sum = [0.0f32; 3];
        let mut sum_w = 0.0f32;
        for it in t0..=t1 {
            let tt = it as f32 - c.y;
            for is in s0..=s1 {
                let ss = is as f32 - c.x;
                let r2 = a * ss * ss + b * ss * tt + cc * tt * tt;
                if r2 < 1.0 {
                    let w = ewa_weight(r2);
                    let texel = im.texel_rgb(is, it, wrap);
                    for k in 0..3 {
                        sum[k] += w * texel[k];
                    }
                    sum_w += w;
                }
            }
        }
        if sum_w > 0.0 {
            sum.map(|v| v / sum_w)
        } else {
            im.bilerp_rgb(st, wrap)
        }
    }
}

/// pbrt-v4's EWA weight: the Gaussian e^(−2r²) − e^(−2) at r² quantised to
/// its table's 128 entries (entry i holds r² = i/127).
fn ewa_weight(r2: f32) -> f32 {
    let i = ((r2 * EWA_LUT_SIZE as f32) as usize).min(EWA_LUT_SIZE - 1);
    let r2q = i as f32 / (EWA_LUT_SIZE - 1) as f32;
    (-2.0 * r2q).exp() - (-2.0f32).exp()
}

/// (1 − t)·a + t·b per channel.
fn lerp3(t: f32, a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    std::array::from_fn(|k| (1.0 - t) * a[k] + t * b[k])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::image::PixelFormat;

    /// A w×h single-channel image of fixed pseudo-random values in [0, 1).
    fn noise(w: usize, h: usize) -> MapImage {
        let mut x = 12345u32;
        let data = (0..w * h)
            .map(|_| {
                x = x.wrapping_mul(1664525).wrapping_add(1013904223);
                (x >> 8) as f32 / (1u32 << 24) as f32
            })
            .collect();
        MapImage::new(w, h, 1, data, PixelFormat::Float)
    }

    #[test]
    fn each_level_box_averages_the_one_below_and_keeps_the_mean() {
        let p = MipPyramid::build(noise(16, 4));
        let sizes: Vec<_> = p.levels().iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, [(16, 4), (8, 2), (4, 1), (2, 1), (1, 1)]);
        for k in 1..p.levels().len() {
            let (lo, hi) = (&p.levels()[k - 1], &p.levels()[k]);
            for y in 0..hi.height {
                for x in 0..hi.width {
                    let (x1, y1) = (
                        (2 * x + 1).min(lo.width - 1),
                        (2 * y + 1).min(lo.height - 1),
                    );
                    let t = |xx, yy| lo.data[yy * lo.width + xx];
                    let want = (t(2 * x, 2 * y) + t(x1, 2 * y) + t(2 * x, y1) + t(x1, y1)) / 4.0;
                    let got = hi.data[y * hi.width + x];
                    assert!(
                        (got - want).abs() < 1e-6,
                        "level {k} ({x},{y}): {got} vs {want}"
                    );
                }
            }
        }
        // Box averages over power-of-two sides preserve the mean (f32 sums of 64 values).
        let mean = p.base().data.iter().sum::<f32>() / 64.0;
        assert!((p.levels()[4].data[0] - mean).abs() < 1e-5);
        let c = MipPyramid::build(MapImage::new(4, 4, 3, vec![0.3; 48], PixelFormat::Float));
        assert!(c.levels().iter().flat_map(|l| &l.data).all(|&v| v == 0.3));
    }

    #[test]
    fn trilinear_picks_levels_by_footprint_and_ewa_is_a_normalised_average() {
        let p = MipPyramid::build(noise(64, 64));
        let wrap = WrapMode::Repeat;
        let st = Vec2::new(0.3, 0.7);
        let base = p.base().bilerp_rgb(st, wrap);
        // Magnified (a texel spans many pixels): level 0, as bilinear.
        let tiny = Vec2::new(1e-4, 0.0);
        assert_eq!(p.trilinear(st, tiny, tiny.perp(), wrap), base);
        // Footprint wider than the texture: the top texel, the image mean.
        let top = p.levels()[6].data[0];
        assert_eq!(p.trilinear(st, Vec2::X, Vec2::Y, wrap), [top; 3]);
        // Width 2·(1/16) = 1/8 of the texture: level ℓ = 6 − 3 = 3 exactly.
        let d = Vec2::new(1.0 / 16.0, 0.0);
        assert_eq!(
            p.trilinear(st, d, d.perp(), wrap),
            p.levels()[3].bilerp_rgb(st, wrap)
        );
        // ℓ = 3.5: halfway between levels 3 and 4.
        let d = d * 2f32.sqrt();
        let mid = p.trilinear(st, d, d.perp(), wrap)[0];
        let (l3, l4) = (
            p.levels()[3].bilerp(st, 0, wrap),
            p.levels()[4].bilerp(st, 0, wrap),
        );
        assert!((mid - 0.5 * (l3 + l4)).abs() < 1e-5, "{mid} vs {l3}, {l4}");
        // EWA: zero footprint is bilinear; a wide one stays within the texel
        // range and tends to the mean.
        assert_eq!(p.ewa(st, Vec2::ZERO, Vec2::ZERO, 8.0, wrap), base);
        let e = p.ewa(st, Vec2::new(0.3, 0.1), Vec2::new(-0.05, 0.2), 8.0, wrap)[0];
        assert!(e.is_finite() && (e - top).abs() < 0.05, "{e} vs mean {top}");
    }
}
