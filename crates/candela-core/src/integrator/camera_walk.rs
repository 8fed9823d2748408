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
//!   estimation ([`crate::integrator::nee`]). With `mis_direct` (SPPM,
//!   PPM) it is combined with BSDF sampling by the power heuristic [Veach
//!   1997, eq. 9.13], as pbrt-v4's SPPM camera pass does: emission found
//!   after a non-delta scattering counts with the BSDF-sampling weight, and
//!   where the walk ends on such a vertex (the visible point) one BSDF
//!   sample is drawn only to look for emission at its first hit (an area
//!   light, or the infinite lights if it escapes; not traced at all when
//!   no light can be hit). Light sampling alone
//!   cannot find the reflection of a large light in a narrow glossy lobe (a
//!   coated floor under a sky: salt noise that SPPM's photons, which never
//!   estimate direct light, do not fill in). Without it (the photon map,
//!   whose final gather owns the paths beyond), light sampling alone, and
//!   emission counts only after delta scatterings;
//! - then the caller's `shade` says what the vertex is for and how the walk
//!   goes on: SPPM records its visible point at the first diffuse vertex
//!   and stops ([`Flow::Stop`]), or follows glossy and specular lobes
//!   ([`Flow::Continue`]); the photon map reads its maps and follows only
//!   delta lobes ([`Flow::SpecularOnly`]). Vertices with only delta lobes
//!   are crossed along them.
//!
//! With `split_specular`, a walk whose first vertex is a smooth dielectric
//! forks there: the fork follows the reflection alone (β times F) and counts
//! the emission it reaches through delta scatterings, and the walk leaves
//! that emission out when it took the reflection (module doc of
//! [`super::subpath`], "Splitting"): a light's glint on water is found on
//! every sample through it. The fork makes no visible point and estimates
//! no direct light, so each pixel still has one visible point.
//!
//! Depths: vertex d is reached after d − 1 scatterings; light is estimated
//! at vertices d ≤ `max_depth`. With `emission_beyond` the emission of
//! vertex `max_depth` + 1 also counts, so a path of `max_depth` scattering
//! events ends on a light as in the path tracer (the photon map); without
//! it the walk ends at vertex `max_depth`, as pbrt-v4's SPPM does, but
//! for the first hit, whose emission counts at `max_depth` 0 too (as
//! there).

use super::nee::{sample_light, Receiver};
use super::subpath::{walk, Dispersion, Escape, Flow, Start, Vertex, Visitor, Walk};
use crate::bsdf::{Bsdf, SampleFlags, TransportMode};
use crate::interaction::{LightId, SurfaceInteraction};
use crate::light::{LightChooser, LightSampleContext};
use crate::math::{Ray, Vec3};
use crate::sampling::{power_heuristic, PathRng, PdfSolidAngle};
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// How deep a camera walk goes.
#[derive(Clone, Copy, Debug)]
pub struct CameraWalk {
    /// Deepest vertex at which light is estimated.
    pub max_depth: u32,
    /// Also count the emission of vertex `max_depth` + 1.
    pub emission_beyond: bool,
    /// Direct light by MIS of light and BSDF sampling (module doc).
    pub mis_direct: bool,
    /// Fork at a first vertex that is a smooth dielectric (module doc).
    pub split_specular: bool,
}

/// The last vertex the walk left along a non-delta lobe: what the MIS
/// weight of emission found next needs.
#[derive(Clone, Copy)]
struct Scattered {
    ctx: LightSampleContext,
    bsdf: Bsdf,
    wo: Vec3,
}

impl Scattered {
    fn at(v: &Vertex, bsdf: &Bsdf) -> Self {
        Scattered {
            ctx: LightSampleContext {
                p: v.it.p,
                p_error: v.it.p_error,
                n: v.it.n,
                ns: v.ns,
            },
            bsdf: *bsdf,
            wo: v.wo,
        }
    }

