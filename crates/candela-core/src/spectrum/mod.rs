//! Spectral representation: sampled spectra, spectrum functions, colour.

mod sampled;

pub use sampled::*;
