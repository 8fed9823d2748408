//! Test shapes described by their geometry, built as the renderer's real
//! shapes. A parallelogram becomes two triangles, as a mesh quad does in a
//! scene, so tests of a "quad light" sum over its two triangle lights.

use crate::math::{Mat4, Transform, Vec3};
use crate::shape::{Disk, Shape, Sphere, Triangle, TriangleMesh};
use std::sync::Arc;

/// Geometry of a test emitter (render space).
#[derive(Clone, Debug)]
pub enum Geo {
    /// Sphere, outward normal.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
    /// Disk with normal `n`.
    Disk {
        /// Centre.
        center: Vec3,
        /// Unit normal.
        n: Vec3,
        /// Radius.
        radius: f32,
    },
    /// Triangle, normal (p1 − p0) × (p2 − p0).
    Triangle {
        /// Vertices.
        p: [Vec3; 3],
    },
    /// Parallelogram p0 + s·e1 + t·e2, normal e1 × e2.
    Quad {
        /// Corner.
        p0: Vec3,
        /// First edge.
        e1: Vec3,
        /// Second edge.
        e2: Vec3,
    },
}

fn triangle(p: [Vec3; 3]) -> Shape {
    let mesh = TriangleMesh::new(
        &Transform::IDENTITY,
        false,
        vec![0, 1, 2],
        p.to_vec(),
        None,
        None,
        None,
    )
    .expect("valid triangle");
    Shape::Triangle(Triangle::new(Arc::new(mesh), 0))
}

impl Geo {
    /// The real shapes (one, or two triangles for a parallelogram).
    pub fn shapes(&self) -> Vec<Shape> {
        match self {
            Geo::Sphere { center, radius } => {
                vec![Shape::Sphere(Sphere::new(
                    Arc::new(Transform::translate(*center)),
                    false,
                    *radius,
                    -radius,
                    *radius,
                    360.0,
                ))]
            }
            Geo::Disk { center, n, radius } => {
                let f = crate::math::Frame::from_z(*n);
                let m = Mat4::from_cols(
                    f.x.extend(0.0),
                    f.y.extend(0.0),
                    f.z.extend(0.0),
                    center.extend(1.0),
                );
                let t = Transform::new(m, m.inverse());
                vec![Shape::Disk(Disk::new(
                    Arc::new(t),
                    false,
                    0.0,
                    *radius,
                    0.0,
                    360.0,
                ))]
            }
            Geo::Triangle { p } => vec![triangle(*p)],
            Geo::Quad { p0, e1, e2 } => {
                let (a, b, c, d) = (*p0, *p0 + *e1, *p0 + *e1 + *e2, *p0 + *e2);
                vec![triangle([a, b, c]), triangle([a, c, d])]
            }
        }
    }
    /// The single real shape (panics for a parallelogram: test misuse).
    pub fn shape(&self) -> Shape {
        let mut s = self.shapes();
        assert_eq!(s.len(), 1, "a parallelogram is two shapes");
        s.remove(0)
    }
}
