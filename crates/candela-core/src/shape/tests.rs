//! Tests of intersection, error bounds and sampling for all shapes.

use super::*;
use crate::math::{Mat4, Transform, PI};
use crate::sampling::{sample_uniform_sphere, Pcg32};
use glam::DVec3;
use std::sync::Arc;

pub(super) fn u2(r: &mut Pcg32) -> Vec2 {
    Vec2::new(r.uniform_f32(), r.uniform_f32())
}

pub(super) fn dir(r: &mut Pcg32) -> Vec3 {
    sample_uniform_sphere(u2(r))
}

/// Rotation about a tilted axis, uniform scale `s`, then translation `t`.
pub(super) fn similarity(s: f32, t: Vec3) -> Arc<Transform> {
    let m = Mat4::from_translation(t)
        * Mat4::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7)
        * Mat4::from_scale(Vec3::splat(s));
    Arc::new(Transform::new(m, m.inverse()))
}

pub(super) fn tri_mesh(
    p: Vec<Vec3>,
    idx: Vec<u32>,
    n: Option<Vec<Vec3>>,
    rev: bool,
) -> Arc<TriangleMesh> {
    Arc::new(TriangleMesh::new(&Transform::IDENTITY, rev, idx, p, n, None, None).unwrap())
}

/// Icosahedron subdivided `levels` times, projected on the unit sphere.
fn icosphere(levels: u32) -> Arc<TriangleMesh> {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut p: Vec<Vec3> = [
        [-1., t, 0.],
        [1., t, 0.],
        [-1., -t, 0.],
        [1., -t, 0.],
        [0., -1., t],
        [0., 1., t],
        [0., -1., -t],
        [0., 1., -t],
        [t, 0., -1.],
        [t, 0., 1.],
        [-t, 0., -1.],
        [-t, 0., 1.],
    ]
    .iter()
    .map(|a| Vec3::from_array(*a).normalize())
    .collect();
    let mut f: Vec<[u32; 3]> = vec![
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
        let mut cache = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, p: &mut Vec<Vec3>| {
            *cache.entry((a.min(b), a.max(b))).or_insert_with(|| {
                p.push((p[a as usize] + p[b as usize]).normalize());
                p.len() as u32 - 1
            })
        };
        f = f
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b, &mut p), mid(b, c, &mut p), mid(c, a, &mut p));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    tri_mesh(p, f.concat(), None, false)
}

fn closest(tris: &[Triangle], ray: &Ray) -> Option<ShapeIntersection> {
    let mut best: Option<ShapeIntersection> = None;
    for t in tris {
        let t_max = best.map_or(f32::INFINITY, |b| b.t_hit);
        if let Some(h) = t.intersect(ray, t_max) {
            best = Some(h);
        }
    }
    best
}

#[test]
fn rays_through_shared_edges_and_vertices_never_slip_through() {
    let mesh = icosphere(3);
    let tris = Triangle::all(&mesh);
    let mut targets: Vec<Vec3> = mesh.p.clone();
    for t in &tris {
        let [a, b, c] = t.positions();
        targets.extend([(a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5]);
    }
    let mut r = Pcg32::new(5, 5);
    let mut misses = 0;
    for (k, &target) in targets.iter().enumerate() {
        // From inside (centre and random points) and from outside.
        let inside = (Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32()) - 0.5) * 0.8;
        let origin = match k % 3 {
            0 => Vec3::ZERO,
            1 => inside,
            _ => target * 3.0 + dir(&mut r) * 0.5,
        };
        misses += closest(&tris, &Ray::new(origin, target - origin)).is_none() as usize;
    }
    assert_eq!(misses, 0, "of {} rays", targets.len());
}

