//! Cones bounding a shape's surface normals [pbrt-v4 §6.1 `NormalBounds`],
//! for the light BVH: a one-sided area light emits on the side of the
//! normal its sampled points carry, so the cone must hold every normal
//! [`Shape::sample_area`] can return, with that orientation.
//!
//! - Spheres and cylinders (closed or partial): the whole sphere.
//! - Disks: their single normal.
//! - Triangles: the face normal, oriented as the triangle orients its
//!   samples: towards the interpolated shading normal when the mesh has
//!   normals (one orientation for the whole face when every vertex normal
//!   lies on the same side of the face: the interpolated normal is a
//!   positive combination of them), else flipped by reverse orientation xor
//!   handedness swap. Vertex normals on both sides (or in the plane) give
//!   both orientations: the whole sphere, where pbrt-v4 keeps the side of
//!   their sum.
//! - Bilinear patches: ∂p/∂u × ∂p/∂v is bilinear in (u, v) with the corner
//!   cross products as coefficients, so every normal is a positive
//!   combination of the four corner normals and lies in any convex cone
//!   holding them: the cone about their mean reaching the farthest one
//!   (pbrt-v4's construction), if its half-angle is below π/2 (a wider
//!   circular cone is not convex: the whole sphere then). Without shading normals the orientation
//!   is the flip of triangles. With them, each sampled normal is turned
//!   towards the bilinear shading normal ns(u, v) = Σ w_k ns_k, and
//!   n·ns = Σ_j Σ_k w_j w_k (N_j·ns_k) with weights w ≥ 0: when the 16
//!   products N_j·ns_k share one sign, so does n·ns everywhere, and the
//!   whole patch has one orientation (pbrt-v4 checks each corner's own
//!   normal only, which a twisted patch defeats); otherwise the whole sphere.

use super::bilinear_math::partials;
use super::{BilinearPatch, Shape, Triangle};
use crate::math::{DirectionCone, Vec2, Vec3};

impl Shape {
    /// A cone holding the normals of every point [`Shape::sample_area`]
    /// returns (module doc).
    pub fn normal_bounds(&self) -> DirectionCone {
        match self {
            Shape::Sphere(_) | Shape::Cylinder(_) => DirectionCone::entire_sphere(),
            Shape::Disk(d) => DirectionCone::from_direction(d.normal()),
            Shape::Triangle(t) => t.normal_bounds(),
            Shape::BilinearPatch(b) => b.normal_bounds(),
        }
    }
}

/// +1 when every `dots` value is positive, −1 when every one is negative,
/// `None` otherwise.
fn common_side(dots: impl IntoIterator<Item = f32>) -> Option<f32> {
    let (mut pos, mut neg, mut any) = (true, true, false);
    for d in dots {
        pos &= d > 0.0;
        neg &= d < 0.0;
        any = true;
    }
    match (any, pos, neg) {
        (true, true, _) => Some(1.0),
        (true, _, true) => Some(-1.0),
        _ => None,
    }
}

impl Triangle {
    /// The oriented face normal (module doc).
    fn normal_bounds(&self) -> DirectionCone {
        let [p0, p1, p2] = self.positions();
        let Some(n) = (p0 - p2).cross(p1 - p2).try_normalize() else {
            return DirectionCone::entire_sphere();
        };
        let flips = self.mesh.reverse_orientation ^ self.mesh.transform_swaps_handedness;
        let side = match &self.mesh.n {
            Some(ns) => {
                let v = self.mesh.vertex_indices(self.index);
                match common_side(v.map(|i| n.dot(ns[i]))) {
                    Some(s) => s,
                    None => return DirectionCone::entire_sphere(),
                }
            }
            None if flips => -1.0,
            None => 1.0,
        };
        DirectionCone::from_direction(side * n)
    }
}

