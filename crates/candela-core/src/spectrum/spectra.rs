//! Spectrum functions of wavelength and their integrals.

use super::color::ColorSpace;
use super::rgb2spec::RgbSigmoidPolynomial;
use super::{
    cie_xyz, Rgb, SampledSpectrum, SampledWavelengths, Xyz, CIE_Y_INTEGRAL, LAMBDA_MAX, LAMBDA_MIN,
    N_SPECTRUM_SAMPLES,
};
use std::sync::Arc;

/// A piecewise-linear function through sorted (λ, value) samples, zero outside.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseLinear {
    lambda: Vec<f32>,
    values: Vec<f32>,
    /// (first λ, 1/step) when the samples are evenly spaced: O(1) lookup.
    even: Option<(f32, f32)>,
    /// (λᵢ, λᵢ₊₁, vᵢ, vᵢ₊₁) of every interval, so an evaluation reads one
    /// 16-byte record (the same numbers as `lambda` and `values`).
    segments: Vec<[f32; 4]>,
}

impl PiecewiseLinear {
    /// From sorted pairs.
    pub fn new(pairs: &[(f32, f32)]) -> Self {
        let lambda: Vec<f32> = pairs.iter().map(|p| p.0).collect();
        let step = if lambda.len() > 1 {
            lambda[1] - lambda[0]
        } else {
            0.0
        };
        let is_even = step > 0.0
            && lambda
                .windows(2)
                .all(|w| ((w[1] - w[0]) - step).abs() <= 1e-4 * step);
        let values: Vec<f32> = pairs.iter().map(|p| p.1).collect();
        Self {
            even: is_even.then(|| (lambda[0], 1.0 / step)),
            segments: segments(&lambda, &values),
            lambda,
            values,
        }
    }
    /// From evenly spaced values starting at `start` with step `step` \[nm\].
    pub fn from_even(start: f32, step: f32, values: &[f32]) -> Self {
        let lambda: Vec<f32> = (0..values.len()).map(|i| start + step * i as f32).collect();
        Self {
            segments: segments(&lambda, values),
            lambda,
            values: values.to_vec(),
            even: (step > 0.0).then(|| (start, 1.0 / step)),
        }
    }
    /// Value at `l`.
    pub fn eval(&self, l: f32) -> f32 {
        let n = self.lambda.len();
        if n == 0 || l < self.lambda[0] || l > self.lambda[n - 1] {
            return 0.0;
        }
        let i = match self.even {
            Some((start, inv_step)) => (((l - start) * inv_step) as usize).min(n.saturating_sub(2)),
            None => self.lambda.partition_point(|&x| x <= l).clamp(1, n - 1) - 1,
        };
        if n == 1 {
            return self.values[0];
        }
        lerp_segment(&self.segments[i], l)
    }
    /// Values at the path's wavelengths: [`Self::eval`] lane by lane (the
    /// same arithmetic), with the table checks made once.
    #[inline]
    pub fn sample(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        let n = self.lambda.len();
        let Some((start, inv_step)) = self.even.filter(|_| n >= 2) else {
            return SampledSpectrum::from_fn(|i| self.eval(lambda.lambda(i)));
        };
        let (lo, hi) = (self.lambda[0], self.lambda[n - 1]);
        let last = n as i32 - 2;
        let l = lambda.lambdas();
        // Three passes over the lanes (indices, reads, arithmetic) so that the
        // first and last run as vector instructions. Lanes outside the table
        // read segment 0 and are zeroed at the end.
        let mut seg = [0usize; N_SPECTRUM_SAMPLES];
        for k in 0..N_SPECTRUM_SAMPLES {
            // In range the index is ≥ 0, so `as i32` agrees with `as usize`.
            seg[k] = (((l[k] - start) * inv_step) as i32).clamp(0, last) as usize;
        }
        let s = seg.map(|i| self.segments[i]);
        let mut out = [0.0f32; N_SPECTRUM_SAMPLES];
        for k in 0..N_SPECTRUM_SAMPLES {
            let v = lerp_segment(&s[k], l[k]);
            out[k] = if l[k] < lo || l[k] > hi { 0.0 } else { v };
        }
        SampledSpectrum(out)
    }
    /// Scales all values.
    pub fn scaled(mut self, s: f32) -> Self {
        self.values.iter_mut().for_each(|v| *v *= s);
        self.segments = segments(&self.lambda, &self.values);
        self
    }
    /// The (λ, value) samples.
    pub fn samples(&self) -> impl Iterator<Item = (f32, f32)> + '_ {
        self.lambda.iter().copied().zip(self.values.iter().copied())
    }
    /// Largest value.
    pub fn max_value(&self) -> f32 {
        self.values.iter().copied().fold(0.0, f32::max)
    }
}

