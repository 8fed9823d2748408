//! Light bounds packed into 24 bytes for the nodes of the light BVH
//! [pbrt-v4 §12.6.3 `CompactLightBounds`].
//!
//! - The box is quantised to 16 bits per coordinate relative to the box of
//!   all bounded lights, rounded outwards (floor for the lower corner, ceil
//!   for the upper), so the decoded box holds the original one.
//! - cos θo and cos θe are quantised to 15 bits over [−1, 1], rounded down:
//!   the decoded angles are never smaller, so the bound stays conservative.
//! - The cone axis w is stored in the octahedral map [Meyer et al. 2010,
//!   "On floating-point normal vectors"] at 16 bits per coordinate. Unlike
//!   pbrt-v4, the angle between w and its decoded value is added to θo, so
//!   the decoded cone still holds every normal of the original.
//!
//! Each rounding is checked against the decoder itself (the same f32
//! arithmetic that runs at render time), so "holds the original" is exact,
//! not up to decoding round-off.

use crate::light::LightBounds;
use crate::math::{lerp, Bounds3, Vec3};

/// Largest 15-bit value: the scale of the cosines.
const COS_MAX: u32 = (1 << 15) - 1;
/// Largest 16-bit value: the scale of box coordinates and of w.
const Q_MAX: f32 = 65535.0;

/// [`LightBounds`] in 24 bytes (module doc).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct CompactLightBounds {
    /// Octahedral w: u in the low 16 bits, v in the high.
    w: u32,
    /// Scalar power.
    phi: f32,
    /// cos θo (bits 0–14), cos θe (bits 15–29), two-sided (bit 30).
    packed: u32,
    /// Lower and upper box corners, quantised.
    qb: [[u16; 3]; 2],
}

impl CompactLightBounds {
    /// Packs `lb`, whose box lies inside `all`.
    pub fn new(lb: &LightBounds, all: &Bounds3) -> Self {
        let w = encode_octahedral(lb.w);
        let err = angle_between_f64(lb.w, decode_octahedral(w));
        let theta_o = (lb.cos_theta_o.clamp(-1.0, 1.0) as f64).acos();
        let cos_o = if lb.cos_theta_o <= -1.0 {
            -1.0
        } else {
            (theta_o + err).min(std::f64::consts::PI).cos() as f32
        };
        let packed = quantize_cos(cos_o)
            | (quantize_cos(lb.cos_theta_e) << 15)
            | (u32::from(lb.two_sided) << 30);
        let q = |corner: crate::math::Vec3, up: bool| {
            std::array::from_fn(|c| quantize_coord(corner[c], all.min[c], all.max[c], up))
        };
        let qb = [q(lb.bounds.min, false), q(lb.bounds.max, true)];
        Self {
            w,
            phi: lb.phi,
            packed,
            qb,
        }
    }

    /// The bounds this packs (conservative: module doc).
    #[inline]
    pub fn decode(&self, all: &Bounds3) -> LightBounds {
        let corner = |q: &[u16; 3]| {
            Vec3::new(
                decode_coord(q[0], all.min.x, all.max.x),
                decode_coord(q[1], all.min.y, all.max.y),
                decode_coord(q[2], all.min.z, all.max.z),
            )
        };
        LightBounds {
            bounds: Bounds3 {
                min: corner(&self.qb[0]),
                max: corner(&self.qb[1]),
            },
            phi: self.phi,
            w: decode_octahedral(self.w),
            cos_theta_o: decode_cos(self.packed & COS_MAX),
            cos_theta_e: decode_cos((self.packed >> 15) & COS_MAX),
            two_sided: self.packed & (1 << 30) != 0,
        }
    }
}

/// The 15-bit code of cos θ: the largest whose decoded value is ≤ c.
fn quantize_cos(c: f32) -> u32 {
    let c = c.clamp(-1.0, 1.0);
    let mut q = ((c as f64 + 1.0) / 2.0 * COS_MAX as f64).floor() as u32;
    q = q.min(COS_MAX);
    while q > 0 && decode_cos(q) > c {
        q -= 1;
    }
    q
}

#[inline]
fn decode_cos(q: u32) -> f32 {
    2.0 * (q as f32 / COS_MAX as f32) - 1.0
}

/// The 16-bit code of coordinate `c ∈ [lo, hi]`, rounded down (lower
/// corner) or up (upper corner) through the decoder.
fn quantize_coord(c: f32, lo: f32, hi: f32, up: bool) -> u16 {
    if lo >= hi {
        return 0;
    }
    let t = ((c as f64 - lo as f64) / (hi as f64 - lo as f64)).clamp(0.0, 1.0) * Q_MAX as f64;
    let mut q = if up { t.ceil() } else { t.floor() } as u32;
    if up {
        while q < Q_MAX as u32 && decode_coord(q as u16, lo, hi) < c {
            q += 1;
        }
    } else {
        while q > 0 && decode_coord(q as u16, lo, hi) > c {
            q -= 1;
        }
    }
    q as u16
}

