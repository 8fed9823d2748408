//! A tiny 4x4 double-precision matrix for scene transforms.
//!
//! The scene reader must not depend on the rendering core's math, so it keeps
//! its own minimal `Mat4d`: row-major storage, applied as `m * p` to column
//! points, composed like pbrt's `Transform` (the CTM is post-multiplied by
//! each new transform). Constructors follow pbrt-v4's `transform.cpp`
//! definitions of `Translate`, `Scale`, `Rotate` and `LookAt`.

use std::ops::Mul;

/// A 4x4 matrix of `f64`, row-major: `m[row][col]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mat4d {
    /// Rows of the matrix.
    pub m: [[f64; 4]; 4],
}

impl Default for Mat4d {
    fn default() -> Self {
        Mat4d::IDENTITY
    }
}

impl Mat4d {
    /// The identity matrix.
    pub const IDENTITY: Mat4d = Mat4d {
        m: [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ],
    };

    /// A matrix from its rows.
    pub fn from_rows(m: [[f64; 4]; 4]) -> Mat4d {
        Mat4d { m }
    }

    /// Translation by `d`.
    pub fn translate(d: [f64; 3]) -> Mat4d {
        let mut r = Mat4d::IDENTITY;
        for (i, v) in d.iter().enumerate() {
            r.m[i][3] = *v;
        }
        r
    }

    /// Non-uniform scale.
    pub fn scale(s: [f64; 3]) -> Mat4d {
        let mut r = Mat4d::IDENTITY;
        for (i, v) in s.iter().enumerate() {
            r.m[i][i] = *v;
        }
        r
    }

    /// Rotation by `degrees` about `axis` (normalized here), right-handed
    /// as in pbrt-v4's `Rotate(theta, axis)`. A zero axis gives identity.
    pub fn rotate(degrees: f64, axis: [f64; 3]) -> Mat4d {
        let len = dot(axis, axis).sqrt();
        if len == 0.0 || !len.is_finite() {
            return Mat4d::IDENTITY;
        }
        let [x, y, z] = axis.map(|c| c / len);
        let (s, c) = degrees.to_radians().sin_cos();
        Mat4d::from_rows([
            [
                x * x + (1.0 - x * x) * c,
                x * y * (1.0 - c) - z * s,
                x * z * (1.0 - c) + y * s,
                0.0,
            ],
            [
                x * y * (1.0 - c) + z * s,
                y * y + (1.0 - y * y) * c,
                y * z * (1.0 - c) - x * s,
                0.0,
            ],
            [
                x * z * (1.0 - c) - y * s,
                y * z * (1.0 - c) + x * s,
                z * z + (1.0 - z * z) * c,
                0.0,
            ],
            [0.0, 0.0, 0.0, 1.0],
        ])
    }

    /// pbrt-v4 `LookAt`: the camera-from-world matrix for a camera at `eye`
    /// looking at `look` with approximate `up`. `None` if the view
    /// direction is degenerate or parallel to `up`.
    pub fn look_at(eye: [f64; 3], look: [f64; 3], up: [f64; 3]) -> Option<Mat4d> {
        let dir = normalize(sub(look, eye))?;
        let right = normalize(cross(normalize(up)?, dir))?;
        let new_up = cross(dir, right);
        // Columns of world-from-camera are right, up, dir and the eye.
        let mut w = Mat4d::IDENTITY;
        for i in 0..3 {
            w.m[i][0] = right[i];
            w.m[i][1] = new_up[i];
            w.m[i][2] = dir[i];
            w.m[i][3] = eye[i];
        }
        w.inverse()
    }

