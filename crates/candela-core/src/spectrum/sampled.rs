//! Point-sampled spectra: the per-path spectral quantity.
//!
//! Every camera sample carries [`N_SPECTRUM_SAMPLES`] wavelengths drawn by
//! [`SampledWavelengths::sample_visible`]: one "hero" wavelength from the
//! visible-importance density of pbrt-v4 and the others at equal offsets in
//! the sample space (stratified rotation) [Wilkie et al. 2014; pbrt-v4 §4.6.5].

use std::ops::{Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Neg, Sub};

/// Number of wavelengths carried by each path.
pub const N_SPECTRUM_SAMPLES: usize = 4;
/// Shortest wavelength considered by the renderer \[nm\].
pub const LAMBDA_MIN: f32 = 360.0;
/// Longest wavelength considered by the renderer \[nm\].
pub const LAMBDA_MAX: f32 = 830.0;

/// Values of a spectral quantity at the path's sampled wavelengths.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct SampledSpectrum(pub [f32; N_SPECTRUM_SAMPLES]);

impl SampledSpectrum {
    /// All samples set to `v`.
    #[inline]
    pub const fn splat(v: f32) -> Self {
        Self([v; N_SPECTRUM_SAMPLES])
    }
    /// The zero spectrum.
    #[inline]
    pub const fn zero() -> Self {
        Self::splat(0.0)
    }
    /// The unit spectrum.
    #[inline]
    pub const fn one() -> Self {
        Self::splat(1.0)
    }
    /// Builds from a per-sample function.
    #[inline]
    pub fn from_fn(f: impl FnMut(usize) -> f32) -> Self {
        Self(std::array::from_fn(f))
    }
    /// Applies `f` to every sample.
    #[inline]
    pub fn map(self, mut f: impl FnMut(f32) -> f32) -> Self {
        Self::from_fn(|i| f(self.0[i]))
    }
    /// True when every sample is exactly zero.
    #[inline]
    pub fn is_black(&self) -> bool {
        // `&` rather than `&&`: four compares and no branches.
        let [a, b, c, d] = self.0;
        (a == 0.0) & (b == 0.0) & (c == 0.0) & (d == 0.0)
    }
    /// True when any sample is NaN or infinite.
    #[inline]
    pub fn has_non_finite(&self) -> bool {
        let [a, b, c, d] = self.0;
        !(a.is_finite() & b.is_finite() & c.is_finite() & d.is_finite())
    }
    /// Arithmetic mean of the samples.
    #[inline]
    pub fn average(&self) -> f32 {
        self.0.iter().sum::<f32>() / N_SPECTRUM_SAMPLES as f32
    }
    /// Largest sample.
    #[inline]
    pub fn max_component(&self) -> f32 {
        self.0.iter().copied().fold(f32::NEG_INFINITY, f32::max)
    }
    /// Smallest sample.
    #[inline]
    pub fn min_component(&self) -> f32 {
        self.0.iter().copied().fold(f32::INFINITY, f32::min)
    }
    /// Per-sample division that yields 0 where the divisor is 0.
    #[inline]
    pub fn safe_div(self, d: Self) -> Self {
        Self::from_fn(|i| {
            if d.0[i] != 0.0 {
                self.0[i] / d.0[i]
            } else {
                0.0
            }
        })
    }
    /// Per-sample square root.
    #[inline]
    pub fn sqrt(self) -> Self {
        self.map(f32::sqrt)
    }
    /// Per-sample exponential.
    #[inline]
    pub fn exp(self) -> Self {
        self.map(f32::exp)
    }
    /// Clamps every sample to `[lo, hi]`.
    #[inline]
    pub fn clamp(self, lo: f32, hi: f32) -> Self {
        self.map(|v| v.clamp(lo, hi))
    }
}

