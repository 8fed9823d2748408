//! Code shared by the benches and the examples.

// Each bench or example uses a part of it.
#![allow(dead_code)]

pub mod bvh_scene;
