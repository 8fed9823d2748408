//! Images: RGB float images (the film's EXR and PNG output and the
//! comparison metrics of `candela diff`, validation.md "Image metrics"), and
//! map images read for textures and environment lights ([`MapImage`]), and
//! false-colour pictures of photometric layers ([`falsecolor`]).

pub mod atomic;
mod compare;
pub mod exr_write;
pub mod falsecolor;
pub mod font;
mod map;
mod pyramid;
mod read;
mod resize;

pub use atomic::{write_atomic, write_atomic_bytes};
pub use compare::{compare, non_finite, Comparison, NonFinite, TRIM};
pub use exr_write::{
    encode_exr_layers, read_exr_layers, write_exr_layers, ExrAttribute, ExrAttributes, ExrChannel,
    ExrImage, ExrLayer,
};
pub use map::{MapImage, PixelFormat, WrapMode};
pub use pyramid::MipPyramid;
pub use read::{read_map, ColorEncoding, MapFile};
pub use resize::resize_to_power_of_two;

use std::path::Path;
use thiserror::Error;

/// Failure reading or writing an image file.
///
/// The codec's error is printed in the message and deliberately not chained
/// as a `source()`: the codecs' errors chain their I/O error in turn, so an
/// error reporter walking the chain (`anyhow`'s `{:#}`) would print the same
/// "No such file or directory" three times.
#[derive(Debug, Error)]
pub enum ImageError {
    /// The EXR codec failed.
    #[error("{path}: {error}")]
    Exr {
        /// File.
        path: String,
        /// Cause.
        error: exr::error::Error,
    },
    /// The PNG codec failed.
    #[error("{path}: {error}")]
    Png {
        /// File.
        path: String,
        /// Cause.
        error: image::ImageError,
    },
    /// Writing the file failed.
    #[error("{path}: {error}")]
    Io {
        /// File.
        path: String,
        /// Cause (not a `source`: the message already holds it).
        error: std::io::Error,
    },
    /// The file is not a map candela can read.
    #[error("{path}: {msg}")]
    Format {
        /// File.
        path: String,
        /// What is wrong.
        msg: String,
    },
    /// The two images cannot be compared.
    #[error("image sizes differ: {0}x{1} vs {2}x{3}")]
    SizeMismatch(usize, usize, usize, usize),
}

/// A linear RGB image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// `width·height` RGB triples.
    pub pixels: Vec<[f32; 3]>,
}

impl RgbImage {
    /// Black image.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            pixels: vec![[0.0; 3]; width * height],
        }
    }

    /// Pixel at (x, y).
    #[inline]
    pub fn get(&self, x: usize, y: usize) -> [f32; 3] {
        self.pixels[y * self.width + x]
    }

    /// Reads the first RGB(A) layer of an EXR file (any sample type).
    pub fn read_exr(path: &Path) -> Result<Self, ImageError> {
        use exr::prelude::*;
        let img = read_first_rgba_layer_from_file(
            path,
            |res, _| RgbImage::new(res.width(), res.height()),
            |img: &mut RgbImage, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                let w = img.width;
                img.pixels[pos.y() * w + pos.x()] = [r, g, b];
            },
        )
        .map_err(|error| ImageError::Exr {
            path: path.display().to_string(),
            error,
        })?;
        Ok(img.layer_data.channel_data.pixels)
    }

    /// Writes a 32-bit float RGB EXR, atomically and with the same bytes for
    /// the same pixels ([`write_exr_layers`]).
    pub fn write_exr(&self, path: &Path) -> Result<(), ImageError> {
        let layers = [ExrLayer::from_rgb("", self)];
        write_exr_layers(
            path,
            self.width,
            self.height,
            &layers,
            &ExrAttributes::new(),
        )
    }

    /// Writes an 8-bit sRGB PNG, atomically: linear values scaled by
    /// 2^`stops`, clipped to [0, 1] and encoded with the sRGB transfer curve.
    pub fn write_png(&self, path: &Path, stops: f32) -> Result<(), ImageError> {
        let scale = 2f32.powf(stops);
        let mut buf = Vec::with_capacity(self.width * self.height * 3);
        for p in &self.pixels {
            for &c in p {
                buf.push((srgb_encode(c * scale) * 255.0 + 0.5) as u8);
            }
        }
        write_rgb8_png(path, &buf, self.width, self.height)
    }

    /// The pixels x0 ≤ x < x1, y0 ≤ y < y1 of `r = [x0, y0, x1, y1]`; `None` if outside.
    pub fn crop(&self, r: [usize; 4]) -> Option<RgbImage> {
        let [x0, y0, x1, y1] = r;
        if x1 > self.width || y1 > self.height || x0 >= x1 || y0 >= y1 {
            return None;
        }
        let mut out = RgbImage::new(x1 - x0, y1 - y0);
        for y in y0..y1 {
            for x in x0..x1 {
                out.pixels[(y - y0) * out.width + (x - x0)] = self.get(x, y);
            }
        }
        Some(out)
    }

    /// Mean of each channel.
    pub fn channel_means(&self) -> [f64; 3] {
        let mut s = [0.0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                s[c] += p[c] as f64;
            }
        }
        let n = self.pixels.len().max(1) as f64;
        s.map(|v| v / n)
    }
}

/// sRGB opto-electronic transfer function of a linear value, clipped to [0, 1].
pub fn srgb_encode(v: f32) -> f32 {
    let v = if v.is_finite() {
        v.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Writes 8-bit sRGB triples (`width × height`, row-major) as a PNG at
/// `path`, atomically.
pub(crate) fn write_rgb8_png(
    path: &Path,
    rgb: &[u8],
    width: usize,
    height: usize,
) -> Result<(), ImageError> {
    use image::ImageEncoder;
    let name = || path.display().to_string();
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(
            rgb,
            width as u32,
            height as u32,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(|error| ImageError::Png {
            path: name(),
            error,
        })?;
    write_atomic_bytes(path, &png).map_err(|error| ImageError::Io {
        path: name(),
        error,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_round_trip_is_exact() {
        let mut img = RgbImage::new(5, 3);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            *p = [i as f32 * 0.25, 1e-7 * i as f32, 1e6 + i as f32];
        }
        let dir = std::env::temp_dir().join(format!("candela-exr-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.exr");
        img.write_exr(&path).unwrap();
        assert_eq!(RgbImage::read_exr(&path).unwrap(), img);
        img.write_png(&dir.join("t.png"), -20.0).unwrap();
        let png = image::open(dir.join("t.png")).unwrap().into_rgb8();
        for (p, q) in img.pixels.iter().zip(png.pixels()) {
            let want = p.map(|c| (srgb_encode(c * 2f32.powi(-20)) * 255.0 + 0.5) as u8);
            assert_eq!(q.0, want);
        }
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn srgb_curve_endpoints() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_encode(0.18) - 0.4614).abs() < 1e-3);
        assert_eq!(srgb_encode(f32::NAN), 0.0);
    }
}
