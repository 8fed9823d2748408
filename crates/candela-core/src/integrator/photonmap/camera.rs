//! The camera side of photon mapping: the specular camera path with its
//! direct light (the shared camera walk, [`crate::integrator::camera_walk`]),
//! the caustic lookup and final gathering (partition in the parent module's
//! doc).

use super::maps::{Lookup, PassMaps, Query};
use super::PhotonMapSettings;
use crate::bsdf::{Bsdf, SampleFlags, TransportMode};
use crate::integrator::camera_walk::{camera_walk, CameraWalk};
use crate::integrator::subpath::{walk, Dispersion, Flow, Start, Vertex, Visitor, Walk};
use crate::interaction::SurfaceInteraction;
use crate::math::Ray;
use crate::sampler::Sampler;
use crate::sampling::{PathRng, PdfSolidAngle};
use crate::scene::Scene;
use crate::spatial::Neighbor;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Everything a camera sample of one pass reads.
pub struct CameraSide<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The photon maps of the pixel's wavelength group.
    pub maps: &'a PassMaps,
    /// Integrator settings.
    pub settings: &'a PhotonMapSettings,
    /// Global-map lookups (radius resolved).
    pub global_lookup: Lookup,
    /// Caustic-map lookups (radius resolved).
    pub caustic_lookup: Lookup,
}

impl CameraSide<'_> {
    /// Radiance arriving along the camera ray `ray` at the pass wavelengths.
    pub fn li(
        &self,
        ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        scratch: &mut Vec<Neighbor>,
    ) -> SampledSpectrum {
        let cw = CameraWalk {
            max_depth: self.settings.max_depth,
            emission_beyond: true,
            mis_direct: false,
            split_specular: self.settings.split_specular,
        };
        let mut l = SampledSpectrum::zero();
        let one = SampledSpectrum::one();
        let direct = camera_walk(
            self.scene,
            ray,
            one,
            lambda,
            sampler,
            &cw,
            |v, _, bsdf, lam, s| {
                l += v.beta * self.shade(v, bsdf, lam, s, scratch);
                Flow::SpecularOnly
            },
        );
        direct + l
    }

    /// Caustic + indirect light reflected at a non-specular camera vertex.
    fn shade(
        &self,
        v: &Vertex,
        bsdf: &Bsdf,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        scratch: &mut Vec<Neighbor>,
    ) -> SampledSpectrum {
        let q = self.query(v, bsdf);
        let caustic = self
            .maps
            .caustic
            .radiance(&q, &self.caustic_lookup, scratch);
        let indirect = if self.settings.final_gather {
            self.final_gather(v, bsdf, lambda, sampler, scratch)
        } else {
            self.maps.global.radiance(&q, &self.global_lookup, scratch)
        };
        caustic + indirect
    }

    /// A lookup at `v` admitting photons that keep the path within `maxdepth`.
    fn query<'v>(&self, v: &'v Vertex, bsdf: &'v Bsdf) -> Query<'v> {
        Query {
            p: v.p(),
            n: v.it.n,
            wo: v.wo,
            bsdf,
            // j + d − 1 ≤ maxdepth for a photon at its d-th hit read at vertex j.
            max_photon_depth: self.settings.max_depth + 1 - v.depth,
        }
    }

    /// Indirect light at `v` by `gatherrays` BSDF samples of its non-specular
    /// lobes, each reading the global map where it lands [Jensen 2001, ch. 9,
    /// final gathering].
    fn final_gather(
        &self,
        v: &Vertex,
        bsdf: &Bsdf,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        scratch: &mut Vec<Neighbor>,
    ) -> SampledSpectrum {
        let n = self.settings.gather_rays;
        let w = Walk {
            mode: TransportMode::Radiance,
            max_depth: self.settings.max_depth,
            roulette: None,
            regularize: false,
            dispersion: Dispersion::Keep,
        };
        let mut gather = Gather {
            side: self,
            l: SampledSpectrum::zero(),
            scratch,
        };
        for _ in 0..n {
            let (uc, u) = (sampler.u1(), sampler.u2());
            let Some(bs) = bsdf.sample_f(v.wo, uc, u, TransportMode::Radiance, SampleFlags::ALL)
            else {
                continue;
            };
            // The delta lobes are the camera path's own continuation.
            if bs.is_specular() {
                continue;
            }
            let start = Start {
                ray: v.it.spawn_ray(bs.wi),
                beta: bs.f * (bs.wi.dot(bsdf.ns()).abs() / bs.pdf.0),
                depth: v.depth,
                from: None,
                pdf_dir: PdfSolidAngle(0.0),
            };
            walk(self.scene, lambda, sampler, &w, start, &mut gather);
        }
        if n == 0 {
            gather.l
        } else {
            gather.l / n as f32
        }
    }
}

/// The visitor of gather rays: the global map at every vertex with a
/// non-specular lobe (emission excluded), through delta lobes.
struct Gather<'a, 'b> {
    side: &'a CameraSide<'b>,
    l: SampledSpectrum,
    scratch: &'a mut Vec<Neighbor>,
}

impl Visitor<Sampler> for Gather<'_, '_> {
    fn vertex(
        &mut self,
        v: &Vertex,
        _: &SurfaceInteraction,
        _: &mut SampledWavelengths,
        _: &mut Sampler,
    ) -> Flow {
        if let Some(bsdf) = &v.bsdf {
            if bsdf.flags().is_non_specular() {
                let q = self.side.query(v, bsdf);
                let side = self.side;
                let e = side
                    .maps
                    .global
                    .radiance(&q, &side.global_lookup, self.scratch);
                self.l += v.beta * e;
            }
        }
        Flow::SpecularOnly
    }
}