macro_rules! impl_binop {
    ($tr:ident, $f:ident, $tra:ident, $fa:ident, $op:tt) => {
        impl $tr for SampledSpectrum {
            type Output = Self;
            #[inline]
            fn $f(self, r: Self) -> Self {
                Self::from_fn(|i| self.0[i] $op r.0[i])
            }
        }
        impl $tr<f32> for SampledSpectrum {
            type Output = Self;
            #[inline]
            fn $f(self, r: f32) -> Self {
                Self::from_fn(|i| self.0[i] $op r)
            }
        }
        impl $tra for SampledSpectrum {
            #[inline]
            fn $fa(&mut self, r: Self) {
                *self = *self $op r;
            }
        }
        impl $tra<f32> for SampledSpectrum {
            #[inline]
            fn $fa(&mut self, r: f32) {
                *self = *self $op r;
            }
        }
    };
}
impl_binop!(Add, add, AddAssign, add_assign, +);
impl_binop!(Mul, mul, MulAssign, mul_assign, *);
impl_binop!(Div, div, DivAssign, div_assign, /);

impl Sub for SampledSpectrum {
    type Output = Self;
    #[inline]
    fn sub(self, r: Self) -> Self {
        Self::from_fn(|i| self.0[i] - r.0[i])
    }
}
impl Neg for SampledSpectrum {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        self.map(|v| -v)
    }
}
impl Mul<SampledSpectrum> for f32 {
    type Output = SampledSpectrum;
    #[inline]
    fn mul(self, s: SampledSpectrum) -> SampledSpectrum {
        s * self
    }
}
impl Index<usize> for SampledSpectrum {
    type Output = f32;
    #[inline]
    fn index(&self, i: usize) -> &f32 {
        &self.0[i]
    }
}
impl IndexMut<usize> for SampledSpectrum {
    #[inline]
    fn index_mut(&mut self, i: usize) -> &mut f32 {
        &mut self.0[i]
    }
}

/// The wavelengths a path carries and the density they were drawn with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampledWavelengths {
    lambda: [f32; N_SPECTRUM_SAMPLES],
    pdf: [f32; N_SPECTRUM_SAMPLES],
}

impl SampledWavelengths {
    /// Uniform stratified sampling over `[lambda_min, lambda_max]`.
    pub fn sample_uniform(u: f32, lambda_min: f32, lambda_max: f32) -> Self {
        let span = lambda_max - lambda_min;
        let l0 = lambda_min + u * span;
        let delta = span / N_SPECTRUM_SAMPLES as f32;
        let mut lambda = [l0; N_SPECTRUM_SAMPLES];
        for i in 1..N_SPECTRUM_SAMPLES {
            lambda[i] = lambda[i - 1] + delta;
            if lambda[i] > lambda_max {
                lambda[i] = lambda_min + (lambda[i] - lambda_max);
            }
        }
        Self {
            lambda,
            pdf: [1.0 / span; N_SPECTRUM_SAMPLES],
        }
    }

    /// Hero-style stratified sampling of the visible-importance density
    /// p(λ) ∝ sech²(0.0072 (λ − 538)) on 360–830 nm [pbrt-v4 §5.4.2,
    /// `SampleVisibleWavelengths`]: the four samples are `u + i/4` (mod 1).
    pub fn sample_visible(u: f32) -> Self {
        let mut lambda = [0.0; N_SPECTRUM_SAMPLES];
        let mut pdf = [0.0; N_SPECTRUM_SAMPLES];
        for i in 0..N_SPECTRUM_SAMPLES {
            let mut up = u + i as f32 / N_SPECTRUM_SAMPLES as f32;
            if up > 1.0 {
                up -= 1.0;
            }
            (lambda[i], pdf[i]) = sample_visible_wavelength_with_pdf(up);
        }
        Self { lambda, pdf }
    }

    /// Builds from explicit wavelengths and densities (tests, photometry).
    pub fn from_parts(lambda: [f32; N_SPECTRUM_SAMPLES], pdf: [f32; N_SPECTRUM_SAMPLES]) -> Self {
        Self { lambda, pdf }
    }

    /// Wavelength `i` \[nm\].
    #[inline]
    pub fn lambda(&self, i: usize) -> f32 {
        self.lambda[i]
    }
    /// All wavelengths \[nm\].
    #[inline]
    pub fn lambdas(&self) -> &[f32; N_SPECTRUM_SAMPLES] {
        &self.lambda
    }
    /// Densities of the wavelengths, as a spectrum (zero once terminated).
    #[inline]
    pub fn pdf(&self) -> SampledSpectrum {
        SampledSpectrum(self.pdf)
    }
    /// Keeps only the hero wavelength (after wavelength-dependent refraction):
    /// the others get pdf 0 and the hero's pdf is divided by the count.
    pub fn terminate_secondary(&mut self) {
        if self.secondary_terminated() {
            return;
        }
        for i in 1..N_SPECTRUM_SAMPLES {
            self.pdf[i] = 0.0;
        }
        self.pdf[0] /= N_SPECTRUM_SAMPLES as f32;
    }
    /// True once only the hero wavelength remains.
    #[inline]
    pub fn secondary_terminated(&self) -> bool {
        self.pdf[1..].iter().all(|&p| p == 0.0)
    }
}

