//! Sampling tests: area densities, solid-angle densities and their
//! agreement, and Monte Carlo estimates of subtended solid angles.

use super::tests::{dir, similarity, tri_mesh, u2};
use super::*;
use crate::math::Transform;
use crate::sampling::Pcg32;
use glam::DVec3;
use std::sync::Arc;

fn test_shapes() -> Vec<(&'static str, Shape)> {
    let p = vec![
        Vec3::new(0.3, -0.2, 2.0),
        Vec3::new(1.4, 0.1, 2.6),
        Vec3::new(0.2, 1.3, 2.2),
    ];
    vec![
        (
            "sphere",
            Shape::Sphere(Sphere::new(
                similarity(0.7, Vec3::new(0.5, 0.2, 3.0)),
                false,
                1.0,
                -1.0,
                1.0,
                360.0,
            )),
        ),
        (
            "sphere-rev",
            Shape::Sphere(Sphere::new(
                similarity(1.3, Vec3::new(-2.0, 0.2, 1.0)),
                true,
                1.0,
                -1.0,
                1.0,
                360.0,
            )),
        ),
        (
            "sphere-clipped",
            Shape::Sphere(Sphere::new(
                similarity(1.0, Vec3::new(0.0, 0.0, 4.0)),
                false,
                1.5,
                -0.4,
                1.1,
                250.0,
            )),
        ),
        (
            "disk",
            Shape::Disk(Disk::new(
                similarity(2.0, Vec3::new(0.0, 1.0, 3.0)),
                false,
                0.2,
                1.0,
                0.0,
                360.0,
            )),
        ),
        (
            "annulus-rev",
            Shape::Disk(Disk::new(
                similarity(1.0, Vec3::new(1.0, 0.0, 2.0)),
                true,
                0.0,
                1.2,
                0.4,
                200.0,
            )),
        ),
        (
            "triangle",
            Shape::Triangle(Triangle::new(
                tri_mesh(p.clone(), vec![0, 1, 2], None, false),
                0,
            )),
        ),
        (
            "triangle-rev",
            Shape::Triangle(Triangle::new(tri_mesh(p, vec![0, 1, 2], None, true), 0)),
        ),
    ]
    .into_iter()
    .chain(cylinders_and_patches())
    .collect()
}

/// Shapes whose area sampling may be non-uniform.
fn cylinders_and_patches() -> Vec<(&'static str, Shape)> {
    vec![
        (
            "cylinder",
            Shape::Cylinder(Cylinder::new(
                similarity(0.8, Vec3::new(0.3, -0.4, 3.0)),
                false,
                1.0,
                -0.7,
                0.9,
                360.0,
            )),
        ),
        (
            "cylinder-aniso-rev",
            Shape::Cylinder(Cylinder::new(
                Arc::new(
                    Transform::translate(Vec3::new(-1.0, 0.5, 3.0))
                        .then_after(&Transform::scale(Vec3::new(2.0, 0.7, 1.5))),
                ),
                true,
                0.6,
                -0.4,
                0.5,
                250.0,
            )),
        ),
        ("bilinear-rect", bilinear(RECT, false, None, None)),
        ("bilinear-saddle", bilinear(SADDLE, false, None, None)),
        (
            "bilinear-saddle-uv-rev",
            bilinear(SADDLE, true, Some(SADDLE_UV), None),
        ),
        (
            "bilinear-saddle-n",
            bilinear(SADDLE, false, None, Some(SADDLE_N)),
        ),
    ]
}

