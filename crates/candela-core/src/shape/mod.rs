//! Geometric shapes: ray intersection, bounds, area, and point sampling.
//!
//! Every shape answers the same questions [pbrt-v4 §6.1]: its render-space
//! bounds and area, the closest hit along a ray (as a [`SurfaceInteraction`]
//! with a conservative error bound on the hit point, so rays can be spawned
//! without epsilons [pbrt-v4 §6.8]), an any-hit test, a point sampled
//! uniformly by area, and a point sampled with respect to solid angle as seen
//! from a reference point (what area lights need). Densities carry their
//! measure ([`PdfArea`], [`PdfSolidAngle`]).
//!
//! Dispatch is a closed enum built by value; the `dispatch!` macro writes the
//! match arms once. A new shape adds a variant and a file. Loop subdivision
//! surfaces are refined into triangle meshes at load time ([`loop_subdivide`]).
//!
//! Area sampling need not be uniform: cylinders under general linear maps and
//! curved bilinear patches sample with a density that varies over the surface,
//! so [`Shape::pdf_area`] evaluates it at the point.
//!
//! Normal orientation: the geometric normal points to the object's outside
//! (the side `∂p/∂u × ∂p/∂v` points to in object space) and is flipped by
//! `reverse_orientation`. Intersection and sampling agree on this, also under
//! handedness-swapping transforms. For triangle meshes with per-vertex
//! normals, the geometric normal follows the interpolated shading normal, as
//! in pbrt-v4.

mod bilinear;
mod bilinear_math;
mod cylinder;
mod disk;
mod interval;
mod loop_subdiv;
mod mesh;
mod normal_bounds;
mod sphere;
mod sphere_cull;
mod triangle;

#[cfg(test)]
mod bilinear_tests;
#[cfg(test)]
mod loop_subdiv_tests;
#[cfg(test)]
mod sampling_tests;
#[cfg(test)]
mod tests;

pub use bilinear::{BilinearPatch, BilinearPatchMesh};
pub use bilinear_math::{intersect_bilinear_patch, invert_bilinear, BilinearIntersection};
pub use cylinder::Cylinder;
pub use disk::Disk;
pub use loop_subdiv::{loop_subdivide, LoopSubdivError, LoopSurface};
pub use mesh::{MeshError, TriangleMesh};
pub use sphere::Sphere;
pub use triangle::{
    intersect_triangle, Triangle, TriangleIntersection, TriangleSampler, WatertightRay,
};

/// A closest-hit candidate from [`Shape::intersect_deferred`].
#[derive(Clone, Copy, Debug)]
pub enum DeferredHit {
    /// A triangle hit: barycentrics and t only.
    Triangle(TriangleIntersection),
    /// Another shape's complete intersection.
    Done(ShapeIntersection),
}

impl DeferredHit {
    /// Ray parameter of the hit.
    pub fn t(&self) -> f32 {
        match self {
            DeferredHit::Triangle(t) => t.t,
            DeferredHit::Done(h) => h.t_hit,
        }
    }
}

use crate::interaction::{Interaction, SurfaceInteraction};
use crate::math::{offset_ray_origin, Bounds3, Ray, Vec2, Vec3};
use crate::sampling::{pdf_area_to_solid_angle, PdfArea, PdfSolidAngle};

/// A reference point from which a shape is sampled by solid angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeSampleContext {
    /// Reference position.
    pub p: Vec3,
    /// Absolute error bound of `p`, per axis.
    pub p_error: Vec3,
    /// Geometric normal at `p` (zero in media / free space).
    pub n: Vec3,
    /// Shading normal at `p` (zero in media / free space).
    pub ns: Vec3,
    /// Whether the sampled point's (u, v) is read (textured or cut-out
    /// emitters); without it a sphere sampled by its cone skips the inverse
    /// transform, arctangent and arccosine that (u, v) costs.
    pub need_uv: bool,
}

