//! Tests of bilinear patches: intersection against analytic planes and the
//! bilinear equation, watertightness, error bounds, area, sampling density,
//! the inverse map and orientation rules.

use super::sampling_tests::{bilinear, RECT, SADDLE};
use super::tests::{dir, u2};
use super::*;
use crate::math::Transform;
use crate::sampling::Pcg32;
use glam::DVec3;
use std::sync::Arc;

fn patch(shape: &Shape) -> &BilinearPatch {
    match shape {
        Shape::BilinearPatch(b) => b,
        _ => unreachable!("not a patch"),
    }
}

/// p(u, v) in f64.
fn eval(p: &[Vec3; 4], u: f64, v: f64) -> DVec3 {
    let p = p.map(|q| q.as_dvec3());
    p[0].lerp(p[2], v).lerp(p[1].lerp(p[3], v), u)
}

#[test]
fn planar_quad_hits_match_plane_and_polygon_test() {
    // A convex, non-rectangular planar quad (corners in patch order).
    let q = [
        Vec3::new(-1.0, -0.8, 3.0),
        Vec3::new(1.2, -0.5, 3.4),
        Vec3::new(-0.7, 1.0, 2.6),
        Vec3::new(0.9, 1.3, 3.0),
    ];
    // Make it exactly planar: p11 = p10 + p01 − p00 + a shift within the plane.
    let q = [q[0], q[1], q[2], q[1] + q[2] - q[0] + 0.3 * (q[1] - q[0])];
    let shape = bilinear(q, false, None, None);
    let qd = q.map(|v| v.as_dvec3());
    let n = (qd[1] - qd[0]).cross(qd[2] - qd[0]);
    // Polygon order p00 → p10 → p11 → p01.
    let poly = [qd[0], qd[1], qd[3], qd[2]];
    let mut r = Pcg32::new(3, 9);
    let mut hits = 0;
    for _ in 0..5000 {
        let o = Vec3::new(0.0, 0.0, 3.0) + dir(&mut r) * 4.0;
        let target = Vec3::new(0.0, 0.2, 3.0) + dir(&mut r) * 1.5;
        let ray = Ray::new(o, target - o);
        let (od, dd) = (o.as_dvec3(), ray.d.as_dvec3());
        let t = (qd[0] - od).dot(n) / dd.dot(n);
        let x = od + t * dd;
        let side = |k: usize| (poly[(k + 1) % 4] - poly[k]).cross(x - poly[k]).dot(n);
        let sides = [side(0), side(1), side(2), side(3)];
        let margin = 1e-4 * n.length();
        if sides.iter().any(|s| s.abs() < margin) || n.normalize().dot(dd.normalize()).abs() < 0.05
        {
            continue; // too close to an edge or grazing
        }
        let want = t > 0.0 && sides.iter().all(|&s| s > 0.0);
        let got = shape.intersect(&ray, f32::INFINITY);
        assert_eq!(got.is_some(), want, "{ray:?}");
        if let Some(h) = got {
            hits += 1;
            assert!((h.t_hit as f64 - t).abs() < 1e-5 * t, "{} vs {t}", h.t_hit);
            let uv = h.si.it.uv;
            assert!(eval(&q, uv.x as f64, uv.y as f64).distance(x) < 1e-5);
            assert!(h.si.p().as_dvec3().distance(x) < 1e-5);
        }
    }
    assert!(hits > 1000, "{hits}");
}