/// A planar rectangle patch, tilted.
pub(super) const RECT: [Vec3; 4] = [
    Vec3::new(-0.5, -0.4, 2.0),
    Vec3::new(0.7, -0.4, 2.5),
    Vec3::new(-0.5, 0.6, 2.0),
    Vec3::new(0.7, 0.6, 2.5),
];
/// A non-planar (hyperbolic paraboloid) patch.
pub(super) const SADDLE: [Vec3; 4] = [
    Vec3::new(-0.6, -0.5, 2.4),
    Vec3::new(0.8, -0.6, 2.0),
    Vec3::new(-0.4, 0.7, 1.9),
    Vec3::new(0.6, 0.5, 2.8),
];
/// Texture coordinates with a non-diagonal, orientation-reversing Jacobian.
const SADDLE_UV: [Vec2; 4] = [
    Vec2::new(0.0, 0.0),
    Vec2::new(0.3, 2.0),
    Vec2::new(1.0, 0.2),
    Vec2::new(1.4, 2.5),
];
/// Per-vertex normals pointing away from the origin side (−z).
const SADDLE_N: [Vec3; 4] = [
    Vec3::new(0.2, 0.1, -1.0),
    Vec3::new(-0.1, 0.2, -1.0),
    Vec3::new(0.1, -0.2, -1.0),
    Vec3::new(0.0, 0.0, -1.0),
];

/// A one-patch bilinear mesh.
pub(super) fn bilinear(
    p: [Vec3; 4],
    rev: bool,
    uv: Option<[Vec2; 4]>,
    n: Option<[Vec3; 4]>,
) -> Shape {
    let mesh = BilinearPatchMesh::new(
        &Transform::IDENTITY,
        rev,
        vec![0, 1, 2, 3],
        p.to_vec(),
        n.map(|n| n.to_vec()),
        uv.map(|uv| uv.to_vec()),
        None,
    )
    .expect("valid patch");
    Shape::BilinearPatch(BilinearPatch::new(Arc::new(mesh), 0))
}

/// Shapes whose area sampling is uniform.
fn uniform_by_area(name: &str) -> bool {
    !(name.contains("aniso") || name.contains("saddle"))
}

/// For triangles: signed distance of `p` from the plane and the winding normal.
fn triangle_plane(shape: &Shape, p: Vec3) -> Option<(f32, Vec3)> {
    let Shape::Triangle(t) = shape else {
        return None;
    };
    let [a, b, c] = t.positions();
    let n = (a - c).cross(b - c).normalize();
    Some(((p - a).dot(n), n))
}

#[test]
fn area_samples_lie_on_surface_with_uniform_density_and_oriented_normals() {
    let mut r = Pcg32::new(3, 3);
    for (name, shape) in test_shapes() {
        let area = shape.area();
        for _ in 0..2000 {
            let s = shape.sample_area(u2(&mut r)).unwrap();
            if uniform_by_area(name) {
                assert!(
                    (s.pdf.0 * area - 1.0).abs() < 1e-5,
                    "{name}: {}",
                    s.pdf.0 * area
                );
            }
            let pdf_at = shape.pdf_area(&s.intr).0;
            assert!(
                (pdf_at / s.pdf.0 - 1.0).abs() < 1e-3,
                "{name}: {pdf_at} vs {}",
                s.pdf.0
            );
            assert!((s.intr.n.length() - 1.0).abs() < 1e-5, "{name}");
            // On the surface: a ray from outside the point, along −n, hits it.
            let o = s.intr.p + s.intr.n * 1e-2;
            let h = shape.intersect(&Ray::new(o, -s.intr.n), f32::INFINITY);
            let h = h.unwrap_or_else(|| panic!("{name}: sample {:?} not on surface", s.intr.p));
            assert!(h.si.p().distance(s.intr.p) < 1e-4, "{name}");
            let pdf_hit = shape.pdf_area(&h.si.it).0;
            assert!(
                (pdf_hit / s.pdf.0 - 1.0).abs() < 1e-3,
                "{name}: {pdf_hit} vs {}",
                s.pdf.0
            );
            // Sampled and intersected normals agree (orientation included).
            assert!(
                h.si.n().dot(s.intr.n) > 0.999,
                "{name}: {} vs {}",
                h.si.n(),
                s.intr.n
            );
            let reversed = name.ends_with("-rev");
            if let Some((dist, n_wind)) = triangle_plane(&shape, s.intr.p) {
                assert!(dist.abs() < 1e-5, "{name}");
                assert_eq!(n_wind.dot(s.intr.n) > 0.0, !reversed, "{name}");
            } else if let Shape::Sphere(_) = shape {
                let c = shape.bounds().centroid();
                let outward = (s.intr.p - c).dot(s.intr.n) > 0.0;
                assert_eq!(outward, !reversed, "{name}");
            }
        }
    }
}

