//! Acceleration structures for ray queries over many primitives.

mod bvh;
#[cfg(test)]
mod tests;

pub use bvh::Bvh;
