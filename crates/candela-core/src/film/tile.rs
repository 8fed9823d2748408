//! What one thread writes during a pass: a [`FilmTile`] of filtered camera
//! samples for a rectangle of pixels, or a [`SplatBuffer`] of direct values
//! (light-tracing splats, per-pass pixel estimates) over the film's pixel
//! bounds. Both hold f64 sums of one pass; the pass block gathers them in a
//! fixed order and the film state quantises them ([`super::fixed`]).
//!
//! A splat at raster position p adds f(p − c)/∫f to every pixel centre c
//! within the filter's radius, as in pbrt-v4, so splatted and filtered camera
//! samples reconstruct the same image.

use super::filter::Filter;
use super::layout::{self, Buckets, FilmLayout, SurfaceAov};
use crate::math::{UVec2, Vec2};
use crate::spectrum::{luminous, PixelSensor, SampledSpectrum, SampledWavelengths};

/// Scales `rgb` so its largest component is at most `max_component`
/// (pbrt-v4's `maxcomponentvalue`); returns the factor applied.
#[inline]
pub(crate) fn clamp_rgb(rgb: [f32; 3], max_component: f32) -> ([f32; 3], f32) {
    let m = rgb[0].max(rgb[1]).max(rgb[2]);
    if m > max_component {
        let s = max_component / m;
        (rgb.map(|v| v * s), s)
    } else {
        (rgb, 1.0)
    }
}

/// Everything a tile or splat buffer needs to turn spectra into channels.
#[derive(Clone, Debug)]
pub(crate) struct Encoder {
    pub sensor: PixelSensor,
    pub max_component_value: f32,
    pub buckets: Option<Buckets>,
    /// Also record the luminance Y_v (photometric layers; never clamped).
    pub luminance: bool,
}

impl Encoder {
    /// Sensor RGB of `l` (clamped) and the clamp factor.
    #[inline]
    fn rgb(&self, l: SampledSpectrum, lambda: &SampledWavelengths) -> ([f32; 3], f32) {
        clamp_rgb(
            self.sensor.to_sensor_rgb(l, lambda),
            self.max_component_value,
        )
    }

    /// Adds w·L(λ)/(p(λ)·n·Δ) of each wavelength λ to its bucket: an
    /// estimate of the radiance averaged over the bucket (see
    /// [`super::layout`]; pbrt-v4's `SpectralFilm::AddSample` with
    /// non-uniform wavelength densities).
    fn add_spectral(
        &self,
        l: SampledSpectrum,
        lambda: &SampledWavelengths,
        w: f64,
        sums: &mut [f64],
    ) {
        let Some(b) = self.buckets else { return };
        let lm = l.max_component();
        let l = if lm > self.max_component_value {
            l * (self.max_component_value / lm)
        } else {
            l
        };
        let scale = w / (l.0.len() as f64 * b.width() as f64);
        let pdf = lambda.pdf();
        for i in 0..l.0.len() {
            let Some(k) = b.bucket(lambda.lambda(i)) else {
                continue;
            };
            if pdf.0[i] > 0.0 {
                sums[k] += scale * (l.0[i] / pdf.0[i]) as f64;
            }
        }
    }
}

/// Filtered camera samples of one pass over the pixels `[lo, hi)`.
pub struct FilmTile {
    pub(crate) lo: UVec2,
    pub(crate) hi: UVec2,
    pub(crate) stride: usize,
    pub(crate) rows: Vec<f64>,
    layout: FilmLayout,
    enc: Encoder,
    pub(crate) dropped: u64,
}

/// First-hit values of one camera sample (see [`SurfaceAov`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct SurfaceSample {
    /// Albedo in output RGB.
    pub albedo: [f32; 3],
    /// Position (world or camera space, [`super::SurfaceSpace`]).
    pub p: [f32; 3],
    /// Geometric normal, facing the ray.
    pub n: [f32; 3],
    /// Shading normal, facing the ray.
    pub ns: [f32; 3],
    /// Distance from the ray's origin on the lens.
    pub depth: f32,
    /// Surface (u, v).
    pub uv: [f32; 2],
    /// |∂z/∂x|, |∂z/∂y|.
    pub dz: [f32; 2],
}

