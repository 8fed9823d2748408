//! candela-core: the rendering core of candela.
//!
//! A plain scene description (from `candela-scene`) is turned into a
//! traceable scene, which the integrators render onto a film.

pub mod accel;
pub mod bsdf;
pub mod camera;
pub mod film;
pub mod interaction;
pub mod light;
pub mod math;
pub mod sampler;
pub mod sampling;
pub mod shape;
pub mod spectrum;
