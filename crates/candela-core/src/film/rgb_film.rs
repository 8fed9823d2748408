//! pbrt-v4's `rgb` film: per-pixel weighted sums of sensor RGB, converted to
//! the output colour space (linear sRGB by default) when the image is read.
//!
//! A sample's spectral radiance L(λ) at the path's wavelengths is turned into
//! sensor RGB by the pixel sensor (for the default `cie1931` sensor: the
//! Monte Carlo estimate of XYZ times the imaging ratio), clamped to
//! `maxcomponentvalue`, and added with its filter weight. Light-tracing
//! splats go to a separate buffer that is scaled by 1/spp on output.

use super::filter::Filter;
use crate::image::RgbImage;
use crate::math::{Mat3, UVec2, Vec3};
use crate::spectrum::{PixelSensor, SampledSpectrum, SampledWavelengths};

/// Film construction values (parsed from the `Film` directive).
#[derive(Clone, Debug)]
pub struct FilmSettings {
    /// Full resolution in pixels.
    pub resolution: UVec2,
    /// Half-open pixel range actually rendered (crop window).
    pub pixel_bounds: (UVec2, UVec2),
    /// Samples whose largest sensor-RGB component exceeds this are scaled down (pbrt: +∞).
    pub max_component_value: f32,
}

/// Weighted sum of samples in one pixel.
#[derive(Clone, Copy, Debug, Default)]
struct Pixel {
    rgb_sum: [f64; 3],
    weight_sum: f64,
}

/// The rgb film.
#[derive(Clone, Debug)]
pub struct RgbFilm {
    settings: FilmSettings,
    filter: Filter,
    sensor: PixelSensor,
    output_from_sensor: Mat3,
    pixels: Vec<Pixel>,
    splats: Vec<[f64; 3]>,
    splat_scale: f64,
    dropped_samples: u64,
}

/// Light-tracing splats of one batch of paths over the full raster; merged
/// into the film in a fixed order so results do not depend on scheduling.
///
/// As in pbrt-v4, a splat at raster position p adds f(p − c)/∫f to every
/// pixel centre c within the filter's radius, so splatted and filtered
/// camera samples reconstruct the same image.
pub struct SplatBuffer {
    res: UVec2,
    lo: UVec2,
    hi: UVec2,
    sums: Vec<[f64; 3]>,
    sensor: PixelSensor,
    filter: Filter,
    inv_filter_integral: f32,
    max_component_value: f32,
    dropped_samples: u64,
}

impl SplatBuffer {
    /// Adds radiance-weighted importance `l` at raster position `p`
    /// (ignored outside the rendered pixel bounds; non-finite values are dropped and counted).
    pub fn add(&mut self, p: crate::math::Vec2, l: SampledSpectrum, lambda: &SampledWavelengths) {
        if self.sums.is_empty() {
            return;
        }
        if l.has_non_finite() {
            self.dropped_samples += 1;
            return;
        }
        let r = self.filter.radius();
        // Pixel centres within the radius: c = i + ½ with |p − c| ≤ r.
        let x0 = ((p.x - 0.5 - r.x).ceil().max(self.lo.x as f32)) as i64;
        let y0 = ((p.y - 0.5 - r.y).ceil().max(self.lo.y as f32)) as i64;
        let x1 = ((p.x - 0.5 + r.x).floor().min(self.hi.x as f32 - 1.0)) as i64;
        let y1 = ((p.y - 0.5 + r.y).floor().min(self.hi.y as f32 - 1.0)) as i64;
        if x0 > x1 || y0 > y1 {
            return;
        }
        let rgb = clamp_rgb(
            self.sensor.to_sensor_rgb(l, lambda),
            self.max_component_value,
        );
        for y in y0..=y1 {
            for x in x0..=x1 {
                let c = crate::math::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let w = self.filter.evaluate(p - c) * self.inv_filter_integral;
                if w == 0.0 {
                    continue;
                }
                let s = &mut self.sums[(y as u32 * self.res.x + x as u32) as usize];
                for (c, v) in rgb.iter().enumerate() {
                    s[c] += (w * *v) as f64;
                }
            }
        }
    }

    /// A buffer that ignores every splat (for estimators that never splat).
    pub fn disabled() -> Self {
        Self {
            res: UVec2::ZERO,
            lo: UVec2::ZERO,
            hi: UVec2::ZERO,
            sums: Vec::new(),
            sensor: PixelSensor::cie1931(1.0),
            filter: Filter::default(),
            inv_filter_integral: 0.0,
            max_component_value: 0.0,
            dropped_samples: 0,
        }
    }
}

/// The part of the film one thread renders; merged back with [`RgbFilm::merge_tile`].
pub struct FilmTile {
    lo: UVec2,
    hi: UVec2,
    pixels: Vec<Pixel>,
    sensor: PixelSensor,
    max_component_value: f32,
    dropped_samples: u64,
}

impl RgbFilm {
    /// New black film; `output_from_sensor` maps sensor RGB to output RGB.
    pub fn new(
        settings: FilmSettings,
        filter: Filter,
        sensor: PixelSensor,
        output_from_sensor: Mat3,
    ) -> Self {
        let n = (settings.resolution.x * settings.resolution.y) as usize;
        Self {
            settings,
            filter,
            sensor,
            output_from_sensor,
            pixels: vec![Pixel::default(); n],
            splats: vec![[0.0; 3]; n],
            splat_scale: 1.0,
            dropped_samples: 0,
        }
    }

    /// A film with the same settings and no samples.
    pub fn cleared(&self) -> Self {
        Self::new(
            self.settings.clone(),
            self.filter.clone(),
            self.sensor.clone(),
            self.output_from_sensor,
        )
    }

