//! BVH build time and incoherent closest-hit throughput on a ≥1M-triangle
//! displaced sphere generated in code.

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

use candela_core::accel::Bvh;
use candela_core::math::{Bounds3, Ray, Transform, Vec3};
use candela_core::sampling::{sample_uniform_sphere, Pcg32};
use candela_core::shape::{intersect_triangle, TriangleMesh};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::Vec2;
use std::time::Instant;

/// Latitude–longitude sphere with a bumpy radial displacement: 2·n² triangles.
fn displaced_sphere(n: u32) -> TriangleMesh {
    let mut p = Vec::new();
    for i in 0..=n {
        let theta = std::f32::consts::PI * i as f32 / n as f32;
        for j in 0..=n {
            let phi = 2.0 * std::f32::consts::PI * j as f32 / n as f32;
            let r = 1.0 + 0.05 * (23.0 * theta).sin() * (17.0 * phi).cos();
            p.push(
                r * Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                ),
            );
        }
    }
    let mut idx = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let a = i * (n + 1) + j;
            let (b, c, d) = (a + 1, a + n + 1, a + n + 2);
            idx.extend([a, c, b, b, c, d]);
        }
    }
    TriangleMesh::new(&Transform::IDENTITY, false, idx, p, None, None, None).unwrap()
}

/// Random origins inside the bounds, random directions.
fn incoherent_rays(b: &Bounds3, n: usize) -> Vec<Ray> {
    let mut r = Pcg32::new(1, 2);
    (0..n)
        .map(|_| {
            let o =
                b.min + b.diagonal() * Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32());
            Ray::new(
                o,
                sample_uniform_sphere(Vec2::new(r.uniform_f32(), r.uniform_f32())),
            )
        })
        .collect()
}

fn trace_all(bvh: &Bvh, mesh: &TriangleMesh, rays: &[Ray]) -> usize {
    rays.iter()
        .filter(|ray| {
            bvh.intersect(ray, f32::INFINITY, |i, ray, t_max| {
                let [p0, p1, p2] = mesh.positions(i);
                intersect_triangle(ray, t_max, p0, p1, p2).map(|h| h.t)
            })
            .is_some()
        })
        .count()
}

fn bench_bvh(c: &mut Criterion) {
    let mesh = displaced_sphere(720);
    let n_tris = mesh.triangle_count();
    let bounds: Vec<Bounds3> = (0..n_tris as u32)
        .map(|i| {
            let [a, b, c] = mesh.positions(i);
            Bounds3::from_points(a, b).union_point(c)
        })
        .collect();
    let t0 = Instant::now();
    let bvh = Bvh::build(&bounds);
    let build = t0.elapsed();
    println!(
        "BVH build: {n_tris} triangles, {} nodes, depth {}, {:.3} s on {} threads",
        bvh.node_count(),
        bvh.depth(),
        build.as_secs_f64(),
        rayon::current_num_threads()
    );
    let rays = incoherent_rays(&bvh.bounds(), 1 << 20);
    let t0 = Instant::now();
    let hits = trace_all(&bvh, &mesh, &rays);
    let secs = t0.elapsed().as_secs_f64();
    println!(
        "closest hit, 1 thread: {:.2} Mrays/s ({hits} of {} rays hit)",
        rays.len() as f64 / secs / 1e6,
        rays.len()
    );
    let batch = &rays[..1 << 16];
    let mut g = c.benchmark_group("bvh");
    g.sample_size(10)
        .throughput(Throughput::Elements(batch.len() as u64));
    g.bench_function("closest_hit_incoherent_1M_tris", |b| {
        b.iter(|| trace_all(&bvh, &mesh, batch))
    });
    g.finish();
}

criterion_group!(benches, bench_bvh);
criterion_main!(benches);