#[test]
fn saddle_hits_satisfy_the_bilinear_equation() {
    let shape = bilinear(SADDLE, false, None, None);
    let b = patch(&shape);
    let mut r = Pcg32::new(5, 9);
    for _ in 0..5000 {
        // Aim at a known surface point from outside the patch's box.
        let (u, v) = (r.uniform_f64(), r.uniform_f64());
        let target = eval(&SADDLE, u, v);
        let o = target.as_vec3() + dir(&mut r) * 3.0;
        let ray = Ray::new(o, target.as_vec3() - o);
        let q = SADDLE.map(|x| x.as_dvec3());
        let dpdu = q[1].lerp(q[3], v) - q[0].lerp(q[2], v);
        let dpdv = q[2].lerp(q[3], u) - q[0].lerp(q[1], u);
        if dpdu
            .cross(dpdv)
            .normalize()
            .dot(ray.d.as_dvec3().normalize())
            .abs()
            < 0.02
        {
            continue; // grazing: the f32 ray may miss the tangent point
        }
        let Some(h) = b.intersect(&ray, f32::INFINITY) else {
            panic!("missed ({u}, {v}) from {o}");
        };
        let x = ray.o.as_dvec3() + h.t_hit as f64 * ray.d.as_dvec3();
        let uv = h.si.it.uv;
        // The hit lies on the ray and on the patch at its (u, v).
        assert!(eval(&SADDLE, uv.x as f64, uv.y as f64).distance(x) < 1e-5);
        assert!(h.si.p().as_dvec3().distance(x) < 1e-5);
        // The ray meets the patch first at or before the target (t = 1).
        assert!(h.t_hit <= 1.0 + 1e-5, "{}", h.t_hit);
        if (h.t_hit - 1.0).abs() < 1e-6 {
            assert!((uv.x as f64 - u).abs() < 1e-3 && (uv.y as f64 - v).abs() < 1e-3);
        }
        assert!((h.si.n().length() - 1.0).abs() < 1e-5);
    }
}

#[test]
fn rays_through_shared_patch_edges_never_slip_through() {
    // A 4×4 grid of patches on the height field z = 0.3 sin(3x) cos(2y).
    let k = 5usize;
    let height = |x: f32, y: f32| 0.3 * (3.0 * x).sin() * (2.0 * y).cos();
    let p: Vec<Vec3> = (0..k * k)
        .map(|i| {
            let (x, y) = ((i % k) as f32 * 0.5, (i / k) as f32 * 0.5);
            Vec3::new(x, y, height(x, y))
        })
        .collect();
    let mut idx = Vec::new();
    for j in 0..k - 1 {
        for i in 0..k - 1 {
            let a = (j * k + i) as u32;
            idx.extend([a, a + 1, a + k as u32, a + k as u32 + 1]);
        }
    }
    let mesh = BilinearPatchMesh::new(
        &Transform::IDENTITY,
        false,
        idx,
        p.clone(),
        None,
        None,
        None,
    );
    let patches = BilinearPatch::all(&Arc::new(mesh.expect("valid grid")));
    let mut r = Pcg32::new(7, 9);
    let mut misses = 0;
    let mut n = 0;
    for j in 0..k - 1 {
        for i in 1..k - 1 {
            // Points on interior vertical and horizontal edges, and vertices.
            for t in [0.0f32, 0.13, 0.37, 0.5, 0.81, 0.999] {
                let (x, y) = (i as f32 * 0.5, (j as f32 + t) * 0.5);
                for (px, py) in [(x, y), (y, x)] {
                    if px <= 0.0 || py <= 0.0 || px >= 2.0 || py >= 2.0 {
                        continue; // the mesh boundary
                    }
                    // On an edge the patch is linear along it: exact target.
                    let target = patch_point(&p, k, px, py);
                    for _ in 0..20 {
                        let o = target + Vec3::new(0.0, 0.0, 2.0) + dir(&mut r) * 1.5;
                        let ray = Ray::new(o, target - o);
                        n += 1;
                        misses += patches.iter().all(|b| !b.intersect_p(&ray, 2.0)) as usize;
                    }
                }
            }
        }
    }
    assert_eq!(misses, 0, "of {n} rays");
}

/// The grid surface's point at (x, y), interpolating the cell's corners.
fn patch_point(p: &[Vec3], k: usize, x: f32, y: f32) -> Vec3 {
    let (ci, cj) = (
        ((x / 0.5) as usize).min(k - 2),
        ((y / 0.5) as usize).min(k - 2),
    );
    let (u, v) = (x / 0.5 - ci as f32, y / 0.5 - cj as f32);
    let a = cj * k + ci;
    let c = [p[a], p[a + 1], p[a + k], p[a + k + 1]];
    c[0].lerp(c[2], v).lerp(c[1].lerp(c[3], v), u)
}

