//! Textures: float and spectrum values that vary over surfaces.
//!
//! Only constant textures exist so far; image and procedural textures plug
//! in as further enum variants evaluated from the hit's (u, v) and position.

use crate::interaction::SurfaceInteraction;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};

/// A scalar texture.
#[derive(Clone, Debug)]
pub enum FloatTexture {
    /// The same value everywhere.
    Constant(f32),
}

impl FloatTexture {
    /// Value at a hit.
    #[inline]
    pub fn evaluate(&self, _si: &SurfaceInteraction) -> f32 {
        match self {
            FloatTexture::Constant(v) => *v,
        }
    }
}

/// A spectral texture.
#[derive(Clone, Debug)]
pub enum SpectrumTexture {
    /// The same spectrum everywhere.
    Constant(Spectrum),
}

impl SpectrumTexture {
    /// Value at a hit for the path's wavelengths.
    #[inline]
    pub fn evaluate(
        &self,
        _si: &SurfaceInteraction,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        match self {
            SpectrumTexture::Constant(s) => s.sample(lambda),
        }
    }
}
