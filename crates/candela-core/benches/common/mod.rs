//! Code shared by the benches and the examples.

pub mod bvh_scene;
