//! The spectral type lights store, and its photometric normalisation
//! (pbrt-v4 `SpectrumToPhotometric`: ∫ ȳ(λ) s(λ) dλ without K_m; for an
//! RGB illuminant only its illuminant counts).

/// An emission spectrum as stored by lights.
pub type LightSpectrum = crate::spectrum::Spectrum;

/// pbrt-v4 `SpectrumToPhotometric`, used to normalise a light's spectrum to 1 nit.
pub fn spectrum_photometric(s: &LightSpectrum) -> f32 {
    crate::spectrum::spectrum_to_photometric(s)
}
