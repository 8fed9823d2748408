//! Geometry and floating-point support: vectors (glam), frames, bounds, rays
//! with error-bounded origins, transforms, and small numeric helpers.

mod animated;
mod bounds;
mod cone;
mod frame;
mod ray;
mod transform;

pub use animated::AnimatedTransform;
pub use bounds::Bounds3;
pub use cone::DirectionCone;
pub use frame::{Frame, FrameA};
pub use glam::{Mat3, Mat4, UVec2, Vec2, Vec3, Vec3A, Vec4};
pub use ray::{offset_ray_origin, spawn_ray, spawn_ray_to, Ray, SHADOW_EPSILON};
pub use transform::{perspective, Transform};

/// π.
pub const PI: f32 = std::f32::consts::PI;
/// 1/π.
pub const INV_PI: f32 = std::f32::consts::FRAC_1_PI;
/// 1/(2π).
pub const INV_2PI: f32 = 0.5 * std::f32::consts::FRAC_1_PI;
/// 1/(4π).
pub const INV_4PI: f32 = 0.25 * std::f32::consts::FRAC_1_PI;
/// Half the distance between 1 and the next float: the unit round-off.
pub const MACHINE_EPSILON: f32 = f32::EPSILON * 0.5;

/// Conservative bound on the relative error of `n` floating-point operations
/// [pbrt-v4 §6.8.1, eq. 6.47]: γₙ = nε / (1 − nε).
#[inline]
pub fn gamma(n: i32) -> f32 {
    let ne = n as f32 * MACHINE_EPSILON;
    ne / (1.0 - ne)
}

/// Smallest float strictly greater than `v` (for conservative bounds).
#[inline]
pub fn next_float_up(v: f32) -> f32 {
    // Selects, not branches (see `ray::round_away`); −0 counts as +0.
    let z = if v == 0.0 { 0.0 } else { v };
    let bits = z.to_bits();
    let next = f32::from_bits(if z >= 0.0 {
        bits.wrapping_add(1)
    } else {
        bits.wrapping_sub(1)
    });
    if v == f32::INFINITY {
        v
    } else {
        next
    }
}

/// Largest float strictly less than `v`: the mirror image of
/// [`next_float_up`] (negation only flips the sign bit, so it stays
/// branch-free and keeps −∞, NaN and the zeros as they were).
#[inline]
pub fn next_float_down(v: f32) -> f32 {
    -next_float_up(-v)
}

/// `x²`.
#[inline]
pub fn sqr(x: f32) -> f32 {
    x * x
}

/// Square root clamped at zero (guards round-off below 0).
#[inline]
pub fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

/// `acos` with its argument clamped to [−1, 1].
#[inline]
pub fn safe_acos(x: f32) -> f32 {
    x.clamp(-1.0, 1.0).acos()
}

/// `asin` with its argument clamped to [−1, 1].
#[inline]
pub fn safe_asin(x: f32) -> f32 {
    x.clamp(-1.0, 1.0).asin()
}

/// Linear interpolation `(1 − t)·a + t·b`.
#[inline]
pub fn lerp(t: f32, a: f32, b: f32) -> f32 {
    (1.0 - t) * a + t * b
}

/// Direction from spherical coordinates in the frame's local space (z up).
#[inline]
pub fn spherical_direction(sin_theta: f32, cos_theta: f32, phi: f32) -> Vec3 {
    let s = sin_theta.clamp(-1.0, 1.0);
    Vec3::new(s * phi.cos(), s * phi.sin(), cos_theta.clamp(-1.0, 1.0))
}

/// Flips `n` into the hemisphere of `v`.
#[inline]
pub fn face_forward(n: Vec3, v: Vec3) -> Vec3 {
    if n.dot(v) < 0.0 {
        -n
    } else {
        n
    }
}

/// Angle between two unit vectors, accurate for nearly parallel vectors.
#[inline]
pub fn angle_between(a: Vec3, b: Vec3) -> f32 {
    if a.dot(b) < 0.0 {
        PI - 2.0 * safe_asin((a + b).length() / 2.0)
    } else {
        2.0 * safe_asin((b - a).length() / 2.0)
    }
}

