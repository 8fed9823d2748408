//! Spheres, optionally clipped in z and φ, placed by a transform.
//!
//! Intersection solves the ray–sphere quadratic in object space with
//! conservative interval arithmetic, using the discriminant form
//! 4a(r − |f|)(r + |f|) that avoids cancellation, where f is the ray point
//! closest to the centre [pbrt-v4 §6.2.2 and §6.8.5]. The hit point is
//! re-projected onto the sphere and carries the error bound γ₅|p| before the
//! transform [pbrt-v4 eq. 6.49].
//!
//! Sampling: uniform by area uses Archimedes' theorem (area is uniform in z).
//! Seen from outside, a full sphere is sampled uniformly inside the cone it
//! subtends and the sampled direction is mapped back to the visible cap
//! [pbrt-v4 §6.2.4]; from inside, or for a clipped sphere, area samples are
//! converted to solid angle.
//!
//! Transforms are assumed to be similarities (rotation, translation,
//! uniform scale) for `area` and sampling densities; the render-space radius
//! is the object radius times |det M|^(1/3).

use super::interval::{mid3, transform_point_i, transform_vector_i, Interval};
use super::sphere_cull::MissTest;
use super::{
    area_sample_to_solid_angle, pdf_from_hit, ShapeIntersection, ShapeSample, ShapeSampleContext,
    ShapeSampleSa,
};
use crate::interaction::{Interaction, SurfaceInteraction};
use crate::math::{
    gamma, lerp, safe_acos, safe_sqrt, spherical_direction, sqr, Bounds3, Frame, Mat3, Ray,
    Transform, Vec2, Vec3, PI,
};
use crate::sampling::{PdfArea, PdfSolidAngle};
use std::sync::Arc;

/// A sphere of given radius around the object-space origin, clipped to
/// `z ∈ [z_min, z_max]` and `φ ∈ [0, φ_max]`.
#[derive(Clone, Debug)]
pub struct Sphere {
    render_from_object: Arc<Transform>,
    reverse_orientation: bool,
    radius: f32,
    z_min: f32,
    z_max: f32,
    theta_z_min: f32,
    theta_z_max: f32,
    phi_max: f32,
    /// Linear scale of the (similarity) transform.
    scale: f32,
    /// The f64 test that rejects certain misses before the intervals.
    miss_test: Option<MissTest>,
}

/// Object-space hit of a quadric.
pub(super) struct QuadricHit {
    t: f32,
    p_obj: Vec3,
    phi: f32,
}

impl Sphere {
    /// A sphere; `z_min`, `z_max` are clamped to ±radius, `phi_max_deg` to [0, 360].
    pub fn new(
        render_from_object: Arc<Transform>,
        reverse_orientation: bool,
        radius: f32,
        z_min: f32,
        z_max: f32,
        phi_max_deg: f32,
    ) -> Self {
        // The builder refuses radii that are not positive; `max`/`min`
        // rather than `clamp` keep a bad one from panicking here.
        let (lo, hi) = (z_min.min(z_max), z_min.max(z_max));
        let z_min = lo.max(-radius).min(radius);
        let z_max = hi.max(-radius).min(radius);
        let det = Mat3::from_mat4(render_from_object.m).determinant();
        Self {
            reverse_orientation,
            radius,
            z_min,
            z_max,
            theta_z_min: (z_min / radius).clamp(-1.0, 1.0).acos(),
            theta_z_max: (z_max / radius).clamp(-1.0, 1.0).acos(),
            phi_max: phi_max_deg.clamp(0.0, 360.0).to_radians(),
            scale: det.abs().cbrt(),
            miss_test: MissTest::new(&render_from_object),
            render_from_object,
        }
    }

    /// True when not clipped in z or φ.
    fn is_full(&self) -> bool {
        self.z_min <= -self.radius && self.z_max >= self.radius && self.phi_max >= 2.0 * PI
    }

    /// Render-space bounds (of the clipped object-space box).
    pub fn bounds(&self) -> Bounds3 {
        let r = self.radius;
        let b = Bounds3::from_points(Vec3::new(-r, -r, self.z_min), Vec3::new(r, r, self.z_max));
        self.render_from_object.bounds(&b)
    }