    /// Full resolution.
    pub fn resolution(&self) -> UVec2 {
        self.settings.resolution
    }
    /// Rendered pixel range.
    pub fn pixel_bounds(&self) -> (UVec2, UVec2) {
        self.settings.pixel_bounds
    }
    /// The pixel filter.
    pub fn filter(&self) -> &Filter {
        &self.filter
    }
    /// The pixel sensor.
    pub fn sensor(&self) -> &PixelSensor {
        &self.sensor
    }
    /// Samples discarded because they were NaN or infinite (should stay 0).
    pub fn dropped_samples(&self) -> u64 {
        self.dropped_samples
    }

    /// An empty tile covering `[lo, hi)`.
    pub fn tile(&self, lo: UVec2, hi: UVec2) -> FilmTile {
        let n = ((hi.x - lo.x) * (hi.y - lo.y)) as usize;
        FilmTile {
            lo,
            hi,
            pixels: vec![Pixel::default(); n],
            sensor: self.sensor.clone(),
            max_component_value: self.settings.max_component_value,
            dropped_samples: 0,
        }
    }

    /// Adds a finished tile's sums.
    pub fn merge_tile(&mut self, tile: FilmTile) {
        let w = tile.hi.x - tile.lo.x;
        for y in tile.lo.y..tile.hi.y {
            for x in tile.lo.x..tile.hi.x {
                let src = tile.pixels[((y - tile.lo.y) * w + (x - tile.lo.x)) as usize];
                let dst = &mut self.pixels[(y * self.settings.resolution.x + x) as usize];
                for c in 0..3 {
                    dst.rgb_sum[c] += src.rgb_sum[c];
                }
                dst.weight_sum += src.weight_sum;
            }
        }
        self.dropped_samples += tile.dropped_samples;
    }

    /// Replaces a pixel's value by `rgb` in sensor space (estimators that
    /// compute final pixel values themselves, like SPPM). Non-finite values
    /// are dropped and counted.
    pub fn set_pixel_sensor_rgb(&mut self, pixel: UVec2, rgb: [f64; 3]) {
        let i = (pixel.y * self.settings.resolution.x + pixel.x) as usize;
        if rgb.iter().any(|v| !v.is_finite()) {
            self.dropped_samples += 1;
            self.pixels[i] = Pixel::default();
            return;
        }
        self.pixels[i] = Pixel {
            rgb_sum: rgb,
            weight_sum: 1.0,
        };
    }

    /// An empty splat buffer for one batch of light paths.
    pub fn splat_buffer(&self) -> SplatBuffer {
        let (lo, hi) = self.settings.pixel_bounds;
        SplatBuffer {
            res: self.settings.resolution,
            lo,
            hi,
            sums: vec![[0.0; 3]; self.splats.len()],
            sensor: self.sensor.clone(),
            filter: self.filter.clone(),
            inv_filter_integral: 1.0 / self.filter.integral(),
            max_component_value: self.settings.max_component_value,
            dropped_samples: 0,
        }
    }

    /// Adds a batch's splats (call in a fixed order for reproducible images).
    pub fn merge_splats(&mut self, buf: SplatBuffer) {
        if buf.sums.is_empty() {
            return;
        }
        for (d, s) in self.splats.iter_mut().zip(&buf.sums) {
            for c in 0..3 {
                d[c] += s[c];
            }
        }
        self.dropped_samples += buf.dropped_samples;
    }

    /// Sets the factor splats are multiplied by on output (light tracing: 1/spp).
    pub fn set_splat_scale(&mut self, s: f64) {
        self.splat_scale = s;
    }

    /// The image in output RGB over the pixel bounds (filtered samples plus scaled splats).
    pub fn image(&self) -> RgbImage {
        let splat_scale = self.splat_scale;
        let (lo, hi) = self.settings.pixel_bounds;
        let mut img = RgbImage::new((hi.x - lo.x) as usize, (hi.y - lo.y) as usize);
        for y in lo.y..hi.y {
            for x in lo.x..hi.x {
                let i = (y * self.settings.resolution.x + x) as usize;
                let p = self.pixels[i];
                let mut rgb = [0.0f64; 3];
                if p.weight_sum != 0.0 {
                    rgb = p.rgb_sum.map(|v| v / p.weight_sum);
                }
                for (v, s) in rgb.iter_mut().zip(&self.splats[i]) {
                    *v += splat_scale * s;
                }
                let out = self.output_from_sensor
                    * Vec3::new(rgb[0] as f32, rgb[1] as f32, rgb[2] as f32);
                img.pixels[((y - lo.y) as usize) * img.width + (x - lo.x) as usize] =
                    out.to_array();
            }
        }
        img
    }
}

fn clamp_rgb(rgb: [f32; 3], max_component: f32) -> [f32; 3] {
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    if m > max_component {
        rgb.map(|v| v * max_component / m)
    } else {
        rgb
    }
}

impl FilmTile {
    /// Adds one camera sample of radiance `l` with filter weight `weight`.
    /// Non-finite samples are dropped and counted, never written.
    pub fn add_sample(
        &mut self,
        pixel: UVec2,
        l: SampledSpectrum,
        lambda: &SampledWavelengths,
        weight: f32,
    ) {
        if l.has_non_finite() || !weight.is_finite() {
            self.dropped_samples += 1;
            return;
        }
        let rgb = clamp_rgb(
            self.sensor.to_sensor_rgb(l, lambda),
            self.max_component_value,
        );
        let w = self.hi.x - self.lo.x;
        let p = &mut self.pixels[((pixel.y - self.lo.y) * w + (pixel.x - self.lo.x)) as usize];
        for (sum, v) in p.rgb_sum.iter_mut().zip(rgb) {
            *sum += (weight * v) as f64;
        }
        p.weight_sum += weight as f64;
    }
}
