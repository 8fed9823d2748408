//! Transforms that move during the shutter interval (motion blur).
//!
//! pbrt-v4 keeps two transforms per object, at `TransformTimes` start and end
//! [pbrt-v4 §A.5 "Animating Transformations"]. Interpolating the matrices
//! entry by entry would shear a rotating object, so each matrix is decomposed
//! as M = T·R·S (translation, rotation, the remaining scale/shear) and the
//! factors are interpolated separately: T and S linearly, R by quaternion
//! slerp [Shoemake and Duff 1992, "Matrix animation and polar decomposition"].
//! R comes from the polar decomposition of M's 3×3 part, computed by the
//! Newton iteration Rᵢ₊₁ = ½(Rᵢ + Rᵢ⁻ᵀ), which converges to the orthogonal
//! factor nearest to M; then S = R⁻¹M.
//!
//! [`AnimatedTransform::motion_bounds`] bounds a box over the whole interval:
//! the union of the box transformed at 65 evenly spaced times, padded by the
//! largest distance a corner moves between two consecutive times. Between
//! samples each corner follows a smooth curve turning by at most 1/64 of the
//! total rotation, so it stays within that distance of a sampled position.

use super::{Bounds3, Transform};
use glam::{DMat3, DMat4, DQuat, DVec3};

/// A transform interpolated between its values at two times.
#[derive(Clone, Copy, Debug)]
pub struct AnimatedTransform {
    start: Transform,
    end: Transform,
    start_time: f32,
    end_time: f32,
    /// Decomposition of `start` and `end`: translation, rotation, scale.
    t: [DVec3; 2],
    r: [DQuat; 2],
    s: [DMat3; 2],
}

/// M = T·R·S: translation, rotation (unit quaternion), scale/shear.
fn decompose(m: &DMat4) -> (DVec3, DQuat, DMat3) {
    let t = m.w_axis.truncate();
    let a = DMat3::from_mat4(*m);
    let mut r = a;
    for _ in 0..100 {
        let next = (r + r.inverse().transpose()) * 0.5;
        let change = (0..3)
            .map(|c| (next.col(c) - r.col(c)).abs().element_sum())
            .fold(0.0, f64::max);
        r = next;
        if change < 1e-12 {
            break;
        }
    }
    // A reflection is kept in S so that R is a proper rotation.
    if r.determinant() < 0.0 {
        r = -r;
    }
    let s = r.transpose() * a;
    (t, DQuat::from_mat3(&r).normalize(), s)
}

impl AnimatedTransform {
    /// The transform `start` at `start_time` moving to `end` at `end_time`.
    pub fn new(start: Transform, start_time: f32, end: Transform, end_time: f32) -> Self {
        let d = |x: &Transform| x.m.as_dmat4();
        let (t0, r0, s0) = decompose(&d(&start));
        let (t1, mut r1, s1) = decompose(&d(&end));
        // Take the shorter way round.
        if r0.dot(r1) < 0.0 {
            r1 = -r1;
        }
        Self {
            start,
            end,
            start_time,
            end_time,
            t: [t0, t1],
            r: [r0, r1],
            s: [s0, s1],
        }
    }

    /// True when the start and end transforms differ.
    pub fn is_animated(&self) -> bool {
        self.start != self.end
    }

    /// The transform at `time` (clamped to the interval).
    pub fn at(&self, time: f32) -> Transform {
        if !self.is_animated() || time <= self.start_time {
            return self.start;
        }
        if time >= self.end_time {
            return self.end;
        }
        let u = ((time - self.start_time) / (self.end_time - self.start_time)) as f64;
        let t = self.t[0].lerp(self.t[1], u);
        let r = self.r[0].slerp(self.r[1], u);
        let s = self.s[0] * (1.0 - u) + self.s[1] * u;
        let m3 = DMat3::from_quat(r) * s;
        let m = DMat4::from_cols(
            m3.x_axis.extend(0.0),
            m3.y_axis.extend(0.0),
            m3.z_axis.extend(0.0),
            t.extend(1.0),
        );
        Transform::new(m.as_mat4(), m.inverse().as_mat4())
    }