#[test]
fn sample_from_density_agrees_with_pdf_from() {
    let mut r = Pcg32::new(5, 3);
    for (name, shape) in test_shapes() {
        if name == "sphere-clipped" {
            continue; // its far side can hide behind its near side
        }
        let c = shape.bounds().centroid();
        let (mut checked, mut zero) = (0, 0);
        for k in 0..3000 {
            // Near, far, and (for spheres) inside reference points.
            let dist = [0.3, 2.0, 8.0][k % 3];
            let ctx = ShapeSampleContext::from_point(c + dir(&mut r) * dist);
            let Some(s) = shape.sample_from(&ctx, u2(&mut r)) else {
                continue;
            };
            let wi = (s.intr.p - ctx.p).normalize();
            // Near grazing, rounding moves the hit along a curved surface
            // enough to change cos θ' by a few parts in 10³.
            if s.intr.n.dot(wi).abs() < 5e-2 {
                continue;
            }
            // A point hidden behind another part of the shape has the
            // density of the visible one (cylinders, saddles): skip it.
            let first = shape.intersect(&ctx.spawn_ray(wi), f32::INFINITY);
            if first.is_some_and(|h| h.si.p().distance(s.intr.p) > 1e-3) {
                continue;
            }
            let pdf = shape.pdf_from(&ctx, wi);
            checked += 1;
            if pdf.0 == 0.0 {
                zero += 1;
                continue;
            }
            assert!(
                (pdf.0 / s.pdf.0 - 1.0).abs() < 2e-3,
                "{name}: {} vs {}",
                pdf.0,
                s.pdf.0
            );
        }
        assert!(
            checked > 1000 && zero <= checked / 1000,
            "{name}: {zero} of {checked}"
        );
        // A direction away from the shape has density 0.
        let ctx = ShapeSampleContext::from_point(c + Vec3::splat(5.0));
        assert_eq!(shape.pdf_from(&ctx, Vec3::splat(1.0)).0, 0.0, "{name}");
    }
}

#[test]
fn triangle_sampler_density_is_the_shapes() {
    // The light's shortcut (no surface interaction) against the shape's
    // own `pdf_from`, towards the triangle and past its edges.
    let mut r = Pcg32::new(9, 4);
    for (name, shape) in test_shapes() {
        let Shape::Triangle(tri) = &shape else {
            continue;
        };
        let sampler = tri.sampler();
        let c = shape.bounds().centroid();
        let (mut hits, mut misses) = (0, 0);
        for k in 0..2000 {
            let ctx = ShapeSampleContext::from_point(c + dir(&mut r) * [0.3, 2.0, 8.0][k % 3]);
            let target = c + dir(&mut r) * 0.8;
            let wi = target - ctx.p;
            let (mine, theirs) = (sampler.pdf_from(&ctx, wi).0, shape.pdf_from(&ctx, wi).0);
            if theirs == 0.0 {
                misses += 1;
                assert_eq!(mine, 0.0, "{name}");
            } else {
                hits += 1;
                assert!(
                    (mine / theirs - 1.0).abs() < 1e-5,
                    "{name}: {mine} vs {theirs}"
                );
            }
        }
        assert!(
            hits > 200 && misses > 200,
            "{name}: {hits} hits, {misses} misses"
        );
    }
}

/// Mean and standard error of E[1/pdf] over `n` solid-angle samples (misses count 0).
fn mc_solid_angle(shape: &Shape, ctx: &ShapeSampleContext, n: usize, seed: u64) -> (f64, f64) {
    let mut r = Pcg32::new(seed, 1);
    let (mut s1, mut s2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let x = shape
            .sample_from(ctx, u2(&mut r))
            .map_or(0.0, |s| 1.0 / s.pdf.0 as f64);
        s1 += x;
        s2 += x * x;
    }
    let mean = s1 / n as f64;
    let var = (s2 / n as f64 - mean * mean).max(0.0);
    (mean, (var / n as f64).sqrt())
}