#[test]
fn spawned_rays_never_rehit_the_patch_nearby() {
    let shape = bilinear(
        SADDLE.map(|q| q * 1000.0 + Vec3::splat(2.0e4)),
        false,
        None,
        None,
    );
    let mut r = Pcg32::new(11, 9);
    let (mut hits, mut rehits) = (0, 0);
    for _ in 0..20_000 {
        let s = shape.sample_area(u2(&mut r)).expect("sample");
        let o = s.intr.p + dir(&mut r) * 3.0e3;
        let Some(h) = shape.intersect(&Ray::new(o, s.intr.p - o), f32::INFINITY) else {
            continue;
        };
        hits += 1;
        for _ in 0..4 {
            let ray = h.si.spawn_ray(dir(&mut r));
            // A curved patch may be met again far away, never at the origin.
            if let Some(again) = shape.intersect(&ray, f32::INFINITY) {
                rehits += (again.si.p().distance(h.si.p()) < 1e-2) as usize;
            }
        }
    }
    assert!(hits > 19_000, "{hits}");
    assert_eq!(rehits, 0);
}

#[test]
fn areas_match_closed_forms_and_quadrature() {
    let area = |p: [Vec3; 4]| bilinear(p, false, None, None).area() as f64;
    // Rectangle 1.2 × |(0, 1, 0)|, tilted: |e10| |e00|.
    let rect = (RECT[1] - RECT[0]).length() as f64 * (RECT[2] - RECT[0]).length() as f64;
    assert!((area(RECT) - rect).abs() < 1e-6 * rect);
    // Trapezoid with parallel sides 2 and 1, height 1.5: (2 + 1)/2 · 1.5.
    let trap = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(0.5, 1.5, 0.0),
        Vec3::new(1.5, 1.5, 0.0),
    ];
    assert!((area(trap) - 2.25).abs() < 1e-6);
    // A collapsed edge (p10 = p11) is the triangle p00 p10 p01.
    let tri = [Vec3::ZERO, Vec3::X, Vec3::new(0.3, 2.0, 0.0), Vec3::X];
    assert!((area(tri) - 1.0).abs() < 1e-6);
    // Saddle z = xy over [0,1]²: ∫∫ √(1 + x² + y²) by fine midpoint quadrature.
    let saddle = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 1.0)];
    let n = 2000;
    let exact: f64 = (0..n * n)
        .map(|k| {
            let (x, y) = (
                ((k % n) as f64 + 0.5) / n as f64,
                ((k / n) as f64 + 0.5) / n as f64,
            );
            (1.0 + x * x + y * y).sqrt()
        })
        .sum::<f64>()
        / (n * n) as f64;
    assert!(
        (area(saddle) - exact).abs() < 1e-6 * exact,
        "{} vs {exact}",
        area(saddle)
    );
    assert!((area(SADDLE) / patch_area_midpoint(&SADDLE) - 1.0).abs() < 1e-5);
}

/// ∫∫ |∂p/∂u × ∂p/∂v| by the midpoint rule (reference for curved patches).
fn patch_area_midpoint(p: &[Vec3; 4]) -> f64 {
    let n = 1000;
    let q = p.map(|v| v.as_dvec3());
    (0..n * n)
        .map(|k| {
            let (u, v) = (
                ((k % n) as f64 + 0.5) / n as f64,
                ((k / n) as f64 + 0.5) / n as f64,
            );
            let dpdu = q[1].lerp(q[3], v) - q[0].lerp(q[2], v);
            let dpdv = q[2].lerp(q[3], u) - q[0].lerp(q[1], u);
            dpdu.cross(dpdv).length()
        })
        .sum::<f64>()
        / (n * n) as f64
}