#[test]
fn spawned_rays_never_rehit_far_tilted_triangle() {
    let p = vec![
        Vec3::new(1.0e4, 2.0e4, -1.3e4),
        Vec3::new(1.3e4, 2.1e4, -1.1e4),
        Vec3::new(1.05e4, 2.4e4, -0.9e4),
    ];
    let tri = Triangle::new(tri_mesh(p, vec![0, 1, 2], None, false), 0);
    let mut r = Pcg32::new(17, 3);
    let (mut hits, mut rehits) = (0, 0);
    for _ in 0..20_000 {
        let target = tri.sample_area(u2(&mut r)).unwrap().intr.p;
        let o = target + dir(&mut r) * 3.0e3;
        let Some(h) = tri.intersect(&Ray::new(o, target - o), f32::INFINITY) else {
            continue;
        };
        hits += 1;
        // Leave on either side, including grazing directions.
        for _ in 0..4 {
            let d = dir(&mut r);
            rehits += tri.intersect_p(&h.si.spawn_ray(d), f32::INFINITY) as usize;
        }
    }
    assert!(hits > 19_000, "{hits}");
    assert_eq!(rehits, 0);
}

/// Asserts the f64 ray-hit point `exact` lies within `k`·|p_error| of `p`.
/// pbrt-v4's per-axis bounds limit the distance to the *surface*; along the
/// surface the rounding of t and of the barycentrics moves the point by an
/// amount that scales with the largest coordinate, not per axis.
fn assert_near_error_box(p: Vec3, err: Vec3, exact: DVec3, k: f64) {
    let d = p.as_dvec3().distance(exact);
    assert!(
        d <= k * err.length() as f64,
        "|{p} − {exact}| = {d} > {k}·|{err}|"
    );
}

/// The error box around `p` meets the plane through `q` with normal `n`.
fn box_meets_plane(p: Vec3, err: Vec3, q: DVec3, n: DVec3) -> bool {
    (p.as_dvec3() - q).dot(n).abs() <= n.abs().dot(err.as_dvec3())
}

/// The error box around `p` meets the sphere (`c`, `r`).
fn box_meets_sphere(p: Vec3, err: Vec3, c: DVec3, r: f64) -> bool {
    let (lo, hi) = ((p - err).as_dvec3(), (p + err).as_dvec3());
    let nearest = c.clamp(lo, hi);
    let far = DVec3::select(c.cmplt((lo + hi) * 0.5), hi, lo);
    c.distance(nearest) <= r && r <= c.distance(far)
}

#[test]
fn triangle_hits_match_f64_and_error_bounds_contain_them() {
    let mut r = Pcg32::new(23, 1);
    for _ in 0..5000 {
        let c = (Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32()) - 0.5) * 200.0;
        let p: Vec<Vec3> = (0..3).map(|_| c + dir(&mut r) * 3.0).collect();
        let tri = Triangle::new(tri_mesh(p.clone(), vec![0, 1, 2], None, false), 0);
        let target = tri.sample_area(u2(&mut r)).unwrap().intr.p;
        let o = target + dir(&mut r) * 10.0;
        let ray = Ray::new(o, target - o);
        let (pd, od, dd) = (
            p.iter().map(|v| v.as_dvec3()).collect::<Vec<_>>(),
            o.as_dvec3(),
            ray.d.as_dvec3(),
        );
        // Exact plane hit in f64.
        let n = (pd[1] - pd[0]).cross(pd[2] - pd[0]);
        let t = (pd[0] - od).dot(n) / dd.dot(n);
        if n.normalize().dot(dd.normalize()).abs() < 0.05 {
            continue;
        }
        let Some(h) = tri.intersect(&ray, f32::INFINITY) else {
            continue; // the f32 target may round just outside a thin triangle
        };
        assert!((h.t_hit as f64 - t).abs() < 1e-4 * t, "{} vs {t}", h.t_hit);
        assert!(
            box_meets_plane(h.si.p(), h.si.it.p_error, pd[0], n),
            "{h:?}"
        );
        assert_near_error_box(h.si.p(), h.si.it.p_error, od + t * dd, 4.0);
    }
}

