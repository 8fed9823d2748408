//! BVH tests against brute force, watertightness on closed meshes, and
//! termination on hostile input.

use super::build::{MAX_LEAF, SAH_DEPTH};
use super::triangle4::{Tri4Ray, TriPack};
use super::{Bvh, BvhHit};
use crate::math::{Bounds3, Ray, Vec3};
use crate::sampling::{sample_uniform_sphere, Pcg32};
use crate::shape::{intersect_triangle, TriangleIntersection, WatertightRay};
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

/// The closest triangle by testing all, with the scalar watertight test.
fn brute_closest(tris: &[Tri], ray: &Ray, t_max: f32) -> Option<(u32, TriangleIntersection)> {
    let mut best = None;
    let mut t_max = t_max;
    for (i, t) in tris.iter().enumerate() {
        if let Some(h) = intersect_triangle(ray, t_max, t[0], t[1], t[2]) {
            if h.t < t_max {
                t_max = h.t;
                best = Some((i as u32, h));
            }
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

/// A BVH that packs the triangles for which `packed(i)` holds.
fn bvh_of(tris: &[Tri], packed: impl Fn(u32) -> bool) -> Bvh {
    Bvh::build_with_triangles(&bounds(tris), |i| packed(i).then(|| tris[i as usize]))
}

/// Closest hit through the BVH, the unpacked items tested by the closure,
/// as (item, t, barycentrics).
fn bvh_closest(bvh: &Bvh, tris: &[Tri], ray: &Ray, t_max: f32) -> Option<(u32, f32, [f32; 3])> {
    let mut last = None;
    let hit = bvh.intersect(ray, t_max, |i, ray, tm| {
        let t = &tris[i as usize];
        let h = intersect_triangle(ray, tm, t[0], t[1], t[2]).filter(|h| h.t < tm)?;
        last = Some(h.b);
        Some(h.t)
    })?;
    Some(match hit {
        BvhHit::Triangle { item, hit } => (item, hit.t, hit.b),
        BvhHit::Other { item, t } => (item, t, last?),
    })
}

fn bvh_any(bvh: &Bvh, tris: &[Tri], ray: &Ray, t_max: f32) -> bool {
    bvh.intersect_p(ray, t_max, |i, ray, tm| {
        let t = &tris[i as usize];
        intersect_triangle(ray, tm, t[0], t[1], t[2]).is_some_and(|h| h.t < tm)
    })
}

/// Checks closest and any hit of `rays` rays against brute force; returns the hit count.
fn check_against_brute_force(tris: &[Tri], bvh: &Bvh, seed: u64, rays: usize) -> usize {
    let mut r = Pcg32::new(seed, 99);
    let mut hits = 0;
    for k in 0..rays {
        let ray = random_ray(&mut r, k % 4 == 0);
        let t_max = if k % 3 == 0 { 0.5 } else { f32::INFINITY };
        let want = brute_closest(tris, &ray, t_max).map(|(i, h)| (i, h.t, h.b));
        let got = bvh_closest(bvh, tris, &ray, t_max);
        assert_eq!(got, want, "n={} ray {k}: {ray:?}", tris.len());
        assert_eq!(bvh_any(bvh, tris, &ray, t_max), want.is_some(), "ray {k}");
        hits += want.is_some() as usize;
    }
    hits
}

#[test]
fn bvh_matches_brute_force() {
    for (n, seed) in [(1usize, 1u64), (3, 2), (50, 3), (2000, 4), (40_000, 5)] {
        let tris = soup(n, seed);
        // All packed, none packed (every item through the closure), and mixed.
        for packed in [|_| true, |_| false, |i: u32| !i.is_multiple_of(3)] as [fn(u32) -> bool; 3] {
            let bvh = bvh_of(&tris, packed);
            assert_eq!(bvh.item_count(), n);
            let hits = check_against_brute_force(&tris, &bvh, seed, 1500);
            // The rays must exercise both outcomes to mean anything.
            if n >= 2000 {
                assert!(hits > 150 && hits < 1500, "n={n}: {hits} hits");
            }
        }
    }
}

#[test]
fn degenerate_meshes_match_brute_force() {
    let mut r = Pcg32::new(3, 5);
    let mut tris = soup(3000, 21);
    // Zero-area triangles: points and segments.
    for t in tris.iter_mut().step_by(7) {
        t[2] = t[0];
    }
    for t in tris.iter_mut().skip(3).step_by(11) {
        t[1] = t[0];
        t[2] = t[0];
    }
    // Coincident duplicates, and fans of long thin triangles through one vertex.
    let dup: Vec<Tri> = tris[..200].to_vec();
    tris.extend(dup);
    for _ in 0..300 {
        let far = rand3(&mut r) * 3.0 - 1.0;
        tris.push([Vec3::splat(0.5), far, far + 1e-3 * rand3(&mut r)]);
    }
    // Axis-aligned triangles lying in the planes the axis-parallel rays run in.
    for i in 0..100 {
        let z = i as f32 / 100.0;
        tris.push([
            Vec3::new(0.0, 0.0, z),
            Vec3::new(1.0, 0.0, z),
            Vec3::new(0.0, 1.0, z),
        ]);
    }
    let bvh = bvh_of(&tris, |i| i % 5 != 0);
    let hits = check_against_brute_force(&tris, &bvh, 77, 3000);
    assert!(hits > 300, "{hits} hits");
}

/// Pack test equals scalar test lane by lane, to the bit, including rays
/// aimed exactly at vertices (zero edge functions take the f64 path).
#[test]
fn pack_test_rounds_like_the_scalar_test() {
    let mut r = Pcg32::new(8, 1);
    let tris = soup(4000, 9);
    for (k, quad) in tris.chunks(4).enumerate() {
        let lanes: Vec<(u32, Option<Tri>)> = quad
            .iter()
            .enumerate()
            .map(|(i, t)| (i as u32, Some(*t)))
            .collect();
        let pack = TriPack::new(&lanes);
        let o = rand3(&mut r) * 1.4 - 0.2;
        let d = match k % 3 {
            0 => quad[0][k % 3] - o,
            1 => 0.5 * (quad[1][0] + quad[1][1]) - o,
            _ => sample_uniform_sphere(Vec2::new(r.uniform_f32(), r.uniform_f32())),
        };
        let ray = Ray::new(o, d);
        let wr = WatertightRay::new(&ray);
        let t_max = if k % 2 == 0 { f32::INFINITY } else { 1.5 };
        let want = quad
            .iter()
            .enumerate()
            .filter_map(|(i, t)| Some((i, wr.intersect(t_max, t[0], t[1], t[2])?)))
            .filter(|(_, h)| h.t < t_max)
            .fold(
                None,
                |best: Option<(usize, TriangleIntersection)>, (i, h)| match best {
                    Some(b) if b.1.t <= h.t => Some(b),
                    _ => Some((i, h)),
                },
            );
        let simd = Tri4Ray::new(&wr);
        let got = simd.closest(&pack, t_max);
        assert_eq!(
            got.map(|(_, h)| (h.t.to_bits(), h.b.map(f32::to_bits))),
            want.map(|(_, h)| (h.t.to_bits(), h.b.map(f32::to_bits))),
            "pack {k}"
        );
        assert_eq!(simd.any(&pack, t_max), want.is_some());
    }
}

/// An icosphere subdivided `levels` times: a closed mesh.
fn icosphere(levels: usize) -> Vec<Tri> {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut v: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut f: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut m = |a: usize, b: usize, v: &mut Vec<Vec3>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push((0.5 * (v[a] + v[b])).normalize());
                v.len() - 1
            })
        };
        f = f
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (m(a, b, &mut v), m(b, c, &mut v), m(c, a, &mut v));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    f.iter().map(|t| t.map(|i| v[i])).collect()
}

