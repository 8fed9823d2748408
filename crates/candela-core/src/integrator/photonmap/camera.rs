//! The camera side of photon mapping: the specular camera path, direct
//! light, the caustic lookup and final gathering (partition in the parent
//! module's doc).

use super::maps::{Lookup, PassMaps, Query};
use super::PhotonMapSettings;
use crate::bsdf::{Bsdf, BsdfSample, SampleFlags, TransportMode};
use crate::integrator::direct::light_sampled_direct;
use crate::interaction::SurfaceInteraction;
use crate::math::{Ray, Vec3};
use crate::sampler::Sampler;
use crate::scene::Scene;
use crate::spatial::Neighbor;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Everything a camera sample of one pass reads.
pub struct CameraWalk<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The pass's photon maps.
    pub maps: &'a PassMaps,
    /// Integrator settings.
    pub settings: &'a PhotonMapSettings,
    /// Global-map lookups (radius resolved).
    pub global_lookup: Lookup,
    /// Caustic-map lookups (radius resolved).
    pub caustic_lookup: Lookup,
}

/// A non-specular vertex of the camera path (or of a gather ray).
struct Vertex<'a> {
    si: &'a SurfaceInteraction,
    bsdf: &'a Bsdf,
    wo: Vec3,
    /// Scattering events up to and including this vertex.
    depth: u32,
}

impl CameraWalk<'_> {
    /// Radiance arriving along the camera ray `ray` at the pass wavelengths.
    pub fn li(
        &self,
        mut ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        scratch: &mut Vec<Neighbor>,
    ) -> SampledSpectrum {
        let scene = self.scene;
        let mut l = SampledSpectrum::zero();
        let mut beta = SampledSpectrum::one();
        let mut depth = 0;
        loop {
            let Some(mut si) = scene.intersect(&ray, f32::INFINITY) else {
                // Only delta lobes led here: no other estimator sees this light.
                for &id in scene.infinite_lights() {
                    l += beta * scene.light(id).le(&ray, lambda);
                }
                break;
            };
            if let Some(id) = si.area_light {
                l += beta * scene.light(id).l(si.p(), si.n(), si.it.uv, si.wo, lambda);
            }
            let Some(bsdf) = scene.bsdf(&mut si, lambda) else {
                ray = si.spawn_ray(ray.d);
                continue;
            };
            if depth == self.settings.max_depth {
                break;
            }
            depth += 1;
            let wo = si.wo;
            if bsdf.flags().is_non_specular() {
                let v = Vertex {
                    si: &si,
                    bsdf: &bsdf,
                    wo,
                    depth,
                };
                l += beta * self.shade(&v, lambda, sampler, scratch);
            }
            let Some(bs) = sample_delta(&bsdf, wo, sampler) else {
                break;
            };
            beta *= throughput(&bsdf, &bs);
            ray = si.spawn_ray(bs.wi);
        }
        l
    }

    /// Direct + caustic + indirect light reflected at a non-specular camera vertex.
    fn shade(
        &self,
        v: &Vertex<'_>,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        scratch: &mut Vec<Neighbor>,
    ) -> SampledSpectrum {
        let direct = light_sampled_direct(self.scene, v.si, v.bsdf, v.wo, lambda, sampler);
        let caustic = self
            .maps
            .caustic
            .radiance(&self.query(v), &self.caustic_lookup, scratch);
        let indirect = if self.settings.final_gather {
            self.final_gather(v, lambda, sampler, scratch)
        } else {
            self.maps
                .global
                .radiance(&self.query(v), &self.global_lookup, scratch)
        };
        direct + caustic + indirect
    }

    /// A lookup at `v` admitting photons that keep the path within `maxdepth`.
    fn query<'v>(&self, v: &Vertex<'v>) -> Query<'v> {
        Query {
            si: v.si,
            bsdf: v.bsdf,
            wo: v.wo,
            // j + d − 1 ≤ maxdepth for a photon at its d-th hit read at vertex j.
            max_photon_depth: self.settings.max_depth + 1 - v.depth,
        }
    }

    /// Indirect light at `v` by `gatherrays` BSDF samples of its non-specular
    /// lobes, each reading the global map where it lands [Jensen 2001, ch. 9,
    /// final gathering].
    fn final_gather(
        &self,
        v: &Vertex<'_>,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        scratch: &mut Vec<Neighbor>,
    ) -> SampledSpectrum {
        let n = self.settings.gather_rays;
        let mut sum = SampledSpectrum::zero();
        for _ in 0..n {
            let (uc, u) = (sampler.get_1d(), sampler.get_2d());
            let Some(bs) = v
                .bsdf
                .sample_f(v.wo, uc, u, TransportMode::Radiance, SampleFlags::ALL)
            else {
                continue;
            };
            // The delta lobes are the camera path's own continuation.
            if bs.is_specular() {
                continue;
            }
            let beta = throughput(v.bsdf, &bs);
            let ray = v.si.spawn_ray(bs.wi);
            sum += beta * self.gather_ray(ray, v.depth, lambda, sampler, scratch);
        }
        if n == 0 {
            sum
        } else {
            sum / n as f32
        }
    }

    /// Radiance reflected towards a gather ray's origin, emission excluded:
    /// the global map at the first non-specular vertex, through delta lobes.
    fn gather_ray(
        &self,
        mut ray: Ray,
        mut depth: u32,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        scratch: &mut Vec<Neighbor>,
    ) -> SampledSpectrum {
        let scene = self.scene;
        let mut l = SampledSpectrum::zero();
        let mut beta = SampledSpectrum::one();
        while let Some(mut si) = scene.intersect(&ray, f32::INFINITY) {
            let Some(bsdf) = scene.bsdf(&mut si, lambda) else {
                ray = si.spawn_ray(ray.d);
                continue;
            };
            if depth == self.settings.max_depth {
                break;
            }
            depth += 1;
            let wo = si.wo;
            if bsdf.flags().is_non_specular() {
                let v = Vertex {
                    si: &si,
                    bsdf: &bsdf,
                    wo,
                    depth,
                };
                l += beta
                    * self
                        .maps
                        .global
                        .radiance(&self.query(&v), &self.global_lookup, scratch);
            }
            let Some(bs) = sample_delta(&bsdf, wo, sampler) else {
                break;
            };
            beta *= throughput(&bsdf, &bs);
            ray = si.spawn_ray(bs.wi);
        }
        l
    }
}

/// Samples `bsdf` and keeps the sample only if it chose a delta lobe (the
/// estimate of the delta part alone: non-delta samples count zero).
fn sample_delta(bsdf: &Bsdf, wo: Vec3, sampler: &mut Sampler) -> Option<BsdfSample> {
    if !bsdf.flags().is_specular() {
        return None;
    }
    let bs = bsdf.sample_f(
        wo,
        sampler.get_1d(),
        sampler.get_2d(),
        TransportMode::Radiance,
        SampleFlags::ALL,
    )?;
    bs.is_specular().then_some(bs)
}

/// f·|cos θ|/p of a BSDF sample.
fn throughput(bsdf: &Bsdf, bs: &BsdfSample) -> SampledSpectrum {
    bs.f * (bs.wi.dot(bsdf.ns()).abs() / bs.pdf.0)
}