#[inline]
fn decode_coord(q: u16, lo: f32, hi: f32) -> f32 {
    lerp(q as f32 / Q_MAX, lo, hi)
}

/// Octahedral code of a unit vector: project on |x|+|y|+|z| = 1, fold the
/// lower half over the diagonals, quantise to 16 bits per axis (rounded).
fn encode_octahedral(v: Vec3) -> u32 {
    let v = v / (v.x.abs() + v.y.abs() + v.z.abs());
    let (x, y) = if v.z >= 0.0 {
        (v.x, v.y)
    } else {
        ((1.0 - v.y.abs()) * sign(v.x), (1.0 - v.x.abs()) * sign(v.y))
    };
    let q = |f: f32| ((f.clamp(-1.0, 1.0) + 1.0) / 2.0 * Q_MAX).round() as u32;
    q(x) | (q(y) << 16)
}

#[inline]
fn decode_octahedral(code: u32) -> Vec3 {
    let f = |q: u32| -1.0 + 2.0 * (q as f32 / Q_MAX);
    let (mut x, mut y) = (f(code & 0xffff), f(code >> 16));
    let z = 1.0 - x.abs() - y.abs();
    if z < 0.0 {
        (x, y) = ((1.0 - y.abs()) * sign(x), (1.0 - x.abs()) * sign(y));
    }
    Vec3::new(x, y, z).normalize()
}

/// ±1 with the sign of `f` (+1 for ±0).
#[inline]
fn sign(f: f32) -> f32 {
    if f < 0.0 {
        -1.0
    } else {
        1.0
    }
}

/// Angle between two unit vectors in f64.
fn angle_between_f64(a: Vec3, b: Vec3) -> f64 {
    let (a, b) = (a.as_dvec3().normalize(), b.as_dvec3().normalize());
    if a.dot(b) < 0.0 {
        std::f64::consts::PI - 2.0 * ((a + b).length() / 2.0).min(1.0).asin()
    } else {
        2.0 * ((b - a).length() / 2.0).min(1.0).asin()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DirectionCone;
    use crate::sampling::{sample_uniform_sphere, Pcg32};
    use glam::Vec2;

    /// Random bounds: the decoded box holds the original, the decoded cone
    /// holds the original cone's axis and edge, and the cosines only drop.
    #[test]
    fn packing_is_conservative() {
        let mut rng = Pcg32::new(3, 0);
        let all = Bounds3::from_points(Vec3::new(-3.0, 0.5, -100.0), Vec3::new(7.0, 0.6, 1e3));
        for _ in 0..5000 {
            let mut r = || rng.uniform_f32();
            let a = all.min + (all.max - all.min) * Vec3::new(r(), r(), r());
            let b = all.min + (all.max - all.min) * Vec3::new(r(), r(), r());
            let w = sample_uniform_sphere(Vec2::new(r(), r()));
            let (cos_o, cos_e) = (2.0 * r() - 1.0, 2.0 * r() - 1.0);
            let lb = LightBounds::new(
                Bounds3::from_points(a, b),
                DirectionCone::new(w, cos_o),
                r(),
                cos_e,
                r() < 0.5,
            );
            let d = CompactLightBounds::new(&lb, &all).decode(&all);
            assert!(
                d.bounds.min.cmple(lb.bounds.min).all() && d.bounds.max.cmpge(lb.bounds.max).all()
            );
            assert!(d.cos_theta_o <= lb.cos_theta_o && d.cos_theta_e <= lb.cos_theta_e);
            assert_eq!((d.phi, d.two_sided), (lb.phi, lb.two_sided));
            let theta_gap = angle_between_f64(d.w, lb.w) + (lb.cos_theta_o as f64).acos();
            assert!(
                theta_gap <= (d.cos_theta_o as f64).acos() + 1e-6,
                "{lb:?} → {d:?}"
            );
        }
    }

    #[test]
    fn octahedral_round_trip_is_within_a_code_step() {
        let mut rng = Pcg32::new(5, 0);
        for _ in 0..10000 {
            let w = sample_uniform_sphere(Vec2::new(rng.uniform_f32(), rng.uniform_f32()));
            let e = angle_between_f64(w, decode_octahedral(encode_octahedral(w)));
            assert!(e < 1e-4, "{w:?}: {e}");
        }
    }
}
