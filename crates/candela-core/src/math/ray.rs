//! Rays and error-bounded ray spawning.
//!
//! Intersection routines return a conservative absolute error bound
//! `p_error` on each hit point. A spawned ray's origin is pushed along the
//! geometric normal just past that bound, so it can neither re-hit the
//! surface it leaves nor start behind it — no scene-scale epsilon involved
//! [pbrt-v4 §6.8.6, `OffsetRayOrigin`].

use super::{next_float_down, next_float_up};
use glam::Vec3;

/// Fraction of a segment a shadow ray stops short of its target, so the
/// target surface itself is not reported as an occluder (pbrt-v4's `ShadowEpsilon`).
pub const SHADOW_EPSILON: f32 = 0.0001;

/// A ray `o + t·d`, `t ∈ (0, t_max)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub o: Vec3,
    /// Direction (not necessarily normalised).
    pub d: Vec3,
    /// Time within the shutter interval; moving geometry is placed at this
    /// time (0 and irrelevant in static scenes).
    pub time: f32,
}

impl Ray {
    /// New ray at time 0.
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        Self { o, d, time: 0.0 }
    }
    /// The same ray at another time.
    #[inline]
    pub fn at_time(self, time: f32) -> Self {
        Self { time, ..self }
    }
    /// Point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

/// Moves `p` along ±`n` past its error box `p_error`, to the side `w` points to,
/// then rounds each coordinate away from the surface.
#[inline]
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(p_error);
    let mut offset = d * n;
    if w.dot(n) < 0.0 {
        offset = -offset;
    }
    let mut po = p + offset;
    for i in 0..3 {
        if offset[i] > 0.0 {
            po[i] = next_float_up(po[i]);
        } else if offset[i] < 0.0 {
            po[i] = next_float_down(po[i]);
        }
    }
    po
}

/// Ray leaving a surface point in direction `d`.
#[inline]
pub fn spawn_ray(p: Vec3, p_error: Vec3, n: Vec3, d: Vec3) -> Ray {
    Ray::new(offset_ray_origin(p, p_error, n, d), d)
}

/// Ray from a surface point towards `p_to`; its direction is scaled so that
/// `t = 1 − SHADOW_EPSILON` stops just before the target.
#[inline]
pub fn spawn_ray_to(p: Vec3, p_error: Vec3, n: Vec3, p_to: Vec3) -> Ray {
    let o = offset_ray_origin(p, p_error, n, p_to - p);
    Ray::new(o, p_to - o)
}
