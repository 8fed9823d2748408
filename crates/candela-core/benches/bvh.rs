//! BVH build time, memory and incoherent closest-hit and any-hit throughput
//! on a ≥1M-triangle displaced sphere generated in code.
//!
//! `cargo bench -p candela-core --bench bvh`; `bench/bvh_vs_embree.py`
//! compares the same mesh and rays against Embree.

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

mod common;

use common::bvh_scene::{displaced_sphere, incoherent_rays, mesh_bvh, trace_any, trace_closest};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::time::Instant;

fn bench_bvh(c: &mut Criterion) {
    let mesh = displaced_sphere(720);
    let n_tris = mesh.triangle_count();
    let t0 = Instant::now();
    let bvh = mesh_bvh(&mesh);
    let build = t0.elapsed();
    println!(
        "BVH build: {n_tris} triangles, {} nodes, depth {}, {:.3} s on {} threads, {:.1} bytes/triangle",
        bvh.node_count(),
        bvh.depth(),
        build.as_secs_f64(),
        rayon::current_num_threads(),
        bvh.memory_bytes() as f64 / n_tris as f64
    );
    let rays = incoherent_rays(&bvh.bounds(), 1 << 20);
    for (name, trace) in [
        ("closest hit", trace_closest as fn(_, _) -> usize),
        ("any hit", trace_any),
    ] {
        let t0 = Instant::now();
        let hits = trace(&bvh, &rays);
        let secs = t0.elapsed().as_secs_f64();
        println!(
            "{name}, 1 thread: {:.2} Mrays/s ({hits} of {} rays hit)",
            rays.len() as f64 / secs / 1e6,
            rays.len()
        );
    }
    let batch = &rays[..1 << 16];
    let mut g = c.benchmark_group("bvh");
    g.sample_size(10)
        .throughput(Throughput::Elements(batch.len() as u64));
    g.bench_function("closest_hit_incoherent_1M_tris", |b| {
        b.iter(|| trace_closest(&bvh, batch))
    });
    g.bench_function("any_hit_incoherent_1M_tris", |b| {
        b.iter(|| trace_any(&bvh, batch))
    });
    g.finish();
}

criterion_group!(benches, bench_bvh);
criterion_main!(benches);
