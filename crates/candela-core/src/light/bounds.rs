//! Spatial and directional bounds of a light's emission, and the importance
//! they give a receiving point [pbrt-v4 §12.6.3 `LightBounds`].
//!
//! A bounded light (everything but distant and infinite lights) is
//! summarised by
//! - a box `bounds` around its emitting points,
//! - a scalar power `phi` (see below),
//! - a cone of emission normals: axis `w`, half-angle θo (cos θo); every
//!   emitting point's normal lies within θo of `w`,
//! - an emission spread θe (cos θe): each point emits only within θe of its
//!   own normal (π/2 for Lambertian surfaces, the falloff width for spots),
//! - `two_sided`: the normals are also bounded by the reflected cone (−w).
//!
//! **Importance** [pbrt-v4 §12.6.3, "Importance of LightBounds"]. From a
//! point p with normal n (zero in free space), with pc the box centre and θw
//! the angle between w and p − pc (folded to [0, π/2] when two-sided), θb the
//! half-angle of the cone p sees the box's bounding sphere under, and
//! x ⊖ y = max(x − y, 0):
//! - θ' = (θw ⊖ θo) ⊖ θb is the smallest angle any emitter's normal in the
//!   box can make with the direction to p; if θ' ≥ θe, nothing in the box
//!   emits towards p and the importance is zero;
//! - otherwise I = φ·cos θ' / d², with d² = |p − pc|² clamped below by
//!   pbrt-v4's |diagonal|/2 so that points inside the box do not make the
//!   importance blow up (pbrt-v4 compares a length with a squared length
//!   here; candela keeps its choice so the two samplers agree);
//! - at a surface, I is multiplied by cos θi' with θi' = θi ⊖ θb and θi the
//!   angle between n and p − pc taken with |cos| (both sides of a surface
//!   may receive light: transmission).
//!
//! The angle differences are done with sines and cosines only
//! (cos(a ⊖ b) = 1 when a ≤ b, else cos a cos b + sin a sin b).
//!
//! **Scalar power.** `phi` weights the importance. It is computed as the
//! power light sampler computes Φ (the average of spectrum/p(λ) at the
//! fixed wavelengths of [`SampledWavelengths::sample_visible`]`(0.5)`), of
//! the quantity pbrt-v4 uses: 4π times the peak (spots) or mean
//! (projection, over the frustum) intensity for point-like lights, so that
//! a spot and a point light of equal intensity rank alike inside the cone,
//! and π·A·L for area lights, per side.

use super::Light;
use crate::math::{safe_sqrt, Bounds3, DirectionCone, Transform, Vec3};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use wide::{f32x4, CmpEq, CmpGt, CmpLe};

/// The emission bounds of one light or of a set of lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightBounds {
    /// Box around the emitting points.
    pub bounds: Bounds3,
    /// Scalar power (module doc).
    pub phi: f32,
    /// Axis of the cone of emission normals (unit).
    pub w: Vec3,
    /// cos θo: every emitting normal is within θo of `w`.
    pub cos_theta_o: f32,
    /// cos θe: emission reaches at most θe away from the normal.
    pub cos_theta_e: f32,
    /// Normals may also point along −w.
    pub two_sided: bool,
}

impl LightBounds {
    /// Bounds from a box, a normal cone, the emission spread and the power.
    pub fn new(
        bounds: Bounds3,
        normals: DirectionCone,
        phi: f32,
        cos_theta_e: f32,
        two_sided: bool,
    ) -> Self {
        Self {
            bounds,
            phi,
            w: normals.w,
            cos_theta_o: normals.cos_theta,
            cos_theta_e,
            two_sided,
        }
    }

    /// Centre of the box.
    pub fn centroid(&self) -> Vec3 {
        self.bounds.centroid()
    }

