//! Orthonormal frames: the shading frame of BSDFs and local light frames.

use glam::{Vec3, Vec3A};

/// An orthonormal basis; `z` is the normal direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent.
    pub x: Vec3,
    /// Second tangent.
    pub y: Vec3,
    /// Normal.
    pub z: Vec3,
}

impl Frame {
    /// Frame with `z = n` and tangents chosen without branching on a
    /// degenerate axis [Duff et al. 2017, "Building an orthonormal basis, revisited"].
    pub fn from_z(n: Vec3) -> Self {
        let (x, y) = coordinate_system(n);
        Self { x, y, z: n }
    }

    /// Frame with `z = n` whose `x` follows the tangent `t` (Gram–Schmidt).
    pub fn from_xz(t: Vec3, n: Vec3) -> Self {
        FrameA::from_xz(t.into(), n.into()).into()
    }

    /// World (or parent) space → local coordinates.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }

    /// Local coordinates → world (or parent) space.
    #[inline]
    pub fn from_local(&self, v: Vec3) -> Vec3 {
        self.x * v.x + self.y * v.y + self.z * v.z
    }
}

/// A [`Frame`] held in 16-byte `Vec3A` vectors, for the frames built and
/// used at every hit (the BSDF's): the same operations lane by lane in the
/// same order as on `Vec3`, so the same numbers, but as whole-register SIMD.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameA {
    /// First tangent.
    pub x: Vec3A,
    /// Second tangent.
    pub y: Vec3A,
    /// Normal.
    pub z: Vec3A,
}

impl FrameA {
    /// Frame with `z = n` whose `x` follows the tangent `t` (Gram–Schmidt);
    /// [`Frame::from_z`] when `t` is (nearly) parallel to `n`.
    #[inline]
    pub fn from_xz(t: Vec3A, n: Vec3A) -> Self {
        let x = t - n * n.dot(t);
        let len = x.length();
        if len.is_nan() || len <= 1e-12 || !len.is_finite() {
            return Frame::from_z(n.into()).into();
        }
        let x = x / len;
        Self {
            x,
            y: n.cross(x),
            z: n,
        }
    }

    /// World (or parent) space → local coordinates.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        let v = Vec3A::from(v);
        Vec3::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }

    /// Local coordinates → world (or parent) space.
    #[inline]
    pub fn from_local(&self, v: Vec3) -> Vec3 {
        (self.x * v.x + self.y * v.y + self.z * v.z).into()
    }
}

impl From<Frame> for FrameA {
    #[inline]
    fn from(f: Frame) -> Self {
        Self {
            x: f.x.into(),
            y: f.y.into(),
            z: f.z.into(),
        }
    }
}

impl From<FrameA> for Frame {
    #[inline]
    fn from(f: FrameA) -> Self {
        Self {
            x: f.x.into(),
            y: f.y.into(),
            z: f.z.into(),
        }
    }
}

/// Two unit vectors completing `n` to an orthonormal basis [Duff et al. 2017].
pub fn coordinate_system(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_and_round_trip() {
        let dirs = [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.4, 0.866).normalize(),
            Vec3::new(0.0, 0.0, -0.9999).normalize(),
        ];
        for n in dirs {
            let f = Frame::from_z(n);
            assert!((f.x.length() - 1.0).abs() < 1e-5 && (f.y.length() - 1.0).abs() < 1e-5);
            assert!(
                f.x.dot(f.y).abs() < 1e-5 && f.x.dot(n).abs() < 1e-5 && f.y.dot(n).abs() < 1e-5
            );
            let v = Vec3::new(0.2, -0.7, 0.5);
            assert!((f.from_local(f.to_local(v)) - v).length() < 1e-5);
        }
    }
}