impl BilinearPatch {
    /// The cone of the four oriented corner normals (module doc).
    fn normal_bounds(&self) -> DirectionCone {
        let p = self.positions();
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
        let raw: [Vec3; 4] = uv.map(|c| {
            let (dpdu, dpdv) = partials(&p, c);
            dpdu.cross(dpdv).normalize_or_zero()
        });
        let flips = self.mesh.reverse_orientation ^ self.mesh.transform_swaps_handedness;
        let side = match &self.mesh.n {
            Some(ns) => {
                let v = self.mesh.vertex_indices(self.index);
                let corners = (0..4).filter(|&k| raw[k] != Vec3::ZERO);
                let dots = corners.flat_map(|j| v.map(|i| raw[j].dot(ns[i])));
                match common_side(dots) {
                    Some(s) => s,
                    None => return DirectionCone::entire_sphere(),
                }
            }
            None if flips => -1.0,
            None => 1.0,
        };
        let normals: Vec<Vec3> = raw
            .iter()
            .filter(|n| **n != Vec3::ZERO)
            .map(|n| side * *n)
            .collect();
        let Some(w) = normals.iter().sum::<Vec3>().try_normalize() else {
            return DirectionCone::entire_sphere();
        };
        let cos = normals.iter().map(|n| n.dot(w)).fold(1.0f32, f32::min);
        if cos <= 0.0 {
            // Wider than a hemisphere, the cone is not convex: it may miss
            // combinations of the corners (pbrt-v4 returns it anyway).
            return DirectionCone::entire_sphere();
        }
        // The f32 round-off of those dot products must not shrink the cone.
        DirectionCone::new(w, cos - 4.0 * f32::EPSILON)
    }
}

#[cfg(test)]
mod tests {
    use super::super::{BilinearPatchMesh, Disk, TriangleMesh};
    use super::*;
    use crate::math::{Mat4, Transform};
    use crate::sampling::{sample_uniform_sphere, Pcg32};
    use std::sync::Arc;

    /// Slack of a dot product of two f32 unit vectors computed two ways.
    const ROUND_OFF: f32 = 1e-6;

    fn u3(r: &mut Pcg32) -> Vec3 {
        Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32()) * 2.0 - Vec3::ONE
    }

    /// A random affine map, mirroring (swapping handedness) half the time.
    fn transform(r: &mut Pcg32) -> Transform {
        let m = Mat4::from_cols(
            (Vec3::X + 0.5 * u3(r)).extend(0.0),
            (Vec3::Y + 0.5 * u3(r)).extend(0.0),
            (Vec3::Z + 0.5 * u3(r)).extend(0.0),
            u3(r).extend(1.0),
        );
        let mirror = if r.uniform_f32() < 0.5 { -1.0 } else { 1.0 };
        let m = m * Mat4::from_scale(Vec3::new(mirror, 1.0, 1.0));
        Transform::new(m, m.inverse())
    }

    fn random_normals(r: &mut Pcg32, k: usize) -> Option<Vec<Vec3>> {
        (r.uniform_f32() < 0.5).then(|| {
            let bias = sample_uniform_sphere(Vec2::new(r.uniform_f32(), r.uniform_f32()));
            (0..k).map(|_| bias + 0.8 * u3(r)).collect()
        })
    }

    /// Every normal `sample_area` returns lies in the cone.
    fn assert_bounds_normals(shape: &Shape, r: &mut Pcg32) {
        let cone = shape.normal_bounds();
        for _ in 0..200 {
            let Some(ss) = shape.sample_area(Vec2::new(r.uniform_f32(), r.uniform_f32())) else {
                continue;
            };
            let d = cone.w.dot(ss.intr.n);
            assert!(
                d >= cone.cos_theta - ROUND_OFF,
                "{shape:?}: n {:?} outside {cone:?}",
                ss.intr.n
            );
        }
    }

    #[test]
    fn sampled_normals_lie_in_the_normal_bounds() {
        let mut r = Pcg32::new(11, 0);
        for _ in 0..300 {
            let t = transform(&mut r);
            let rev = r.uniform_f32() < 0.5;
            let p: Vec<Vec3> = (0..4).map(|_| u3(&mut r)).collect();
            let n = random_normals(&mut r, 3);
            let tri = TriangleMesh::new(&t, rev, vec![0, 1, 2], p[..3].to_vec(), n, None, None);
            assert_bounds_normals(
                &Shape::Triangle(Triangle::new(Arc::new(tri.unwrap()), 0)),
                &mut r,
            );
            let n = random_normals(&mut r, 4);
            let blp = BilinearPatchMesh::new(&t, rev, vec![0, 1, 2, 3], p, n, None, None);
            assert_bounds_normals(
                &Shape::BilinearPatch(BilinearPatch::new(Arc::new(blp.unwrap()), 0)),
                &mut r,
            );
            let disk = Disk::new(Arc::new(t), rev, r.uniform_f32(), 1.0, 0.2, 300.0);
            assert_bounds_normals(&Shape::Disk(disk), &mut r);
        }
    }
}