impl ShapeSampleContext {
    /// Context from its parts (with (u, v)).
    pub fn new(p: Vec3, p_error: Vec3, n: Vec3, ns: Vec3) -> Self {
        Self {
            p,
            p_error,
            n,
            ns,
            need_uv: true,
        }
    }
    /// Context for a point in a medium or free space (no normal, no error).
    pub fn from_point(p: Vec3) -> Self {
        Self::new(p, Vec3::ZERO, Vec3::ZERO, Vec3::ZERO)
    }
    /// Context at a surface hit.
    pub fn from_surface(si: &SurfaceInteraction) -> Self {
        Self::new(si.it.p, si.it.p_error, si.it.n, si.shading.n)
    }
    /// Ray origin offset past `p`'s error bound towards `w`.
    pub fn offset_ray_origin(&self, w: Vec3) -> Vec3 {
        offset_ray_origin(self.p, self.p_error, self.n, w)
    }
    /// Ray leaving the reference point in direction `w`.
    pub fn spawn_ray(&self, w: Vec3) -> Ray {
        Ray::new(self.offset_ray_origin(w), w)
    }
}

/// A point sampled on a shape with its density with respect to area.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeSample {
    /// Sampled point, its error bound, oriented normal and uv.
    pub intr: Interaction,
    /// Density with respect to surface area.
    pub pdf: PdfArea,
}

/// A point sampled on a shape with its density with respect to solid angle
/// at the reference point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeSampleSa {
    /// Sampled point, its error bound, oriented normal and uv.
    pub intr: Interaction,
    /// Density with respect to solid angle at the reference point.
    pub pdf: PdfSolidAngle,
}

/// A ray–shape hit: the surface interaction and the ray parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeIntersection {
    /// The hit (material and light fields left for the primitive to fill).
    pub si: SurfaceInteraction,
    /// Ray parameter of the hit.
    pub t_hit: f32,
}

/// Any shape candela can intersect and sample.
#[derive(Clone, Debug)]
pub enum Shape {
    /// One triangle of a mesh.
    Triangle(Triangle),
    /// A (partial) sphere.
    Sphere(Sphere),
    /// A (partial) disk or annulus.
    Disk(Disk),
    /// A (partial) cylinder.
    Cylinder(Cylinder),
    /// One patch of a bilinear patch mesh.
    BilinearPatch(BilinearPatch),
}

/// Expands to a match forwarding `$call` to the concrete shape.
macro_rules! dispatch {
    ($self:expr, $s:ident => $call:expr) => {
        match $self {
            Shape::Triangle($s) => $call,
            Shape::Sphere($s) => $call,
            Shape::Disk($s) => $call,
            Shape::Cylinder($s) => $call,
            Shape::BilinearPatch($s) => $call,
        }
    };
}

impl Shape {
    /// Render-space bounding box.
    pub fn bounds(&self) -> Bounds3 {
        dispatch!(self, s => s.bounds())
    }

    /// Surface area in render space.
    pub fn area(&self) -> f32 {
        dispatch!(self, s => s.area())
    }