#[test]
fn area_density_integrates_to_one() {
    for p in [RECT, SADDLE] {
        let shape = bilinear(p, false, None, None);
        // Quadrature: ∫ p_A dA = ∫∫ p_A(u, v) |∂p/∂u × ∂p/∂v| du dv.
        let n = 200;
        let q = p.map(|v| v.as_dvec3());
        let mut sum = 0.0;
        for k in 0..n * n {
            let (u, v) = (
                ((k % n) as f64 + 0.5) / n as f64,
                ((k / n) as f64 + 0.5) / n as f64,
            );
            let it = Interaction {
                p: eval(&p, u, v).as_vec3(),
                p_error: Vec3::ZERO,
                n: Vec3::Z,
                uv: Vec2::new(u as f32, v as f32),
                time: 0.0,
            };
            let dpdu = q[1].lerp(q[3], v) - q[0].lerp(q[2], v);
            let dpdv = q[2].lerp(q[3], u) - q[0].lerp(q[1], u);
            sum += shape.pdf_area(&it).0 as f64 * dpdu.cross(dpdv).length();
        }
        assert!((sum / (n * n) as f64 - 1.0).abs() < 1e-4, "{sum}");
        // Monte Carlo: E[1/p_A] over samples is the area.
        let mut r = Pcg32::new(13, 9);
        let m = 200_000;
        let (mut s1, mut s2) = (0.0f64, 0.0f64);
        for _ in 0..m {
            let x = 1.0 / shape.sample_area(u2(&mut r)).expect("sample").pdf.0 as f64;
            s1 += x;
            s2 += x * x;
        }
        let mean = s1 / m as f64;
        let sigma = ((s2 / m as f64 - mean * mean).max(0.0) / m as f64).sqrt();
        let a = shape.area() as f64;
        assert!(
            (mean - a).abs() <= 5.0 * sigma + 1e-5 * a,
            "{mean} vs {a} ± {sigma}"
        );
    }
}

#[test]
fn inverse_bilinear_round_trips() {
    let t = [
        Vec2::new(0.0, 0.0),
        Vec2::new(2.0, 0.3),
        Vec2::new(-0.4, 1.0),
        Vec2::new(1.5, 1.9),
    ];
    let mut r = Pcg32::new(17, 9);
    for _ in 0..10_000 {
        let uv = u2(&mut r);
        let st = t[0].lerp(t[2], uv.y).lerp(t[1].lerp(t[3], uv.y), uv.x);
        let back = invert_bilinear(st, &t).expect("inside");
        assert!((back - uv).abs().max_element() < 1e-4, "{uv} -> {back}");
    }
    // Parallelogram (k₂ = 0) and a point outside.
    let par = [
        Vec2::ZERO,
        Vec2::X,
        Vec2::new(0.5, 1.0),
        Vec2::new(1.5, 1.0),
    ];
    let back = invert_bilinear(Vec2::new(0.75, 0.5), &par).expect("inside");
    assert!((back - Vec2::new(0.5, 0.5)).length() < 1e-6);
    assert!(invert_bilinear(Vec2::new(5.0, 5.0), &par).is_none());
}

#[test]
fn patch_normal_orientation_rules() {
    // Unit square in z = 0 with ∂p/∂u × ∂p/∂v = +z.
    let sq = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
    let ray = Ray::new(Vec3::new(0.3, 0.4, 1.0), -Vec3::Z);
    let n_of = |s: Shape| s.intersect(&ray, f32::INFINITY).expect("hit").si.n();
    assert_eq!(n_of(bilinear(sq, false, None, None)), Vec3::Z);
    assert_eq!(n_of(bilinear(sq, true, None, None)), -Vec3::Z);
    // Per-vertex normals decide; sampling agrees.
    let s = bilinear(sq, false, None, Some([-Vec3::Z; 4]));
    let h = s.intersect(&ray, f32::INFINITY).expect("hit");
    assert_eq!((h.si.it.n, h.si.shading.n), (-Vec3::Z, -Vec3::Z));
    assert_eq!(
        s.sample_area(Vec2::splat(0.3)).expect("sample").intr.n,
        -Vec3::Z
    );
    // A mirroring transform keeps the object-space side.
    let mirror = Transform::scale(Vec3::new(-1.0, 1.0, 1.0));
    let m = BilinearPatchMesh::new(
        &mirror,
        false,
        vec![0, 1, 2, 3],
        sq.to_vec(),
        None,
        None,
        None,
    );
    let s = Shape::BilinearPatch(BilinearPatch::new(Arc::new(m.expect("valid")), 0));
    let ray = Ray::new(Vec3::new(-0.3, 0.4, 1.0), -Vec3::Z);
    assert_eq!(
        s.intersect(&ray, f32::INFINITY).expect("hit").si.n(),
        Vec3::Z
    );
    assert_eq!(
        s.sample_area(Vec2::splat(0.3)).expect("sample").intr.n,
        Vec3::Z
    );
}