impl SurfaceSample {
    fn values(&self, aov: SurfaceAov) -> &[f32] {
        match aov {
            SurfaceAov::Albedo => &self.albedo,
            SurfaceAov::Position => &self.p,
            SurfaceAov::Normal => &self.n,
            SurfaceAov::ShadingNormal => &self.ns,
            SurfaceAov::Depth => std::slice::from_ref(&self.depth),
            SurfaceAov::Uv => &self.uv,
            SurfaceAov::DepthGradient => &self.dz,
        }
    }
}

impl FilmTile {
    pub(crate) fn new(lo: UVec2, hi: UVec2, layout: &FilmLayout, enc: Encoder) -> Self {
        let stride = layout.pass_stride();
        let n = ((hi.x - lo.x) * (hi.y - lo.y)) as usize;
        Self {
            lo,
            hi,
            stride,
            rows: vec![0.0; n * stride],
            layout: layout.clone(),
            enc,
            dropped: 0,
        }
    }

    #[inline]
    fn row_range(&self, pixel: UVec2) -> std::ops::Range<usize> {
        let w = self.hi.x - self.lo.x;
        let i = ((pixel.y - self.lo.y) * w + (pixel.x - self.lo.x)) as usize;
        i * self.stride..(i + 1) * self.stride
    }

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
            self.dropped += 1;
            return;
        }
        let (rgb, _) = self.enc.rgb(l, lambda);
        let w = weight as f64;
        let nb = self.layout.n_buckets();
        let so = self.layout.spectral_offset();
        let po = self.layout.photometric_offset();
        let photometric = self.layout.photometric;
        let range = self.row_range(pixel);
        let row = &mut self.rows[range];
        for (c, v) in rgb.iter().enumerate() {
            row[layout::MAIN_WRGB + c] += w * *v as f64;
        }
        row[layout::MAIN_W] += w;
        if nb > 0 {
            self.enc.add_spectral(l, lambda, w, &mut row[so..so + nb]);
        }
        if photometric {
            row[po + layout::photo::WY] += w * luminous(&l, lambda);
        }
    }

    /// Adds the illuminance `e` \[lx\] at the first visible surface of one
    /// camera ray with filter weight `weight` (`None`: the ray escaped and
    /// adds its weight only). Ignored without photometric layers;
    /// non-finite values are dropped and counted.
    pub fn add_illuminance(&mut self, pixel: UVec2, e: Option<f64>, weight: f32) {
        if !self.layout.photometric {
            return;
        }
        let e = e.unwrap_or(0.0);
        if !e.is_finite() || !weight.is_finite() {
            self.dropped += 1;
            return;
        }
        let w = weight as f64;
        let po = self.layout.photometric_offset();
        let range = self.row_range(pixel);
        let row = &mut self.rows[range];
        row[po + layout::photo::WE] += w;
        row[po + layout::photo::WEE] += w * e;
    }

    /// Adds the first-hit values of one camera sample with weight `weight`.
    pub fn add_surface(&mut self, pixel: UVec2, s: &SurfaceSample, weight: f32) {
        if self.layout.surface.is_empty() || !weight.is_finite() {
            return;
        }
        let w = weight as f64;
        let range = self.row_range(pixel);
        let (layout, row) = (&self.layout, &mut self.rows[range]);
        row[layout.surface_offset()] += w;
        for &aov in &layout.surface {
            let Some(o) = layout.surface_channel(aov) else {
                continue;
            };
            for (k, v) in s.values(aov).iter().enumerate() {
                if v.is_finite() {
                    row[o + k] += w * *v as f64;
                }
            }
        }
    }
}

/// Direct values of one pass over the film's pixel bounds.
pub struct SplatBuffer {
    pub(crate) lo: UVec2,
    pub(crate) hi: UVec2,
    /// Channels per pixel: rgb, then the spectral buckets, then Y_v if recorded.
    pub(crate) stride: usize,
    /// Offset of Y_v in a pixel (photometric films only).
    pub(crate) luminance: Option<usize>,
    pub(crate) sums: Vec<f64>,
    filter: Filter,
    inv_filter_integral: f32,
    enc: Encoder,
    pub(crate) dropped: u64,
    /// When recording, the splats in the order they came instead of sums
    /// ([`SplatBuffer::recording`]).
    records: Option<Vec<SplatRecord>>,
}