    /// The transpose.
    pub fn transpose(&self) -> Mat4d {
        let mut r = Mat4d::IDENTITY;
        for (i, row) in r.m.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = self.m[j][i];
            }
        }
        r
    }

    /// The inverse by Gauss-Jordan elimination with partial pivoting;
    /// `None` for singular (or non-finite) matrices.
    pub fn inverse(&self) -> Option<Mat4d> {
        let mut a = self.m;
        let mut inv = Mat4d::IDENTITY.m;
        for col in 0..4 {
            let pivot = (col..4).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
            let p = a[pivot][col];
            if p == 0.0 || !p.is_finite() {
                return None;
            }
            a.swap(col, pivot);
            inv.swap(col, pivot);
            for j in 0..4 {
                a[col][j] /= p;
                inv[col][j] /= p;
            }
            for row in 0..4 {
                let f = a[row][col];
                if row != col && f != 0.0 {
                    for j in 0..4 {
                        a[row][j] -= f * a[col][j];
                        inv[row][j] -= f * inv[col][j];
                    }
                }
            }
        }
        let r = Mat4d { m: inv };
        r.m.iter().flatten().all(|v| v.is_finite()).then_some(r)
    }

    /// Applies the matrix to a point (w = 1) with perspective divide.
    pub fn transform_point(&self, p: [f64; 3]) -> [f64; 3] {
        let h = |r: &[f64; 4]| r[0] * p[0] + r[1] * p[1] + r[2] * p[2] + r[3];
        let w = h(&self.m[3]);
        let w = if w == 0.0 { 1.0 } else { w };
        [h(&self.m[0]) / w, h(&self.m[1]) / w, h(&self.m[2]) / w]
    }

    /// Applies the upper 3x3 block to a vector.
    pub fn transform_vector(&self, v: [f64; 3]) -> [f64; 3] {
        let h = |r: &[f64; 4]| r[0] * v[0] + r[1] * v[1] + r[2] * v[2];
        [h(&self.m[0]), h(&self.m[1]), h(&self.m[2])]
    }

    /// Whether the upper 3x3 block has a negative determinant (the
    /// transform flips handedness).
    pub fn swaps_handedness(&self) -> bool {
        let m = &self.m;
        let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
        det < 0.0
    }

    /// Whether all entries are within `eps` of `other`'s.
    pub fn approx_eq(&self, other: &Mat4d, eps: f64) -> bool {
        self.m
            .iter()
            .flatten()
            .zip(other.m.iter().flatten())
            .all(|(a, b)| (a - b).abs() <= eps)
    }
}

impl Mul for Mat4d {
    type Output = Mat4d;
    fn mul(self, rhs: Mat4d) -> Mat4d {
        let mut r = [[0.0; 4]; 4];
        for (i, row) in r.iter_mut().enumerate() {
            for (j, v) in row.iter_mut().enumerate() {
                *v = (0..4).map(|k| self.m[i][k] * rhs.m[k][j]).sum();
            }
        }
        Mat4d { m: r }
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Unit vector along `v`, or `None` for a zero or non-finite vector.
fn normalize(v: [f64; 3]) -> Option<[f64; 3]> {
    let l = dot(v, v).sqrt();
    (l > 0.0 && l.is_finite()).then(|| v.map(|c| c / l))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_round_trip() {
        let m = Mat4d::translate([1.0, 2.0, 3.0])
            * Mat4d::rotate(33.0, [1.0, 1.0, 0.0])
            * Mat4d::scale([2.0, -1.0, 0.5]);
        let i = m.inverse().unwrap();
        assert!((m * i).approx_eq(&Mat4d::IDENTITY, 1e-12));
        assert!(Mat4d::scale([0.0, 1.0, 1.0]).inverse().is_none());
    }

    #[test]
    fn rotate_z_90() {
        let r = Mat4d::rotate(90.0, [0.0, 0.0, 1.0]);
        let p = r.transform_point([1.0, 0.0, 0.0]);
        assert!((p[0]).abs() < 1e-12 && (p[1] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn look_at_maps_eye_to_origin_and_look_to_plus_z() {
        let m = Mat4d::look_at([1.0, 2.0, 3.0], [1.0, 2.0, 5.0], [0.0, 1.0, 0.0]).unwrap();
        let e = m.transform_point([1.0, 2.0, 3.0]);
        let l = m.transform_point([1.0, 2.0, 5.0]);
        assert!(e.iter().all(|c| c.abs() < 1e-12));
        assert!((l[2] - 2.0).abs() < 1e-12 && l[0].abs() < 1e-12);
        assert!(Mat4d::look_at([0.0; 3], [0.0, 1.0, 0.0], [0.0, 1.0, 0.0]).is_none());
    }
}
