//! Measured spectral tables (generated; see each file's header).

pub mod cie;
pub mod daylight;
pub mod metals;
pub mod swatches;