/// The (λᵢ, λᵢ₊₁, vᵢ, vᵢ₊₁) records of [`PiecewiseLinear::segments`].
fn segments(lambda: &[f32], values: &[f32]) -> Vec<[f32; 4]> {
    (1..lambda.len())
        .map(|i| [lambda[i - 1], lambda[i], values[i - 1], values[i]])
        .collect()
}

/// Linear interpolation within one segment at `l`.
#[inline]
fn lerp_segment(&[l0, l1, v0, v1]: &[f32; 4], l: f32) -> f32 {
    let t = if l1 > l0 { (l - l0) / (l1 - l0) } else { 0.0 };
    v0 + t * (v1 - v0)
}

/// How an RGB value is lifted to a spectrum [pbrt-v4 `SpectrumType`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SpectrumKind {
    /// Reflectances in [0, 1].
    Albedo,
    /// Any non-negative value (η, k, scattering coefficients).
    Unbounded,
    /// Emission: RGB × the colour space's illuminant.
    Illuminant,
}

/// A spectral distribution: emission, reflectance or index of refraction.
#[derive(Clone, Debug)]
pub enum Spectrum {
    /// The same value at every wavelength.
    Constant(f32),
    /// Tabulated, linearly interpolated.
    PiecewiseLinear(Arc<PiecewiseLinear>),
    /// Planck's law at temperature `t` \[K\], scaled so its peak is 1 (pbrt-v4 `BlackbodySpectrum`).
    Blackbody {
        /// Temperature \[K\].
        t: f32,
        /// 1 / peak radiance.
        normalization: f32,
    },
    /// Reflectance from RGB: s(λ) ∈ [0, 1].
    RgbAlbedo(RgbSigmoidPolynomial),
    /// Unbounded RGB: scale · s(λ).
    RgbUnbounded {
        /// Sigmoid polynomial of rgb / scale.
        poly: RgbSigmoidPolynomial,
        /// 2 · max(r, g, b).
        scale: f32,
    },
    /// Emission from RGB: scale · s(λ) · illuminant(λ) of the colour space.
    RgbIlluminant {
        /// Sigmoid polynomial of rgb / scale.
        poly: RgbSigmoidPolynomial,
        /// 2 · max(r, g, b).
        scale: f32,
        /// The colour space's (normalised) standard illuminant.
        illuminant: Arc<PiecewiseLinear>,
    },
}

impl Spectrum {
    /// Value at wavelength `lambda` \[nm\].
    pub fn eval(&self, lambda: f32) -> f32 {
        match self {
            Spectrum::Constant(c) => *c,
            Spectrum::PiecewiseLinear(p) => p.eval(lambda),
            Spectrum::Blackbody { t, normalization } => planck(lambda, *t) * normalization,
            Spectrum::RgbAlbedo(p) => p.eval(lambda),
            Spectrum::RgbUnbounded { poly, scale } => scale * poly.eval(lambda),
            Spectrum::RgbIlluminant {
                poly,
                scale,
                illuminant,
            } => scale * poly.eval(lambda) * illuminant.eval(lambda),
        }
    }
    /// Values at the path's wavelengths: one `match` for all of them, each
    /// variant evaluating its lanes together with the arithmetic of
    /// [`Self::eval`] (so the same values).
    #[inline]
    pub fn sample(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Spectrum::Constant(c) => SampledSpectrum::splat(*c),
            Spectrum::PiecewiseLinear(p) => p.sample(lambda),
            Spectrum::RgbAlbedo(p) => p.sample(lambda),
            Spectrum::RgbUnbounded { poly, scale } => poly.sample(lambda) * *scale,
            Spectrum::RgbIlluminant {
                poly,
                scale,
                illuminant,
            } => (poly.sample(lambda) * *scale) * illuminant.sample(lambda),
            Spectrum::Blackbody { .. } => SampledSpectrum::from_fn(|i| self.eval(lambda.lambda(i))),
        }
    }
    /// An upper bound of the function.
    pub fn max_value(&self) -> f32 {
        match self {
            Spectrum::Constant(c) => *c,
            Spectrum::PiecewiseLinear(p) => p.max_value(),
            Spectrum::Blackbody { .. } => 1.0,
            Spectrum::RgbAlbedo(p) => p.max_value(),
            Spectrum::RgbUnbounded { poly, scale } => scale * poly.max_value(),
            Spectrum::RgbIlluminant {
                poly,
                scale,
                illuminant,
            } => scale * poly.max_value() * illuminant.max_value(),
        }
    }
    /// Reflectance spectrum of an RGB in [0, 1]³.
    pub fn rgb_albedo(cs: &'static ColorSpace, rgb: Rgb) -> Spectrum {
        Spectrum::RgbAlbedo(cs.to_rgb_coeffs(rgb))
    }
    /// Unbounded spectrum of a non-negative RGB.
    pub fn rgb_unbounded(cs: &'static ColorSpace, rgb: Rgb) -> Spectrum {
        let (poly, scale) = scaled_coeffs(cs, rgb);
        Spectrum::RgbUnbounded { poly, scale }
    }
    /// Emission spectrum of a non-negative RGB (× the colour space's illuminant).
    pub fn rgb_illuminant(cs: &'static ColorSpace, rgb: Rgb) -> Spectrum {
        let (poly, scale) = scaled_coeffs(cs, rgb);
        Spectrum::RgbIlluminant {
            poly,
            scale,
            illuminant: cs.illuminant_table.clone(),
        }
    }
    /// Normalised blackbody emitter.
    pub fn blackbody(t: f32) -> Spectrum {
        // Wien's displacement law gives the peak [pbrt-v4 §4.4.2].
        let lambda_max = 2.897_772e-3 / t * 1e9;
        Spectrum::Blackbody {
            t,
            normalization: 1.0 / planck(lambda_max, t),
        }
    }
    /// Tabulated spectrum from (λ, value) pairs.
    pub fn piecewise_linear(pairs: &[(f32, f32)]) -> Spectrum {
        Spectrum::PiecewiseLinear(Arc::new(PiecewiseLinear::new(pairs)))
    }
}

