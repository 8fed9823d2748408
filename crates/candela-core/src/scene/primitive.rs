//! A shape with its material and optional area light.

use crate::interaction::{LightId, MaterialId};
use crate::shape::Shape;

/// Continued rays after cut-out hits of one primitive ([`Primitive::hit`]).
const MAX_CUTOUT_CONTINUATIONS: usize = 3;

/// One intersectable object.
#[derive(Clone, Debug)]
pub struct Primitive {
    /// Geometry.
    pub shape: Shape,
    /// Material (`None`: interface, rays pass through).
    pub material: Option<MaterialId>,
    /// Emission.
    pub area_light: Option<LightId>,
    /// Cut-out mask (`None`: opaque) [pbrt-v4 `GeometricPrimitive`].
    pub alpha: Option<crate::texture::FloatTexture>,
}

impl Primitive {
    /// The vertices of an opaque mesh triangle, which the BVH stores and
    /// tests itself; `None` for anything the primitive must test (other
    /// shapes, alpha cut-outs).
    #[inline]
    pub fn packed_triangle(&self) -> Option<[crate::math::Vec3; 3]> {
        match (&self.shape, &self.alpha) {
            (crate::shape::Shape::Triangle(t), None) => Some(t.positions()),
            _ => None,
        }
    }

    /// A BVH over `prims` followed by `extra` items of the given bounds
    /// (item `prims.len() + k` is `extra[k]`); opaque triangles go into its
    /// packs.
    pub fn bvh(prims: &[Primitive], extra: &[crate::math::Bounds3]) -> crate::accel::Bvh {
        use rayon::prelude::*;
        let mut bounds: Vec<_> = prims.par_iter().map(|p| p.shape.bounds()).collect();
        bounds.extend_from_slice(extra);
        crate::accel::Bvh::build_with_triangles(&bounds, |i| {
            prims.get(i as usize).and_then(Primitive::packed_triangle)
        })
    }

    /// Closest-hit candidate before `t_max` that survives the alpha test.
    #[inline]
    pub fn hit(
        &self,
        ray: &crate::math::Ray,
        wr: &crate::shape::WatertightRay,
        t_max: f32,
    ) -> Option<crate::shape::DeferredHit> {
        let hit = self.shape.intersect_deferred(ray, wr, t_max)?;
        if self.alpha.is_none() {
            return Some(hit);
        }
        let first = self.shape.finish_hit(hit, ray);
        if self.alpha_passes(first.si, ray) {
            return Some(hit);
        }
        self.hit_beyond(first, ray, t_max)
    }

    /// The next hit of this shape along `ray` after the cut-out hit `cut`
    /// that survives the alpha test, as pbrt-v4's `GeometricPrimitive`
    /// finds it: a ray continued from the rejected point, its `t` added to
    /// the first's. A sphere, cylinder or bilinear patch can be hit again
    /// (the far side seen through a hole, which without this was skipped:
    /// see-through spheres showed the floor where pbrt-v4 shows their
    /// inside); a triangle or disk cannot. Each continued ray draws its own
    /// alpha test ([`Self::alpha_passes`] hashes the ray), as in pbrt-v4.
    fn hit_beyond(
        &self,
        cut: crate::shape::ShapeIntersection,
        ray: &crate::math::Ray,
        t_max: f32,
    ) -> Option<crate::shape::DeferredHit> {
        if matches!(self.shape, Shape::Triangle(_) | Shape::Disk(_)) {
            return None;
        }
        let (mut cut, mut t) = (cut, cut.t_hit);
        // Two roots for the quadrics and the bilinear patch: one more hit
        // at most, and a bound against round-off finding the same point.
        for _ in 0..MAX_CUTOUT_CONTINUATIONS {
            let next = cut.si.spawn_ray(ray.d);
            let mut h = self.shape.intersect(&next, t_max - t)?;
            t += h.t_hit;
            h.t_hit = t;
            if self.alpha_passes(h.si, &next) {
                return Some(crate::shape::DeferredHit::Done(h));
            }
            cut = h;
        }
        None
    }

    /// True if the primitive blocks the ray before `t_max` (alpha-tested).
    #[inline]
    pub fn blocks(
        &self,
        ray: &crate::math::Ray,
        wr: &crate::shape::WatertightRay,
        t_max: f32,
    ) -> bool {
        if self.alpha.is_none() {
            return self.shape.intersect_p(ray, t_max);
        }
        self.hit(ray, wr, t_max).is_some()
    }

    /// pbrt-v4's alpha test at a candidate hit: kept when α ≥ 1, dropped when
    /// α ≤ 0, otherwise kept with probability α using a hash of the ray (so a
    /// ray and its shadow-ray twin decide alike, and images stay deterministic).
    pub fn alpha_passes(
        &self,
        si: crate::interaction::SurfaceInteraction,
        ray: &crate::math::Ray,
    ) -> bool {
        let Some(alpha) = &self.alpha else {
            return true;
        };
        let a = alpha.evaluate(&crate::texture::TextureEvalContext::from_si(&si));
        if a >= 1.0 {
            return true;
        }
        if a <= 0.0 {
            return false;
        }
        let bits = |v: crate::math::Vec3| {
            ((v.x.to_bits() as u64) << 32 | v.y.to_bits() as u64)
                ^ (v.z.to_bits() as u64).rotate_left(17)
        };
        let h = crate::sampling::hash_u64s(&[bits(ray.o), bits(ray.d)]);
        let u = (h >> 40) as f32 / (1u64 << 24) as f32;
        u < a
    }
}
