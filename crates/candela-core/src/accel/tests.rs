//! BVH tests against brute force.

use super::Bvh;
use crate::math::{Bounds3, Ray, Vec3};
use crate::sampling::{sample_uniform_sphere, Pcg32};
use crate::shape::intersect_triangle;
use glam::Vec2;

type Tri = [Vec3; 3];

fn rand3(r: &mut Pcg32) -> Vec3 {
    Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32())
}

/// Random small triangles scattered in the unit cube.
fn soup(n: usize, seed: u64) -> Vec<Tri> {
    let mut r = Pcg32::new(seed, 7);
    (0..n)
        .map(|_| {
            let c = rand3(&mut r);
            let s = 0.02 + 0.1 * r.uniform_f32();
            [0; 3].map(|_| c + s * (rand3(&mut r) - 0.5))
        })
        .collect()
}

fn bounds(tris: &[Tri]) -> Vec<Bounds3> {
    tris.iter()
        .map(|t| Bounds3::from_points(t[0], t[1]).union_point(t[2]))
        .collect()
}

fn brute_closest(tris: &[Tri], ray: &Ray, t_max: f32) -> Option<(u32, f32)> {
    let mut best = None;
    let mut t_max = t_max;
    for (i, t) in tris.iter().enumerate() {
        if let Some(h) = intersect_triangle(ray, t_max, t[0], t[1], t[2]) {
            t_max = h.t;
            best = Some((i as u32, h.t));
        }
    }
    best
}

fn random_ray(r: &mut Pcg32, axis_aligned: bool) -> Ray {
    let o = rand3(r) * 1.4 - 0.2;
    let mut d = sample_uniform_sphere(Vec2::new(r.uniform_f32(), r.uniform_f32()));
    if axis_aligned {
        let axis = (r.next_u32() % 3) as usize;
        d = Vec3::ZERO;
        d[axis] = if r.uniform_f32() < 0.5 { -1.0 } else { 1.0 };
    }
    Ray::new(o, d)
}

#[test]
fn bvh_matches_brute_force() {
    for (n, seed) in [(1usize, 1u64), (3, 2), (50, 3), (2000, 4), (40_000, 5)] {
        let tris = soup(n, seed);
        let bvh = Bvh::build(&bounds(&tris));
        assert!(bvh.prim_indices().len() == n);
        let mut r = Pcg32::new(seed, 99);
        let (mut hits, rays) = (0, 2000);
        for k in 0..rays {
            let ray = random_ray(&mut r, k % 4 == 0);
            let t_max = if k % 3 == 0 { 0.5 } else { f32::INFINITY };
            let want = brute_closest(&tris, &ray, t_max);
            let got = bvh.intersect(&ray, t_max, |i, ray, tm| {
                let t = &tris[i as usize];
                intersect_triangle(ray, tm, t[0], t[1], t[2]).map(|h| h.t)
            });
            assert_eq!(got, want, "n={n} ray {k}: {ray:?}");
            let any = bvh.intersect_p(&ray, t_max, |i, ray, tm| {
                let t = &tris[i as usize];
                intersect_triangle(ray, tm, t[0], t[1], t[2]).is_some()
            });
            assert_eq!(any, want.is_some(), "n={n} ray {k}");
            hits += want.is_some() as usize;
        }
        // The rays must exercise both outcomes to mean anything.
        if n >= 2000 {
            assert!(hits > rays / 10 && hits < rays, "n={n}: {hits} hits");
        }
    }
}

#[test]
fn bvh_leaves_small_and_nodes_cover_prims() {
    let tris = soup(10_000, 11);
    let b = bounds(&tris);
    let bvh = Bvh::build(&b);
    let mut seen = bvh.prim_indices().to_vec();
    seen.sort_unstable();
    assert!(seen.iter().enumerate().all(|(i, &p)| p == i as u32));
    // Every primitive lies inside the root.
    let root = bvh.bounds();
    assert!(b.iter().all(|x| root.union(*x) == root));
    assert!(bvh.node_count() >= 2 * 10_000 / 4 - 1);
}

#[test]
fn bvh_build_is_deterministic() {
    let tris = soup(60_000, 12);
    let b = bounds(&tris);
    let a = Bvh::build(&b);
    let c = Bvh::build(&b);
    assert_eq!(a.prim_indices(), c.prim_indices());
    assert_eq!(a.node_count(), c.node_count());
}

#[test]
fn empty_and_degenerate_inputs() {
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    let empty = Bvh::build(&[]);
    assert!(empty.bounds().is_empty());
    assert_eq!(
        empty.intersect(&ray, f32::INFINITY, |_, _, _| Some(1.0)),
        None
    );
    assert!(!empty.intersect_p(&ray, f32::INFINITY, |_, _, _| true));
    // Many coincident boxes still give leaves of at most four.
    let same = vec![Bounds3::from_points(Vec3::ONE, Vec3::splat(2.0)); 100];
    let bvh = Bvh::build(&same);
    assert_eq!(bvh.prim_indices().len(), 100);
    let mut count = 0;
    bvh.intersect(
        &Ray::new(Vec3::ZERO, Vec3::ONE),
        f32::INFINITY,
        |_, _, _| {
            count += 1;
            None
        },
    );
    assert_eq!(count, 100);
}

#[test]
fn single_primitive_and_axis_parallel_rays() {
    let tri = [
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
    ];
    let bvh = Bvh::build(&bounds(&[tri]));
    let f =
        |_: u32, r: &Ray, tm: f32| intersect_triangle(r, tm, tri[0], tri[1], tri[2]).map(|h| h.t);
    // The box is flat in z; the ray runs along +z, exactly through the edge x = 0.
    let ray = Ray::new(Vec3::new(0.0, 0.25, 0.0), Vec3::Z);
    assert_eq!(bvh.intersect(&ray, f32::INFINITY, f), Some((0, 1.0)));
    assert_eq!(bvh.intersect(&ray, 0.9, f), None);
    let miss = Ray::new(Vec3::new(0.6, 0.6, 0.0), Vec3::Z);
    assert_eq!(bvh.intersect(&miss, f32::INFINITY, f), None);
    let along_x = Ray::new(Vec3::new(-1.0, 0.1, 1.0), Vec3::X);
    assert_eq!(bvh.intersect(&along_x, f32::INFINITY, f), None);
}
