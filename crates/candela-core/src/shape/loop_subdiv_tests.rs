//! Tests of Loop subdivision: topology counts, invariance of limit points and
//! normals under refinement, the control hull, boundaries and bad input.

use super::*;
use std::collections::HashSet;

fn octahedron() -> (Vec<Vec3>, Vec<i32>) {
    let p = vec![Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    // Counter-clockwise seen from outside.
    let f = vec![
        0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5,
    ];
    (p, f)
}

fn tetrahedron() -> (Vec<Vec3>, Vec<i32>) {
    let p = vec![
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(-1.0, -1.0, 1.0),
    ];
    (p, vec![0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2])
}

/// A flat n × n grid of quads split into triangles in z = 0, counter-clockwise from +z.
fn grid(n: usize) -> (Vec<Vec3>, Vec<i32>) {
    let p = (0..(n + 1) * (n + 1))
        .map(|i| Vec3::new((i % (n + 1)) as f32, (i / (n + 1)) as f32, 0.0))
        .collect();
    let mut f = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = (j * (n + 1) + i) as i32;
            let (b, c, d) = (a + 1, a + n as i32 + 1, a + n as i32 + 2);
            f.extend([a, b, d, a, d, c]);
        }
    }
    (p, f)
}

/// V − E + F of a triangle list.
fn euler(s: &LoopSurface) -> i64 {
    let mut edges = HashSet::new();
    let mut verts = HashSet::new();
    for f in s.indices.chunks_exact(3) {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            edges.insert((a.min(b), a.max(b)));
            verts.insert(a);
        }
    }
    verts.len() as i64 - edges.len() as i64 + (s.indices.len() / 3) as i64
}

/// Counter-clockwise winding normal of triangle `t`.
fn winding_normal(s: &LoopSurface, t: usize) -> Vec3 {
    let [a, b, c] = [0, 1, 2].map(|k| s.p[s.indices[3 * t + k] as usize]);
    (b - a).cross(c - a)
}

#[test]
fn closed_meshes_keep_euler_characteristic_and_quadruple_faces() {
    for (name, (p, f)) in [("octahedron", octahedron()), ("tetrahedron", tetrahedron())] {
        for levels in 0..4 {
            let s = loop_subdivide(levels, &f, &p).expect("valid mesh");
            assert_eq!(
                s.indices.len() / 3,
                f.len() / 3 * 4usize.pow(levels),
                "{name}"
            );
            assert_eq!(euler(&s), 2, "{name} level {levels}");
            assert_eq!(s.p.len(), s.n.len());
            assert!(s.indices.iter().all(|&i| (i as usize) < s.p.len()));
        }
    }
}

#[test]
fn limit_points_lie_in_the_control_hull() {
    let (p, f) = octahedron();
    let s = loop_subdivide(3, &f, &p).expect("valid mesh");
    for q in &s.p {
        // The octahedron is |x| + |y| + |z| ≤ 1; the limit surface is strictly inside.
        let l1 = q.x.abs() + q.y.abs() + q.z.abs();
        assert!(l1 < 1.0 && q.length() > 0.3, "{q}");
    }
    let (p, f) = tetrahedron();
    let s = loop_subdivide(2, &f, &p).expect("valid mesh");
    let faces: Vec<(Vec3, Vec3)> = f
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| p[t[k] as usize]);
            (a, (b - a).cross(c - a))
        })
        .collect();
    for q in &s.p {
        assert!(faces.iter().all(|(a, n)| (*q - *a).dot(*n) < 0.0), "{q}");
    }
}

#[test]
fn limit_points_and_normals_do_not_depend_on_the_level() {
    // Even vertices keep their indices, and the limit of a vertex is the
    // same whatever the level it is computed from.
    for (p, f) in [octahedron(), tetrahedron(), grid(3)] {
        let coarse = loop_subdivide(1, &f, &p).expect("valid");
        let fine = loop_subdivide(3, &f, &p).expect("valid");
        for v in 0..coarse.p.len() {
            assert!(coarse.p[v].distance(fine.p[v]) < 1e-5, "{v}");
            assert!(coarse.n[v].dot(fine.n[v]) > 1.0 - 1e-5, "{v}");
        }
    }
}

