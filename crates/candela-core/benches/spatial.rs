//! Build time and query time of the spatial structures on 1M points uniform
//! in the unit cube: kd-tree kNN (k = 50) and fixed-radius queries, hash-grid
//! fixed-radius queries, and kNN against the `kiddo` crate's immutable
//! kd-tree on the same points. The fixed radius holds 50 points on average.
//! Also the SPPM sphere grid: 1M spheres of that radius centred on the
//! points, queried with points (each inside 50 spheres on average).

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

use candela_core::sampling::Pcg32;
use candela_core::spatial::{HashGrid, Neighbor, PointKdTree, SphereGrid};
use criterion::{criterion_group, criterion_main, BatchSize, Criterion, SamplingMode, Throughput};
use glam::Vec3;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::hint::black_box;
use std::num::NonZero;
use std::time::Instant;

const N_POINTS: usize = 1_000_000;
const K: usize = 50;
const N_QUERIES: usize = 4096;

fn uniform_points(n: usize, seed: u64) -> Vec<Vec3> {
    let mut r = Pcg32::new(seed, 3);
    (0..n)
        .map(|_| Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32()))
        .collect()
}

/// Radius of a ball holding `K` of `N_POINTS` uniform points on average.
fn radius_for_k() -> f32 {
    (3.0 * K as f32 / (4.0 * std::f32::consts::PI * N_POINTS as f32)).cbrt()
}

/// Spheres of the fixed radius centred on the points (SPPM visible points).
fn spheres(points: &[Vec3]) -> Vec<(Vec3, f32)> {
    points.iter().map(|&p| (p, radius_for_k())).collect()
}

fn kiddo_tree(points: &[Vec3]) -> ImmutableKdTree<f32, 3> {
    let arr: Vec<[f32; 3]> = points.iter().map(|p| p.to_array()).collect();
    ImmutableKdTree::new_from_slice(&arr).expect("kiddo build")
}

fn kiddo_knn(tree: &ImmutableKdTree<f32, 3>, q: Vec3) -> Vec<f32> {
    let k = NonZero::new(K).unwrap();
    let q = q.to_array();
    let res = tree
        .query(&q)
        .nearest_n::<SquaredEuclidean<f32>>(k)
        .execute();
    res.iter().map(|r| r.distance).collect()
}

/// Checks on a few queries that our kNN and kiddo's find the same distances.
fn check_agreement(ours: &PointKdTree<Vec3>, theirs: &ImmutableKdTree<f32, 3>, qs: &[Vec3]) {
    let mut out = Vec::new();
    for &q in &qs[..64] {
        ours.k_nearest(q, K, f32::INFINITY, &mut out);
        let mut d: Vec<f32> = out.iter().map(|n| n.dist2).collect();
        d.sort_by(f32::total_cmp);
        let mut want = kiddo_knn(theirs, q);
        want.sort_by(f32::total_cmp);
        assert_eq!(d, want, "kNN distances differ from kiddo at {q}");
    }
}

/// Prints one-shot build times, then times the builds under criterion.
fn bench_build(c: &mut Criterion, pts: &[Vec3]) {
    let t0 = Instant::now();
    let tree = PointKdTree::build(pts.to_vec());
    let t_kd = t0.elapsed().as_secs_f64() * 1e3;
    let t0 = Instant::now();
    let grid = HashGrid::build(pts, radius_for_k());
    let t_grid = t0.elapsed().as_secs_f64() * 1e3;
    let t0 = Instant::now();
    let kiddo = kiddo_tree(pts);
    let t_kiddo = t0.elapsed().as_secs_f64() * 1e3;
    println!(
        "build, 1 thread, {} points: kd-tree {t_kd:.1} ms, hash grid {t_grid:.1} ms, \
         kiddo {t_kiddo:.1} ms",
        pts.len()
    );
    black_box((tree, grid, kiddo));

    let mut g = c.benchmark_group("spatial_build_1M");
    g.sample_size(10).sampling_mode(SamplingMode::Flat);
    g.bench_function("kdtree", |b| {
        b.iter_batched(|| pts.to_vec(), PointKdTree::build, BatchSize::LargeInput)
    });
    g.bench_function("hash_grid", |b| {
        b.iter(|| HashGrid::build(pts, radius_for_k()))
    });
    g.bench_function("kiddo", |b| b.iter(|| kiddo_tree(pts)));
    let spheres = spheres(pts);
    g.bench_function("sphere_grid", |b| b.iter(|| SphereGrid::build(&spheres)));
    g.finish();
}

