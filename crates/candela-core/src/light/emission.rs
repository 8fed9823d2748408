//! The spectral type lights store, and its photometric normalisation: the one
//! place to switch when the full `Spectrum` type lands.
//!
//! Interim: only constant spectra, with pbrt-v4's `SpectrumToPhotometric`
//! of a constant `c` = c·Σ_{λ=360}^{830} ȳ(λ) = c·106.856895.

use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Σ ȳ(λ) over 360–830 nm at 1 nm (pbrt-v4 `CIE_Y_integral`).
const CIE_Y_INTEGRAL: f32 = 106.856_895;

/// An emission spectrum as stored by lights.
#[derive(Clone, Debug, PartialEq)]
pub enum LightSpectrum {
    /// The same value at every wavelength.
    Constant(f32),
}

impl LightSpectrum {
    /// Values at the sampled wavelengths.
    #[inline]
    pub fn sample(&self, _lambda: &SampledWavelengths) -> SampledSpectrum {
        match self {
            LightSpectrum::Constant(c) => SampledSpectrum::splat(*c),
        }
    }
}

/// pbrt-v4 `SpectrumToPhotometric`: ∫ ȳ(λ) s(λ) dλ (no K_m), used to
/// normalise a light's spectrum to 1 nit.
pub fn spectrum_photometric(s: &LightSpectrum) -> f32 {
    match s {
        LightSpectrum::Constant(c) => c * CIE_Y_INTEGRAL,
    }
}
