//! Cylinders around the object-space z axis, clipped in z and φ, placed by a
//! transform.
//!
//! Intersection solves the ray–cylinder quadratic (x² + y² = r²) in object
//! space with conservative interval arithmetic, using the discriminant form
//! 4a(r − |f|)(r + |f|) where f is the xy part of the ray point closest to
//! the axis [pbrt-v4 §6.3.2 and §6.8.5]. The hit point's x and y are
//! re-projected onto the circle and carry the error bound γ₃|(x, y, 0)|;
//! any z lies on the (infinite) surface, so z needs no bound
//! [pbrt-v4 §6.8.5].
//!
//! Sampling picks (φ, z) uniformly. Under a transform with linear part M,
//! the render-space area element is |cof(M)·n̂(φ)| r dφ dz, where
//! n̂(φ) = (cos φ, sin φ, 0) and cof(M) = det(M)·M⁻ᵀ is the cofactor matrix
//! (the map of cross products). The sampling density per render-space area
//! is therefore 1 / (φ_max (z_max − z_min) r |cof(M) n̂(φ)|): exactly 1/A
//! for rigid, uniformly scaled or z-stretched cylinders, and still exact
//! (though not uniform) under general linear maps, where pbrt-v4 assumes
//! the object-space area. The area is ∫|cof(M) n̂(φ)| dφ · r (z_max − z_min),
//! integrated once with Simpson's rule (exact when the integrand is constant).

use super::interval::{mid3, transform_point_i, transform_vector_i, Interval};
use super::sphere::{phi_of, weingarten};
use super::{ShapeIntersection, ShapeSample};
use crate::interaction::{Interaction, SurfaceInteraction};
use crate::math::{gamma, lerp, Bounds3, Mat3, Ray, Transform, Vec2, Vec3};
use crate::sampling::PdfArea;
use std::sync::Arc;

/// Simpson panels for the area integral over φ (even).
const AREA_PANELS: usize = 256;

/// A cylinder of given radius around the object-space z axis, clipped to
/// `z ∈ [z_min, z_max]` and `φ ∈ [0, φ_max]`.
#[derive(Clone, Debug)]
pub struct Cylinder {
    render_from_object: Arc<Transform>,
    reverse_orientation: bool,
    radius: f32,
    z_min: f32,
    z_max: f32,
    phi_max: f32,
    /// |det M|, for the area element |det M|·|M⁻ᵀ n̂|.
    abs_det: f32,
    /// Render-space area.
    area: f32,
}

/// Object-space hit of the cylinder.
struct CylinderHit {
    t: f32,
    p_obj: Vec3,
    phi: f32,
}

impl Cylinder {
    /// A cylinder; `z_min` and `z_max` are sorted, `phi_max_deg` is clamped to [0, 360].
    pub fn new(
        render_from_object: Arc<Transform>,
        reverse_orientation: bool,
        radius: f32,
        z_min: f32,
        z_max: f32,
        phi_max_deg: f32,
    ) -> Self {
        let abs_det = Mat3::from_mat4(render_from_object.m).determinant().abs();
        let mut c = Self {
            render_from_object,
            reverse_orientation,
            radius,
            z_min: z_min.min(z_max),
            z_max: z_min.max(z_max),
            phi_max: phi_max_deg.clamp(0.0, 360.0).to_radians(),
            abs_det,
            area: 0.0,
        };
        c.area = c.integrate_area();
        c
    }

    /// |cof(M)·n̂(φ)| / r: render-space area per unit (φ, z) per unit radius.
    fn area_factor(&self, phi: f32) -> f32 {
        let n = Vec3::new(phi.cos(), phi.sin(), 0.0);
        self.abs_det * self.render_from_object.normal(n).length()
    }