/// One splat as [`SplatBuffer::add`] was called with it, to be replayed
/// into a summing buffer later.
#[derive(Clone, Copy, Debug)]
pub struct SplatRecord {
    p: Vec2,
    l: SampledSpectrum,
    lambda: SampledWavelengths,
}

impl SplatRecord {
    /// A splat of `l` at raster position `p`.
    #[cfg(test)]
    pub(crate) fn new(p: Vec2, l: SampledSpectrum, lambda: SampledWavelengths) -> Self {
        Self { p, l, lambda }
    }

    /// The raster position.
    pub(crate) fn position(&self) -> Vec2 {
        self.p
    }

    /// True when the value is not finite ([`SplatBuffer::add`] drops it).
    pub(crate) fn is_dropped(&self) -> bool {
        self.l.has_non_finite()
    }
}

impl SplatBuffer {
    pub(crate) fn new(lo: UVec2, hi: UVec2, filter: Filter, enc: Encoder) -> Self {
        let spectral = 3 + enc.buckets.map_or(0, |b| b.n);
        let luminance = enc.luminance.then_some(spectral);
        let stride = spectral + enc.luminance as usize;
        let n = ((hi.x - lo.x) * (hi.y - lo.y)) as usize;
        Self {
            lo,
            hi,
            stride,
            luminance,
            sums: vec![0.0; n * stride],
            inv_filter_integral: 1.0 / filter.integral(),
            filter,
            enc,
            dropped: 0,
            records: None,
        }
    }

    /// A buffer over no pixels that records what [`Self::add`] is given
    /// instead of summing it; [`Self::take_records`] hands the records over
    /// and [`Self::replay`] adds them to a summing buffer in the same order,
    /// with the same result as adding them there directly.
    pub fn recording(film: &super::Film) -> Self {
        Self::empty_at(film.pixel_bounds().0, film).into_recording()
    }

    /// This buffer, recording from now on ([`Self::recording`]).
    fn into_recording(self) -> Self {
        Self {
            records: Some(Vec::new()),
            ..self
        }
    }

    /// The splats recorded since the last call (none when not recording).
    pub fn take_records(&mut self) -> Vec<SplatRecord> {
        self.records
            .as_mut()
            .map(std::mem::take)
            .unwrap_or_default()
    }

    /// Adds recorded splats in their order ([`Self::add`] on each).
    pub fn replay(&mut self, records: &[SplatRecord]) {
        for r in records {
            self.add(r.p, r.l, &r.lambda);
        }
    }

    #[inline]
    fn index(&self, x: u32, y: u32) -> usize {
        (((y - self.lo.y) * (self.hi.x - self.lo.x) + (x - self.lo.x)) as usize) * self.stride
    }

