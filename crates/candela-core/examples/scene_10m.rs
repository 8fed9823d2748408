//! Builds a traceable scene of ten million triangles and reports build
//! time, BVH memory and the process's peak memory; see `bench/bvh_10m.sh`.
//!
//! `scene_10m [N]` uses the bench's displaced sphere with `2·N²` triangles
//! (N = 2237 by default: 10,008,338 triangles) as one mesh of opaque
//! triangle primitives, through [`Scene::new`] as the scene builder does.

#[path = "../benches/common/mod.rs"]
mod common;

use candela_core::light::LightSelection;
use candela_core::scene::{Primitive, Scene};
use candela_core::shape::{Shape, Triangle};
use common::bvh_scene::{displaced_sphere, incoherent_rays};
use std::sync::Arc;
use std::time::Instant;

/// The process's peak resident memory in bytes (Linux), or 0.
fn peak_rss() -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map_or(0, |kb| kb * 1024)
}

fn main() {
    let n: u32 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(2237);
    let t0 = Instant::now();
    let mesh = Arc::new(displaced_sphere(n));
    let prims: Vec<Primitive> = Triangle::all(&mesh)
        .into_iter()
        .map(|t| Primitive {
            shape: Shape::Triangle(t),
            material: None,
            area_light: None,
            alpha: None,
        })
        .collect();
    let n_tris = prims.len();
    let mesh_time = t0.elapsed().as_secs_f64();
    let before = peak_rss();
    let t0 = Instant::now();
    let scene = Scene::new(prims, Vec::new(), Vec::new(), LightSelection::Uniform);
    let build = t0.elapsed().as_secs_f64();
    let rays = incoherent_rays(&scene.bounds(), 1 << 16);
    let t0 = Instant::now();
    let hits = rays
        .iter()
        .filter(|r| scene.intersect(r, f32::INFINITY).is_some())
        .count();
    let trace = t0.elapsed().as_secs_f64();
    let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
    println!(
        "{n_tris} triangles: mesh and primitives {mesh_time:.1} s, peak {:.2} GiB before the scene",
        gib(before)
    );
    println!(
        "Scene::new (BVH build) {build:.1} s on {} threads; BVH {:.1} bytes/triangle; primitive {} bytes",
        rayon::current_num_threads(),
        scene.bvh_memory_bytes() as f64 / n_tris as f64,
        std::mem::size_of::<Primitive>()
    );
    println!(
        "peak resident memory {:.2} GiB; {} of {} closest-hit rays hit, {:.2} Mrays/s on 1 thread",
        gib(peak_rss()),
        hits,
        rays.len(),
        rays.len() as f64 / trace / 1e6
    );
}