    /// Surface area: φ_max · r · (z_max − z_min), scaled to render space.
    pub fn area(&self) -> f32 {
        self.phi_max * self.radius * (self.z_max - self.z_min) * sqr(self.scale)
    }

    /// Closest hit with `t ∈ (0, t_max)`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeIntersection> {
        let hit = self.basic_intersect(ray, t_max)?;
        let si = self.interaction(&hit, -ray.d);
        Some(ShapeIntersection { si, t_hit: hit.t })
    }

    /// True when the ray hits for some `t ∈ (0, t_max)`.
    pub fn intersect_p(&self, ray: &Ray, t_max: f32) -> bool {
        self.basic_intersect(ray, t_max).is_some()
    }

    /// The hit nearest the ray origin: certain misses are rejected by the
    /// f64 [`MissTest`], the rest go to the interval solution.
    fn basic_intersect(&self, ray: &Ray, t_max: f32) -> Option<QuadricHit> {
        if self.miss_test_culls(ray, t_max) {
            return None;
        }
        self.interval_intersect(ray, t_max)
    }

    /// True when the [`MissTest`] proves the ray misses.
    pub(super) fn miss_test_culls(&self, ray: &Ray, t_max: f32) -> bool {
        let test = self.miss_test.as_ref();
        test.is_some_and(|m| m.misses(self.radius, ray, t_max))
    }

    /// Solves the quadratic in intervals and applies the clipping [pbrt-v4 §6.2.2].
    pub(super) fn interval_intersect(&self, ray: &Ray, t_max: f32) -> Option<QuadricHit> {
        let object_from_render = self.render_from_object.inverse();
        let oi = transform_point_i(&object_from_render, ray.o);
        let di = transform_vector_i(&object_from_render, ray.d);
        let r = Interval::exact(self.radius);
        let a = di[0].sqr() + di[1].sqr() + di[2].sqr();
        let b = (di[0] * oi[0] + di[1] * oi[1] + di[2] * oi[2]).scale(2.0);
        let c = oi[0].sqr() + oi[1].sqr() + oi[2].sqr() - r.sqr();
        // f = o − (o·d / d·d) d is the ray point closest to the centre.
        let f = b / a.scale(2.0);
        let fp = [0, 1, 2].map(|i| oi[i] - f * di[i]);
        let len_f = (fp[0].sqr() + fp[1].sqr() + fp[2].sqr()).sqrt();
        let discrim = a.scale(4.0) * (r - len_f) * (r + len_f);
        if discrim.lo < 0.0 {
            return None;
        }
        let root = discrim.sqrt();
        let q = if b.mid() < 0.0 {
            (b - root).scale(-0.5)
        } else {
            (b + root).scale(-0.5)
        };
        let (mut t0, mut t1) = (q / a, c / q);
        if t0.lo > t1.lo {
            std::mem::swap(&mut t0, &mut t1);
        }
        if t0.hi > t_max || t1.lo <= 0.0 {
            return None;
        }
        let (o, d) = (mid3(&oi), mid3(&di));
        if t0.lo > 0.0 {
            if let Some(hit) = self.clipped_hit(o, d, t0.mid()) {
                return Some(hit);
            }
        }
        if t1.hi > t_max {
            return None;
        }
        self.clipped_hit(o, d, t1.mid())
    }

    /// Hit point at `t`, re-projected onto the sphere; `None` if clipped away.
    fn clipped_hit(&self, o: Vec3, d: Vec3, t: f32) -> Option<QuadricHit> {
        let mut p = o + t * d;
        p *= self.radius / p.length();
        if p.x == 0.0 && p.y == 0.0 {
            p.x = 1e-5 * self.radius;
        }
        let phi = phi_of(p);
        let r = self.radius;
        if (self.z_min > -r && p.z < self.z_min) || (self.z_max < r && p.z > self.z_max) {
            return None;
        }
        if phi > self.phi_max {
            return None;
        }
        Some(QuadricHit { t, p_obj: p, phi })
    }

    /// (u, v) of an object-space point: u = φ/φ_max, v linear in θ.
    fn uv(&self, p: Vec3, phi: f32) -> Vec2 {
        let theta = safe_acos(p.z / self.radius);
        let v = (theta - self.theta_z_min) / (self.theta_z_max - self.theta_z_min);
        Vec2::new(phi / self.phi_max, v)
    }

    /// Render-space normal at an object-space point, outward unless reversed.
    fn normal_at(&self, p_obj: Vec3) -> Vec3 {
        let n = self.render_from_object.normal(p_obj).normalize_or_zero();
        if self.reverse_orientation {
            -n
        } else {
            n
        }
    }

    /// Surface interaction of a hit: partial derivatives from the
    /// Weingarten equations [pbrt-v4 §6.2.3], moved to render space.
    fn interaction(&self, hit: &QuadricHit, wo: Vec3) -> SurfaceInteraction {
        let (p, r, phi_max) = (hit.p_obj, self.radius, self.phi_max);
        let dtheta = self.theta_z_max - self.theta_z_min;
        let z_radius = (p.x * p.x + p.y * p.y).sqrt();
        let (cos_phi, sin_phi) = (p.x / z_radius, p.y / z_radius);
        let cos_theta = p.z / r;
        let sin_theta = safe_sqrt(1.0 - cos_theta * cos_theta);
        let dpdu = Vec3::new(-phi_max * p.y, phi_max * p.x, 0.0);
        let dpdv = dtheta * Vec3::new(p.z * cos_phi, p.z * sin_phi, -r * sin_theta);
        let d2pduu = -phi_max * phi_max * Vec3::new(p.x, p.y, 0.0);
        let d2pduv = dtheta * p.z * phi_max * Vec3::new(-sin_phi, cos_phi, 0.0);
        let d2pdvv = -dtheta * dtheta * p;
        let (dndu, dndv) = weingarten(dpdu, dpdv, d2pduu, d2pduv, d2pdvv);
        let t = &*self.render_from_object;
        let (p_r, p_err) = t.point_with_error_prop(p, gamma(5) * p.abs());
        let mut si = SurfaceInteraction::new(
            p_r,
            p_err,
            self.uv(p, hit.phi),
            wo.normalize_or_zero(),
            t.vector(dpdu),
            t.vector(dpdv),
            t.normal(dndu),
            t.normal(dndv),
            false,
        );
        let n = self.normal_at(p);
        si.it.n = n;
        si.shading.n = n;
        si
    }

    /// Interaction for an object-space point on the sphere.
    fn interaction_at(&self, p_obj: Vec3) -> Interaction {
        let p_obj = p_obj * (self.radius / p_obj.length());
        let (p, p_error) = self
            .render_from_object
            .point_with_error_prop(p_obj, gamma(5) * p_obj.abs());
        Interaction {
            p,
            p_error,
            n: self.normal_at(p_obj),
            uv: self.uv(p_obj, phi_of(p_obj)),
            time: 0.0,
        }
    }

    /// A point uniformly distributed by area (uniform z and φ).
    pub fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        let area = self.area();
        if area.is_nan() || area <= 0.0 {
            return None;
        }
        let z = lerp(u.x, self.z_min, self.z_max);
        let phi = u.y * self.phi_max;
        let rho = safe_sqrt(self.radius * self.radius - z * z);
        let p_obj = Vec3::new(rho * phi.cos(), rho * phi.sin(), z);
        Some(ShapeSample {
            intr: self.interaction_at(p_obj),
            pdf: PdfArea(1.0 / area),
        })
    }

    /// Centre and radius in render space.
    fn render_center_radius(&self) -> (Vec3, f32) {
        (
            self.render_from_object.point(Vec3::ZERO),
            self.radius * self.scale,
        )
    }

    /// True when cone sampling applies: a full sphere seen from outside.
    fn uses_cone(&self, ctx: &ShapeSampleContext) -> bool {
        let (c, r) = self.render_center_radius();
        let origin = ctx.offset_ray_origin(c - ctx.p);
        self.is_full() && origin.distance_squared(c) > r * r
    }

    /// A point sampled by solid angle from `ctx` [pbrt-v4 §6.2.4].
    pub fn sample_from(&self, ctx: &ShapeSampleContext, u: Vec2) -> Option<ShapeSampleSa> {
        if !self.uses_cone(ctx) {
            return area_sample_to_solid_angle(ctx, self.sample_area(u)?);
        }
        let (c, r) = self.render_center_radius();
        let sin_theta_max = r / ctx.p.distance(c);
        let sin2_theta_max = sin_theta_max * sin_theta_max;
        let one_minus_cos_max = one_minus_cos(sin2_theta_max);
        // 1 − cos θ is uniform in [0, 1 − cos θ_max]; sin²θ = (1 − cos θ)(1 + cos θ)
        // keeps full precision for tiny cones (pbrt-v4 switches to a Taylor series).
        let one_minus_cos_theta = u.x * one_minus_cos_max;
        let cos_theta = 1.0 - one_minus_cos_theta;
        let sin2_theta = one_minus_cos_theta * (2.0 - one_minus_cos_theta);
        // Angle α at the centre between the axis and the sampled point.
        let cos_alpha =
            sin2_theta / sin_theta_max + cos_theta * safe_sqrt(1.0 - sin2_theta / sin2_theta_max);
        let sin_alpha = safe_sqrt(1.0 - cos_alpha * cos_alpha);
        let w = spherical_direction(sin_alpha, cos_alpha, u.y * 2.0 * PI);
        let frame = Frame::from_z((c - ctx.p).normalize());
        let n_out = frame.from_local(-w);
        let p = c + r * n_out;
        let uv = if ctx.need_uv {
            let p_obj = self.render_from_object.inverse().point(p);
            self.uv(p_obj, phi_of(p_obj))
        } else {
            Vec2::ZERO
        };
        let intr = Interaction {
            p,
            p_error: gamma(5) * p.abs(),
            n: if self.reverse_orientation {
                -n_out
            } else {
                n_out
            },
            uv,
            time: 0.0,
        };
        let pdf = PdfSolidAngle(1.0 / (2.0 * PI * one_minus_cos_max));
        pdf.0.is_finite().then_some(ShapeSampleSa { intr, pdf })
    }

    /// Density of [`Sphere::sample_from`] for direction `wi`; 0 when `wi` misses.
    pub fn pdf_from(&self, ctx: &ShapeSampleContext, wi: Vec3) -> PdfSolidAngle {
        if !self.uses_cone(ctx) {
            let hit = self.intersect(&ctx.spawn_ray(wi), f32::INFINITY);
            return pdf_from_hit(ctx, wi, hit, |_| PdfArea(1.0 / self.area()));
        }
        let (c, r) = self.render_center_radius();
        let d = c - ctx.p;
        let wi = wi.normalize();
        let t = d.dot(wi);
        // Outside the cone (with a little slack for rounding at the rim).
        if t <= 0.0 || (d - t * wi).length_squared() > r * r * (1.0 + 1e-4) {
            return PdfSolidAngle(0.0);
        }
        let one_minus_cos_max = one_minus_cos(r * r / d.length_squared());
        PdfSolidAngle(1.0 / (2.0 * PI * one_minus_cos_max))
    }
}

