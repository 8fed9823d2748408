//! Cones of directions [pbrt-v4 §3.9.4 `DirectionCone`].
//!
//! A cone is a unit axis `w` and the cosine of its half-angle θ; it holds
//! the directions ω with ω·w ≥ cos θ. The whole sphere is the cone of
//! half-angle π (cos θ = −1). Two uses: the normals of a shape's surface
//! (the light BVH's emission cones) and the directions a box subtends from
//! a point (through its bounding sphere).
//!
//! The union of two cones of half-angles θa, θb whose axes are θd apart is
//! the cone that spans both: if one already contains the other it is the
//! union; otherwise its half-angle is θo = (θa + θd + θb)/2 and its axis is
//! `a.w` rotated by θo − θa towards `b.w` in their common plane [pbrt-v4
//! §3.9.4, "Bounding the union of two cones"]. The angles are computed in
//! f64 so that the f32 result does not shrink the union by round-off.

use super::{Bounds3, Vec3};
use glam::DVec3;
use std::f64::consts::PI as PI64;

/// A cone of directions: axis `w` (unit) and cos of the half-angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionCone {
    /// Unit axis.
    pub w: Vec3,
    /// Cosine of the half-angle (−1: the whole sphere).
    pub cos_theta: f32,
}

impl DirectionCone {
    /// The cone about `w` (normalised here; a zero `w` gives the whole
    /// sphere) with half-angle cosine `cos_theta`.
    pub fn new(w: Vec3, cos_theta: f32) -> Self {
        match w.try_normalize() {
            Some(w) => Self { w, cos_theta },
            None => Self::entire_sphere(),
        }
    }

    /// The single direction `w` (half-angle 0).
    pub fn from_direction(w: Vec3) -> Self {
        Self::new(w, 1.0)
    }

    /// Every direction.
    pub fn entire_sphere() -> Self {
        Self {
            w: Vec3::Z,
            cos_theta: -1.0,
        }
    }

    /// True when the direction `w` (any length) lies in the cone.
    pub fn contains(&self, w: Vec3) -> bool {
        self.w.dot(w.normalize()) >= self.cos_theta
    }

    /// The smallest cone holding both (see the module doc).
    pub fn union(self, b: Self) -> Self {
        let theta_a = (self.cos_theta as f64).clamp(-1.0, 1.0).acos();
        let theta_b = (b.cos_theta as f64).clamp(-1.0, 1.0).acos();
        let (wa, wb) = (self.w.as_dvec3(), b.w.as_dvec3());
        let theta_d = angle_between(wa, wb);
        if (theta_d + theta_b).min(PI64) <= theta_a {
            return self;
        }
        if (theta_d + theta_a).min(PI64) <= theta_b {
            return b;
        }
        let theta_o = (theta_a + theta_d + theta_b) / 2.0;
        if theta_o >= PI64 {
            return Self::entire_sphere();
        }
        // Rotate wa by θr = θo − θa about k = wa × wb (Rodrigues; k ⟂ wa).
        let theta_r = theta_o - theta_a;
        let Some(k) = wa.cross(wb).try_normalize() else {
            return Self::entire_sphere();
        };
        let w = wa * theta_r.cos() + k.cross(wa) * theta_r.sin();
        Self::new(w.as_vec3(), theta_o.cos() as f32)
    }

    /// The directions from `p` towards the bounding sphere of `b`; the whole
    /// sphere when `p` lies inside that sphere [pbrt-v4 §3.9.4
    /// `BoundSubtendedDirections`].
    pub fn bound_subtended(b: &Bounds3, p: Vec3) -> Self {
        let (center, radius) = b.bounding_sphere();
        let d2 = p.distance_squared(center);
        if d2 <= radius * radius {
            return Self::entire_sphere();
        }
        let sin2_max = radius * radius / d2;
        Self::new(center - p, (1.0 - sin2_max).max(0.0).sqrt())
    }
}

/// Angle between two unit vectors, accurate when nearly (anti)parallel.
fn angle_between(a: DVec3, b: DVec3) -> f64 {
    if a.dot(b) < 0.0 {
        PI64 - 2.0 * ((a + b).length() / 2.0).min(1.0).asin()
    } else {
        2.0 * ((b - a).length() / 2.0).min(1.0).asin()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subtended_cone_touches_the_bounding_sphere() {
        let b = Bounds3::from_points(Vec3::splat(-1.0), Vec3::splat(1.0));
        let r = 3f32.sqrt();
        let c = DirectionCone::bound_subtended(&b, Vec3::new(0.0, 0.0, 4.0));
        assert_eq!(c.w, -Vec3::Z);
        assert!((c.cos_theta - (1.0 - r * r / 16.0).sqrt()).abs() < 1e-6);
        let inside = DirectionCone::bound_subtended(&b, Vec3::new(0.0, 0.0, 1.5));
        assert_eq!(inside.cos_theta, -1.0);
        let point = Bounds3::from_point(Vec3::ZERO);
        assert_eq!(
            DirectionCone::bound_subtended(&point, Vec3::ZERO).cos_theta,
            -1.0
        );
    }
}