/// Density of [`sample_visible_wavelength`] [1/nm] (0 outside 360–830 nm).
pub fn visible_wavelength_pdf(lambda: f32) -> f32 {
    if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
        return 0.0;
    }
    let c = (0.0072 * (lambda - 538.0)).cosh();
    0.003_939_804 / (c * c)
}

/// Inverts the CDF of [`visible_wavelength_pdf`] [pbrt-v4 `SampleVisibleWavelengths`].
pub fn sample_visible_wavelength(u: f32) -> f32 {
    sample_visible_wavelength_with_pdf(u).0
}

/// [`sample_visible_wavelength`] and its density in one step: with
/// y = 0.8569106 − 1.827502 u, λ = 538 − 138.88889 atanh y, and since
/// 0.0072 · 138.88889 = 1, cosh(0.0072(λ − 538)) = cosh(atanh y) = 1/√(1 − y²),
/// so the density 0.003939804 / cosh²(…) is 0.003939804 (1 − y²): no
/// hyperbolic cosine per wavelength. atanh y is taken as ½ ln((1 + y)/(1 − y))
/// (one `ln`, cheaper than the `log1p` inside `f32::atanh`; y ∈ [−0.971,
/// 0.857] keeps both factors away from 0, so the quotient loses at most an
/// ulp and λ moves by under 10⁻⁴ nm).
#[inline]
pub fn sample_visible_wavelength_with_pdf(u: f32) -> (f32, f32) {
    let y = 0.856_910_6 - 1.827_502 * u;
    let lambda = 538.0 - 69.444_44 * ((1.0 + y) / (1.0 - y)).ln();
    (lambda, 0.003_939_804 * (1.0 - y * y))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visible_pdf_integrates_to_one() {
        let n = 47_000;
        let h = (LAMBDA_MAX - LAMBDA_MIN) / n as f32;
        let s: f64 = (0..n)
            .map(|i| visible_wavelength_pdf(LAMBDA_MIN + (i as f32 + 0.5) * h) as f64 * h as f64)
            .sum();
        assert!((s - 1.0).abs() < 1e-3, "integral {s}");
    }

    #[test]
    fn visible_sampling_inverts_cdf() {
        // CDF(sample(u)) == u, checked by quadrature of the pdf.
        for &u in &[0.05f32, 0.3, 0.5, 0.77, 0.95] {
            let l = sample_visible_wavelength(u);
            let n = 20_000;
            let h = (l - LAMBDA_MIN) / n as f32;
            let cdf: f32 = (0..n)
                .map(|i| visible_wavelength_pdf(LAMBDA_MIN + (i as f32 + 0.5) * h) * h)
                .sum();
            assert!((cdf - u).abs() < 2e-3, "u={u} cdf={cdf}");
        }
    }

    #[test]
    fn sampled_density_is_the_pdf_at_the_sampled_wavelength() {
        // u ∈ [0, 1): the samplers' range (at u = 1 λ rounds to 830.00006).
        for i in 0..1000 {
            let u = i as f32 / 1000.0;
            let (l, p) = sample_visible_wavelength_with_pdf(u);
            let q = visible_wavelength_pdf(l);
            assert!((p - q).abs() <= 2e-6 * q, "u={u} λ={l} {p} vs {q}");
        }
    }

    #[test]
    fn terminate_secondary_keeps_expectation() {
        let mut w = SampledWavelengths::sample_visible(0.3);
        let p0 = w.pdf()[0];
        w.terminate_secondary();
        assert!(w.secondary_terminated());
        assert_eq!(w.pdf()[0], p0 / 4.0);
        assert_eq!(w.pdf()[1], 0.0);
    }
}
