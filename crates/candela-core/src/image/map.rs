//! Images used as maps: texture images and environment maps, with pbrt-v4's
//! texel addressing (`util/image.h`: `RemapPixelCoords`, `GetChannel`,
//! `BilerpChannel`, `LookupNearestChannel`).
//!
//! Texel (x, y) covers [x, x+1)×[y, y+1) in pixel units, row 0 at the top;
//! lookups take (s, t) ∈ [0, 1]² scaled by the resolution. Bilinear lookups
//! place texel centres at half-integers (x = s·w − ½); nearest lookups
//! truncate s·w towards zero as pbrt-v4 does. Out-of-range texels are found by
//! the [`WrapMode`]. Values are stored decoded to linear `f32`; the pixel
//! format they came from ([`PixelFormat`]) is kept because pbrt-v4 stores
//! resampled images back in it (`image::resize`).

use super::read::ColorEncoding;
use crate::math::Vec2;

/// How texel coordinates outside the image are mapped [pbrt-v4 `WrapMode`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum WrapMode {
    /// Tile the image.
    Repeat,
    /// Zero outside.
    Black,
    /// Extend the edge texels.
    Clamp,
    /// Fold across the edges of an equal-area octahedral image, so that
    /// neighbours across the seam are neighbours on the sphere.
    OctahedralSphere,
}

impl WrapMode {
    /// pbrt-v4's spelling (`"repeat"`, `"black"`, `"clamp"`, `"octahedralsphere"`).
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "repeat" => WrapMode::Repeat,
            "black" => WrapMode::Black,
            "clamp" => WrapMode::Clamp,
            "octahedralsphere" => WrapMode::OctahedralSphere,
            _ => return None,
        })
    }
}

/// The storage a map's values came from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PixelFormat {
    /// 8-bit values under a colour encoding.
    U8(ColorEncoding),
    /// 16-bit floats (EXR half, or 16-bit PNG after decoding).
    Half,
    /// 32-bit floats.
    Float,
}

/// A linear float image with one or three channels, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct MapImage {
    /// Width in texels.
    pub width: usize,
    /// Height in texels.
    pub height: usize,
    /// Channels per texel: 1 (grey) or 3 (RGB).
    pub channels: usize,
    /// `width·height·channels` linear values, interleaved.
    pub data: Vec<f32>,
    /// The format the values were stored in.
    pub format: PixelFormat,
}

impl MapImage {
    /// An image of `channels` channels from interleaved linear values.
    pub fn new(
        width: usize,
        height: usize,
        channels: usize,
        data: Vec<f32>,
        format: PixelFormat,
    ) -> Self {
        assert_eq!(data.len(), width * height * channels, "texel count");
        assert!(channels == 1 || channels == 3, "{channels} channels");
        Self {
            width,
            height,
            channels,
            data,
            format,
        }
    }

    /// Maps texel coordinates by `wrap`; `None` for black outside.
    pub fn remap(&self, x: i64, y: i64, wrap: WrapMode) -> Option<(usize, usize)> {
        let (w, h) = (self.width as i64, self.height as i64);
        let (mut x, mut y) = (x, y);
        match wrap {
            WrapMode::OctahedralSphere => {
                // Mirror across the outer edges and the square's middle lines.
                if x < 0 {
                    x = -x;
                    y = h - 1 - y;
                } else if x >= w {
                    x = 2 * w - 1 - x;
                    y = h - 1 - y;
                }
                if y < 0 {
                    x = w - 1 - x;
                    y = -y;
                } else if y >= h {
                    x = w - 1 - x;
                    y = 2 * h - 1 - y;
                }
                // pbrt-v4 pins 1-texel axes; clamping also keeps far-out
                // coordinates (beyond one fold) inside.
                Some((x.clamp(0, w - 1) as usize, y.clamp(0, h - 1) as usize))
            }
            WrapMode::Repeat => Some((x.rem_euclid(w) as usize, y.rem_euclid(h) as usize)),
            WrapMode::Clamp => Some((x.clamp(0, w - 1) as usize, y.clamp(0, h - 1) as usize)),
            WrapMode::Black => {
                ((0..w).contains(&x) && (0..h).contains(&y)).then_some((x as usize, y as usize))
            }
        }
    }

    /// Channel `c` of texel (x, y) after wrapping [pbrt-v4 `GetChannel`].
    #[inline]
    pub fn texel(&self, x: i64, y: i64, c: usize, wrap: WrapMode) -> f32 {
        match self.remap(x, y, wrap) {
            Some((x, y)) => self.data[(y * self.width + x) * self.channels + c],
            None => 0.0,
        }
    }