#[test]
fn sphere_hits_match_analytic_and_error_bounds_contain_them() {
    let (c, s) = (Vec3::new(3.0, -2.0, 5.0), 2.5);
    let sphere = Sphere::new(similarity(s, c), false, 1.0, -1.0, 1.0, 360.0);
    let mut r = Pcg32::new(29, 1);
    for _ in 0..5000 {
        let o = c + dir(&mut r) * (s * (1.2 + 5.0 * r.uniform_f32()));
        let aim = c + dir(&mut r) * s * 0.9;
        let ray = Ray::new(o, aim - o);
        let (od, dd, cd) = (o.as_dvec3(), ray.d.as_dvec3(), c.as_dvec3());
        // |o + t d − c|² = R²
        let (a, b) = (dd.length_squared(), 2.0 * dd.dot(od - cd));
        let cc = (od - cd).length_squared() - (s as f64).powi(2);
        let t = (-b - (b * b - 4.0 * a * cc).sqrt()) / (2.0 * a);
        let h = sphere.intersect(&ray, f32::INFINITY).expect("aimed inside");
        assert!((h.t_hit as f64 - t).abs() < 1e-4 * t);
        let exact = od + t * dd;
        let cos = ((exact - cd).normalize()).dot(dd.normalize()).abs();
        let (p, err) = (h.si.p(), h.si.it.p_error);
        assert!(box_meets_sphere(p, err, cd, s as f64), "{p} ± {err}");
        if cos > 0.2 {
            assert_near_error_box(p, err, exact, 4.0);
        }
        assert!(h.si.n().dot(h.si.p() - c) > 0.0, "outward normal");
        // Leaving outward never re-hits the sphere.
        let out = h.si.spawn_ray(h.si.n() + dir(&mut r) * 0.9);
        assert!(!sphere.intersect_p(&out, f32::INFINITY));
    }
    let inside = Ray::new(c, Vec3::X);
    assert!((sphere.intersect(&inside, f32::INFINITY).unwrap().t_hit - s).abs() < 1e-5);
    assert!(sphere.intersect(&inside, 0.9 * s).is_none());
}

#[test]
fn clipped_sphere_respects_z_and_phi() {
    let sphere = Sphere::new(Arc::new(Transform::IDENTITY), false, 1.0, -0.5, 0.8, 270.0);
    let mut r = Pcg32::new(31, 1);
    let mut hits = 0;
    for _ in 0..5000 {
        let o = dir(&mut r) * 3.0;
        let ray = Ray::new(o, dir(&mut r) * 0.3 - o);
        if let Some(h) = sphere.intersect(&ray, f32::INFINITY) {
            let p = h.si.p();
            let phi = sphere::phi_of(p);
            assert!(p.z >= -0.5 - 1e-5 && p.z <= 0.8 + 1e-5 && phi <= 1.5 * PI + 1e-4);
            hits += 1;
        }
    }
    assert!(hits > 1000);
}

#[test]
fn disk_hits_match_analytic() {
    let (c, s) = (Vec3::new(-1.0, 4.0, 2.0), 1.5);
    let disk = Disk::new(similarity(s, c), false, 0.5, 1.0, 0.3, 360.0);
    let to_obj = similarity(s, c).inverse();
    let mut r = Pcg32::new(37, 1);
    let mut hits = 0;
    for _ in 0..5000 {
        let o = c + dir(&mut r) * 4.0;
        let ray = Ray::new(o, c + dir(&mut r) * 1.5 - o);
        let (oo, dd) = (
            to_obj.point(ray.o).as_dvec3(),
            to_obj.vector(ray.d).as_dvec3(),
        );
        let t = (0.5 - oo.z) / dd.z;
        let pr = oo + t * dd;
        let rr = (pr.x * pr.x + pr.y * pr.y).sqrt();
        let want = t > 0.0 && (0.3..=1.0).contains(&rr);
        let got = disk.intersect(&ray, f32::INFINITY);
        if (rr - 1.0).abs() < 1e-4 || (rr - 0.3).abs() < 1e-4 {
            continue;
        }
        assert_eq!(got.is_some(), want);
        if let Some(h) = got {
            hits += 1;
            assert!((h.t_hit as f64 - t).abs() < 1e-4 * t);
            assert!(!disk.intersect_p(&h.si.spawn_ray(-ray.d), f32::INFINITY));
        }
    }
    assert!(hits > 500);
}