    /// A box bounding `b` transformed at every time of the interval.
    pub fn motion_bounds(&self, b: &Bounds3) -> Bounds3 {
        if !self.is_animated() {
            return self.start.bounds(b);
        }
        const STEPS: usize = 64;
        let corners = |x: &Transform| -> [glam::Vec3; 8] {
            std::array::from_fn(|i| {
                x.point(glam::Vec3::new(
                    if i & 1 == 0 { b.min.x } else { b.max.x },
                    if i & 2 == 0 { b.min.y } else { b.max.y },
                    if i & 4 == 0 { b.min.z } else { b.max.z },
                ))
            })
        };
        let time = |k: usize| {
            self.start_time + (self.end_time - self.start_time) * k as f32 / STEPS as f32
        };
        let mut out = Bounds3::EMPTY;
        let mut prev = corners(&self.at(time(0)));
        let mut pad = 0.0f32;
        for c in prev {
            out = out.union_point(c);
        }
        for k in 1..=STEPS {
            let cur = corners(&self.at(time(k)));
            for (a, c) in prev.iter().zip(cur) {
                pad = pad.max(a.distance(c));
                out = out.union_point(c);
            }
            prev = cur;
        }
        Bounds3 {
            min: out.min - glam::Vec3::splat(pad),
            max: out.max + glam::Vec3::splat(pad),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, Vec3};

    fn tf(m: Mat4) -> Transform {
        Transform::new(m, m.inverse())
    }

    #[test]
    fn endpoints_are_exact_and_translation_interpolates_linearly() {
        let a = tf(Mat4::from_translation(Vec3::new(1.0, 2.0, 3.0)));
        let b = tf(Mat4::from_translation(Vec3::new(5.0, 2.0, -1.0)));
        let at = AnimatedTransform::new(a, 0.0, b, 2.0);
        assert_eq!(at.at(-1.0), a);
        assert_eq!(at.at(3.0), b);
        let p = at.at(0.5).point(Vec3::ZERO);
        assert!(p.distance(Vec3::new(2.0, 2.0, 2.0)) < 1e-5, "{p}");
    }

    #[test]
    fn rotation_is_interpolated_rigidly_not_entrywise() {
        // A quarter turn about z with a scale of 2: half-way is an eighth of a
        // turn, still scaled by 2 (entry-wise lerp would shrink it to √2).
        let a = tf(Mat4::from_scale(Vec3::splat(2.0)));
        let b =
            tf(Mat4::from_rotation_z(std::f32::consts::FRAC_PI_2)
                * Mat4::from_scale(Vec3::splat(2.0)));
        let at = AnimatedTransform::new(a, 0.0, b, 1.0);
        let p = at.at(0.5).point(Vec3::X);
        let h = std::f32::consts::FRAC_1_SQRT_2 * 2.0;
        assert!(p.distance(Vec3::new(h, h, 0.0)) < 1e-5, "{p}");
    }

    #[test]
    fn decomposition_recovers_a_sheared_reflected_matrix() {
        let m = Mat4::from_cols_array(&[
            -1.5, 0.2, 0.0, 0.0, 0.3, 0.9, 0.1, 0.0, 0.0, -0.4, 2.0, 0.0, 3.0, -1.0, 0.5, 1.0,
        ]);
        let at = AnimatedTransform::new(tf(m), 0.0, tf(Mat4::IDENTITY), 1.0);
        // At t = 0⁺ the interpolated matrix must be (nearly) m itself.
        let m0 = at.at(1e-7).m;
        assert!(m0.abs_diff_eq(m, 1e-4), "{m0} vs {m}");
    }

    #[test]
    fn motion_bounds_contain_the_box_at_every_time() {
        let a = tf(Mat4::from_translation(Vec3::new(0.0, 0.0, 0.0)));
        let b = tf(Mat4::from_translation(Vec3::new(4.0, 0.0, 0.0)) * Mat4::from_rotation_y(3.0));
        let at = AnimatedTransform::new(a, 0.0, b, 1.0);
        let bx = Bounds3 {
            min: Vec3::new(-1.0, -0.5, -2.0),
            max: Vec3::new(1.0, 0.5, 2.0),
        };
        let mb = at.motion_bounds(&bx);
        for k in 0..=1000 {
            let t = at.at(k as f32 / 1000.0).bounds(&bx);
            assert!(
                mb.min.cmple(t.min).all() && mb.max.cmpge(t.max).all(),
                "{k}"
            );
        }
    }
}