    /// Texel (x, y) as RGB (a grey texel repeated) after wrapping.
    pub fn texel_rgb(&self, x: i64, y: i64, wrap: WrapMode) -> [f32; 3] {
        match self.remap(x, y, wrap) {
            Some((x, y)) => {
                let i = (y * self.width + x) * self.channels;
                if self.channels == 3 {
                    [self.data[i], self.data[i + 1], self.data[i + 2]]
                } else {
                    [self.data[i]; 3]
                }
            }
            None => [0.0; 3],
        }
    }

    /// Texel containing `st` (s·w truncated towards zero) [pbrt-v4 `LookupNearestChannel`].
    pub fn nearest_rgb(&self, st: Vec2, wrap: WrapMode) -> [f32; 3] {
        let (x, y) = (
            (st.x * self.width as f32) as i64,
            (st.y * self.height as f32) as i64,
        );
        self.texel_rgb(x, y, wrap)
    }

    /// Texel whose centre is nearest `st` (pbrt-v4's `"point"` texture filter).
    pub fn point_texel(&self, st: Vec2) -> (i64, i64) {
        (
            (st.x * self.width as f32 - 0.5).round() as i64,
            (st.y * self.height as f32 - 0.5).round() as i64,
        )
    }

    /// Bilinear interpolation of the four texels around `st`, with its
    /// weights and texel coordinates [pbrt-v4 `BilerpChannel`].
    pub fn bilerp_taps(&self, st: Vec2) -> [((i64, i64), f32); 4] {
        let x = st.x * self.width as f32 - 0.5;
        let y = st.y * self.height as f32 - 0.5;
        let (xi, yi) = (x.floor(), y.floor());
        let (dx, dy) = (x - xi, y - yi);
        let (xi, yi) = (xi as i64, yi as i64);
        [
            ((xi, yi), (1.0 - dx) * (1.0 - dy)),
            ((xi + 1, yi), dx * (1.0 - dy)),
            ((xi, yi + 1), (1.0 - dx) * dy),
            ((xi + 1, yi + 1), dx * dy),
        ]
    }

    /// Bilinearly filtered channel `c` at `st`.
    pub fn bilerp(&self, st: Vec2, c: usize, wrap: WrapMode) -> f32 {
        self.bilerp_taps(st)
            .iter()
            .map(|&((x, y), w)| w * self.texel(x, y, c, wrap))
            .sum()
    }

    /// Bilinearly filtered RGB at `st`.
    pub fn bilerp_rgb(&self, st: Vec2, wrap: WrapMode) -> [f32; 3] {
        let mut out = [0.0; 3];
        for ((x, y), w) in self.bilerp_taps(st) {
            let t = self.texel_rgb(x, y, wrap);
            for k in 0..3 {
                out[k] += w * t[k];
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(w: usize, h: usize) -> MapImage {
        let data = (0..w * h).map(|i| i as f32).collect();
        MapImage::new(w, h, 1, data, PixelFormat::Float)
    }

    #[test]
    fn wrap_modes_match_pbrt() {
        let im = ramp(4, 4);
        assert_eq!(im.remap(-1, 2, WrapMode::Repeat), Some((3, 2)));
        assert_eq!(im.remap(5, -1, WrapMode::Clamp), Some((3, 0)));
        assert_eq!(im.remap(4, 0, WrapMode::Black), None);
        // Octahedral: x = −1 mirrors to x = 1 and flips y; y = 4 mirrors to 3 and flips x.
        assert_eq!(im.remap(-1, 0, WrapMode::OctahedralSphere), Some((1, 3)));
        assert_eq!(im.remap(1, 4, WrapMode::OctahedralSphere), Some((2, 3)));
        assert_eq!(im.remap(-1, -1, WrapMode::OctahedralSphere), Some((2, 3)));
    }

    #[test]
    fn bilerp_hits_texel_centres_and_interpolates() {
        let im = ramp(4, 2);
        // Centre of texel (1, 0) is s = 1.5/4, t = 0.5/2.
        assert_eq!(
            im.bilerp(Vec2::new(1.5 / 4.0, 0.25), 0, WrapMode::Clamp),
            1.0
        );
        // Halfway between texels 1 and 2 of row 0.
        assert_eq!(im.bilerp(Vec2::new(0.5, 0.25), 0, WrapMode::Clamp), 1.5);
        // Nearest truncates: s = 0.99 → texel 3; t = 0.6 → row 1.
        assert_eq!(
            im.nearest_rgb(Vec2::new(0.99, 0.6), WrapMode::Clamp),
            [7.0; 3]
        );
        assert_eq!(im.point_texel(Vec2::new(0.3, 0.3)), (1, 0));
    }
}