#[test]
fn degenerate_triangles_never_hit_or_nan() {
    let p = vec![
        Vec3::ZERO,
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(2.0, 2.0, 2.0),
        Vec3::ONE,
    ];
    let mesh = tri_mesh(p, vec![0, 1, 2, 0, 3, 1], None, false);
    let mut r = Pcg32::new(41, 1);
    for tri in Triangle::all(&mesh) {
        assert_eq!(tri.area(), 0.0);
        assert!(tri.sample_area(u2(&mut r)).is_none());
        for _ in 0..2000 {
            let o = dir(&mut r) * 3.0;
            let target = Vec3::splat(r.uniform_f32() * 2.0);
            assert!(tri
                .intersect(&Ray::new(o, target - o), f32::INFINITY)
                .is_none());
        }
        // Ray along the degenerate triangle's own line.
        assert!(!tri.intersect_p(&Ray::new(Vec3::splat(-1.0), Vec3::ONE), f32::INFINITY));
    }
}

#[test]
fn triangle_normal_orientation_rules() {
    let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let ray = Ray::new(Vec3::new(0.2, 0.2, 1.0), -Vec3::Z);
    let n_of = |m| {
        Triangle::new(m, 0)
            .intersect(&ray, f32::INFINITY)
            .unwrap()
            .si
            .it
            .n
    };
    assert_eq!(
        n_of(tri_mesh(p.clone(), vec![0, 1, 2], None, false)),
        Vec3::Z
    );
    assert_eq!(
        n_of(tri_mesh(p.clone(), vec![0, 1, 2], None, true)),
        -Vec3::Z
    );
    // Per-vertex normals decide, whatever the winding.
    let down = Some(vec![-Vec3::Z; 3]);
    let m = tri_mesh(p.clone(), vec![0, 1, 2], down, false);
    let h = Triangle::new(m.clone(), 0)
        .intersect(&ray, f32::INFINITY)
        .unwrap();
    assert_eq!((h.si.it.n, h.si.shading.n), (-Vec3::Z, -Vec3::Z));
    let s = Triangle::new(m, 0).sample_area(Vec2::splat(0.3)).unwrap();
    assert_eq!(s.intr.n, -Vec3::Z);
    // A mirroring transform keeps the object-space winding's side.
    let mirror = Transform::scale(Vec3::new(-1.0, 1.0, 1.0));
    let m = TriangleMesh::new(&mirror, false, vec![0, 1, 2], p, None, None, None).unwrap();
    let ray = Ray::new(Vec3::new(-0.2, 0.2, 1.0), -Vec3::Z);
    let h = Triangle::new(Arc::new(m), 0)
        .intersect(&ray, f32::INFINITY)
        .unwrap();
    assert_eq!(h.si.it.n, Vec3::Z);
}

