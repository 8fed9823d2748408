//! Reading map images (PNG and OpenEXR) as pbrt-v4 reads them
//! (`util/image.cpp`: `ReadPNG`, `ReadEXR`; `util/color.h`: `ColorEncoding`).
//!
//! - **PNG.** Grey (with or without alpha) becomes one channel, everything
//!   else (RGB, RGBA, palette) three; alpha is dropped, as pbrt-v4's decode
//!   to `LCT_GREY`/`LCT_RGB` does. 8-bit values are decoded by the colour
//!   encoding (sRGB unless told otherwise). 16-bit values v/65535 are decoded
//!   by the same curve and rounded to half floats, as pbrt-v4 stores them.
//!   The colour space is sRGB.
//! - **OpenEXR.** The first layer; channels `R`, `G`, `B` if present, else a
//!   single channel of any name. Half, float and uint samples are read as
//!   they are (the encoding does not apply). The colour space comes from the
//!   `chromaticities` attribute (sRGB when absent, or — with a warning — when
//!   it matches no supported space, as pbrt-v4 does).
//!
//! Other formats pbrt-v4 reads through stb_image (TGA, BMP, HDR, PFM, …) are
//! not supported.

use super::map::{MapImage, PixelFormat};
use super::ImageError;
use crate::spectrum::ColorSpace;
use exr::prelude::f16;
use std::path::Path;

/// The transfer curve of 8-bit (and 16-bit PNG) values [pbrt-v4 `ColorEncoding`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColorEncoding {
    /// v.
    Linear,
    /// The sRGB curve (IEC 61966-2-1).
    Srgb,
    /// v^γ.
    Gamma(f32),
}

impl ColorEncoding {
    /// pbrt-v4's names: `"linear"`, `"sRGB"`, `"gamma <γ>"`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "linear" => Some(ColorEncoding::Linear),
            "sRGB" | "srgb" => Some(ColorEncoding::Srgb),
            _ => {
                let mut it = s.split_whitespace();
                match (it.next(), it.next().map(str::parse::<f32>), it.next()) {
                    (Some("gamma"), Some(Ok(g)), None) if g > 0.0 => Some(ColorEncoding::Gamma(g)),
                    _ => None,
                }
            }
        }
    }

    /// Linear value of a code value `v` ∈ [0, 1].
    pub fn to_linear(self, v: f32) -> f32 {
        match self {
            ColorEncoding::Linear => v,
            ColorEncoding::Srgb => {
                if v <= 0.04045 {
                    v / 12.92
                } else {
                    ((v + 0.055) / 1.055).powf(2.4)
                }
            }
            ColorEncoding::Gamma(g) => v.powf(g),
        }
    }

    /// The 8-bit code of a linear value (rounded, clamped) [pbrt-v4 `FromLinear`].
    pub fn to_u8(self, v: f32) -> u8 {
        let code = match self {
            ColorEncoding::Linear => v,
            ColorEncoding::Srgb => super::srgb_encode(v),
            ColorEncoding::Gamma(g) => v.max(0.0).powf(1.0 / g),
        };
        (255.0 * code + 0.5).clamp(0.0, 255.0) as u8
    }
}

/// A map image read from a file, with the colour space of its RGB values.
#[derive(Debug)]
pub struct MapFile {
    /// The pixels.
    pub image: MapImage,
    /// The RGB colour space (sRGB for PNG).
    pub color_space: &'static ColorSpace,
    /// Something the reader substituted (an unknown colour space).
    pub warning: Option<String>,
}

/// Reads a PNG or EXR file; `encoding` applies to PNG only.
pub fn read_map(path: &Path, encoding: ColorEncoding) -> Result<MapFile, ImageError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Ok(MapFile {
            image: read_png(path, encoding)?,
            color_space: ColorSpace::srgb(),
            warning: None,
        }),
        Some("exr") => read_exr_map(path),
        _ => Err(format_error(
            path,
            "unsupported image format (candela reads .png and .exr)",
        )),
    }
}

fn format_error(path: &Path, msg: impl Into<String>) -> ImageError {
    ImageError::Format {
        path: path.display().to_string(),
        msg: msg.into(),
    }
}