    /// Closest hit with `t ∈ (0, t_max)`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeIntersection> {
        dispatch!(self, s => s.intersect(ray, t_max))
    }

    /// Closest-hit test that defers building the surface interaction
    /// (the expensive part) until the BVH traversal knows the hit is final.
    pub fn intersect_deferred(
        &self,
        ray: &Ray,
        wr: &WatertightRay,
        t_max: f32,
    ) -> Option<DeferredHit> {
        match self {
            Shape::Triangle(t) => t.intersect_raw(wr, t_max).map(DeferredHit::Triangle),
            other => other.intersect(ray, t_max).map(DeferredHit::Done),
        }
    }

    /// Builds the intersection of a deferred hit of this shape.
    pub fn finish_hit(&self, hit: DeferredHit, ray: &Ray) -> ShapeIntersection {
        match (self, hit) {
            (Shape::Triangle(t), DeferredHit::Triangle(ti)) => ShapeIntersection {
                si: t.interaction(&ti, -ray.d),
                t_hit: ti.t,
            },
            (_, DeferredHit::Done(h)) => h,
            (_, DeferredHit::Triangle(_)) => {
                unreachable!("triangle hit recorded for a non-triangle shape")
            }
        }
    }

    /// Any-hit test with the ray's watertight constants precomputed.
    #[inline]
    pub fn intersect_p_with(&self, ray: &Ray, wr: &WatertightRay, t_max: f32) -> bool {
        match self {
            Shape::Triangle(t) => t.intersect_raw(wr, t_max).is_some(),
            other => other.intersect_p(ray, t_max),
        }
    }

    /// True when the ray hits the shape for some `t ∈ (0, t_max)`.
    pub fn intersect_p(&self, ray: &Ray, t_max: f32) -> bool {
        dispatch!(self, s => s.intersect_p(ray, t_max))
    }

    /// A point sampled by area (uniformly, except for the shapes named in
    /// the module doc); `None` for degenerate shapes.
    pub fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        dispatch!(self, s => s.sample_area(u))
    }

    /// Density of [`Shape::sample_area`] at a point on the shape.
    pub fn pdf_area(&self, intr: &Interaction) -> PdfArea {
        match self {
            Shape::Cylinder(c) => c.pdf_area(intr),
            Shape::BilinearPatch(b) => b.pdf_area(intr),
            _ => PdfArea(1.0 / self.area()),
        }
    }

    /// A point sampled with density with respect to solid angle at `ctx.p`.
    pub fn sample_from(&self, ctx: &ShapeSampleContext, u: Vec2) -> Option<ShapeSampleSa> {
        match self {
            Shape::Sphere(s) => s.sample_from(ctx, u),
            _ => area_sample_to_solid_angle(ctx, self.sample_area(u)?),
        }
    }

    /// Density of [`Shape::sample_from`] for direction `wi` (0 if the ray misses).
    pub fn pdf_from(&self, ctx: &ShapeSampleContext, wi: Vec3) -> PdfSolidAngle {
        match self {
            Shape::Sphere(s) => s.pdf_from(ctx, wi),
            _ => {
                let hit = self.intersect(&ctx.spawn_ray(wi), f32::INFINITY);
                pdf_from_hit(ctx, wi, hit, |it| self.pdf_area(it))
            }
        }
    }
}

/// Converts a uniform-area sample to solid angle at `ctx.p`
/// [pbrt-v4 eq. 6.14]: p_ω = p_A · d² / |cos θ|. `None` when grazing or coincident.
pub(crate) fn area_sample_to_solid_angle(
    ctx: &ShapeSampleContext,
    ss: ShapeSample,
) -> Option<ShapeSampleSa> {
    let d = ss.intr.p - ctx.p;
    let dist2 = d.length_squared();
    if dist2 == 0.0 {
        return None;
    }
    let wi = d / dist2.sqrt();
    let pdf = pdf_area_to_solid_angle(ss.pdf, dist2, ss.intr.n.dot(wi).abs());
    if !(pdf.0 > 0.0 && pdf.0.is_finite()) {
        return None;
    }
    Some(ShapeSampleSa { intr: ss.intr, pdf })
}

/// Solid-angle density of area sampling for direction `wi`, given the hit
/// of the ray from `ctx` along `wi` (0 when it missed) and the area density
/// at a point.
pub(crate) fn pdf_from_hit(
    ctx: &ShapeSampleContext,
    wi: Vec3,
    hit: Option<ShapeIntersection>,
    pdf_area: impl FnOnce(&Interaction) -> PdfArea,
) -> PdfSolidAngle {
    let Some(isect) = hit else {
        return PdfSolidAngle(0.0);
    };
    let it = &isect.si.it;
    pdf_at_point(ctx, wi, it.p, it.n, pdf_area(it))
}

/// Solid-angle density at `ctx` of direction `wi`, which reaches the shape
/// at `p` with normal `n` where the area density is `pdf_area` (0 when not
/// finite).
pub(crate) fn pdf_at_point(
    ctx: &ShapeSampleContext,
    wi: Vec3,
    p: Vec3,
    n: Vec3,
    pdf_area: PdfArea,
) -> PdfSolidAngle {
    let cos = n.dot(wi.normalize()).abs();
    let pdf = pdf_area_to_solid_angle(pdf_area, ctx.p.distance_squared(p), cos);
    if pdf.0.is_finite() {
        pdf
    } else {
        PdfSolidAngle(0.0)
    }
}