#[test]
fn cylinder_hits_match_analytic_and_error_bounds_contain_them() {
    let (c, s) = (Vec3::new(-2.0, 1.0, 4.0), 1.7);
    let to_obj = similarity(s, c).inverse();
    let cyl = Cylinder::new(similarity(s, c), false, 0.8, -0.5, 1.2, 360.0);
    let mut r = Pcg32::new(43, 1);
    let mut hits = 0;
    for _ in 0..5000 {
        let o = c + dir(&mut r) * (s * (2.0 + 4.0 * r.uniform_f32()));
        let ray = Ray::new(o, c + dir(&mut r) * s * 0.9 - o);
        // Object-space f64 quadratic: |(o + t d)_xy|² = r².
        let (oo, dd) = (
            to_obj.point(ray.o).as_dvec3(),
            to_obj.vector(ray.d).as_dvec3(),
        );
        let a = dd.x * dd.x + dd.y * dd.y;
        let b = 2.0 * (oo.x * dd.x + oo.y * dd.y);
        let cc = oo.x * oo.x + oo.y * oo.y - 0.64;
        let disc = b * b - 4.0 * a * cc;
        let roots = if disc < 0.0 {
            vec![]
        } else {
            vec![
                (-b - disc.sqrt()) / (2.0 * a),
                (-b + disc.sqrt()) / (2.0 * a),
            ]
        };
        let z_of = |t: f64| oo.z + t * dd.z;
        let t_want = roots
            .iter()
            .copied()
            .find(|&t| t > 0.0 && (-0.5..=1.2).contains(&z_of(t)));
        // Skip rays grazing the rims or the silhouette.
        let near_rim = |t: f64| (z_of(t) + 0.5).abs() < 1e-3 || (z_of(t) - 1.2).abs() < 1e-3;
        if roots.iter().any(|&t| t > 0.0 && near_rim(t)) || (disc >= 0.0 && disc < 1e-6 * b * b) {
            continue;
        }
        let got = cyl.intersect(&ray, f32::INFINITY);
        assert_eq!(got.is_some(), t_want.is_some(), "{ray:?}");
        let (Some(h), Some(t)) = (got, t_want) else {
            continue;
        };
        hits += 1;
        assert!((h.t_hit as f64 - t).abs() < 1e-4 * t, "{} vs {t}", h.t_hit);
        // The error box meets the render-space cylinder: check in object space.
        let p_obj = to_obj.point(h.si.p()).as_dvec3();
        let rad = (p_obj.x * p_obj.x + p_obj.y * p_obj.y).sqrt();
        assert!((rad - 0.8).abs() <= h.si.it.p_error.length() as f64 / s as f64 + 1e-6);
        // Outward normal: away from the axis.
        let radial = similarity(s, c).vector(Vec3::new(p_obj.x as f32, p_obj.y as f32, 0.0));
        assert!(h.si.n().dot(radial) > 0.0, "outward normal");
        let out = h.si.spawn_ray(h.si.n() + dir(&mut r) * 0.9);
        let back = h.si.spawn_ray(-h.si.n() + dir(&mut r) * 0.9);
        // Outward never re-hits the (convex) cylinder; inward only hits the far wall.
        assert!(!cyl.intersect_p(&out, f32::INFINITY));
        let far = cyl.intersect(&back, f32::INFINITY);
        assert!(far.is_none_or(|o| o.t_hit > 1e-3), "{far:?}");
    }
    assert!(hits > 1500, "{hits}");
}

#[test]
fn clipped_cylinder_respects_z_and_phi_and_area() {
    let cyl = Cylinder::new(Arc::new(Transform::IDENTITY), false, 2.0, 1.0, -0.5, 200.0);
    let area = 2.0 * 1.5 * 200f32.to_radians();
    assert!((cyl.area() - area).abs() < 1e-5 * area, "{}", cyl.area());
    let mut r = Pcg32::new(47, 1);
    let mut hits = 0;
    for _ in 0..5000 {
        let o = dir(&mut r) * 5.0;
        let ray = Ray::new(o, dir(&mut r) * 0.5 - o);
        if let Some(h) = cyl.intersect(&ray, f32::INFINITY) {
            let p = h.si.p();
            let phi = sphere::phi_of(p);
            assert!(p.z >= -0.5 - 1e-5 && p.z <= 1.0 + 1e-5, "{p}");
            assert!(phi <= 200f32.to_radians() + 1e-4, "{phi}");
            assert!((h.si.it.uv.x - phi / 200f32.to_radians()).abs() < 1e-4);
            assert!((h.si.it.uv.y - (p.z + 0.5) / 1.5).abs() < 1e-4);
            hits += 1;
        }
    }
    assert!(hits > 1000);
    // Rays along the axis never hit the side.
    assert!(!cyl.intersect_p(&Ray::new(Vec3::new(0.3, 0.2, -5.0), Vec3::Z), f32::INFINITY));
}

#[test]
fn cylinder_area_under_anisotropic_scale_matches_quadrature() {
    // x stretched by 3: an elliptic cylinder with semi-axes 3r and r.
    let m = Transform::scale(Vec3::new(3.0, 1.0, 2.0));
    let cyl = Cylinder::new(Arc::new(m), false, 1.0, 0.0, 1.0, 360.0);
    // Perimeter of the ellipse by fine midpoint quadrature, times height 2.
    let n = 200_000;
    let per: f64 = (0..n)
        .map(|i| {
            let phi = (i as f64 + 0.5) / n as f64 * 2.0 * std::f64::consts::PI;
            (3.0 * phi.sin()).hypot(phi.cos()) * 2.0 * std::f64::consts::PI / n as f64
        })
        .sum();
    let exact = per * 2.0;
    assert!(
        (cyl.area() as f64 - exact).abs() < 1e-5 * exact,
        "{} vs {exact}",
        cyl.area()
    );
}