#[test]
fn normals_point_against_the_winding_as_in_pbrt() {
    let (p, f) = octahedron();
    let s = loop_subdivide(2, &f, &p).expect("valid");
    for (t, tri) in s.indices.chunks_exact(3).enumerate() {
        let w = winding_normal(&s, t);
        for &v in tri {
            let n = s.n[v as usize];
            assert!((n.length() - 1.0).abs() < 1e-5);
            assert!(n.dot(w) < 0.0, "triangle {t}");
            assert!(n.dot(s.p[v as usize]) < 0.0, "inward on a convex mesh");
        }
    }
}

#[test]
fn open_meshes_subdivide_with_boundary_rules() {
    let (p, f) = grid(3);
    let s = loop_subdivide(2, &f, &p).expect("valid");
    assert_eq!(euler(&s), 1, "a disk");
    assert_eq!(s.indices.len() / 3, 18 * 16);
    for (v, q) in s.p.iter().enumerate() {
        assert_eq!(q.z, 0.0, "a flat mesh stays flat");
        assert!(q.x >= 0.0 && q.x <= 3.0 && q.y >= 0.0 && q.y <= 3.0);
        // Interior and boundary vertices alike: opposite the +z winding.
        assert!(s.n[v].distance(-Vec3::Z) < 1e-5, "{v}: {}", s.n[v]);
    }
    // The bottom edge y = 0 is refined as a cubic B-spline: it stays on
    // y = 0 except near the corners, which Loop's rules round off.
    let mut on_edge: Vec<f32> = s.p.iter().filter(|q| q.y == 0.0).map(|q| q.x).collect();
    on_edge.sort_by(f32::total_cmp);
    assert_eq!(on_edge, [1.0, 1.25, 1.5, 1.75, 2.0]);
    // A single triangle (three valence-2 corners) works too.
    let one = loop_subdivide(3, &[0, 1, 2], &[Vec3::ZERO, Vec3::X, Vec3::Y]).expect("valid");
    assert_eq!(one.indices.len() / 3, 64);
    assert!(one.n.iter().all(|n| n.distance(-Vec3::Z) < 1e-5));
}

#[test]
fn curved_open_mesh_has_consistent_normal_side() {
    // The octahedron without its last face: interior and boundary vertices.
    let (p, f) = octahedron();
    let s = loop_subdivide(2, &f[..f.len() - 3], &p).expect("valid");
    assert_eq!(euler(&s), 1);
    for (t, tri) in s.indices.chunks_exact(3).enumerate() {
        let w = winding_normal(&s, t);
        assert!(
            tri.iter().all(|&v| s.n[v as usize].dot(w) < 0.0),
            "triangle {t}"
        );
    }
}

#[test]
fn bad_control_meshes_are_errors() {
    let (p, f) = octahedron();
    let e = |idx: &[i32]| loop_subdivide(1, idx, &p).expect_err("must fail");
    assert_eq!(e(&[]), LoopSubdivError::Empty);
    assert_eq!(e(&f[..7]), LoopSubdivError::IndexCount(7));
    assert!(matches!(
        e(&[0, 1, 9]),
        LoopSubdivError::IndexOutOfRange { index: 9, .. }
    ));
    assert!(matches!(
        e(&[0, -1, 2]),
        LoopSubdivError::IndexOutOfRange { index: -1, .. }
    ));
    assert_eq!(e(&[0, 1, 2, 3, 3, 4]), LoopSubdivError::DegenerateFace(1));
    // Three faces on edge (0, 2); two faces with opposite winding.
    assert!(matches!(
        e(&[0, 2, 4, 2, 0, 5, 0, 2, 3]),
        LoopSubdivError::NonManifoldEdge(..)
    ));
    assert!(matches!(
        e(&[0, 2, 4, 0, 4, 2]),
        LoopSubdivError::NonManifoldEdge(..)
    ));
    // Two fans meeting only at vertex 0 (a bow tie).
    assert_eq!(
        e(&[0, 1, 2, 0, 3, 4]),
        LoopSubdivError::NonManifoldVertex(0)
    );
    assert!(matches!(
        loop_subdivide(40, &f, &p),
        Err(LoopSubdivError::TooLarge { .. })
    ));
}
