//! The camera walk of the photon estimators: the eye path of SPPM's and
//! PPM's visible points and of the photon map's specular camera path
//! [Hachisuka, Ogaki & Jensen 2008, §4; Jensen 2001, §9.1; pbrt-v4
//! `SPPMIntegrator` camera pass].
//!
//! The walk is the shared subpath walker ([`crate::integrator::subpath`])
//! in radiance mode from a camera ray, with a visitor that does what these
//! estimators' camera sides have in common:
//! - emission seen directly, or through a chain ending in a delta
//!   scattering, is counted (an escaped ray adds every infinite light), as
//!   nothing else finds the light of E S* L paths: light sampling at the
//!   last non-specular vertex is what found the rest;
//! - at each vertex with a non-specular lobe, direct light by next-event
//!   estimation, light sampling alone ([`crate::integrator::nee`]: no MIS,
//!   since the caller's photons never estimate direct light there and the
//!   walk never counts emission after a non-delta scattering);
//! - then the caller's `shade` says what the vertex is for and how the walk
//!   goes on: SPPM records its visible point at the first diffuse vertex
//!   and stops ([`Flow::Stop`]), or follows glossy and specular lobes
//!   ([`Flow::Continue`]); the photon map reads its maps and follows only
//!   delta lobes ([`Flow::SpecularOnly`]). Vertices with only delta lobes
//!   are crossed along them.
//!
//! Depths: vertex d is reached after d − 1 scatterings; light is estimated
//! at vertices d ≤ `max_depth`. With `emission_beyond` the emission of
//! vertex `max_depth` + 1 also counts, so a path of `max_depth` scattering
//! events ends on a light as in the path tracer (the photon map); without
//! it the walk ends at vertex `max_depth`, as pbrt-v4's SPPM does.

use super::nee::{sample_light, Receiver};
use super::subpath::{walk, Dispersion, Escape, Flow, Start, Vertex, Visitor, Walk};
use crate::bsdf::{Bsdf, TransportMode};
use crate::math::Ray;
use crate::sampling::{PathRng, PdfSolidAngle};
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// How deep a camera walk goes.
#[derive(Clone, Copy, Debug)]
pub struct CameraWalk {
    /// Deepest vertex at which light is estimated.
    pub max_depth: u32,
    /// Also count the emission of vertex `max_depth` + 1.
    pub emission_beyond: bool,
}

/// The visitor of a camera walk.
struct Eye<'a, F> {
    scene: &'a Scene,
    max_depth: u32,
    l: SampledSpectrum,
    shade: F,
}

impl<R, F> Visitor<R> for Eye<'_, F>
where
    R: PathRng + ?Sized,
    F: FnMut(&Vertex, &Bsdf, &mut SampledWavelengths, &mut R) -> Flow,
{
    fn vertex(&mut self, v: &Vertex, lambda: &mut SampledWavelengths, rng: &mut R) -> Flow {
        if v.after_delta {
            if let Some(id) = v.area_light {
                let le = self.scene.light(id).l(v.p(), v.it.n, v.it.uv, v.wo, lambda);
                self.l += v.beta * le;
            }
        }
        if v.depth > self.max_depth {
            return Flow::Stop;
        }
        let Some(bsdf) = &v.bsdf else {
            return Flow::Stop;
        };
        if !bsdf.flags().is_non_specular() {
            return Flow::Continue;
        }
        if let Some(r) = Receiver::at_vertex(v) {
            if let Some(ls) =
                sample_light(self.scene, self.scene.nee_light_sampler(), &r, lambda, rng)
            {
                self.l += v.beta * ls.unweighted();
            }
        }
        (self.shade)(v, bsdf, lambda, rng)
    }

    fn escaped(&mut self, e: &Escape, lambda: &SampledWavelengths) {
        if e.after_delta {
            for &id in self.scene.infinite_lights() {
                self.l += e.beta * self.scene.light(id).le(&e.ray, lambda);
            }
        }
    }
}

/// Walks the camera ray `ray` (throughput `beta`) and returns the emission
/// and direct light it gathered; `shade` is called at every vertex with a
/// non-specular lobe after its direct light (module doc).
pub fn camera_walk<R, F>(
    scene: &Scene,
    ray: Ray,
    beta: SampledSpectrum,
    lambda: &mut SampledWavelengths,
    rng: &mut R,
    cw: &CameraWalk,
    shade: F,
) -> SampledSpectrum
where
    R: PathRng + ?Sized,
    F: FnMut(&Vertex, &Bsdf, &mut SampledWavelengths, &mut R) -> Flow,
{
    let w = Walk {
        mode: TransportMode::Radiance,
        max_depth: cw.max_depth + u32::from(cw.emission_beyond),
        roulette: None,
        regularize: false,
        dispersion: Dispersion::Keep,
    };
    let start = Start {
        ray,
        beta,
        depth: 0,
        from: None,
        pdf_dir: PdfSolidAngle(0.0),
    };
    let mut eye = Eye {
        scene,
        max_depth: cw.max_depth,
        l: SampledSpectrum::zero(),
        shade,
    };
    walk(scene, lambda, rng, &w, start, &mut eye);
    eye.l
}
