//! The traceable scene: primitives in a BVH, materials, lights and the
//! light sampler. Built from a plain description by `build`.

mod motion;
mod primitive;
#[cfg(test)]
mod tests;

pub use motion::MovingGroup;
pub use primitive::Primitive;

use crate::accel::{Bvh, BvhHit};
use crate::bsdf::Bsdf;
use crate::camera::PixelFootprint;
use crate::interaction::{Interaction, LightId, MaterialId, SurfaceInteraction};
use crate::light::{Light, LightSampler, LightSelection, NeeLightSampler};
use crate::material::{mix_choice, Material};
use crate::math::{Bounds3, Ray, SHADOW_EPSILON};
use crate::shape::{DeferredHit, WatertightRay};
use crate::spectrum::SampledWavelengths;
use crate::texture::TextureEvalContext;

/// Everything rays can hit or be lit by.
pub struct Scene {
    primitives: Vec<Primitive>,
    /// Moving geometry; BVH item `primitives.len() + k` is `movers[k]`.
    movers: Vec<MovingGroup>,
    /// The shutter interval when anything moves.
    shutter: Option<(f32, f32)>,
    bvh: Bvh,
    materials: Vec<Material>,
    lights: Vec<Light>,
    infinite_lights: Vec<LightId>,
    /// Some light can be hit by a ray ([`Light::is_hittable`]).
    hittable_lights: bool,
    /// Context-free selection: light subpaths, BDPT and VCM.
    light_sampler: LightSampler,
    /// Selection for next-event estimation at a receiver.
    nee_sampler: NeeLightSampler,
    bounds: Bounds3,
    /// The camera's pixel footprint, for texture filtering (none: zero
    /// differentials).
    footprint: Option<PixelFootprint>,
    /// Per material: a hit on it needs the footprint (it reads a texture).
    footprint_materials: Vec<bool>,
}

impl Scene {
    /// Assembles a scene; lights are preprocessed with the scene bounds.
    pub fn new(
        primitives: Vec<Primitive>,
        materials: Vec<Material>,
        lights: Vec<Light>,
        selection: LightSelection,
    ) -> Self {
        Self::with_motion(
            primitives,
            Vec::new(),
            (0.0, 1.0),
            materials,
            lights,
            selection,
        )
    }

    /// Assembles a scene with moving geometry, seen over the camera's
    /// `shutter` interval (open, close).
    pub fn with_motion(
        primitives: Vec<Primitive>,
        movers: Vec<MovingGroup>,
        shutter: (f32, f32),
        materials: Vec<Material>,
        mut lights: Vec<Light>,
        selection: LightSelection,
    ) -> Self {
        let mover_bounds: Vec<Bounds3> = movers.iter().map(|m| m.bounds()).collect();
        let bvh = Primitive::bvh(&primitives, &mover_bounds);
        let bounds = bvh.bounds();
        for l in &mut lights {
            l.preprocess(&bounds);
        }
        let infinite_lights = (0..lights.len())
            .filter(|&i| matches!(lights[i].light_type(), crate::light::LightType::Infinite))
            .map(|i| LightId(i as u32))
            .collect();
        let hittable_lights = lights.iter().any(Light::is_hittable);
        let light_sampler = selection.context_free(&lights);
        let nee_sampler = selection.nee(&lights, &light_sampler);
        Self {
            primitives,
            shutter: (!movers.is_empty()).then_some(shutter),
            movers,
            bvh,
            materials,
            lights,
            infinite_lights,
            hittable_lights,
            light_sampler,
            nee_sampler,
            bounds,
            footprint: None,
            footprint_materials: Vec::new(),
        }
    }

    /// Sets the camera footprint that gives hits their screen-space
    /// differentials in [`Scene::bsdf`], for hits on the materials that
    /// `materials` flags (by [`MaterialId`]; those that read a texture).
    pub fn set_footprint(&mut self, footprint: Option<PixelFootprint>, materials: Vec<bool>) {
        self.footprint = footprint;
        self.footprint_materials = materials;
    }
    /// The camera footprint, if set.
    pub fn footprint(&self) -> Option<&PixelFootprint> {
        self.footprint.as_ref()
    }

    /// Bytes held by the top-level BVH's nodes and triangle packs.
    pub fn bvh_memory_bytes(&self) -> usize {
        self.bvh.memory_bytes()
    }

