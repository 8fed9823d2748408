//! kd-tree, hash grid and sphere grid against brute force.

use super::{HasPosition, HashGrid, Neighbor, PointKdTree, SphereGrid};
use crate::sampling::Pcg32;
use glam::Vec3;

/// A test item: a position and the index it was created with.
#[derive(Clone, Copy, Debug)]
struct Item {
    p: Vec3,
    id: u32,
}

impl HasPosition for Item {
    fn position(&self) -> Vec3 {
        self.p
    }
}

fn rand3(r: &mut Pcg32) -> Vec3 {
    Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32())
}

/// `n` points uniform in `[lo, lo + size)³`.
fn random_points(n: usize, seed: u64, lo: Vec3, size: f32) -> Vec<Vec3> {
    let mut r = Pcg32::new(seed, 11);
    (0..n).map(|_| lo + size * rand3(&mut r)).collect()
}

/// Points on the integer lattice `0..side` on each axis: every coordinate is
/// a cell boundary for cell sizes 1, 2 and 0.5.
fn lattice(side: i32) -> Vec<Vec3> {
    let mut v = Vec::new();
    for z in 0..side {
        for y in 0..side {
            for x in 0..side {
                v.push(Vec3::new(x as f32, y as f32, z as f32));
            }
        }
    }
    v
}

fn items(points: &[Vec3]) -> Vec<Item> {
    points
        .iter()
        .enumerate()
        .map(|(i, &p)| Item { p, id: i as u32 })
        .collect()
}

/// Sorted (id, dist²) of the points within `radius` of `q`.
fn brute_within(points: &[Vec3], q: Vec3, radius: f32) -> Vec<(u32, f32)> {
    let r2 = radius * radius;
    points
        .iter()
        .enumerate()
        .map(|(i, p)| (i as u32, (*p - q).length_squared()))
        .filter(|&(_, d2)| d2 <= r2)
        .collect()
}

fn kd_within(tree: &PointKdTree<Item>, q: Vec3, radius: f32) -> Vec<(u32, f32)> {
    let mut v = Vec::new();
    tree.for_each_within(q, radius, |it, d2| v.push((it.id, d2)));
    v.sort_by_key(|e| e.0);
    v
}

fn grid_within(grid: &HashGrid, q: Vec3, radius: f32) -> Vec<(u32, f32)> {
    let mut v = Vec::new();
    grid.for_each_within(q, radius, |i, d2| v.push((i, d2)));
    v.sort_by_key(|e| e.0);
    v
}

/// Checks the kd-tree and a hash grid built for `radius` against brute force
/// for every query.
fn check_within(points: &[Vec3], queries: &[Vec3], radius: f32) {
    let tree = PointKdTree::build(items(points));
    // A zero radius would make zero-sized cells.
    let grid = HashGrid::build(points, if radius > 0.0 { radius } else { 0.5 });
    for &q in queries {
        let want = brute_within(points, q, radius);
        assert_eq!(
            kd_within(&tree, q, radius),
            want,
            "kd-tree at {q}, r {radius}"
        );
        assert_eq!(
            grid_within(&grid, q, radius),
            want,
            "grid at {q}, r {radius}"
        );
    }
}

/// The k nearest (distance², index) by full sort, indices into `items`.
fn brute_knn(items: &[Item], q: Vec3, k: usize, max_radius: f32) -> Vec<Neighbor> {
    let r2 = max_radius * max_radius;
    let mut all: Vec<Neighbor> = items
        .iter()
        .enumerate()
        .map(|(i, it)| Neighbor {
            dist2: (it.p - q).length_squared(),
            index: i as u32,
        })
        .filter(|n| n.dist2 <= r2)
        .collect();
    all.sort();
    all.truncate(k);
    all
}

/// Checks `k_nearest` against a full sort, and its returned radius².
fn check_knn(points: &[Vec3], queries: &[Vec3], k: usize, max_radius: f32) {
    let tree = PointKdTree::build(items(points));
    let mut got = Vec::new();
    for &q in queries {
        let r2 = tree.k_nearest(q, k, max_radius, &mut got);
        got.sort();
        let want = brute_knn(tree.items(), q, k, max_radius);
        assert_eq!(got, want, "k {k} at {q}");
        let want_r2 = match want.last() {
            _ if k == 0 => 0.0,
            Some(n) if want.len() == k => n.dist2,
            _ => max_radius * max_radius,
        };
        assert_eq!(r2, want_r2, "k {k} at {q}");
    }
}