fn assert_within_5_sigma(name: &str, (mean, sigma): (f64, f64), exact: f64) {
    let tol = 5.0 * sigma + 1e-5 * exact;
    assert!(
        (mean - exact).abs() <= tol,
        "{name}: {mean} vs {exact} (σ = {sigma})"
    );
}

#[test]
fn solid_angle_estimates_match_closed_forms() {
    let n = 100_000;
    // Sphere seen from outside: 2π(1 − √(1 − r²/d²)); from inside: 4π.
    let (c, rad) = (Vec3::new(1.0, -2.0, 0.5), 0.8);
    let sphere = Shape::Sphere(Sphere::new(
        similarity(rad, c),
        false,
        1.0,
        -1.0,
        1.0,
        360.0,
    ));
    for d in [1.5f32, 4.0, 40.0] {
        let ctx = ShapeSampleContext::from_point(c + Vec3::new(0.6, 0.0, 0.8) * d);
        let exact =
            2.0 * std::f64::consts::PI * (1.0 - (1.0 - (rad as f64 / d as f64).powi(2)).sqrt());
        assert_within_5_sigma("sphere", mc_solid_angle(&sphere, &ctx, n, 1), exact);
    }
    let ctx = ShapeSampleContext::from_point(c + Vec3::new(0.1, 0.3, -0.2));
    assert_within_5_sigma(
        "sphere inside",
        mc_solid_angle(&sphere, &ctx, n, 2),
        4.0 * std::f64::consts::PI,
    );

    // Triangle: Van Oosterom & Strackee 1983.
    let p = [
        Vec3::new(0.3, -0.2, 2.0),
        Vec3::new(1.4, 0.1, 2.6),
        Vec3::new(0.2, 1.3, 2.2),
    ];
    let tri = Shape::Triangle(Triangle::new(
        tri_mesh(p.to_vec(), vec![0, 1, 2], None, false),
        0,
    ));
    for o in [Vec3::ZERO, Vec3::new(0.6, 0.4, 1.8)] {
        let [a, b, cc] = p.map(|v| (v - o).as_dvec3());
        let (la, lb, lc) = (a.length(), b.length(), cc.length());
        let num = a.dot(b.cross(cc)).abs();
        let den = la * lb * lc + a.dot(b) * lc + a.dot(cc) * lb + b.dot(cc) * la;
        let exact = 2.0 * num.atan2(den);
        let ctx = ShapeSampleContext::from_point(o);
        assert_within_5_sigma("triangle", mc_solid_angle(&tri, &ctx, n, 3), exact);
    }

    // Disk seen off-axis: midpoint quadrature of ∫ cos θ / d² dA in polar coordinates.
    let (h, rr) = (0.0f32, 1.0f32);
    let disk = Shape::Disk(Disk::new(
        Arc::new(Transform::IDENTITY),
        false,
        h,
        rr,
        0.0,
        360.0,
    ));
    let o = DVec3::new(0.7, 0.4, 0.9);
    let (nr, nphi) = (800, 800);
    let mut exact = 0.0;
    for i in 0..nr {
        let r = (i as f64 + 0.5) / nr as f64 * rr as f64;
        for j in 0..nphi {
            let phi = (j as f64 + 0.5) / nphi as f64 * 2.0 * std::f64::consts::PI;
            let q = DVec3::new(r * phi.cos(), r * phi.sin(), h as f64);
            let d = o - q;
            let da = r * (rr as f64 / nr as f64) * (2.0 * std::f64::consts::PI / nphi as f64);
            exact += d.z.abs() / d.length().powi(3) * da;
        }
    }
    let ctx = ShapeSampleContext::from_point(o.as_vec3());
    assert_within_5_sigma("disk", mc_solid_angle(&disk, &ctx, n, 4), exact);
}