    /// Adds radiance-weighted importance `l` at raster position `p`, filtered
    /// over the pixels around it (ignored outside the pixel bounds;
    /// non-finite values are dropped and counted).
    pub fn add(&mut self, p: Vec2, l: SampledSpectrum, lambda: &SampledWavelengths) {
        if let Some(r) = &mut self.records {
            r.push(SplatRecord {
                p,
                l,
                lambda: *lambda,
            });
            return;
        }
        if l.has_non_finite() {
            self.dropped += 1;
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
        let (rgb, _) = self.enc.rgb(l, lambda);
        let y_v = self.luminance.map(|_| luminous(&l, lambda));
        for y in y0..=y1 {
            for x in x0..=x1 {
                let c = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let w = self.filter.evaluate(p - c) * self.inv_filter_integral;
                if w == 0.0 {
                    continue;
                }
                let i = self.index(x as u32, y as u32);
                for (k, v) in rgb.iter().enumerate() {
                    self.sums[i + k] += (w * *v) as f64;
                }
                self.add_extra(i, l, lambda, w as f64, y_v);
            }
        }
    }

    /// Adds the spectral buckets and the luminance of one weighted value at pixel offset `i`.
    #[inline]
    fn add_extra(
        &mut self,
        i: usize,
        l: SampledSpectrum,
        lambda: &SampledWavelengths,
        w: f64,
        y_v: Option<f64>,
    ) {
        if self.enc.buckets.is_some() {
            let spectral = &mut self.sums[i + 3..i + self.stride];
            self.enc.add_spectral(l, lambda, w, spectral);
        }
        if let (Some(o), Some(y)) = (self.luminance, y_v) {
            self.sums[i + o] += w * y;
        }
    }

    /// Adds an estimate of the radiance of `pixel` itself (PPM's per-pass
    /// pixel values: no filtering); non-finite values are dropped and counted.
    pub fn add_pixel(&mut self, pixel: UVec2, l: SampledSpectrum, lambda: &SampledWavelengths) {
        debug_assert!(
            self.records.is_none(),
            "a recording buffer records add() only"
        );
        if l.has_non_finite() {
            self.dropped += 1;
            return;
        }
        if pixel.x < self.lo.x
            || pixel.y < self.lo.y
            || pixel.x >= self.hi.x
            || pixel.y >= self.hi.y
        {
            return;
        }
        let (rgb, _) = self.enc.rgb(l, lambda);
        let i = self.index(pixel.x, pixel.y);
        for (k, v) in rgb.iter().enumerate() {
            self.sums[i + k] += *v as f64;
        }
        let y_v = self.luminance.map(|_| luminous(&l, lambda));
        self.add_extra(i, l, lambda, 1.0, y_v);
    }
}

impl SplatBuffer {
    /// A buffer over no pixels: every splat falls outside and is ignored
    /// (for estimators that never splat).
    pub fn empty_at(lo: UVec2, film: &super::Film) -> Self {
        SplatBuffer::new(lo, lo, film.filter().clone(), film.encoder_for_empty())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::PixelSensor;

    fn buffer(lo: UVec2, hi: UVec2) -> SplatBuffer {
        let enc = Encoder {
            sensor: PixelSensor::cie1931(1.0),
            max_component_value: f32::INFINITY,
            buckets: None,
            luminance: false,
        };
        SplatBuffer::new(lo, hi, Filter::default(), enc)
    }

    /// Splats recorded and replayed sum to the same bits as splats added
    /// directly, in the same order (a reversed replay fails) (the driver's determinism rests on it), non-finite ones
    /// dropped and counted alike; a recording buffer sums nothing itself.
    #[test]
    fn replayed_splats_equal_direct_ones_bit_for_bit() {
        let (lo, hi) = (UVec2::new(2, 1), UVec2::new(14, 9));
        let (mut direct, mut rec) = (buffer(lo, hi), buffer(lo, lo).into_recording());
        let mut u = 0.137f32;
        let mut next = || {
            u = (u * 97.31 + 0.417).fract();
            u
        };
        for i in 0..500 {
            let p = Vec2::new(16.0 * next(), 10.0 * next());
            let lambda = SampledWavelengths::sample_visible(next());
            // Magnitudes 1e-6 to 1e7, so that f64 sums round and order shows.
            let scale = 10f32.powi(i % 14 - 6);
            let v = if i % 97 == 0 {
                f32::NAN
            } else {
                scale * next()
            };
            let l = SampledSpectrum::from_fn(|k| v * (k as f32 + next()));
            direct.add(p, l, &lambda);
            rec.add(p, l, &lambda);
        }
        assert!(rec.sums.is_empty() && rec.dropped == 0);
        let records = rec.take_records();
        assert_eq!(records.len(), 500);
        assert!(rec.take_records().is_empty());
        let mut replayed = buffer(lo, hi);
        replayed.replay(&records);
        assert!(direct.sums.iter().any(|&v| v > 0.0));
        let bits = |b: &SplatBuffer| b.sums.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&direct), bits(&replayed));
        assert_eq!((direct.dropped, replayed.dropped), (6, 6));
    }
}
