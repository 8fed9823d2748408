//! Affine and projective transforms with their inverses.
//!
//! Matrices are glam's column-major `Mat4`; a transform maps column vectors
//! `p' = M p`. Points carry a rounding-error bound through the transform
//! [pbrt-v4 §6.8.4, eq. 6.54].

use super::{gamma, Bounds3};
use glam::{Mat4, Vec3, Vec4};

/// A transform and its inverse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// The matrix.
    pub m: Mat4,
    /// Its inverse.
    pub m_inv: Mat4,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// The identity.
    pub const IDENTITY: Self = Self {
        m: Mat4::IDENTITY,
        m_inv: Mat4::IDENTITY,
    };

    /// From a matrix and its known inverse.
    pub fn new(m: Mat4, m_inv: Mat4) -> Self {
        Self { m, m_inv }
    }

    /// From row-major f64 rows (the scene description's layout); the inverse
    /// is computed in f64 for accuracy. `None` when singular.
    pub fn from_rows_f64(rows: [[f64; 4]; 4]) -> Option<Self> {
        let m = glam::DMat4::from_cols_array_2d(&rows).transpose();
        let det = m.determinant();
        if !det.is_finite() || det == 0.0 {
            return None;
        }
        let inv = m.inverse();
        Some(Self {
            m: m.as_mat4(),
            m_inv: inv.as_mat4(),
        })
    }

    /// Inverse transform.
    #[inline]
    pub fn inverse(&self) -> Self {
        Self {
            m: self.m_inv,
            m_inv: self.m,
        }
    }

    /// Composition: `self ∘ o` (apply `o` first).
    #[inline]
    pub fn then_after(&self, o: &Self) -> Self {
        Self {
            m: self.m * o.m,
            m_inv: o.m_inv * self.m_inv,
        }
    }

    /// Translation.
    pub fn translate(d: Vec3) -> Self {
        Self {
            m: Mat4::from_translation(d),
            m_inv: Mat4::from_translation(-d),
        }
    }

    /// Non-uniform scale.
    pub fn scale(s: Vec3) -> Self {
        Self {
            m: Mat4::from_scale(s),
            m_inv: Mat4::from_scale(s.recip()),
        }
    }

    /// Transforms a point (with perspective divide).
    #[inline]
    pub fn point(&self, p: Vec3) -> Vec3 {
        let r = self.m * Vec4::new(p.x, p.y, p.z, 1.0);
        if r.w == 1.0 {
            r.truncate()
        } else {
            r.truncate() / r.w
        }
    }

    /// Transforms an affine point and returns a conservative bound on the
    /// absolute rounding error of the result [pbrt-v4 eq. 6.54].
    #[inline]
    pub fn point_with_error(&self, p: Vec3) -> (Vec3, Vec3) {
        let out = self.point(p);
        let a = self.m.abs();
        let err = gamma(3) * (a.transform_vector3(p.abs()) + a.w_axis.truncate());
        (out, err)
    }

    /// Transforms a point that already carries an error bound `p_err`
    /// [pbrt-v4 eq. 6.55 and following].
    #[inline]
    pub fn point_with_error_prop(&self, p: Vec3, p_err: Vec3) -> (Vec3, Vec3) {
        let out = self.point(p);
        let a = self.m.abs();
        let err = (gamma(3) + 1.0) * a.transform_vector3(p_err)
            + gamma(3) * (a.transform_vector3(p.abs()) + a.w_axis.truncate());
        (out, err)
    }

    /// Transforms a direction.
    #[inline]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.m.transform_vector3(v)
    }

    /// Transforms a surface normal (by the inverse transpose).
    #[inline]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        self.m_inv.transpose().transform_vector3(n)
    }

    /// Transforms a box (bounds of its 8 transformed corners).
    pub fn bounds(&self, b: &Bounds3) -> Bounds3 {
        let mut out = Bounds3::EMPTY;
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { b.min.x } else { b.max.x },
                if i & 2 == 0 { b.min.y } else { b.max.y },
                if i & 4 == 0 { b.min.z } else { b.max.z },
            );
            out = out.union_point(self.point(c));
        }
        out
    }

    /// True when the transform flips handedness (negative 3×3 determinant).
    pub fn swaps_handedness(&self) -> bool {
        glam::Mat3::from_mat4(self.m).determinant() < 0.0
    }
}

/// Perspective projection as pbrt-v4 defines it: maps camera space to a
/// canonical volume where z ∈ [0, 1] between `n` and `f` and x, y are
/// scaled by 1/tan(fov/2) [pbrt-v4 §5.2.3].
pub fn perspective(fov_deg: f32, n: f32, f: f32) -> Transform {
    let persp = Mat4::from_cols(
        Vec4::new(1.0, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 1.0, 0.0, 0.0),
        Vec4::new(0.0, 0.0, f / (f - n), 1.0),
        Vec4::new(0.0, 0.0, -f * n / (f - n), 0.0),
    );
    let inv_tan = 1.0 / (fov_deg.to_radians() / 2.0).tan();
    let s = Mat4::from_scale(Vec3::new(inv_tan, inv_tan, 1.0));
    let m = s * persp;
    Transform {
        m,
        m_inv: m.inverse(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_f64_round_trip_and_error_bound() {
        let rows = [
            [2.0, 0.0, 0.0, 1.0],
            [0.0, 3.0, 0.0, -2.0],
            [0.0, 0.0, 1.0, 0.5],
            [0.0, 0.0, 0.0, 1.0],
        ];
        let t = Transform::from_rows_f64(rows).unwrap();
        let p = Vec3::new(1.0, 1.0, 1.0);
        assert_eq!(t.point(p), Vec3::new(3.0, 1.0, 1.5));
        assert!((t.inverse().point(t.point(p)) - p).length() < 1e-6);
        let (q, e) = t.point_with_error(Vec3::new(0.1, 0.2, 0.3));
        let exact = glam::DVec3::new(
            2.0 * 0.1f32 as f64 + 1.0,
            3.0 * 0.2f32 as f64 - 2.0,
            0.3f32 as f64 + 0.5,
        );
        for i in 0..3 {
            assert!((q[i] as f64 - exact[i]).abs() <= e[i] as f64);
        }
        assert!(Transform::from_rows_f64([[0.0; 4]; 4]).is_none());
    }

    #[test]
    fn perspective_maps_near_far() {
        let p = perspective(90.0, 1e-2, 1000.0);
        let a = p.point(Vec3::new(0.0, 0.0, 1e-2));
        let b = p.point(Vec3::new(1.0, 1.0, 1.0));
        assert!(a.z.abs() < 1e-5);
        assert!((b.x - 1.0).abs() < 1e-5 && (b.y - 1.0).abs() < 1e-5);
    }
}