    /// r (z_max − z_min) ∫₀^φmax |cof(M) n̂(φ)| dφ by composite Simpson.
    fn integrate_area(&self) -> f32 {
        let h = self.phi_max as f64 / AREA_PANELS as f64;
        let sum: f64 = (0..=AREA_PANELS)
            .map(|i| {
                let w = if i == 0 || i == AREA_PANELS {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * self.area_factor((i as f64 * h) as f32) as f64
            })
            .sum();
        let integral = sum * h / 3.0;
        (integral * self.radius.abs() as f64 * (self.z_max - self.z_min) as f64) as f32
    }

    /// Render-space bounds (of the clipped object-space box).
    pub fn bounds(&self) -> Bounds3 {
        let r = self.radius;
        let b = Bounds3::from_points(Vec3::new(-r, -r, self.z_min), Vec3::new(r, r, self.z_max));
        self.render_from_object.bounds(&b)
    }

    /// Surface area in render space.
    pub fn area(&self) -> f32 {
        self.area
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

    /// Solves the quadratic in intervals and applies the clipping [pbrt-v4 §6.3.2].
    fn basic_intersect(&self, ray: &Ray, t_max: f32) -> Option<CylinderHit> {
        let object_from_render = self.render_from_object.inverse();
        let oi = transform_point_i(&object_from_render, ray.o);
        let di = transform_vector_i(&object_from_render, ray.d);
        let r = Interval::exact(self.radius);
        let a = di[0].sqr() + di[1].sqr();
        if a.hi == 0.0 {
            return None; // parallel to the axis
        }
        let b = (di[0] * oi[0] + di[1] * oi[1]).scale(2.0);
        let c = oi[0].sqr() + oi[1].sqr() - r.sqr();
        // f = xy part of the ray point closest to the axis.
        let f = b / a.scale(2.0);
        let (fx, fy) = (oi[0] - f * di[0], oi[1] - f * di[1]);
        let len_f = (fx.sqr() + fy.sqr()).sqrt();
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

    /// Hit point at `t` with x, y re-projected onto the circle; `None` if clipped away.
    fn clipped_hit(&self, o: Vec3, d: Vec3, t: f32) -> Option<CylinderHit> {
        let mut p = o + t * d;
        let hit_rad = (p.x * p.x + p.y * p.y).sqrt();
        if hit_rad == 0.0 {
            return None;
        }
        p.x *= self.radius / hit_rad;
        p.y *= self.radius / hit_rad;
        let phi = phi_of(p);
        if p.z < self.z_min || p.z > self.z_max || phi > self.phi_max {
            return None;
        }
        Some(CylinderHit { t, p_obj: p, phi })
    }

    /// (u, v) = (φ/φ_max, (z − z_min)/(z_max − z_min)).
    fn uv(&self, p: Vec3, phi: f32) -> Vec2 {
        Vec2::new(
            phi / self.phi_max,
            (p.z - self.z_min) / (self.z_max - self.z_min),
        )
    }

    /// Render-space normal at an object-space point, outward unless reversed.
    fn normal_at(&self, p_obj: Vec3) -> Vec3 {
        let n = self
            .render_from_object
            .normal(Vec3::new(p_obj.x, p_obj.y, 0.0))
            .normalize_or_zero();
        if self.reverse_orientation {
            -n
        } else {
            n
        }
    }

    /// Surface interaction of a hit: partial derivatives from the
    /// Weingarten equations [pbrt-v4 §6.3.3], moved to render space.
    fn interaction(&self, hit: &CylinderHit, wo: Vec3) -> SurfaceInteraction {
        let (p, phi_max) = (hit.p_obj, self.phi_max);
        let dpdu = Vec3::new(-phi_max * p.y, phi_max * p.x, 0.0);
        let dpdv = Vec3::new(0.0, 0.0, self.z_max - self.z_min);
        let d2pduu = -phi_max * phi_max * Vec3::new(p.x, p.y, 0.0);
        let (dndu, dndv) = weingarten(dpdu, dpdv, d2pduu, Vec3::ZERO, Vec3::ZERO);
        let t = &*self.render_from_object;
        let p_err = gamma(3) * Vec3::new(p.x, p.y, 0.0).abs();
        let (p_r, p_err) = t.point_with_error_prop(p, p_err);
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

    /// Density with respect to render-space area of sampling azimuth `phi`.
    fn pdf_at_phi(&self, phi: f32) -> PdfArea {
        let dens = 1.0
            / (self.phi_max
                * (self.z_max - self.z_min)
                * self.radius.abs()
                * self.area_factor(phi));
        PdfArea(if dens.is_finite() { dens } else { 0.0 })
    }

    /// Density of [`Cylinder::sample_area`] at a point on the cylinder.
    pub fn pdf_area(&self, intr: &Interaction) -> PdfArea {
        let p_obj = self.render_from_object.inverse().point(intr.p);
        self.pdf_at_phi(phi_of(p_obj))
    }

    /// A point with (φ, z) uniform; its density per area is [`Cylinder::pdf_area`].
    pub fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        if self.area.is_nan() || self.area <= 0.0 {
            return None;
        }
        let z = lerp(u.x, self.z_min, self.z_max);
        let phi = u.y * self.phi_max;
        let p_obj = Vec3::new(self.radius * phi.cos(), self.radius * phi.sin(), z);
        let p_err = gamma(3) * Vec3::new(p_obj.x, p_obj.y, 0.0).abs();
        let (p, p_error) = self.render_from_object.point_with_error_prop(p_obj, p_err);
        let pdf = self.pdf_at_phi(phi);
        if pdf.0 <= 0.0 {
            return None;
        }
        let intr = Interaction {
            p,
            p_error,
            n: self.normal_at(p_obj),
            uv: self.uv(p_obj, phi),
            time: 0.0,
        };
        Some(ShapeSample { intr, pdf })
    }
}