    /// Bounds of all geometry.
    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }
    /// Number of primitives (static and moving).
    pub fn primitive_count(&self) -> usize {
        self.primitives.len() + self.movers.iter().map(|m| m.len()).sum::<usize>()
    }
    /// The shutter interval, when anything in the scene moves.
    pub fn shutter(&self) -> Option<(f32, f32)> {
        self.shutter
    }
    /// A time for a path: uniform over the shutter when something moves
    /// (consuming `u`), else 0 (static scenes are the same at every time).
    pub fn sample_time(&self, u: impl FnOnce() -> f32) -> f32 {
        match self.shutter {
            Some((open, close)) => open + (close - open) * u(),
            None => 0.0,
        }
    }
    /// All static primitives.
    pub fn primitives(&self) -> &[Primitive] {
        &self.primitives
    }
    /// The moving shapes.
    pub fn moving_groups(&self) -> &[MovingGroup] {
        &self.movers
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
    /// Whether any light can be hit by a ray (an area light that is not
    /// invisible, or a light at infinity): with none, emission is found
    /// only by sampling the lights.
    pub fn has_hittable_lights(&self) -> bool {
        self.hittable_lights
    }
    /// The context-free light selection: light subpaths, and BDPT's and
    /// VCM's light sampling at camera vertices.
    pub fn light_sampler(&self) -> &LightSampler {
        &self.light_sampler
    }
    /// The light selection of next-event estimation (path tracer, photon
    /// estimators' camera side, `candela measure`).
    pub fn nee_light_sampler(&self) -> &NeeLightSampler {
        &self.nee_sampler
    }
    /// All materials.
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// Closest hit along `ray` before `t_max`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<SurfaceInteraction> {
        let n = self.primitives.len() as u32;
        // The watertight constants, made once the BVH meets an item it does
        // not test itself (never in a scene of opaque triangles).
        let mut wr = None;
        // The last hit the closure accepted: the closest one if an item the
        // BVH does not pack wins.
        let mut other = None;
        let hit = self.bvh.intersect(ray, t_max, |i, ray, t_max| {
            if i >= n {
                let (t, si) = self.movers[(i - n) as usize].intersect(ray, t_max)?;
                other = Some(Err(si));
                return Some(t);
            }
            let wr = wr.get_or_insert_with(|| WatertightRay::new(ray));
            let hit = self.primitives[i as usize].hit(ray, wr, t_max)?;
            other = Some(Ok((i, hit)));
            Some(hit.t())
        })?;
        match hit {
            BvhHit::Triangle { item, hit } => {
                Some(self.finish(item, DeferredHit::Triangle(hit), ray))
            }
            BvhHit::Other { .. } => match other? {
                Ok((i, hit)) => Some(self.finish(i, hit, ray)),
                Err(si) => Some(si),
            },
        }
    }

    /// The interaction of a static primitive's deferred hit.
    fn finish(&self, i: u32, hit: DeferredHit, ray: &Ray) -> SurfaceInteraction {
        let prim = &self.primitives[i as usize];
        let mut si = prim.shape.finish_hit(hit, ray).si;
        si.material = prim.material;
        si.area_light = prim.area_light;
        si.it.time = ray.time;
        si
    }

    /// True if anything blocks `ray` before `t_max`.
    pub fn intersect_p(&self, ray: &Ray, t_max: f32) -> bool {
        let n = self.primitives.len() as u32;
        let mut wr = None;
        self.bvh.intersect_p(ray, t_max, |i, ray, t_max| {
            if i >= n {
                return self.movers[(i - n) as usize].intersect_p(ray, t_max);
            }
            let wr = wr.get_or_insert_with(|| WatertightRay::new(ray));
            self.primitives[i as usize].blocks(ray, wr, t_max)
        })
    }

    /// True if the segment between two interactions is free.
    pub fn unoccluded(&self, a: &Interaction, b: &Interaction) -> bool {
        let ray = a.spawn_ray_to(b);
        !self.intersect_p(&ray, 1.0 - SHADOW_EPSILON)
    }

    /// The BSDF at a hit (`None` for interface materials), with the
    /// material's textures evaluated for `lambda`. The hit first gets its
    /// screen-space differentials from the camera footprint (pbrt-v4's
    /// `ComputeDifferentials` in `GetBSDF`). Mix materials are
    /// resolved to one of their materials, and a bump map replaces the
    /// hit's shading geometry (so the caller sees the bumped shading
    /// normal), as in pbrt-v4's `SurfaceInteraction::GetBSDF`.
    pub fn bsdf(
        &self,
        si: &mut SurfaceInteraction,
        lambda: &mut SampledWavelengths,
    ) -> Option<Bsdf> {
        if let Some(f) = &self.footprint {
            let reads = |m: MaterialId| self.footprint_materials.get(m.0 as usize) != Some(&false);
            if si.material.is_some_and(reads) {
                f.set_differentials(si);
            }
        }
        let m = self.resolve_material(si)?;
        if let Some(b) = m.bump() {
            b.apply(si);
        }
        m.bsdf(si, lambda)
    }

    /// The BSDF at a hit that [`Self::bsdf`] has already prepared
    /// (differentials set, bump applied), for other wavelengths `lambda`.
    pub fn bsdf_prepared(
        &self,
        si: &SurfaceInteraction,
        lambda: &mut SampledWavelengths,
    ) -> Option<Bsdf> {
        self.resolve_material(si)?.bsdf(si, lambda)
    }

    /// True when the hit's material is an interface (no BSDF: rays cross it).
    pub fn is_interface(&self, si: &SurfaceInteraction) -> bool {
        matches!(self.resolve_material(si), None | Some(Material::Interface))
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
