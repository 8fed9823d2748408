//! The BVH bench's mesh and rays, for `bench/bvh_vs_embree.py`.
//!
//! `bvh_peer DIR` writes `DIR/vertices.f32` (x y z per vertex),
//! `DIR/triangles.u32` (three indices per triangle) and `DIR/rays.f32`
//! (origin and direction per ray), little-endian, then prints the build time
//! and memory and serves timing requests on stdin, one per line:
//! `closest THREADS` or `any THREADS` traces every ray and prints
//! `SECONDS HITS`. So a driver can interleave candela and a peer on the same
//! data. `bvh_peer --stats` prints the BVH's shape instead.

#[path = "../benches/common/mod.rs"]
mod common;

use common::bvh_scene::{displaced_sphere, incoherent_rays, mesh_bvh, trace_any, trace_closest};
use rayon::prelude::*;
use std::io::{BufRead, Write};
use std::time::Instant;

/// Rays per request.
const RAYS: usize = 1 << 20;

fn main() -> std::io::Result<()> {
    let arg = std::env::args().nth(1).unwrap_or_default();
    let mesh = displaced_sphere(720);
    let t0 = Instant::now();
    let bvh = mesh_bvh(&mesh);
    let build = t0.elapsed().as_secs_f64();
    let rays = incoherent_rays(&bvh.bounds(), RAYS);
    let n_tris = mesh.triangle_count();
    println!(
        "build {build:.3} s on {} threads, {} nodes, {:.1} bytes/triangle, {n_tris} triangles",
        rayon::current_num_threads(),
        bvh.node_count(),
        bvh.memory_bytes() as f64 / n_tris as f64
    );
    if arg == "--stats" {
        let leaves = bvh.leaf_items();
        let mut hist = [0usize; 9];
        for l in &leaves {
            hist[l.len().min(8)] += 1;
        }
        println!("{} leaves, sizes 1..=8: {:?}", leaves.len(), &hist[1..]);
        return Ok(());
    }
    if arg == "--profile" {
        // An optional ray count, for runs under valgrind.
        let n = std::env::args()
            .nth(2)
            .and_then(|s| s.parse().ok())
            .unwrap_or(RAYS);
        let rays = &rays[..n.min(RAYS)];
        let t0 = Instant::now();
        let hits = trace_closest(&bvh, rays);
        println!("closest {:.3} s {hits}", t0.elapsed().as_secs_f64());
        let t0 = Instant::now();
        let hits = trace_any(&bvh, rays);
        println!("any {:.3} s {hits}", t0.elapsed().as_secs_f64());
        return Ok(());
    }
    let dir = std::path::Path::new(&arg);
    std::fs::create_dir_all(dir)?;
    let bytes = |v: &mut dyn Iterator<Item = [u8; 4]>| v.flatten().collect::<Vec<u8>>();
    let verts = mesh
        .p
        .iter()
        .flat_map(|p| p.to_array())
        .map(f32::to_le_bytes);
    std::fs::write(dir.join("vertices.f32"), bytes(&mut verts.into_iter()))?;
    let tris = mesh.indices.iter().map(|i| i.to_le_bytes());
    std::fs::write(dir.join("triangles.u32"), bytes(&mut tris.into_iter()))?;
    let r = rays
        .iter()
        .flat_map(|r| [r.o.to_array(), r.d.to_array()].concat());
    std::fs::write(dir.join("rays.f32"), bytes(&mut r.map(f32::to_le_bytes)))?;
    println!("ready");
    std::io::stdout().flush()?;
    for line in std::io::stdin().lock().lines() {
        let line = line?;
        let mut words = line.split_whitespace();
        let (Some(kind), Some(threads)) = (words.next(), words.next()) else {
            continue;
        };
        let threads: usize = threads.parse().unwrap_or(1);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(std::io::Error::other)?;
        let trace = if kind == "any" {
            trace_any
        } else {
            trace_closest
        };
        let t0 = Instant::now();
        let hits: usize = pool.install(|| rays.par_chunks(4096).map(|c| trace(&bvh, c)).sum());
        println!("{:.6} {hits}", t0.elapsed().as_secs_f64());
        std::io::stdout().flush()?;
    }
    Ok(())
}
