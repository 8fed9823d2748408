//! candela-core: the rendering core of candela.
//!
//! A plain scene description (from `candela-scene`) is turned into a
//! traceable [`scene`] (shapes in a BVH, materials, lights), which an
//! [`integrator`] renders onto a [`film`] through a [`camera`].

pub mod accel;
pub mod bsdf;
pub mod build;
pub mod camera;
pub mod display;
pub mod film;
pub mod image;
pub mod integrator;
pub mod interaction;
pub mod light;
pub mod material;
pub mod math;
pub mod measure;
pub mod measure_photons;
pub mod render;
pub mod sampler;
pub mod sampling;
pub mod scene;
pub mod shape;
pub mod spatial;
pub mod spectrum;
pub mod texture;