    /// The BSDF-sampling weight of light `id` reached along unit `wi`.
    fn weight(&self, scene: &Scene, id: LightId, wi: Vec3) -> f32 {
        let p_bsdf = self
            .bsdf
            .pdf(self.wo, wi, TransportMode::Radiance, SampleFlags::ALL)
            .0;
        bsdf_weight(scene, &self.ctx, id, wi, p_bsdf)
    }
}

/// Power-heuristic weight of BSDF sampling (density `p_bsdf`) for light
/// `id` reached along `wi` from `ctx`, against the NEE that could also
/// have sampled it.
fn bsdf_weight(scene: &Scene, ctx: &LightSampleContext, id: LightId, wi: Vec3, p_bsdf: f32) -> f32 {
    let light = scene.light(id);
    let p_light = scene.nee_light_sampler().choose_pmf(ctx, id) * light.pdf_li(ctx, wi).0;
    power_heuristic(1.0, p_bsdf, 1.0, p_light)
}

/// The visitor of a camera walk.
struct Eye<'a, F> {
    scene: &'a Scene,
    max_depth: u32,
    /// Depth of the last vertex the walk visits.
    walk_max_depth: u32,
    mis: bool,
    l: SampledSpectrum,
    /// What the caller does at a vertex; `None` in a fork, which counts
    /// emission only.
    shade: Option<F>,
    split_specular: bool,
    /// Set while the walk is between a non-delta scattering and the next vertex.
    scattered: Option<Scattered>,
}

/// Surfaces an emission probe may cross (interface materials) before giving up.
const PROBE_CROSSINGS: u32 = 64;

impl<F> Eye<'_, F> {
    /// Emission seen from vertex `v` along one BSDF sample of `bsdf`, at the
    /// sample's first hit, MIS-weighted (module doc).
    fn emission_probe<R: PathRng + ?Sized>(
        &mut self,
        v: &Vertex,
        bsdf: &Bsdf,
        lambda: &SampledWavelengths,
        rng: &mut R,
    ) {
        let (u1, u2) = (rng.u1(), rng.u2());
        // Nothing to find (delta lights only): the sample is drawn all the
        // same, so the sampler's dimensions do not depend on the scene's
        // lights.
        if !self.scene.has_hittable_lights() {
            return;
        }
        let Some(bs) = bsdf.sample_f(v.wo, u1, u2, TransportMode::Radiance, SampleFlags::ALL)
        else {
            return;
        };
        let beta = v.beta * bs.f * (bs.wi.dot(bsdf.ns()).abs() / bs.pdf.0);
        if beta.is_black() {
            return;
        }
        let from = Scattered::at(v, bsdf);
        let wi = bs.wi.normalize();
        // The density only when emission is found (a layered BSDF's is a
        // costly estimate); a delta lobe, which light sampling cannot
        // take, has full weight.
        let mut p_bsdf = None;
        let mut weight = |id| {
            if bs.is_specular() {
                return 1.0;
            }
            let p = *p_bsdf.get_or_insert_with(|| {
                if bs.pdf_is_proportional {
                    bsdf.pdf(v.wo, bs.wi, TransportMode::Radiance, SampleFlags::ALL)
                        .0
                } else {
                    bs.pdf.0
                }
            });
            bsdf_weight(self.scene, &from.ctx, id, wi, p)
        };
        let scene = self.scene;
        let mut ray = v.it.spawn_ray(bs.wi);
        for _ in 0..PROBE_CROSSINGS {
            let Some(si) = scene.intersect(&ray, f32::INFINITY) else {
                for &id in scene.infinite_lights() {
                    let le = scene.light(id).le(&ray, lambda);
                    if !le.is_black() {
                        self.l += beta * le * weight(id);
                    }
                }
                return;
            };
            if let Some(id) = si.area_light {
                let le = scene.light(id).l(si.p(), si.n(), si.it.uv, si.wo, lambda);
                if !le.is_black() {
                    self.l += beta * le * weight(id);
                }
            }
            if !scene.is_interface(&si) {
                return;
            }
            ray = si.spawn_ray(ray.d);
        }
    }
}