    /// Bounds of both sets of lights: boxes and normal cones united, powers
    /// added, the wider emission spread; a zero-power side is left out.
    pub fn union(&self, o: &Self) -> Self {
        if self.phi == 0.0 {
            return *o;
        }
        if o.phi == 0.0 {
            return *self;
        }
        let cone = DirectionCone {
            w: self.w,
            cos_theta: self.cos_theta_o,
        }
        .union(DirectionCone {
            w: o.w,
            cos_theta: o.cos_theta_o,
        });
        Self {
            bounds: self.bounds.union(o.bounds),
            phi: self.phi + o.phi,
            w: cone.w,
            cos_theta_o: cone.cos_theta,
            cos_theta_e: self.cos_theta_e.min(o.cos_theta_e),
            two_sided: self.two_sided || o.two_sided,
        }
    }

    /// Importance of these bounds at `p` with normal `n` (module doc).
    pub fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        importance(self, p, n)
    }
}

/// cos(a ⊖ b) from sines and cosines: 1 when a ≤ b.
#[inline]
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

/// The importance of `b` at `p` with normal `n`; finite and ≥ 0.
pub(crate) fn importance(b: &LightBounds, p: Vec3, n: Vec3) -> f32 {
    PreparedBounds::new(b).importance(p, n)
}

/// Light bounds with what [`importance`] derives from them alone computed
/// once (box centre, bounding sphere, half diagonal, sin θo), for the BVH
/// light sampler, which evaluates each node's importance many times.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct PreparedBounds {
    /// Box centre.
    pc: Vec3,
    /// Radius of the bounding sphere, which is centred on `pc`, and its square.
    r: f32,
    r2: f32,
    /// |diagonal| / 2 (pbrt-v4's lower bound of d²).
    half_diagonal: f32,
    w: Vec3,
    phi: f32,
    cos_o: f32,
    sin_o: f32,
    cos_e: f32,
    two_sided: bool,
}

impl PreparedBounds {
    /// The prepared form of `b`.
    pub fn new(b: &LightBounds) -> Self {
        let (_, r) = b.bounds.bounding_sphere();
        Self {
            pc: b.bounds.centroid(),
            r,
            r2: r * r,
            half_diagonal: b.bounds.diagonal().length() / 2.0,
            w: b.w,
            phi: b.phi,
            cos_o: b.cos_theta_o,
            sin_o: safe_sqrt(1.0 - b.cos_theta_o * b.cos_theta_o),
            cos_e: b.cos_theta_e,
            two_sided: b.two_sided,
        }
    }

    /// The importance at `p` with normal `n` (module doc); finite and ≥ 0.
    ///
    /// The bounding sphere is centred on the box centre, so one offset
    /// p − pc gives the distance bound, the direction and the subtended
    /// cone. sin θb is r/d directly: from the cosine it would vanish in f32
    /// below θb ≈ 3·10⁻⁴ (cos θb rounds to 1), and the bound would lose the
    /// light's extent. Sines are only taken where a clamped difference
    /// needs them: θw ≤ θo (p inside the emission cone) makes θx = 0 and
    /// θ' = 0, and θi ≤ θb makes that factor 1.
    #[inline]
    pub fn importance(&self, p: Vec3, n: Vec3) -> f32 {
        let v = p - self.pc;
        let dist2 = v.length_squared();
        let d2 = dist2.max(self.half_diagonal);
        // One square root and one division give the direction and sin θb.
        let inv_dist = if dist2 > 0.0 { 1.0 / dist2.sqrt() } else { 0.0 };
        let wi = v * inv_dist;
        let (sin_b, cos_b) = if dist2 <= self.r2 {
            (0.0, -1.0)
        } else {
            let sin_b = self.r * inv_dist;
            (sin_b, safe_sqrt(1.0 - sin_b * sin_b))
        };
        let mut cos_w = self.w.dot(wi);
        if self.two_sided {
            cos_w = cos_w.abs();
        }
        // θx = θw ⊖ θo, then θ' = θx ⊖ θb.
        let cos_p = if cos_w > self.cos_o {
            1.0
        } else {
            let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
            let cos_x = cos_w * self.cos_o + sin_w * self.sin_o;
            let sin_x = sin_w * self.cos_o - cos_w * self.sin_o;
            cos_sub_clamped(sin_x, cos_x, sin_b, cos_b)
        };
        if cos_p <= self.cos_e {
            return 0.0;
        }
        let mut imp = self.phi * cos_p;
        if n != Vec3::ZERO {
            let cos_i = wi.dot(n).abs();
            if cos_i <= cos_b {
                let sin_i = safe_sqrt(1.0 - cos_i * cos_i);
                imp *= cos_i * cos_b + sin_i * sin_b;
            }
        }
        if d2 == 0.0 {
            // p at a point light: the bound is unbounded; keep it finite.
            return if imp > 0.0 { f32::MAX } else { 0.0 };
        }
        (imp / d2).clamp(0.0, f32::MAX)
    }
}