#[test]
fn random_points_fixed_radius() {
    let pts = random_points(20_000, 1, Vec3::ZERO, 1.0);
    // Queries inside, on the edge of and outside the points' box.
    let qs = random_points(300, 2, Vec3::splat(-0.1), 1.2);
    for r in [0.0, 0.01, 0.03, 0.1] {
        check_within(&pts, &qs, r);
    }
}

#[test]
fn radius_other_than_the_build_radius() {
    let pts = random_points(5_000, 3, Vec3::ZERO, 1.0);
    let grid = HashGrid::build(&pts, 0.02);
    for &q in &random_points(100, 4, Vec3::ZERO, 1.0) {
        // Smaller than built for, a few cells, and most of the grid.
        for r in [0.005, 0.1, 0.7] {
            assert_eq!(grid_within(&grid, q, r), brute_within(&pts, q, r));
        }
    }
}

#[test]
fn candidate_runs_of_the_entry_order_hold_the_points_within() {
    let pts = random_points(5_000, 5, Vec3::ZERO, 1.0);
    let grid = HashGrid::build(&pts, 0.03);
    let order = grid.entry_order();
    // A permutation of the build slice, so a copy in entry order holds
    // every item once.
    let mut sorted = order.to_vec();
    sorted.sort_unstable();
    assert!(sorted.iter().enumerate().all(|(i, &j)| i as u32 == j));
    for &q in &random_points(100, 6, Vec3::ZERO, 1.0) {
        // The candidate runs, filtered by the caller, find the same points.
        let mut by_run = Vec::new();
        grid.for_each_candidate_run(q, 0.03, |run| {
            for &i in &order[run] {
                let d2 = (pts[i as usize] - q).length_squared();
                if d2 <= 0.03 * 0.03 {
                    by_run.push((i, d2));
                }
            }
        });
        by_run.sort_by_key(|&(i, _)| i);
        assert_eq!(by_run, brute_within(&pts, q, 0.03));
    }
}

#[test]
fn random_points_knn() {
    let pts = random_points(20_000, 5, Vec3::ZERO, 1.0);
    let qs = random_points(200, 6, Vec3::splat(-0.1), 1.2);
    for k in [1, 7, 50] {
        check_knn(&pts, &qs, k, f32::INFINITY);
        check_knn(&pts, &qs, k, 0.03);
    }
}

#[test]
fn knn_ties_keep_lowest_indices() {
    // A lattice has many points at equal distances from a lattice point.
    let pts = lattice(12);
    let qs = [
        Vec3::splat(5.0),
        Vec3::new(0.0, 3.0, 11.0),
        Vec3::splat(5.5),
    ];
    for k in [1, 6, 7, 19, 27, 100] {
        check_knn(&pts, &qs, k, f32::INFINITY);
        check_knn(&pts, &qs, k, 1.0);
    }
}

#[test]
fn empty_sets() {
    let tree = PointKdTree::<Item>::build(Vec::new());
    assert!(tree.is_empty());
    let mut out = vec![Neighbor {
        dist2: 1.0,
        index: 3,
    }];
    assert_eq!(tree.k_nearest(Vec3::ZERO, 5, 2.0, &mut out), 4.0);
    assert!(out.is_empty());
    tree.for_each_within(Vec3::ZERO, 1e30, |_, _| panic!("empty tree"));
    let grid = HashGrid::build::<Vec3>(&[], 0.5);
    assert!(grid.is_empty());
    grid.for_each_within(Vec3::ZERO, 1e30, |_, _| panic!("empty grid"));
    let spheres = SphereGrid::build::<(Vec3, f32)>(&[]);
    spheres.for_each_containing(Vec3::ZERO, |_| panic!("empty sphere grid"));
}

#[test]
fn k_zero_and_k_above_n() {
    let pts = random_points(100, 7, Vec3::ZERO, 1.0);
    let qs = random_points(20, 8, Vec3::ZERO, 1.0);
    check_knn(&pts, &qs, 0, f32::INFINITY);
    check_knn(&pts, &qs, 100, f32::INFINITY);
    check_knn(&pts, &qs, 1000, f32::INFINITY);
    check_knn(&pts, &qs, 1000, 0.3);
    check_knn(&pts, &qs, usize::MAX, f32::INFINITY);
    // Every size around the leaf size and its multiples.
    for n in 0..100 {
        check_knn(&pts[..n], &qs, 5, f32::INFINITY);
        check_within(&pts[..n], &qs, 0.4);
    }
}