/// Rays from inside a closed mesh through its vertices and edges never miss.
#[test]
fn closed_mesh_is_watertight_at_vertices_and_edges() {
    let tris = icosphere(4);
    let bvh = bvh_of(&tris, |_| true);
    let mut r = Pcg32::new(5, 5);
    let mut rays = 0;
    for (k, t) in tris.iter().enumerate() {
        let o = 0.3 * (rand3(&mut r) - 0.5);
        let targets = [
            t[0],
            t[1],
            0.5 * t[0] + 0.5 * t[1],
            t[2] + (t[0] - t[2]) * 0.25,
        ];
        for p in targets {
            let ray = Ray::new(o, p - o);
            assert!(
                bvh_closest(&bvh, &tris, &ray, f32::INFINITY).is_some(),
                "tri {k}: {ray:?}"
            );
            assert!(bvh_any(&bvh, &tris, &ray, f32::INFINITY), "tri {k}");
            rays += 1;
        }
        // Axis-parallel rays from the centre through the mesh's axis vertices too.
        if k < 6 {
            let mut d = Vec3::ZERO;
            d[k % 3] = if k < 3 { 1.0 } else { -1.0 };
            assert!(bvh_closest(&bvh, &tris, &Ray::new(Vec3::ZERO, d), f32::INFINITY).is_some());
        }
    }
    assert_eq!(rays, 4 * tris.len());
}