/// The prepared bounds of a light BVH node's two children side by side, one
/// SIMD lane each, so that one evaluation gives both importances (the BVH
/// light sampler needs both at every interior node it passes). Each field
/// holds (first child, second child); lanes 2 and 3 compute on zeros and
/// are ignored.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct PreparedPair {
    pc: [[f32; 2]; 3],
    r: [f32; 2],
    r2: [f32; 2],
    half_diagonal: [f32; 2],
    w: [[f32; 2]; 3],
    phi: [f32; 2],
    cos_o: [f32; 2],
    sin_o: [f32; 2],
    cos_e: [f32; 2],
    /// 1 for a two-sided child, else 0.
    two_sided: [f32; 2],
}

/// Two values in the low lanes of a vector.
#[inline(always)]
fn lanes(a: [f32; 2]) -> f32x4 {
    f32x4::from([a[0], a[1], 0.0, 0.0])
}

/// `safe_sqrt` lane by lane (`max` keeps the non-NaN operand, as `f32::max`).
#[inline(always)]
fn safe_sqrt4(x: f32x4) -> f32x4 {
    x.max(f32x4::ZERO).sqrt()
}

impl PreparedPair {
    /// The pair (a, b).
    pub fn new(a: &PreparedBounds, b: &PreparedBounds) -> Self {
        let f = |get: fn(&PreparedBounds) -> f32| [get(a), get(b)];
        Self {
            pc: [f(|x| x.pc.x), f(|x| x.pc.y), f(|x| x.pc.z)],
            r: f(|x| x.r),
            r2: f(|x| x.r2),
            half_diagonal: f(|x| x.half_diagonal),
            w: [f(|x| x.w.x), f(|x| x.w.y), f(|x| x.w.z)],
            phi: f(|x| x.phi),
            cos_o: f(|x| x.cos_o),
            sin_o: f(|x| x.sin_o),
            cos_e: f(|x| x.cos_e),
            two_sided: f(|x| f32::from(u8::from(x.two_sided))),
        }
    }

