//! candela-core: the rendering core of candela.
//!
//! A plain scene description (from `candela-scene`) is turned into a
//! traceable scene, which the integrators render onto a film.

pub mod bsdf;
pub mod interaction;
pub mod light;
pub mod math;
pub mod sampling;
pub mod spectrum;
