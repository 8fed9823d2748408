//! Conservative interval arithmetic for quadric intersection.
//!
//! Each operation rounds its result outward by one ulp on both ends, so the
//! true real-number result is always enclosed [pbrt-v4 §6.8.1, `Interval`].
//! Quadric intersection solves its quadratic in intervals so that a root is
//! accepted only when it is conservatively positive.

use crate::math::{gamma, next_float_down, next_float_up, Transform, Vec3};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// A closed interval `[lo, hi]` enclosing an exact value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Interval {
    pub lo: f32,
    pub hi: f32,
}

impl Interval {
    /// The exact value `v`.
    pub fn exact(v: f32) -> Self {
        Self { lo: v, hi: v }
    }
    /// `v ± err`, rounded outward.
    pub fn with_error(v: f32, err: f32) -> Self {
        if err == 0.0 {
            return Self::exact(v);
        }
        Self::rounded(v - err, v + err)
    }
    /// `[lo, hi]` widened by one ulp each side.
    fn rounded(lo: f32, hi: f32) -> Self {
        Self {
            lo: next_float_down(lo),
            hi: next_float_up(hi),
        }
    }
    /// Midpoint, the best single-float estimate.
    pub fn mid(self) -> f32 {
        0.5 * (self.lo + self.hi)
    }
    /// Square (tighter than `self * self` when the interval spans 0).
    pub fn sqr(self) -> Self {
        let (a, b) = (self.lo.abs(), self.hi.abs());
        let (lo, hi) = if a > b { (b, a) } else { (a, b) };
        if self.lo <= 0.0 && self.hi >= 0.0 {
            return Self {
                lo: 0.0,
                hi: next_float_up(hi * hi),
            };
        }
        Self::rounded(lo * lo, hi * hi)
    }
    /// Square root (the negative part is clamped away).
    pub fn sqrt(self) -> Self {
        Self {
            lo: next_float_down(self.lo.max(0.0).sqrt()).max(0.0),
            hi: next_float_up(self.hi.max(0.0).sqrt()),
        }
    }
    /// Scales by an exact float.
    pub fn scale(self, s: f32) -> Self {
        self * Self::exact(s)
    }
}

impl Add for Interval {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Self::rounded(self.lo + o.lo, self.hi + o.hi)
    }
}

impl Sub for Interval {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Self::rounded(self.lo - o.hi, self.hi - o.lo)
    }
}

impl Neg for Interval {
    type Output = Self;
    fn neg(self) -> Self {
        Self {
            lo: -self.hi,
            hi: -self.lo,
        }
    }
}

impl Mul for Interval {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        let p = [
            self.lo * o.lo,
            self.lo * o.hi,
            self.hi * o.lo,
            self.hi * o.hi,
        ];
        let lo = p.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = p.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        Self::rounded(lo, hi)
    }
}

impl Div for Interval {
    type Output = Self;
    fn div(self, o: Self) -> Self {
        if o.lo <= 0.0 && o.hi >= 0.0 {
            return Self {
                lo: f32::NEG_INFINITY,
                hi: f32::INFINITY,
            };
        }
        let q = [
            self.lo / o.lo,
            self.lo / o.hi,
            self.hi / o.lo,
            self.hi / o.hi,
        ];
        let lo = q.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = q.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        Self::rounded(lo, hi)
    }
}

/// A point or vector whose coordinates are intervals.
pub(crate) type Vec3i = [Interval; 3];

/// Midpoints of an interval vector.
pub(crate) fn mid3(v: &Vec3i) -> Vec3 {
    Vec3::new(v[0].mid(), v[1].mid(), v[2].mid())
}

/// Transforms a point, enclosing the rounding error [pbrt-v4 eq. 6.54].
pub(crate) fn transform_point_i(t: &Transform, p: Vec3) -> Vec3i {
    let (q, e) = t.point_with_error(p);
    [0, 1, 2].map(|i| Interval::with_error(q[i], e[i]))
}

/// Transforms a vector, enclosing the rounding error: γ₃ Σ|mᵢⱼ vⱼ|.
pub(crate) fn transform_vector_i(t: &Transform, v: Vec3) -> Vec3i {
    let q = t.vector(v);
    let e = gamma(3) * t.m.abs().transform_vector3(v.abs());
    [0, 1, 2].map(|i| Interval::with_error(q[i], e[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interval_encloses_f64_results() {
        let a = Interval::exact(0.1);
        let b = Interval::exact(-3.7);
        let check = |i: Interval, x: f64| assert!(i.lo as f64 <= x && x <= i.hi as f64);
        let (x, y) = (0.1f32 as f64, -3.7f32 as f64);
        check(a + b, x + y);
        check(a - b, x - y);
        check(a * b, x * y);
        check(a / b, x / y);
        check(b.sqr(), y * y);
        check(a.sqrt(), x.sqrt());
        check((a - a).sqr(), 0.0);
    }
}