    /// Both children's [`PreparedBounds::importance`] at `p` with normal
    /// `n`, bit for bit: the same operations in the same order, lane by
    /// lane, with each branch turned into a blend of both outcomes (the
    /// vector `max` keeps the non-NaN operand as `f32::max` does, and no
    /// multiply-add is fused); the last steps run per lane as in the scalar.
    #[inline]
    pub fn importances(&self, p: Vec3, n: Vec3) -> [f32; 2] {
        let (zero, one) = (f32x4::ZERO, f32x4::ONE);
        let v = [p.x, p.y, p.z].map(f32x4::splat);
        let v = [0, 1, 2].map(|k| v[k] - lanes(self.pc[k]));
        let dist2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        let d2 = dist2.max(lanes(self.half_diagonal));
        let inv_dist = dist2.cmp_gt(zero).blend(one / dist2.sqrt(), zero);
        let wi = v.map(|c| c * inv_dist);
        let inside = dist2.cmp_le(lanes(self.r2));
        let sin_b_out = lanes(self.r) * inv_dist;
        let sin_b = inside.blend(zero, sin_b_out);
        let cos_b = inside.blend(f32x4::splat(-1.0), safe_sqrt4(one - sin_b_out * sin_b_out));
        let w = self.w.map(lanes);
        let cos_w = w[0] * wi[0] + w[1] * wi[1] + w[2] * wi[2];
        let cos_w = lanes(self.two_sided).cmp_eq(zero).blend(cos_w, cos_w.abs());
        let (cos_o, sin_o) = (lanes(self.cos_o), lanes(self.sin_o));
        let sin_w = safe_sqrt4(one - cos_w * cos_w);
        let cos_x = cos_w * cos_o + sin_w * sin_o;
        let sin_x = sin_w * cos_o - cos_w * sin_o;
        let cos_sub = cos_x
            .cmp_gt(cos_b)
            .blend(one, cos_x * cos_b + sin_x * sin_b);
        let cos_p = cos_w.cmp_gt(cos_o).blend(one, cos_sub);
        let dead = cos_p.cmp_le(lanes(self.cos_e)).move_mask();
        let mut imp = lanes(self.phi) * cos_p;
        if n != Vec3::ZERO {
            let cos_i = (wi[0] * n.x + wi[1] * n.y + wi[2] * n.z).abs();
            let sin_i = safe_sqrt4(one - cos_i * cos_i);
            let scaled = imp * (cos_i * cos_b + sin_i * sin_b);
            imp = cos_i.cmp_le(cos_b).blend(scaled, imp);
        }
        let (imp, d2) = (imp.to_array(), d2.to_array());
        [0, 1].map(|k| {
            if dead & (1 << k) != 0 {
                0.0
            } else if d2[k] == 0.0 {
                if imp[k] > 0.0 {
                    f32::MAX
                } else {
                    0.0
                }
            } else {
                (imp[k] / d2[k]).clamp(0.0, f32::MAX)
            }
        })
    }
}

/// The scalar of a spectral quantity the light samplers rank lights by:
/// the average of s(λ)/p(λ) at the fixed visible wavelengths (the power
/// light sampler's estimate of ∫s dλ); never negative.
pub(crate) fn scalar(s: impl FnOnce(&SampledWavelengths) -> SampledSpectrum) -> f32 {
    let lambda = SampledWavelengths::sample_visible(0.5);
    s(&lambda).safe_div(lambda.pdf()).average().max(0.0)
}

/// True when `t` maps angles to equal angles (a rotation, reflection and
/// uniform scale, with translation): only then is a light-frame cone a
/// cone of the same half-angle in render space. Relative tolerance 10⁻⁴ on
/// the columns' lengths and dot products of the linear part.
pub(crate) fn preserves_angles(t: &Transform) -> bool {
    let c = [t.vector(Vec3::X), t.vector(Vec3::Y), t.vector(Vec3::Z)];
    let s2 = c[0].length_squared();
    let tol = 1e-4 * s2;
    (c[1].length_squared() - s2).abs() <= tol
        && (c[2].length_squared() - s2).abs() <= tol
        && c[0].dot(c[1]).abs() <= tol
        && c[0].dot(c[2]).abs() <= tol
        && c[1].dot(c[2]).abs() <= tol
}

impl Light {
    /// The light's emission bounds; `None` for lights at infinity
    /// (distant and infinite lights), which the BVH light sampler samples
    /// beside its tree [pbrt-v4 `Light::Bounds`].
    pub fn bounds(&self) -> Option<LightBounds> {
        match self {
            Light::Point(l) => Some(l.bounds()),
            Light::Spot(l) => Some(l.bounds()),
            Light::Goniometric(l) => Some(l.bounds()),
            Light::Projection(l) => Some(l.bounds()),
            Light::DiffuseArea(l) => Some(l.bounds()),
            Light::Distant(_) | Light::UniformInfinite(_) | Light::ImageInfinite(_) => None,
        }
    }
}

/// Bounds of a light emitting from point `p` in every direction.
pub(crate) fn isotropic_point(p: Vec3, phi: f32) -> LightBounds {
    LightBounds::new(
        Bounds3::from_point(p),
        DirectionCone::entire_sphere(),
        phi,
        0.0,
        false,
    )
}
