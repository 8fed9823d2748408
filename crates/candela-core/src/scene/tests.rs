//! The scene's intersection entry points against brute force over mixed
//! primitives: packed triangles, alpha-tested triangles, spheres, and a
//! moving group.

use super::{MovingGroup, Primitive, Scene};
use crate::math::{AnimatedTransform, Ray, Transform, Vec3};
use crate::sampling::{sample_uniform_sphere, Pcg32};
use crate::shape::{Shape, Sphere, Triangle, TriangleMesh};
use crate::texture::FloatTexture;
use glam::Vec2;
use std::sync::Arc;

fn rand3(r: &mut Pcg32) -> Vec3 {
    Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32())
}

fn prim(shape: Shape, alpha: Option<f32>) -> Primitive {
    Primitive {
        shape,
        material: None,
        area_light: None,
        alpha: alpha.map(FloatTexture::Constant),
    }
}

/// 600 random triangles (every 5th cut out by alpha 0, every 7th kept by
/// alpha 1) and 20 spheres.
fn mixed_primitives(seed: u64) -> Vec<Primitive> {
    let mut r = Pcg32::new(seed, 3);
    let (mut p, mut idx) = (Vec::new(), Vec::new());
    for i in 0..600u32 {
        let c = rand3(&mut r);
        for _ in 0..3 {
            p.push(c + 0.15 * (rand3(&mut r) - 0.5));
        }
        idx.extend([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    let mesh = TriangleMesh::new(&Transform::IDENTITY, false, idx, p, None, None, None);
    let mesh = Arc::new(mesh.unwrap_or_else(|e| panic!("{e}")));
    let mut prims: Vec<Primitive> = Triangle::all(&mesh)
        .into_iter()
        .enumerate()
        .map(|(i, t)| {
            let alpha = [(i % 5 == 0).then_some(0.0), (i % 7 == 0).then_some(1.0)];
            prim(Shape::Triangle(t), alpha[0].or(alpha[1]))
        })
        .collect();
    for _ in 0..20 {
        let at = Arc::new(Transform::translate(rand3(&mut r)));
        let s = Sphere::new(at, false, 0.05, -1.0, 1.0, 360.0);
        prims.push(prim(Shape::Sphere(s), None));
    }
    prims
}

/// The closest `t` over every primitive's own test (alpha 0 never hits).
fn brute(prims: &[Primitive], ray: &Ray, t_max: f32) -> Option<f32> {
    prims
        .iter()
        .filter(|p| !matches!(p.alpha, Some(FloatTexture::Constant(a)) if a <= 0.0))
        .filter_map(|p| p.shape.intersect(ray, t_max).map(|h| h.t_hit))
        .fold(None, |b: Option<f32>, t| Some(b.map_or(t, |b| b.min(t))))
}

#[test]
fn scene_intersection_matches_brute_force() {
    let prims = mixed_primitives(4);
    // A moving copy, shifted by +2 in x, still at time 0 (start) and moving later.
    let start = Transform::translate(Vec3::new(2.0, 0.0, 0.0));
    let end = Transform::translate(Vec3::new(2.0, 0.5, 0.0));
    let mover = MovingGroup::new(
        mixed_primitives(4),
        AnimatedTransform::new(start, 0.0, end, 1.0),
    );
    let scene = Scene::with_motion(
        prims.clone(),
        vec![mover],
        (0.0, 1.0),
        vec![],
        vec![],
        crate::light::LightSelection::Uniform,
    );
    let mut r = Pcg32::new(9, 9);
    let mut hits = 0;
    for k in 0..3000 {
        let o = Vec3::new(
            3.4 * r.uniform_f32() - 0.2,
            1.4 * r.uniform_f32() - 0.2,
            1.4 * r.uniform_f32() - 0.2,
        );
        let d = sample_uniform_sphere(Vec2::new(r.uniform_f32(), r.uniform_f32()));
        let ray = Ray::new(o, d);
        let t_max = if k % 3 == 0 { 0.7 } else { f32::INFINITY };
        // The moving group at time 0 is the static set moved by +2 in x.
        let local = Ray::new(o - Vec3::new(2.0, 0.0, 0.0), d);
        let want = [brute(&prims, &ray, t_max), brute(&prims, &local, t_max)]
            .into_iter()
            .flatten()
            .fold(None, |b: Option<f32>, t| Some(b.map_or(t, |b| b.min(t))));
        let got = scene
            .intersect(&ray, t_max)
            .map(|si| (si.p() - o).length() / d.length());
        match (got, want) {
            (Some(g), Some(w)) => {
                assert!((g - w).abs() <= 1e-4 * w.max(1.0), "ray {k}: {g} vs {w}")
            }
            (g, w) => assert_eq!(g.is_some(), w.is_some(), "ray {k}: {g:?} vs {w:?}"),
        }
        assert_eq!(scene.intersect_p(&ray, t_max), want.is_some(), "ray {k}");
        hits += want.is_some() as usize;
    }
    assert!(hits > 300 && hits < 2900, "{hits} hits");
}

/// A sphere cut out with constant α = 0.4 blocks a ray through it with
/// probability 1 − (1 − α)² = 0.64: after the near side is cut out, the far
/// side gets its own alpha test (pbrt-v4's continued ray); skipping it gave
/// α = 0.4. Over N = 20,000 rays through the sphere's middle the blocked
/// share's standard deviation is √(0.64·0.36/N) = 0.0034: the bound is 5σ.
/// Closest hits land on the near or the far side (t = 2 or 4 here), and
/// intersect and intersect_p agree ray by ray.
#[test]
fn a_cut_out_sphere_is_seen_through_to_its_far_side() {
    let at = Arc::new(Transform::IDENTITY);
    let s = Sphere::new(at, false, 1.0, -1.0, 1.0, 360.0);
    let scene = Scene::new(
        vec![prim(Shape::Sphere(s), Some(0.4))],
        vec![],
        vec![],
        crate::light::LightSelection::Uniform,
    );
    let mut r = Pcg32::new(5, 1);
    let n = 20_000;
    let (mut blocked, mut far) = (0usize, 0usize);
    for k in 0..n {
        // Along −z from z = 3, through the middle of the unit sphere.
        let o = Vec3::new(0.1 * r.uniform_f32(), 0.1 * r.uniform_f32(), 3.0);
        let ray = Ray::new(o, Vec3::new(0.0, 0.0, -1.0));
        let hit = scene.intersect(&ray, f32::INFINITY);
        assert_eq!(
            hit.is_some(),
            scene.intersect_p(&ray, f32::INFINITY),
            "ray {k}"
        );
        if let Some(si) = hit {
            let t = (si.p() - o).length();
            let near = (t - 2.0).abs() < 0.01;
            assert!(near || (t - 4.0).abs() < 0.01, "ray {k}: t = {t}");
            blocked += 1;
            far += usize::from(!near);
        }
    }
    let share = blocked as f64 / n as f64;
    let sigma = (0.64f64 * 0.36 / n as f64).sqrt();
    assert!(
        (share - 0.64).abs() < 5.0 * sigma,
        "blocked {share}, want 0.64 ± {sigma}"
    );
    // Of those, the far side: (1 − α)·α / 0.64 = 0.375.
    assert!(
        far as f64 > 0.3 * blocked as f64,
        "{far} far hits of {blocked}"
    );
}