fn read_png(path: &Path, enc: ColorEncoding) -> Result<MapImage, ImageError> {
    use image::DynamicImage as D;
    let png_err = |error| ImageError::Png {
        path: path.display().to_string(),
        error,
    };
    let img = image::ImageReader::open(path)
        .map_err(|e| png_err(image::ImageError::IoError(e)))?
        .with_guessed_format()
        .map_err(|e| png_err(image::ImageError::IoError(e)))?
        .decode()
        .map_err(png_err)?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    let u8s = |raw: &[u8], stride: usize, nc: usize| {
        let lut: Vec<f32> = (0..=255u8)
            .map(|b| enc.to_linear(b as f32 / 255.0))
            .collect();
        let data = texels(raw, w * h, stride, nc, |b| lut[b as usize]);
        MapImage::new(w, h, nc, data, PixelFormat::U8(enc))
    };
    let u16s = |raw: &[u16], stride: usize, nc: usize| {
        let data = texels(raw, w * h, stride, nc, |v| {
            f16::from_f32(enc.to_linear(v as f32 / 65535.0)).to_f32()
        });
        MapImage::new(w, h, nc, data, PixelFormat::Half)
    };
    Ok(match &img {
        D::ImageLuma8(b) => u8s(b.as_raw(), 1, 1),
        D::ImageLumaA8(b) => u8s(b.as_raw(), 2, 1),
        D::ImageRgb8(b) => u8s(b.as_raw(), 3, 3),
        D::ImageRgba8(b) => u8s(b.as_raw(), 4, 3),
        D::ImageLuma16(b) => u16s(b.as_raw(), 1, 1),
        D::ImageLumaA16(b) => u16s(b.as_raw(), 2, 1),
        D::ImageRgb16(b) => u16s(b.as_raw(), 3, 3),
        D::ImageRgba16(b) => u16s(b.as_raw(), 4, 3),
        other => u8s(other.to_rgb8().as_raw(), 3, 3),
    })
}

/// The first `nc` of every `stride` samples, decoded by `f`.
fn texels<T: Copy>(
    raw: &[T],
    n: usize,
    stride: usize,
    nc: usize,
    f: impl Fn(T) -> f32,
) -> Vec<f32> {
    let mut out = Vec::with_capacity(n * nc);
    for px in raw.chunks_exact(stride).take(n) {
        out.extend(px[..nc].iter().map(|&v| f(v)));
    }
    out
}

fn read_exr_map(path: &Path) -> Result<MapFile, ImageError> {
    use exr::prelude::{read_first_flat_layer_from_file, FlatSamples};
    let img = read_first_flat_layer_from_file(path).map_err(|error| ImageError::Exr {
        path: path.display().to_string(),
        error,
    })?;
    let layer = &img.layer_data;
    let (w, h) = (layer.size.width(), layer.size.height());
    let chans = &layer.channel_data.list;
    let find = |n: &str| chans.iter().position(|c| c.name.to_string() == n);
    let picked: Vec<usize> = match (find("R"), find("G"), find("B")) {
        (Some(r), Some(g), Some(b)) => vec![r, g, b],
        _ if chans.len() == 1 => vec![0],
        _ => {
            let names: Vec<String> = chans.iter().map(|c| c.name.to_string()).collect();
            return Err(format_error(
                path,
                format!("image has channels {names:?}, not R, G and B (or a single channel)"),
            ));
        }
    };
    let mut half = true;
    let columns: Vec<Vec<f32>> = picked
        .iter()
        .map(|&i| match &chans[i].sample_data {
            FlatSamples::F16(v) => v.iter().map(|x| x.to_f32()).collect(),
            FlatSamples::F32(v) => {
                half = false;
                v.clone()
            }
            FlatSamples::U32(v) => {
                half = false;
                v.iter().map(|&x| x as f32).collect()
            }
        })
        .collect();
    let nc = picked.len();
    let mut data = Vec::with_capacity(w * h * nc);
    for p in 0..w * h {
        data.extend(columns.iter().map(|col| col[p]));
    }
    let format = if half {
        PixelFormat::Half
    } else {
        PixelFormat::Float
    };
    let (color_space, warning) = exr_color_space(path, img.attributes.chromaticities)?;
    Ok(MapFile {
        image: MapImage::new(w, h, nc, data, format),
        color_space,
        warning,
    })
}