/// ∫ |cos θ'| / d² dA over a parametric surface by the midpoint rule: the
/// expected value of 1/pdf for solid-angle sampling (hidden points count too).
fn projected_solid_angle(o: DVec3, n: usize, surf: impl Fn(f64, f64) -> (DVec3, DVec3)) -> f64 {
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let (u, v) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            // surf returns the point and the area-weighted normal ∂p/∂u × ∂p/∂v.
            let (p, c) = surf(u, v);
            let d = o - p;
            sum += c.dot(d).abs() / d.length().powi(3);
        }
    }
    sum / (n * n) as f64
}

#[test]
fn solid_angle_estimates_match_quadrature_for_cylinders_and_patches() {
    let n = 100_000;
    let o = DVec3::new(0.2, -0.1, 0.3);
    let ctx = ShapeSampleContext::from_point(o.as_vec3());
    for (name, shape) in test_shapes() {
        let exact = match (&shape, name) {
            (Shape::BilinearPatch(b), _) => {
                let p = b.positions().map(|q| q.as_dvec3());
                projected_solid_angle(o, 400, |u, v| {
                    let pu0 = p[0].lerp(p[2], v);
                    let pu1 = p[1].lerp(p[3], v);
                    let dpdv = p[2].lerp(p[3], u) - p[0].lerp(p[1], u);
                    (pu0.lerp(pu1, u), (pu1 - pu0).cross(dpdv))
                })
            }
            (Shape::Cylinder(_), "cylinder-aniso-rev") => {
                let t = Transform::translate(Vec3::new(-1.0, 0.5, 3.0))
                    .then_after(&Transform::scale(Vec3::new(2.0, 0.7, 1.5)));
                let (r, z0, z1, phi_max) = (0.6, -0.4, 0.5, 250f64.to_radians());
                projected_solid_angle(o, 400, |u, v| {
                    let (phi, z) = (u * phi_max, z0 + v * (z1 - z0));
                    let p_obj = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                    let dphi = Vec3::new((-r * phi.sin()) as f32, (r * phi.cos()) as f32, 0.0);
                    let c = t.vector(dphi).cross(t.vector(Vec3::Z)).as_dvec3();
                    (t.point(p_obj).as_dvec3(), c * phi_max * (z1 - z0))
                })
            }
            _ => continue,
        };
        assert_within_5_sigma(name, mc_solid_angle(&shape, &ctx, n, 7), exact);
    }
}

/// A sphere gives the same point, normal and density whether or not (u, v)
/// is asked for (sampled by its cone it then leaves (u, v) out), and when
/// it is, the (u, v) a ray hitting that point finds.
#[test]
fn sphere_samples_agree_with_and_without_uv() {
    let mut r = Pcg32::new(9, 4);
    for (name, shape) in test_shapes() {
        if !name.starts_with("sphere") {
            continue;
        }
        let c = shape.bounds().centroid();
        let mut compared = 0;
        for _ in 0..500 {
            let with = ShapeSampleContext::from_point(c + dir(&mut r) * 4.0);
            let without = ShapeSampleContext {
                need_uv: false,
                ..with
            };
            let u = u2(&mut r);
            let (Some(a), Some(b)) = (shape.sample_from(&with, u), shape.sample_from(&without, u))
            else {
                assert!(shape.sample_from(&without, u).is_none(), "{name}");
                continue;
            };
            assert_eq!(
                (a.intr.p, a.intr.n, a.pdf.0),
                (b.intr.p, b.intr.n, b.pdf.0),
                "{name}"
            );
            let wi = (a.intr.p - with.p).normalize();
            let Some(h) = shape.intersect(&with.spawn_ray(wi), f32::INFINITY) else {
                continue;
            };
            if h.si.p().distance(a.intr.p) < 1e-4 {
                assert!(
                    (h.si.it.uv - a.intr.uv).abs().max_element() < 1e-3,
                    "{name}: {} vs {}",
                    h.si.it.uv,
                    a.intr.uv
                );
                compared += 1;
            }
        }
        assert!(compared > 100, "{name}: {compared}");
    }
}