#[test]
fn texture_coordinates_reparameterise_the_derivatives() {
    // st = (v, 2u): the Jacobian is off-diagonal and reverses orientation.
    let uv = [
        Vec2::ZERO,
        Vec2::new(0.0, 2.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(1.0, 2.0),
    ];
    let mesh = BilinearPatchMesh::new(
        &Transform::IDENTITY,
        false,
        vec![0, 1, 2, 3],
        SADDLE.to_vec(),
        None,
        Some(uv.to_vec()),
        None,
    );
    let b = BilinearPatch::new(Arc::new(mesh.expect("valid")), 0);
    let target = eval(&SADDLE, 0.4, 0.6).as_vec3();
    let o = target + Vec3::new(0.1, 0.2, -2.0);
    let h = b
        .intersect(&Ray::new(o, target - o), f32::INFINITY)
        .expect("hit");
    assert!(
        (h.si.it.uv - Vec2::new(0.6, 0.8)).length() < 1e-4,
        "{}",
        h.si.it.uv
    );
    // ∂p/∂s = ∂p/∂v and ∂p/∂t = ½ ∂p/∂u, then t negated to keep the normal's side.
    let e = 1e-3;
    let dpdu = (eval(&SADDLE, 0.4 + e, 0.6) - eval(&SADDLE, 0.4 - e, 0.6)) / (2.0 * e);
    let dpdv = (eval(&SADDLE, 0.4, 0.6 + e) - eval(&SADDLE, 0.4, 0.6 - e)) / (2.0 * e);
    assert!(h.si.dpdu.as_dvec3().distance(dpdv) < 1e-3);
    assert!(h.si.dpdv.as_dvec3().distance(-0.5 * dpdu) < 1e-3);
    assert!(h.si.n().as_dvec3().dot(dpdu.cross(dpdv)) > 0.0);
}

/// A patch in the plane y = 0 has a zero error bound along y, so a ray
/// spawned from a hit starts exactly on it; it must not hit the patch again
/// (it did at t ≈ 1e-17, which hung the path tracer on an `interface`
/// floor: findings/interface-material-hang.pbrt).
#[test]
fn a_ray_spawned_from_a_patch_in_a_coordinate_plane_does_not_rehit_it() {
    let floor = [
        Vec3::new(-5.0, 0.0, -5.0),
        Vec3::new(5.0, 0.0, -5.0),
        Vec3::new(-5.0, 0.0, 5.0),
        Vec3::new(5.0, 0.0, 5.0),
    ];
    let shape = bilinear(floor, false, None, None);
    let mut r = Pcg32::new(7, 1);
    let mut crossings = 0;
    for _ in 0..2000 {
        let o = Vec3::new(0.0, 1.5, -4.0);
        let target = Vec3::new(
            8.0 * r.uniform_f32() - 4.0,
            0.0,
            8.0 * r.uniform_f32() - 4.0,
        );
        let Some(h) = shape.intersect(&Ray::new(o, target - o), f32::INFINITY) else {
            continue;
        };
        // Straight on through the surface, as an interface crossing does.
        let through = h.si.spawn_ray((target - o).normalize());
        assert!(
            shape.intersect(&through, f32::INFINITY).is_none(),
            "re-hit from {:?} along {:?}",
            through.o,
            through.d
        );
        crossings += 1;
    }
    assert!(crossings > 1000, "{crossings}");
}
