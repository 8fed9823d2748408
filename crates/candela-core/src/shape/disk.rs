//! Disks and annuli in the plane z = height, placed by a transform.
//!
//! Intersection is a ray–plane test in object space followed by radius and
//! φ checks [pbrt-v4 §6.4.2]. The hit's z is set exactly to the height, so
//! its object-space error is zero and only the transform's rounding enters
//! the bound. Area sampling maps the square to the annulus sector with
//! r = √(lerp(u₀, r_i², r²)), which is uniform by area (the concentric map
//! for full disks, for its lower distortion [Shirley & Chiu 1997]).

use super::sphere::phi_of;
use super::{ShapeIntersection, ShapeSample};
use crate::interaction::{Interaction, SurfaceInteraction};
use crate::math::{lerp, Bounds3, Ray, Transform, Vec2, Vec3, PI};
use crate::sampling::{sample_uniform_disk_concentric, PdfArea};
use std::sync::Arc;

/// An annulus sector `r ∈ [inner_radius, radius]`, `φ ∈ [0, φ_max]` at z = height.
#[derive(Clone, Debug)]
pub struct Disk {
    render_from_object: Arc<Transform>,
    reverse_orientation: bool,
    height: f32,
    radius: f32,
    inner_radius: f32,
    phi_max: f32,
    /// Render-area per object-area of the transformed plane.
    area_scale: f32,
}

impl Disk {
    /// A disk; `phi_max_deg` is clamped to [0, 360].
    pub fn new(
        render_from_object: Arc<Transform>,
        reverse_orientation: bool,
        height: f32,
        radius: f32,
        inner_radius: f32,
        phi_max_deg: f32,
    ) -> Self {
        let t = &*render_from_object;
        let area_scale = t.vector(Vec3::X).cross(t.vector(Vec3::Y)).length();
        Self {
            reverse_orientation,
            height,
            radius,
            inner_radius,
            phi_max: phi_max_deg.clamp(0.0, 360.0).to_radians(),
            area_scale,
            render_from_object,
        }
    }

    /// Render-space bounds.
    pub fn bounds(&self) -> Bounds3 {
        let r = self.radius;
        let b = Bounds3::from_points(Vec3::new(-r, -r, self.height), Vec3::new(r, r, self.height));
        self.render_from_object.bounds(&b)
    }

    /// Area: φ_max/2 · (r² − r_i²), scaled to render space.
    pub fn area(&self) -> f32 {
        let (r, ri) = (self.radius, self.inner_radius);
        self.phi_max * 0.5 * (r * r - ri * ri) * self.area_scale
    }

    /// Closest hit with `t ∈ (0, t_max)`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeIntersection> {
        let (t, p_obj, phi) = self.basic_intersect(ray, t_max)?;
        let si = self.interaction(p_obj, phi, -ray.d);
        Some(ShapeIntersection { si, t_hit: t })
    }

    /// True when the ray hits for some `t ∈ (0, t_max)`.
    pub fn intersect_p(&self, ray: &Ray, t_max: f32) -> bool {
        self.basic_intersect(ray, t_max).is_some()
    }

    /// Plane hit in object space, then radius and φ tests.
    fn basic_intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, Vec3, f32)> {
        let inv = self.render_from_object.inverse();
        let (o, d) = (inv.point(ray.o), inv.vector(ray.d));
        if d.z == 0.0 {
            return None;
        }
        let t = (self.height - o.z) / d.z;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let p = o + t * d;
        let dist2 = p.x * p.x + p.y * p.y;
        if dist2 > self.radius * self.radius || dist2 < self.inner_radius * self.inner_radius {
            return None;
        }
        let phi = phi_of(p);
        if phi > self.phi_max {
            return None;
        }
        Some((t, Vec3::new(p.x, p.y, self.height), phi))
    }

    /// Render-space normal: object +z, negated when reversed.
    pub(super) fn normal(&self) -> Vec3 {
        let n = self.render_from_object.normal(Vec3::Z).normalize_or_zero();
        if self.reverse_orientation {
            -n
        } else {
            n
        }
    }

    /// (u, v): u = φ/φ_max, v = 0 on the rim and 1 on the inner radius.
    fn uv(&self, r_hit: f32, phi: f32) -> Vec2 {
        Vec2::new(
            phi / self.phi_max,
            (self.radius - r_hit) / (self.radius - self.inner_radius),
        )
    }

    /// Surface interaction of a hit [pbrt-v4 §6.4.3].
    fn interaction(&self, p: Vec3, phi: f32, wo: Vec3) -> SurfaceInteraction {
        let r_hit = (p.x * p.x + p.y * p.y).sqrt();
        let dpdu = Vec3::new(-self.phi_max * p.y, self.phi_max * p.x, 0.0);
        let radial = if r_hit > 0.0 {
            Vec3::new(p.x / r_hit, p.y / r_hit, 0.0)
        } else {
            Vec3::X
        };
        let dpdv = radial * (self.inner_radius - self.radius);
        let t = &*self.render_from_object;
        let (p_r, p_err) = t.point_with_error(p);
        let mut si = SurfaceInteraction::new(
            p_r,
            p_err,
            self.uv(r_hit, phi),
            wo.normalize_or_zero(),
            t.vector(dpdu),
            t.vector(dpdv),
            Vec3::ZERO,
            Vec3::ZERO,
            false,
        );
        let n = self.normal();
        si.it.n = n;
        si.shading.n = n;
        si
    }

    /// A point uniformly distributed by area.
    pub fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        let area = self.area();
        if area.is_nan() || area <= 0.0 {
            return None;
        }
        let full = self.inner_radius == 0.0 && self.phi_max >= 2.0 * PI;
        let pd = if full {
            self.radius * sample_uniform_disk_concentric(u)
        } else {
            let r = lerp(u.x, self.inner_radius.powi(2), self.radius.powi(2)).sqrt();
            let phi = u.y * self.phi_max;
            Vec2::new(r * phi.cos(), r * phi.sin())
        };
        let p_obj = Vec3::new(pd.x, pd.y, self.height);
        let (p, p_error) = self.render_from_object.point_with_error(p_obj);
        let intr = Interaction {
            p,
            p_error,
            n: self.normal(),
            uv: self.uv(pd.length(), phi_of(p_obj)),
            time: 0.0,
        };
        Some(ShapeSample {
            intr,
            pdf: PdfArea(1.0 / area),
        })
    }
}