#[test]
fn leaves_hold_every_item_once_and_build_is_deterministic() {
    let tris = soup(60_000, 12);
    let bvh = bvh_of(&tris, |i| i % 4 != 0);
    let leaves = bvh.leaf_items();
    assert!(leaves.iter().all(|l| !l.is_empty() && l.len() <= MAX_LEAF));
    let mut seen: Vec<u32> = leaves.iter().flatten().copied().collect();
    seen.sort_unstable();
    assert!(seen.iter().enumerate().all(|(i, &p)| p == i as u32));
    assert!(bvh.depth() <= SAH_DEPTH + 32);
    let again = bvh_of(&tris, |i| i % 4 != 0);
    assert_eq!(again.leaf_items(), leaves);
    // Every item lies inside the root.
    let root = bvh.bounds();
    assert!(bounds(&tris).iter().all(|x| root.union(*x) == root));
}

#[test]
fn empty_and_coincident_inputs() {
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    let empty = Bvh::build(&[]);
    assert!(empty.bounds().is_empty());
    assert_eq!(
        empty.intersect(&ray, f32::INFINITY, |_, _, _| Some(1.0)),
        None
    );
    assert!(!empty.intersect_p(&ray, f32::INFINITY, |_, _, _| true));
    // Many coincident boxes: small leaves, and a ray meets every item.
    let same = vec![Bounds3::from_points(Vec3::ONE, Vec3::splat(2.0)); 100];
    let bvh = Bvh::build(&same);
    assert!(bvh.leaf_items().iter().all(|l| l.len() <= MAX_LEAF));
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
fn single_triangle_and_axis_parallel_rays() {
    let tri = [
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
    ];
    let tris = [tri];
    let bvh = bvh_of(&tris, |_| true);
    let t = |ray: Ray, t_max| bvh_closest(&bvh, &tris, &ray, t_max).map(|h| (h.0, h.1));
    // The box is flat in z; the ray runs along +z, exactly through the edge x = 0.
    let ray = Ray::new(Vec3::new(0.0, 0.25, 0.0), Vec3::Z);
    assert_eq!(t(ray, f32::INFINITY), Some((0, 1.0)));
    assert_eq!(t(ray, 0.9), None);
    assert_eq!(
        t(Ray::new(Vec3::new(0.6, 0.6, 0.0), Vec3::Z), f32::INFINITY),
        None
    );
    assert_eq!(
        t(Ray::new(Vec3::new(-1.0, 0.1, 1.0), Vec3::X), f32::INFINITY),
        None
    );
}

/// Non-finite and extreme boxes never make the build recurse without end
/// or panic: unusable boxes are left out, the rest are traced correctly.
#[test]
fn hostile_bounds_terminate() {
    let inf = f32::INFINITY;
    let b = |lo: Vec3, hi: Vec3| Bounds3 { min: lo, max: hi };
    let mut boxes = vec![
        // `Translate 0 1e39 0` in f32.
        b(
            Vec3::new(0.0, 1e39f64 as f32, 0.0),
            Vec3::new(1.0, 1e39f64 as f32, 1.0),
        ),
        b(Vec3::splat(f32::NAN), Vec3::ONE),
        b(Vec3::splat(-inf), Vec3::splat(inf)),
        b(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX)),
        b(Vec3::splat(f32::MAX), Vec3::splat(f32::MAX)),
        b(Vec3::splat(-f32::MAX), Vec3::splat(-f32::MAX)),
    ];
    // Exponentially spaced boxes: each SAH split would peel off one.
    for k in 0..2000 {
        let x = 2f32.powi(k % 240 - 120);
        boxes.push(b(Vec3::splat(x), Vec3::splat(x * 1.5)));
    }
    boxes.extend(std::iter::repeat_n(b(Vec3::ZERO, Vec3::ONE), 50_000));
    let bvh = Bvh::build(&boxes);
    assert_eq!(bvh.item_count(), boxes.len() - 3);
    assert!(bvh.depth() <= SAH_DEPTH + 32, "depth {}", bvh.depth());
    let mut seen = 0;
    let ray = Ray::new(Vec3::splat(-2.0), Vec3::ONE);
    bvh.intersect_p(&ray, inf, |_, _, _| {
        seen += 1;
        false
    });
    assert!(seen > 50_000, "{seen}");
    // Rays with non-finite parts return without panicking.
    for bad in [
        Ray::new(Vec3::splat(f32::NAN), Vec3::X),
        Ray::new(Vec3::ZERO, Vec3::splat(inf)),
    ] {
        let _ = bvh.intersect(&bad, inf, |_, _, _| None);
        let _ = bvh.intersect_p(&bad, inf, |_, _, _| false);
    }
}