/// The colour space named by EXR chromaticities [pbrt-v4 `RGBColorSpace::Lookup`].
fn exr_color_space(
    path: &Path,
    c: Option<exr::meta::attribute::Chromaticities>,
) -> Result<(&'static ColorSpace, Option<String>), ImageError> {
    let Some(c) = c else {
        return Ok((ColorSpace::srgb(), None));
    };
    const D65: (f32, f32) = (0.3127, 0.3290);
    type Xy = (f32, f32);
    let known: [(&str, [Xy; 4]); 4] = [
        ("srgb", [(0.64, 0.33), (0.30, 0.60), (0.15, 0.06), D65]),
        (
            "rec2020",
            [(0.708, 0.292), (0.170, 0.797), (0.131, 0.046), D65],
        ),
        (
            "dci-p3",
            [(0.680, 0.320), (0.265, 0.690), (0.150, 0.060), D65],
        ),
        (
            "aces2065-1",
            [
                (0.7347, 0.2653),
                (0.0, 1.0),
                (0.0001, -0.077),
                (0.32168, 0.33767),
            ],
        ),
    ];
    let got = [c.red, c.green, c.blue, c.white].map(|v| (v.x(), v.y()));
    let close = |a: Xy, b: Xy| (a.0 - b.0).abs() < 1e-3 && (a.1 - b.1).abs() < 1e-3;
    for (name, p) in known {
        if p.iter().zip(&got).all(|(a, b)| close(*a, *b)) {
            return ColorSpace::by_name(name)
                .map(|cs| (cs, None))
                .ok_or_else(|| {
                    format_error(path, format!("colour space {name} is not supported yet"))
                });
        }
    }
    Ok((
        ColorSpace::srgb(),
        Some(format!(
            "{}: chromaticities {got:?} match no supported colour space; using sRGB",
            path.display()
        )),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("candela-read-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn encodings_parse_and_invert() {
        assert_eq!(ColorEncoding::parse("sRGB"), Some(ColorEncoding::Srgb));
        assert_eq!(
            ColorEncoding::parse("gamma 2.2"),
            Some(ColorEncoding::Gamma(2.2))
        );
        assert_eq!(ColorEncoding::parse("gamma"), None);
        assert_eq!(ColorEncoding::parse("log"), None);
        for enc in [
            ColorEncoding::Linear,
            ColorEncoding::Srgb,
            ColorEncoding::Gamma(1.8),
        ] {
            for b in 0..=255u8 {
                assert_eq!(enc.to_u8(enc.to_linear(b as f32 / 255.0)), b, "{enc:?}");
            }
        }
    }

    #[test]
    fn png_channels_and_decoding() {
        let d = dir("png");
        let rgba = image::RgbaImage::from_raw(2, 1, vec![255, 128, 0, 7, 10, 20, 30, 0]).unwrap();
        rgba.save(d.join("a.png")).unwrap();
        let m = read_map(&d.join("a.png"), ColorEncoding::Srgb).unwrap();
        assert_eq!((m.image.width, m.image.height, m.image.channels), (2, 1, 3));
        let srgb = |b: u8| ColorEncoding::Srgb.to_linear(b as f32 / 255.0);
        assert_eq!(&m.image.data[..3], &[1.0, srgb(128), 0.0]);
        let lin = read_map(&d.join("a.png"), ColorEncoding::Linear).unwrap();
        assert_eq!(lin.image.data[3], 10.0 / 255.0);
        image::GrayImage::from_raw(1, 2, vec![0, 51])
            .unwrap()
            .save(d.join("g.png"))
            .unwrap();
        let g = read_map(&d.join("g.png"), ColorEncoding::Gamma(2.0)).unwrap();
        assert_eq!(g.image.channels, 1);
        assert!((g.image.data[1] - 0.04).abs() < 1e-6);
        let wide =
            image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(1, 1, vec![65535u16, 32768, 0]);
        wide.unwrap().save(d.join("w.png")).unwrap();
        let w = read_map(&d.join("w.png"), ColorEncoding::Linear).unwrap();
        assert_eq!(w.image.format, PixelFormat::Half);
        assert_eq!(
            w.image.data,
            vec![1.0, f16::from_f32(32768.0 / 65535.0).to_f32(), 0.0]
        );
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn exr_reads_rgb_and_rejects_other_formats() {
        let d = dir("exr");
        let mut im = super::super::RgbImage::new(2, 2);
        im.pixels[3] = [4.0, 5.0, 6.0];
        im.write_exr(&d.join("e.exr")).unwrap();
        let m = read_map(&d.join("e.exr"), ColorEncoding::Srgb).unwrap();
        assert_eq!(m.image.channels, 3);
        assert_eq!(m.image.format, PixelFormat::Float);
        assert_eq!(&m.image.data[9..], &[4.0, 5.0, 6.0]);
        assert!(std::ptr::eq(m.color_space, ColorSpace::srgb()));
        assert!(read_map(&d.join("e.tga"), ColorEncoding::Srgb).is_err());
        assert!(read_map(&d.join("missing.exr"), ColorEncoding::Srgb).is_err());
        std::fs::remove_dir_all(&d).ok();
    }
}