/// Local-frame trigonometry of a unit direction (z is the normal).
pub mod local {
    use super::Vec3;

    /// cos θ.
    #[inline]
    pub fn cos_theta(w: Vec3) -> f32 {
        w.z
    }
    /// cos² θ.
    #[inline]
    pub fn cos2_theta(w: Vec3) -> f32 {
        w.z * w.z
    }
    /// |cos θ|.
    #[inline]
    pub fn abs_cos_theta(w: Vec3) -> f32 {
        w.z.abs()
    }
    /// sin² θ.
    #[inline]
    pub fn sin2_theta(w: Vec3) -> f32 {
        (1.0 - cos2_theta(w)).max(0.0)
    }
    /// sin θ.
    #[inline]
    pub fn sin_theta(w: Vec3) -> f32 {
        sin2_theta(w).sqrt()
    }
    /// tan θ.
    #[inline]
    pub fn tan_theta(w: Vec3) -> f32 {
        sin_theta(w) / cos_theta(w)
    }
    /// tan² θ.
    #[inline]
    pub fn tan2_theta(w: Vec3) -> f32 {
        sin2_theta(w) / cos2_theta(w)
    }
    /// cos φ.
    #[inline]
    pub fn cos_phi(w: Vec3) -> f32 {
        let s = sin_theta(w);
        if s == 0.0 {
            1.0
        } else {
            (w.x / s).clamp(-1.0, 1.0)
        }
    }
    /// sin φ.
    #[inline]
    pub fn sin_phi(w: Vec3) -> f32 {
        let s = sin_theta(w);
        if s == 0.0 {
            0.0
        } else {
            (w.y / s).clamp(-1.0, 1.0)
        }
    }
    /// True when both directions lie in the same hemisphere.
    #[inline]
    pub fn same_hemisphere(a: Vec3, b: Vec3) -> bool {
        a.z * b.z > 0.0
    }
    /// Mirror reflection of `wo` about `n`.
    #[inline]
    pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
        -wo + 2.0 * wo.dot(n) * n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn next_float_brackets() {
        for &v in &[0.0f32, -0.0, 1.0, -1.0, 1e-30, 3.5e20] {
            assert!(next_float_up(v) > v);
            assert!(next_float_down(v) < v);
        }
    }

    /// The select-based versions against the definition: the adjacent float
    /// in the ordering where −0 and +0 are one point, infinities fixed at
    /// their own end, NaN staying NaN.
    #[test]
    fn next_float_is_the_adjacent_float() {
        let specials = [
            0.0f32,
            -0.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::from_bits(1),
            -f32::from_bits(1),
            1.0,
            -1.0,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
        ];
        for &v in &specials {
            let up = next_float_up(v);
            let down = next_float_down(v);
            if v == f32::INFINITY {
                assert_eq!(up, v);
            } else {
                assert!(up > v, "{v}");
                // Nothing lies strictly between: stepping back lands on v
                // (or on the other zero).
                assert_eq!(next_float_down(up), if v == 0.0 { -0.0 } else { v });
            }
            if v == f32::NEG_INFINITY {
                assert_eq!(down, v);
            } else {
                assert!(down < v, "{v}");
                assert_eq!(next_float_up(down), if v == 0.0 { 0.0 } else { v });
            }
        }
        assert_eq!(next_float_up(0.0), f32::from_bits(1));
        assert_eq!(next_float_up(-0.0), f32::from_bits(1));
        assert_eq!(next_float_down(0.0), -f32::from_bits(1));
        assert_eq!(next_float_up(f32::MAX), f32::INFINITY);
        assert!(next_float_up(f32::NAN).is_nan() && next_float_down(f32::NAN).is_nan());
    }

    #[test]
    fn angle_between_matches_acos() {
        let a = Vec3::new(1.0, 2.0, 3.0).normalize();
        let b = Vec3::new(-2.0, 0.5, 1.0).normalize();
        assert!((angle_between(a, b) - a.dot(b).acos()).abs() < 1e-5);
        assert_eq!(angle_between(a, a), 0.0);
    }
}
