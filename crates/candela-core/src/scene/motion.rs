//! Moving geometry: primitives whose object-to-render transform changes
//! over the shutter interval (pbrt-v4's `ActiveTransform StartTime/EndTime`).
//!
//! A [`MovingGroup`] keeps its primitives in object space with their own
//! BVH, like pbrt-v4's `AnimatedPrimitive` [pbrt-v4 §7.1.4]. A ray is taken
//! into object space by the inverse of the transform at the ray's time, the
//! hit is found there and its geometry is carried back to render space.
//! Rounding: the transformed origin's error box is stepped over along the
//! ray, as pbrt-v4's `Transform::operator()(Ray, tMax)` does, and the hit
//! point's error bound is propagated through the forward transform, so rays
//! spawned from moving surfaces need no epsilon either.

use super::Primitive;
use crate::accel::{Bvh, BvhHit};
use crate::interaction::SurfaceInteraction;
use crate::math::{AnimatedTransform, Bounds3, Ray, Transform};
use crate::shape::{DeferredHit, WatertightRay};

/// Primitives moving together under one animated transform.
#[derive(Debug)]
pub struct MovingGroup {
    prims: Vec<Primitive>,
    bvh: Bvh,
    render_from_object: AnimatedTransform,
    bounds: Bounds3,
}

impl MovingGroup {
    /// Primitives given in object space, placed by `render_from_object`.
    pub fn new(prims: Vec<Primitive>, render_from_object: AnimatedTransform) -> Self {
        let bvh = Primitive::bvh(&prims, &[]);
        let object_bounds = bvh.bounds();
        let bounds = if object_bounds.is_empty() {
            object_bounds
        } else {
            render_from_object.motion_bounds(&object_bounds)
        };
        Self {
            bvh,
            prims,
            render_from_object,
            bounds,
        }
    }

    /// Render-space bounds over the whole shutter interval.
    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    /// Its primitives, in object space.
    pub fn primitives(&self) -> &[Primitive] {
        &self.prims
    }

    /// Number of primitives.
    pub fn len(&self) -> usize {
        self.prims.len()
    }

    /// True without primitives.
    pub fn is_empty(&self) -> bool {
        self.prims.is_empty()
    }

    /// The transform at the ray's time and the ray in object space with its
    /// origin moved past its rounding error; `dt` is the parameter skipped.
    fn object_ray(&self, ray: &Ray, t_max: f32) -> (Transform, Ray, f32, f32) {
        let render_from_object = self.render_from_object.at(ray.time);
        let object_from_render = render_from_object.inverse();
        let (mut o, o_err) = object_from_render.point_with_error(ray.o);
        let d = object_from_render.vector(ray.d);
        let len2 = d.length_squared();
        let mut dt = 0.0;
        if len2 > 0.0 {
            dt = d.abs().dot(o_err) / len2;
            o += d * dt;
        }
        let r = Ray {
            o,
            d,
            time: ray.time,
        };
        (render_from_object, r, dt, t_max - dt)
    }

    /// Closest hit before `t_max` (render-space ray parameter), with its
    /// render-space interaction.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<(f32, SurfaceInteraction)> {
        let (render_from_object, r, dt, t_obj_max) = self.object_ray(ray, t_max);
        if t_obj_max <= 0.0 {
            return None;
        }
        let (i, hit) = closest_hit(&self.prims, &self.bvh, &r, t_obj_max)?;
        let prim = &self.prims[i as usize];
        let shape_hit = prim.shape.finish_hit(hit, &r);
        let mut si = to_render(&render_from_object, &shape_hit.si, ray);
        si.material = prim.material;
        si.area_light = prim.area_light;
        Some((shape_hit.t_hit + dt, si))
    }

    /// True if the group blocks the ray before `t_max`.
    pub fn intersect_p(&self, ray: &Ray, t_max: f32) -> bool {
        let (_, r, _, t_obj_max) = self.object_ray(ray, t_max);
        t_obj_max > 0.0 && any_hit(&self.prims, &self.bvh, &r, t_obj_max)
    }
}

/// Carries an object-space hit to render space.
fn to_render(m: &Transform, si: &SurfaceInteraction, ray: &Ray) -> SurfaceInteraction {
    let (p, p_error) = m.point_with_error_prop(si.it.p, si.it.p_error);
    let n = m.normal(si.it.n).normalize_or_zero();
    let mut out = *si;
    out.it.p = p;
    out.it.p_error = p_error;
    out.it.n = n;
    out.it.time = ray.time;
    out.wo = (-ray.d).normalize_or_zero();
    out.dpdu = m.vector(si.dpdu);
    out.dpdv = m.vector(si.dpdv);
    let mut ns = m.normal(si.shading.n).normalize_or_zero();
    if ns.dot(n) < 0.0 {
        ns = -ns;
    }
    out.shading.n = ns;
    out.shading.dpdu = m.vector(si.shading.dpdu);
    out.shading.dpdv = m.vector(si.shading.dpdv);
    out.shading.dndu = m.normal(si.shading.dndu);
    out.shading.dndv = m.normal(si.shading.dndv);
    out
}

/// Closest primitive hit in `prims` (through `bvh`), honouring alpha cut-outs.
fn closest_hit(
    prims: &[Primitive],
    bvh: &Bvh,
    ray: &Ray,
    t_max: f32,
) -> Option<(u32, DeferredHit)> {
    let mut other = None;
    let wr = WatertightRay::new(ray);
    let hit = bvh.intersect(ray, t_max, |i, ray, t_max| {
        let hit = prims[i as usize].hit(ray, &wr, t_max)?;
        other = Some((i, hit));
        Some(hit.t())
    })?;
    match hit {
        BvhHit::Triangle { item, hit } => Some((item, DeferredHit::Triangle(hit))),
        BvhHit::Other { .. } => other,
    }
}

/// True if any primitive in `prims` blocks the ray, honouring alpha cut-outs.
fn any_hit(prims: &[Primitive], bvh: &Bvh, ray: &Ray, t_max: f32) -> bool {
    let wr = WatertightRay::new(ray);
    bvh.intersect_p(ray, t_max, |i, ray, t_max| {
        prims[i as usize].blocks(ray, &wr, t_max)
    })
}