fn bench_spatial(c: &mut Criterion) {
    let pts = uniform_points(N_POINTS, 1);
    let qs = uniform_points(N_QUERIES, 2);
    let radius = radius_for_k();
    bench_build(c, &pts);
    let tree = PointKdTree::build(pts.clone());
    let grid = HashGrid::build(&pts, radius);
    let kiddo = kiddo_tree(&pts);
    check_agreement(&tree, &kiddo, &qs);

    let mut g = c.benchmark_group("spatial_query_1M");
    g.throughput(Throughput::Elements(qs.len() as u64));
    let mut out: Vec<Neighbor> = Vec::with_capacity(K);
    g.bench_function("kdtree_knn50", |b| {
        b.iter(|| {
            qs.iter()
                .map(|&q| tree.k_nearest(q, K, f32::INFINITY, &mut out))
                .sum::<f32>()
        })
    });
    // kiddo returns its neighbours sorted; this is the like-for-like figure.
    g.bench_function("kdtree_knn50_sorted", |b| {
        b.iter(|| {
            qs.iter()
                .map(|&q| {
                    let r2 = tree.k_nearest(q, K, f32::INFINITY, &mut out);
                    out.sort_unstable();
                    r2 + out[0].dist2
                })
                .sum::<f32>()
        })
    });
    g.bench_function("kiddo_knn50", |b| {
        let k = NonZero::new(K).unwrap();
        b.iter(|| {
            qs.iter()
                .map(|&q| {
                    let q = q.to_array();
                    let res = kiddo.query(&q).nearest_n::<SquaredEuclidean<f32>>(k);
                    res.execute()[K - 1].distance
                })
                .sum::<f32>()
        })
    });
    bench_radius_queries(&mut g, &tree, &grid, &pts, &qs, radius);
    g.finish();
}

/// Fixed-radius queries: kd-tree, hash grids with cells of 2r and r, sphere grid.
fn bench_radius_queries(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    tree: &PointKdTree<Vec3>,
    grid: &HashGrid,
    pts: &[Vec3],
    qs: &[Vec3],
    radius: f32,
) {
    g.bench_function("kdtree_radius", |b| {
        b.iter(|| {
            let mut n = 0usize;
            for &q in qs {
                tree.for_each_within(q, radius, |_, _| n += 1);
            }
            n
        })
    });
    g.bench_function("hash_grid_radius", |b| {
        b.iter(|| {
            let mut n = 0usize;
            for &q in qs {
                grid.for_each_within(q, radius, |_, _| n += 1);
            }
            n
        })
    });
    // Cells of r instead of 2r: 27 cells per query, but fewer points each.
    let fine_grid = HashGrid::with_cell_size(pts, radius);
    g.bench_function("hash_grid_radius_cell_r", |b| {
        b.iter(|| {
            let mut n = 0usize;
            for &q in qs {
                fine_grid.for_each_within(q, radius, |_, _| n += 1);
            }
            n
        })
    });
    let sphere_grid = SphereGrid::build(&spheres(pts));
    g.bench_function("sphere_grid_containing", |b| {
        b.iter(|| {
            let mut n = 0usize;
            for &q in qs {
                sphere_grid.for_each_containing(q, |_| n += 1);
            }
            n
        })
    });
}

criterion_group!(benches, bench_spatial);
criterion_main!(benches);
