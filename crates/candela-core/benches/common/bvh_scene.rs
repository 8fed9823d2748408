//! The mesh and rays of the BVH bench, shared with the `bvh_peer` example
//! that `bench/bvh_vs_embree.py` drives.

use candela_core::accel::Bvh;
use candela_core::math::{Bounds3, Ray, Transform, Vec3};
use candela_core::sampling::{sample_uniform_sphere, Pcg32};
use candela_core::shape::TriangleMesh;
use glam::Vec2;

/// Latitude–longitude sphere with a bumpy radial displacement: 2·n² triangles.
pub fn displaced_sphere(n: u32) -> TriangleMesh {
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
    let mesh = TriangleMesh::new(&Transform::IDENTITY, false, idx, p, None, None, None);
    mesh.unwrap_or_else(|e| panic!("the bench mesh is valid: {e}"))
}

/// Random origins inside the bounds, random directions.
pub fn incoherent_rays(b: &Bounds3, n: usize) -> Vec<Ray> {
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

/// Bounds of every triangle.
pub fn triangle_bounds(mesh: &TriangleMesh) -> Vec<Bounds3> {
    (0..mesh.triangle_count() as u32)
        .map(|i| {
            let [a, b, c] = mesh.positions(i);
            Bounds3::from_points(a, b).union_point(c)
        })
        .collect()
}

/// The BVH over the mesh with every triangle packed.
pub fn mesh_bvh(mesh: &TriangleMesh) -> Bvh {
    Bvh::build_with_triangles(&triangle_bounds(mesh), |i| Some(mesh.positions(i)))
}

/// Closest hits of all rays (the number that hit).
pub fn trace_closest(bvh: &Bvh, rays: &[Ray]) -> usize {
    rays.iter()
        .filter(|ray| bvh.intersect(ray, f32::INFINITY, |_, _, _| None).is_some())
        .count()
}

/// Any-hit (shadow) tests of all rays (the number blocked).
pub fn trace_any(bvh: &Bvh, rays: &[Ray]) -> usize {
    rays.iter()
        .filter(|ray| bvh.intersect_p(ray, f32::INFINITY, |_, _, _| false))
        .count()
}
