//! Measured spectral tables (generated; see each file's header).

pub mod cie;
pub mod daylight;
pub mod dielectrics;
pub mod fluorescent;
pub mod metals;
pub mod swatches;