impl<R, F> Visitor<R> for Eye<'_, F>
where
    R: PathRng + ?Sized,
    F: FnMut(&Vertex, &SurfaceInteraction, &Bsdf, &mut SampledWavelengths, &mut R) -> Flow,
{
    const FORKS: bool = true;

    fn vertex(
        &mut self,
        v: &Vertex,
        si: &SurfaceInteraction,
        lambda: &mut SampledWavelengths,
        rng: &mut R,
    ) -> Flow {
        let scattered = self.scattered.take();
        if let Some(id) = v.area_light.filter(|_| !v.fork_emission) {
            let weight = match &scattered {
                _ if v.after_delta => Some(1.0),
                Some(s) => Some(s.weight(self.scene, id, -v.wo)),
                None => None,
            };
            if let Some(w) = weight {
                let le = self.scene.light(id).l(v.p(), v.it.n, v.it.uv, v.wo, lambda);
                self.l += v.beta * le * w;
            }
        }
        if self.shade.is_none() {
            return Flow::SpecularOnly;
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
                let ld = if self.mis {
                    ls.bsdf_mis_weighted(self.scene, &r)
                } else {
                    ls.unweighted()
                };
                self.l += v.beta * ld;
            }
        }
        let flow = match &mut self.shade {
            Some(shade) => shade(v, si, bsdf, lambda, rng),
            None => Flow::SpecularOnly,
        };
        if self.mis {
            if flow == Flow::Stop || v.depth >= self.walk_max_depth {
                self.emission_probe(v, bsdf, lambda, rng);
            } else {
                self.scattered = Some(Scattered::at(v, bsdf));
            }
        }
        flow
    }

    fn escaped(&mut self, e: &Escape, lambda: &SampledWavelengths) {
        let scattered = self.scattered.take();
        if (!e.after_delta && scattered.is_none()) || e.fork_emission {
            return;
        }
        let wi = e.ray.d.normalize();
        for &id in self.scene.infinite_lights() {
            let le = self.scene.light(id).le(&e.ray, lambda);
            let w = match &scattered {
                Some(s) if !e.after_delta => s.weight(self.scene, id, wi),
                _ => 1.0,
            };
            self.l += e.beta * le * w;
        }
    }

    /// Forks at the first vertex with `split_specular` (module doc).
    fn fork(&self, v: &Vertex) -> Option<Self> {
        (self.split_specular && v.depth == 1).then(|| Eye {
            scene: self.scene,
            max_depth: self.max_depth,
            walk_max_depth: self.walk_max_depth,
            mis: self.mis,
            l: SampledSpectrum::zero(),
            shade: None,
            split_specular: false,
            scattered: None,
        })
    }

    fn join(&mut self, branch: Self) {
        self.l += branch.l;
    }
}

/// Walks the camera ray `ray` (throughput `beta`) and returns the emission
/// and direct light it gathered; `shade` is called at every vertex with a
/// non-specular lobe after its direct light (module doc), with the hit the
/// vertex was made from.
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
    F: FnMut(&Vertex, &SurfaceInteraction, &Bsdf, &mut SampledWavelengths, &mut R) -> Flow,
{
    // The first hit is always visited, for the emission it shows (or the
    // infinite lights if the ray escapes): pbrt-v4's SPPM camera pass counts
    // it at maxdepth 0 too, then stops.
    let walk_max_depth = (cw.max_depth + u32::from(cw.emission_beyond)).max(1);
    let w = Walk {
        mode: TransportMode::Radiance,
        max_depth: walk_max_depth,
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
        walk_max_depth,
        mis: cw.mis_direct,
        l: SampledSpectrum::zero(),
        shade: Some(shade),
        split_specular: cw.split_specular,
        scattered: None,
    };
    walk(scene, lambda, rng, &w, start, &mut eye);
    eye.l
}
