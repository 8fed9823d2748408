//! The traceable scene: primitives in a BVH, materials, lights and the
//! light sampler. Built from a plain description by [`build`].

pub mod build;
mod primitive;

pub use primitive::Primitive;

use crate::accel::Bvh;
use crate::bsdf::Bsdf;
use crate::interaction::{Interaction, LightId, SurfaceInteraction};
use crate::light::{Light, LightSampler};
use crate::material::{apply_bump, mix_choice, Material};
use crate::math::{Bounds3, Ray, SHADOW_EPSILON};
use crate::shape::WatertightRay;
use crate::spectrum::SampledWavelengths;
use crate::texture::TextureEvalContext;
use rayon::prelude::*;

/// Everything rays can hit or be lit by.
pub struct Scene {
    primitives: Vec<Primitive>,
    bvh: Bvh,
    materials: Vec<Material>,
    lights: Vec<Light>,
    infinite_lights: Vec<LightId>,
    light_sampler: LightSampler,
    bounds: Bounds3,
}

impl Scene {
    /// Assembles a scene; lights are preprocessed with the scene bounds.
    pub fn new(
        primitives: Vec<Primitive>,
        materials: Vec<Material>,
        mut lights: Vec<Light>,
        power_sampling: bool,
    ) -> Self {
        let prim_bounds: Vec<Bounds3> = primitives.par_iter().map(|p| p.shape.bounds()).collect();
        let bounds = prim_bounds.iter().fold(Bounds3::EMPTY, |a, b| a.union(*b));
        let bvh = Bvh::build(&prim_bounds);
        for l in &mut lights {
            l.preprocess(&bounds);
        }
        let infinite_lights = (0..lights.len())
            .filter(|&i| matches!(lights[i].light_type(), crate::light::LightType::Infinite))
            .map(|i| LightId(i as u32))
            .collect();
        let light_sampler = if power_sampling {
            LightSampler::power(&lights)
        } else {
            LightSampler::uniform(&lights)
        };
        Self {
            primitives,
            bvh,
            materials,
            lights,
            infinite_lights,
            light_sampler,
            bounds,
        }
    }

    /// Bounds of all geometry.
    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }
    /// Number of primitives.
    pub fn primitive_count(&self) -> usize {
        self.primitives.len()
    }
    /// All primitives.
    pub fn primitives(&self) -> &[Primitive] {
        &self.primitives
    }
    /// All lights.
    pub fn lights(&self) -> &[Light] {
        &self.lights
    }
    /// One light.
    #[inline]
    pub fn light(&self, id: LightId) -> &Light {
        &self.lights[id.0 as usize]
    }
    /// Lights at infinity (seen by escaping rays).
    pub fn infinite_lights(&self) -> &[LightId] {
        &self.infinite_lights
    }
    /// The light-selection distribution.
    pub fn light_sampler(&self) -> &LightSampler {
        &self.light_sampler
    }
    /// All materials.
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// Closest hit along `ray` before `t_max`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<SurfaceInteraction> {
        let mut best = None;
        let wr = WatertightRay::new(ray);
        self.bvh.intersect(ray, t_max, |i, ray, t_max| {
            let prim = &self.primitives[i as usize];
            let hit = prim.shape.intersect_deferred(ray, &wr, t_max)?;
            if prim.alpha.is_some() && !prim.alpha_passes(prim.shape.finish_hit(hit, ray).si, ray) {
                return None;
            }
            let t = hit.t();
            best = Some((i, hit));
            Some(t)
        });
        let (i, hit) = best?;
        let prim = &self.primitives[i as usize];
        let mut si = prim.shape.finish_hit(hit, ray).si;
        si.material = prim.material;
        si.area_light = prim.area_light;
        Some(si)
    }

    /// True if anything blocks `ray` before `t_max`.
    pub fn intersect_p(&self, ray: &Ray, t_max: f32) -> bool {
        let wr = WatertightRay::new(ray);
        self.bvh.intersect_p(ray, t_max, |i, ray, t_max| {
            let prim = &self.primitives[i as usize];
            if prim.alpha.is_none() {
                return prim.shape.intersect_p(ray, t_max);
            }
            match prim.shape.intersect_deferred(ray, &wr, t_max) {
                Some(hit) => prim.alpha_passes(prim.shape.finish_hit(hit, ray).si, ray),
                None => false,
            }
        })
    }

    /// True if the segment between two interactions is free.
    pub fn unoccluded(&self, a: &Interaction, b: &Interaction) -> bool {
        let ray = a.spawn_ray_to(b);
        !self.intersect_p(&ray, 1.0 - SHADOW_EPSILON)
    }

    /// The BSDF at a hit (`None` for interface materials), with the
    /// material's textures evaluated for `lambda`. Mix materials are
    /// resolved to one of their materials, and a bump map replaces the
    /// hit's shading geometry (so the caller sees the bumped shading
    /// normal), as in pbrt-v4's `SurfaceInteraction::GetBSDF`.
    pub fn bsdf(
        &self,
        si: &mut SurfaceInteraction,
        lambda: &mut SampledWavelengths,
    ) -> Option<Bsdf> {
        let m = self.resolve_material(si)?;
        if let Some(d) = m.displacement() {
            apply_bump(si, d);
        }
        m.bsdf(si, lambda)
    }

    /// The hit's material with mixes resolved (the builder rejects cycles;
    /// the bound guards against them anyway).
    fn resolve_material(&self, si: &SurfaceInteraction) -> Option<&Material> {
        let mut m = &self.materials[si.material?.0 as usize];
        for _ in 0..self.materials.len() {
            let Material::Mix { materials, amount } = m else {
                return Some(m);
            };
            let a = amount.evaluate(&TextureEvalContext::from_si(si));
            m = &self.materials[materials[mix_choice(a, si.p(), si.wo)].0 as usize];
        }
        None
    }
}