fn scaled_coeffs(cs: &'static ColorSpace, rgb: Rgb) -> (RgbSigmoidPolynomial, f32) {
    let m = rgb.r.max(rgb.g).max(rgb.b);
    let scale = 2.0 * m;
    let rgb = if scale > 0.0 {
        Rgb::new(rgb.r / scale, rgb.g / scale, rgb.b / scale)
    } else {
        Rgb::new(0.0, 0.0, 0.0)
    };
    (cs.to_rgb_coeffs(rgb), scale)
}

/// Blackbody spectral radiance at `lambda_nm` and temperature `t` \[K\] (Planck's law, W/(m²·sr·m)).
pub fn planck(lambda_nm: f32, t: f32) -> f32 {
    if t <= 0.0 {
        return 0.0;
    }
    let (c, h, kb) = (299_792_458.0f64, 6.626_069_57e-34f64, 1.380_648_8e-23f64);
    let l = lambda_nm as f64 * 1e-9;
    ((2.0 * h * c * c) / (l.powi(5) * (((h * c) / (l * kb * t as f64)).exp() - 1.0))) as f32
}

/// ∫ f g dλ over 360–830 nm at 1 nm steps (pbrt-v4 `InnerProduct`).
pub fn inner_product(f: impl Fn(f32) -> f32, g: impl Fn(f32) -> f32) -> f32 {
    let mut s = 0.0f64;
    let mut l = LAMBDA_MIN as i32;
    while l <= LAMBDA_MAX as i32 {
        s += f(l as f32) as f64 * g(l as f32) as f64;
        l += 1;
    }
    s as f32
}

/// XYZ of a spectrum (Y of the equal-energy unit spectrum = 1) [pbrt-v4 `SpectrumToXYZ`].
pub fn spectrum_to_xyz(s: &Spectrum) -> Xyz {
    let c = |k: usize| inner_product(|l| cie_xyz(l)[k], |l| s.eval(l)) / CIE_Y_INTEGRAL;
    Xyz {
        x: c(0),
        y: c(1),
        z: c(2),
    }
}

/// pbrt-v4 `SpectrumToPhotometric`: ∫ ȳ s dλ, using only the illuminant of an
/// RGB illuminant spectrum. Lights divide their scale by it so that
/// `scale = 1` means a luminance of 1 nit for a white source.
pub fn spectrum_to_photometric(s: &Spectrum) -> f32 {
    match s {
        Spectrum::RgbIlluminant { illuminant, .. } => {
            inner_product(|l| cie_xyz(l)[1], |l| illuminant.eval(l))
        }
        other => inner_product(|l| cie_xyz(l)[1], |l| other.eval(l)),
    }
}