#[test]
fn all_identical_points() {
    let pts = vec![Vec3::new(0.25, -3.0, 7.0); 1000];
    let qs = [pts[0], pts[0] + Vec3::X, pts[0] + Vec3::splat(0.3)];
    for r in [0.0, 0.5, 1.0] {
        check_within(&pts, &qs, r);
    }
    check_knn(&pts, &qs, 10, f32::INFINITY);
    check_knn(&pts, &qs, 1000, 0.5);
}

#[test]
fn points_on_cell_boundaries() {
    let pts = lattice(10);
    // Lattice points, face and edge midpoints, cell centres (for cell 1).
    let mut qs = lattice(10);
    qs.extend(lattice(10).iter().map(|p| *p + Vec3::new(0.5, 0.0, 0.5)));
    qs.extend(lattice(10).iter().map(|p| *p + 0.5));
    qs.push(Vec3::splat(-1.0));
    // r = 0.5 gives cells of side 1 with their faces on the lattice; r = 1
    // puts the six lattice neighbours exactly on the sphere.
    for r in [0.25, 0.5, 1.0, 1.5] {
        check_within(&pts, &qs, r);
    }
}

#[test]
fn huge_and_offset_coordinates() {
    // Far from the origin: cells relative to the points' lower bound.
    let far = random_points(5_000, 9, Vec3::splat(1.0e6), 100.0);
    let qs = random_points(100, 10, Vec3::splat(1.0e6), 100.0);
    check_within(&far, &qs, 3.0);
    check_knn(&far, &qs, 20, f32::INFINITY);
    // Spread over ±1e30 with a small radius: cell coordinates saturate, and
    // distances² overflow to infinity.
    let mut r = Pcg32::new(11, 12);
    let mut huge: Vec<Vec3> = (0..2_000)
        .map(|_| (rand3(&mut r) * 2.0 - 1.0) * 1.0e30_f32.powf(r.uniform_f32()))
        .collect();
    huge.extend(random_points(500, 13, Vec3::ZERO, 1.0));
    let qs: Vec<Vec3> = huge.iter().step_by(25).copied().collect();
    for radius in [0.1, 2.0, 1.0e20, 1.0e30] {
        check_within(&huge, &qs, radius);
    }
    check_knn(&huge, &qs, 30, f32::INFINITY);
}

#[test]
fn radius_whose_square_underflows() {
    // r² and the distances² round to 0, so a point 1e-31 away is "within"
    // 1e-35; the grid must still look in its cell, across the boundary at 0.
    let mut pts = random_points(200, 19, Vec3::ZERO, 1.0);
    pts.push(Vec3::ZERO);
    let qs = [
        Vec3::new(-1.0e-31, 0.0, 0.0),
        Vec3::splat(-1.0e-25),
        Vec3::ZERO,
    ];
    for r in [1.0e-35, 1.0e-20] {
        check_within(&pts, &qs, r);
    }
    let spheres = [(Vec3::new(-1.0e-31, 0.0, 0.0), 1.0e-35), (Vec3::ONE, 0.5)];
    let grid = SphereGrid::build(&spheres);
    assert_eq!(check_spheres(&spheres, &grid, &[Vec3::ZERO]), 1);
}

#[test]
fn permutation_keeps_every_item_once() {
    let pts = random_points(3_000, 14, Vec3::ZERO, 1.0);
    let tree = PointKdTree::build(items(&pts));
    let mut seen = vec![false; pts.len()];
    for (i, it) in tree.items().iter().enumerate() {
        assert!(!seen[it.id as usize]);
        seen[it.id as usize] = true;
        assert_eq!(it.p, pts[it.id as usize]);
        assert_eq!(tree.position(i as u32), it.p);
    }
}

/// Indices of the spheres containing `p`, by brute force.
fn brute_containing(spheres: &[(Vec3, f32)], p: Vec3) -> Vec<u32> {
    spheres
        .iter()
        .enumerate()
        .filter(|(_, (c, r))| *r >= 0.0 && (p - *c).length_squared() <= r * r)
        .map(|(i, _)| i as u32)
        .collect()
}

