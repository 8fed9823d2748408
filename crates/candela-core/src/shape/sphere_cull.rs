//! A cheap, certain miss test in front of the sphere's interval intersection.
//!
//! [`Sphere`](super::sphere::Sphere) solves its quadratic in conservative
//! intervals [pbrt-v4 §6.8.5], which costs a few thousand instructions. Most
//! rays that reach a sphere's bounds do not hit it: shadow rays aimed at a
//! point sampled on a spherical light stop at `t = 1 − ε`, just before that
//! point, and rays passing near it miss. This test decides those cases in
//! f64 and answers "miss" only when the interval code would also answer
//! `None`; everything else goes to the interval code, so hits and their
//! bits do not change.
//!
//! Why the answer is certain. The interval code encloses the exact real
//! object-space ray (`transform_point_i`, `transform_vector_i`) and, from it,
//! the real discriminant and both real roots. It returns `None` when the
//! discriminant interval reaches below 0, when the smaller root's interval
//! ends above `t_max`, or when the larger root's interval starts at or below
//! 0. So it surely returns `None` when the *real* discriminant is negative,
//! when both real roots exceed `t_max`, or when both are negative. This test
//! computes the same real quantities in f64, whose products of f32 inputs
//! are exact and whose rounding (a few 1e-16 of the magnitudes involved) is
//! seven orders below the margin of 1e-9 of those magnitudes it requires
//! before it decides. Nearly grazing rays (half-chord below √1e-9 of the
//! magnitudes, where the roots are ill-conditioned) are left to the
//! interval code, and so are transforms that are not affine or are badly
//! conditioned (where the rounding of the transformed ray is not bounded by
//! the magnitudes used here).

use crate::math::{Ray, Transform};
use glam::{DAffine3, Mat4};

/// Relative margin over the f64 rounding error before the test decides.
const MARGIN: f64 = 1e-9;

/// The object-from-render transform of a sphere, in f64.
#[derive(Clone, Debug)]
pub(super) struct MissTest {
    object_from_render: DAffine3,
    /// Σ |mᵢⱼ| over the linear part, and Σ |tᵢ|: bound the magnitudes
    /// (hence the rounding) of the transformed origin's terms.
    lin_abs: f64,
    trans_abs: f64,
}

impl MissTest {
    /// The test for a sphere placed by `render_from_object`; `None` when the
    /// transform is not affine or its condition number exceeds 1e3.
    pub fn new(render_from_object: &Transform) -> Option<Self> {
        let m: Mat4 = render_from_object.m_inv;
        let affine = m.row(3) == glam::Vec4::new(0.0, 0.0, 0.0, 1.0);
        let frob = |m: &Mat4| {
            (0..3)
                .map(|i| m.row(i).truncate().length_squared() as f64)
                .sum::<f64>()
                .sqrt()
        };
        let cond = frob(&render_from_object.m) * frob(&m);
        let well_conditioned = cond < 1e3; // false for NaN
        if !affine || !well_conditioned {
            return None;
        }
        let object_from_render = DAffine3::from_mat4(m.as_dmat4());
        let lin = object_from_render.matrix3;
        let lin_abs = (lin.x_axis.abs() + lin.y_axis.abs() + lin.z_axis.abs()).element_sum();
        let trans_abs = object_from_render.translation.abs().element_sum();
        Some(Self {
            object_from_render,
            lin_abs,
            trans_abs,
        })
    }

    /// True only if the ray certainly misses the sphere of `radius` for
    /// every `t ∈ (0, t_max]` (see the module doc).
    pub fn misses(&self, radius: f32, ray: &Ray, t_max: f32) -> bool {
        let (ro, rd) = (ray.o.as_dvec3(), ray.d.as_dvec3());
        let o = self.object_from_render.transform_point3(ro);
        let d = self.object_from_render.transform_vector3(rd);
        let r = f64::from(radius);
        let dd = d.length_squared();
        // Ray parameter and distance from the centre of the closest point.
        let tc = -o.dot(d) / dd;
        let len_f = (o + tc * d).length();
        let scale = o.length() + r + self.lin_abs * ro.abs().max_element() + self.trans_abs;
        let tol = MARGIN * scale;
        if len_f > r + tol {
            return true;
        }
        let h2 = (r - len_f) * (r + len_f);
        let well_conditioned = h2 > MARGIN * scale * scale; // false for NaN
        if !well_conditioned {
            return false;
        }
        // Half-chord in units of t, and the margin in those units.
        let inv_len_d = dd.sqrt().recip();
        let (h, t_tol) = (h2.sqrt() * inv_len_d, tol * inv_len_d);
        tc - h > f64::from(t_max) + t_tol || tc + h < -t_tol
    }
}

#[cfg(test)]
mod tests {
    use super::super::sphere::Sphere;
    use crate::math::{Ray, Transform, Vec3};
    use crate::sampling::{sample_uniform_sphere, Pcg32};
    use glam::{Mat4, Quat, Vec2};

    use std::sync::Arc;

    fn u2(r: &mut Pcg32) -> Vec2 {
        Vec2::new(r.uniform_f32(), r.uniform_f32())
    }

    /// Rays built to straddle every decision boundary of the test (grazing,
    /// ending just before or after the surface, starting on it), checked
    /// against the interval intersection: a miss must never hide a hit.
    #[test]
    fn miss_test_never_rejects_an_interval_hit() {
        let m = Mat4::from_scale_rotation_translation(
            Vec3::splat(2.5),
            Quat::from_rotation_z(0.7),
            Vec3::new(150.0, 120.0, 20.0),
        );
        let sphere = Sphere::new(
            Arc::new(Transform::new(m, m.inverse())),
            false,
            3.0,
            -3.0,
            3.0,
            360.0,
        );
        let (c, r) = (Vec3::new(150.0, 120.0, 20.0), 7.5);
        let mut rng = Pcg32::new(7, 0);
        let (mut culled, mut hits) = (0, 0);
        for i in 0..200_000 {
            let o =
                c + sample_uniform_sphere(u2(&mut rng)) * r * [0.0, 1.0, 1.001, 3.0, 300.0][i % 5];
            // Towards a point on, just inside or just outside the sphere.
            let rim = 1.0 + (rng.uniform_f32() - 0.5) * [0.0, 1e-6, 1e-3, 0.2][i % 4];
            let target = c + sample_uniform_sphere(u2(&mut rng)) * r * rim;
            let ray = Ray::new(o, target - o);
            let t_max = [1.0 - 1e-4, 1.0, 1.0 + 1e-7, f32::INFINITY][(i / 4) % 4];
            let culls = sphere.miss_test_culls(&ray, t_max);
            let hit = sphere.interval_intersect(&ray, t_max).is_some();
            assert!(!(culls && hit), "ray {i}: culled a hit");
            culled += culls as u32;
            hits += hit as u32;
        }
        // Both outcomes must be exercised many times for the check to mean anything.
        assert!(
            culled > 10_000 && hits > 10_000,
            "culled {culled}, hits {hits}"
        );
    }
}
