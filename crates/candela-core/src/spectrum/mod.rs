//! Spectral representation: sampled spectra carried by paths, spectrum
//! functions of wavelength, colour spaces and the camera sensor.
//!
//! Paths carry [`SampledSpectrum`] values at four wavelengths. Scene inputs
//! become [`Spectrum`] functions: constants, measured tables (CIE
//! illuminants), closed forms (Planck blackbody, Sellmeier glass) and RGB
//! values lifted by the sigmoid-polynomial model of Jakob & Hanika 2019, as
//! pbrt-v4 does (albedo, unbounded and illuminant kinds). The film turns
//! sampled radiance into sensor RGB: XYZ through the CIE 1931 2° observer,
//! or a measured camera's responses with a fitted XYZ matrix (`sensor`).

mod color;
mod data;
mod daylight;
mod named;
mod rgb2spec;
mod rgb2spec_table;
mod sampled;
mod sensor;
mod spectra;

pub use color::{white_balance, ColorSpace, Rgb, Xyz};
pub use daylight::{daylight, daylight_cct, daylight_xy};
pub use named::named_spectrum;
pub use rgb2spec::RgbSigmoidPolynomial;
pub use rgb2spec_table::{RgbToSpectrumTable, TABLE_RES};
pub use sampled::*;
pub use sensor::{cameras, sensor_names, CameraCurves, PixelSensor, UnknownSensor};
pub use spectra::{
    inner_product, planck, spectrum_to_photometric, spectrum_to_xyz, PiecewiseLinear, Spectrum,
    SpectrumKind,
};

/// Σ ȳ(λ) over 360–830 nm at 1 nm: the normaliser of XYZ (pbrt-v4's `CIE_Y_integral`).
pub const CIE_Y_INTEGRAL: f32 = 106.856_895;
/// Maximum luminous efficacy [lm/W].
pub const K_M: f32 = 683.0;

/// CIE 1931 colour-matching functions at wavelength `lambda` \[nm\] (linear between 1 nm samples).
pub fn cie_xyz(lambda: f32) -> [f32; 3] {
    if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
        return [0.0; 3];
    }
    let x = lambda - LAMBDA_MIN;
    let i = (x as usize).min(data::cie::CIE_X.len() - 2);
    let t = x - i as f32;
    let f = |a: &[f32; 471]| a[i] + t * (a[i + 1] - a[i]);
    [
        f(&data::cie::CIE_X),
        f(&data::cie::CIE_Y),
        f(&data::cie::CIE_Z),
    ]
}

/// [`cie_xyz`] at the path's wavelengths: the same interpolation, with the
/// indices, table reads and arithmetic each done for all lanes at once.
#[inline]
pub fn cie_xyz_sampled(lambda: &[f32; N_SPECTRUM_SAMPLES]) -> [[f32; 3]; N_SPECTRUM_SAMPLES] {
    use data::cie::{CIE_X, CIE_Y, CIE_Z};
    let last = CIE_X.len() - 2;
    let mut idx = [0usize; N_SPECTRUM_SAMPLES];
    let mut t = [0.0f32; N_SPECTRUM_SAMPLES];
    for k in 0..N_SPECTRUM_SAMPLES {
        let x = lambda[k] - LAMBDA_MIN;
        // Below the range (or NaN) the index saturates to 0 and the lane is
        // zeroed below; in range `as i32` agrees with `cie_xyz`'s `as usize`.
        idx[k] = (x as i32).clamp(0, last as i32) as usize;
        t[k] = x - idx[k] as f32;
    }
    let mut out = [[0.0f32; 3]; N_SPECTRUM_SAMPLES];
    for k in 0..N_SPECTRUM_SAMPLES {
        let i = idx[k];
        let f = |a: &[f32; 471]| a[i] + t[k] * (a[i + 1] - a[i]);
        if (LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda[k]) {
            out[k] = [f(&CIE_X), f(&CIE_Y), f(&CIE_Z)];
        }
    }
    out
}

/// The photometric value of a spectral estimate at sampled wavelengths:
/// K_m·(1/N) Σ_k ȳ(λ_k)·e_k/p(λ_k), with V(λ) = ȳ(λ) un-normalised (ȳ(555) = 1,
/// *not* divided by ∫ȳ as pbrt-v4's sensor Y is). Radiance in W/(m²·sr·nm)
/// gives cd/m², irradiance lx; terminated wavelengths (pdf 0) count 0.
pub fn luminous(e: &SampledSpectrum, lambda: &SampledWavelengths) -> f64 {
    let pdf = lambda.pdf();
    let n = lambda.lambdas().len();
    let y: f64 = (0..n)
        .filter(|&k| pdf[k] > 0.0)
        .map(|k| cie_xyz(lambda.lambda(k))[1] as f64 * e[k] as f64 / pdf[k] as f64)
        .sum();
    K_M as f64 * y / n as f64
}

#[cfg(test)]
mod sensor_tests;
#[cfg(test)]
mod tests;