fn check_spheres(spheres: &[(Vec3, f32)], grid: &SphereGrid, queries: &[Vec3]) -> usize {
    let mut hits = 0;
    for &q in queries {
        let mut got = Vec::new();
        grid.for_each_containing(q, |i| got.push(i));
        got.sort_unstable();
        let want = brute_containing(spheres, q);
        assert_eq!(got, want, "at {q}");
        hits += got.len();
    }
    hits
}

#[test]
fn sphere_grid_random() {
    let mut r = Pcg32::new(15, 16);
    let spheres: Vec<(Vec3, f32)> = (0..5_000)
        .map(|_| (rand3(&mut r), 0.005 + 0.045 * r.uniform_f32()))
        .collect();
    let qs = random_points(2_000, 17, Vec3::splat(-0.1), 1.2);
    let grid = SphereGrid::build(&spheres);
    assert!(check_spheres(&spheres, &grid, &qs) > 500);
    // Finer and coarser cells (0.05: pbrt-v3's) give the same answers.
    for cell in [0.01, 0.05, 0.3] {
        let grid = SphereGrid::with_cell_size(&spheres, cell);
        check_spheres(&spheres, &grid, &qs);
    }
    // Photons at the sphere centres and exactly on their surfaces.
    let on: Vec<Vec3> = spheres.iter().map(|(c, r)| *c + Vec3::X * *r).collect();
    let centres: Vec<Vec3> = spheres.iter().map(|s| s.0).collect();
    check_spheres(&spheres, &grid, &on);
    check_spheres(&spheres, &grid, &centres);
}

#[test]
fn sphere_grid_odd_items() {
    let spheres = vec![
        (Vec3::ZERO, 1.0),
        (Vec3::splat(0.5), -1.0),     // no visible point: left out
        (Vec3::splat(0.5), f32::NAN), // likewise
        (Vec3::new(2.0, 0.0, 0.0), 0.0),
        (Vec3::splat(3.0), 1.0e30), // covers everything: every bucket
        (Vec3::splat(1.0e31), 2.0),
        (Vec3::new(1.0, 0.0, 0.0), 1.0),
    ];
    let mut qs = lattice(4);
    qs.extend([Vec3::splat(1.0e31), Vec3::splat(-5.0), Vec3::splat(0.5)]);
    let grid = SphereGrid::build(&spheres);
    check_spheres(&spheres, &grid, &qs);
    // The zero-radius sphere contains exactly its centre.
    let mut got = Vec::new();
    grid.for_each_containing(Vec3::new(2.0, 0.0, 0.0), |i| got.push(i));
    assert!(got.contains(&3));
}

#[test]
fn sphere_grid_all_same_centre() {
    let spheres: Vec<(Vec3, f32)> = (0..300).map(|i| (Vec3::ONE, i as f32 * 0.01)).collect();
    let qs = random_points(500, 18, Vec3::ZERO, 2.0);
    check_spheres(&spheres, &SphereGrid::build(&spheres), &qs);
}

#[test]
fn buckets_of_a_cell_range_are_visited_once() {
    use super::hash_grid::CellHash;
    use glam::IVec3;
    // Few buckets, so the cells of a range collide often.
    for n_buckets in [1, 3, 7, 64, 1000] {
        let cells = CellHash::new(Vec3::ZERO, 1.0, n_buckets);
        for (lo, hi) in [
            (IVec3::ZERO, IVec3::ZERO),
            (IVec3::new(-1, 0, 2), IVec3::new(0, 1, 3)),
            (IVec3::splat(-2), IVec3::splat(1)),
            (IVec3::new(5, -7, 0), IVec3::new(9, -3, 2)),
        ] {
            let mut want: Vec<usize> = Vec::new();
            for z in lo.z..=hi.z {
                for y in lo.y..=hi.y {
                    for x in lo.x..=hi.x {
                        want.push(cells.bucket(IVec3::new(x, y, z)));
                    }
                }
            }
            let n_cells = want.len();
            want.sort_unstable();
            want.dedup();
            let mut got = Vec::new();
            cells.for_each_bucket(lo, hi, |b| got.push(b));
            let n_got = got.len();
            got.sort_unstable();
            got.dedup();
            assert_eq!(n_got, got.len(), "a bucket twice, {n_buckets} buckets");
            // Ranges with at least as many cells as buckets visit them all.
            if n_cells < n_buckets {
                assert_eq!(got, want);
            } else {
                assert_eq!(got, (0..n_buckets).collect::<Vec<_>>());
            }
            assert!(got.iter().all(|&b| b < n_buckets));
        }
    }
}
