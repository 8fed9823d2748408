//! A shape with its material and optional area light.

use crate::interaction::{LightId, MaterialId};
use crate::shape::Shape;

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
    /// Closest-hit candidate before `t_max` that survives the alpha test.
    #[inline]
    pub fn hit(
        &self,
        ray: &crate::math::Ray,
        wr: &crate::shape::WatertightRay,
        t_max: f32,
    ) -> Option<crate::shape::DeferredHit> {
        let hit = self.shape.intersect_deferred(ray, wr, t_max)?;
        if self.alpha.is_some() && !self.alpha_passes(self.shape.finish_hit(hit, ray).si, ray) {
            return None;
        }
        Some(hit)
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