/// 1 − cos θ from sin²θ (θ ≤ π/2) without cancellation: sin²θ / (1 + cos θ).
fn one_minus_cos(sin2: f32) -> f32 {
    sin2 / (1.0 + safe_sqrt(1.0 - sin2))
}

/// Azimuth of an object-space point in [0, 2π).
pub(super) fn phi_of(p: Vec3) -> f32 {
    let phi = p.y.atan2(p.x);
    if phi < 0.0 {
        phi + 2.0 * PI
    } else {
        phi
    }
}

/// ∂n/∂u, ∂n/∂v from the first and second fundamental forms
/// [pbrt-v4 eq. 6.10, the Weingarten equations].
pub(super) fn weingarten(dpdu: Vec3, dpdv: Vec3, duu: Vec3, duv: Vec3, dvv: Vec3) -> (Vec3, Vec3) {
    let (e1, f1, g1) = (dpdu.dot(dpdu), dpdu.dot(dpdv), dpdv.dot(dpdv));
    let n = dpdu.cross(dpdv).normalize_or_zero();
    let (e, f, g) = (n.dot(duu), n.dot(duv), n.dot(dvv));
    let egf2 = e1 * g1 - f1 * f1;
    if egf2 == 0.0 {
        return (Vec3::ZERO, Vec3::ZERO);
    }
    let inv = 1.0 / egf2;
    let dndu = (f * f1 - e * g1) * inv * dpdu + (e * f1 - f * e1) * inv * dpdv;
    let dndv = (g * f1 - f * g1) * inv * dpdu + (f * f1 - g * e1) * inv * dpdv;
    (dndu, dndv)
}
