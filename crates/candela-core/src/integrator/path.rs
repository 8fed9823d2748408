//! Unidirectional path tracing with next-event estimation and multiple
//! importance sampling [Veach 1997, ch. 9; pbrt-v4 §13.4].
//!
//! At every non-specular vertex the estimator combines two strategies for
//! direct light: a light sample (NEE) and the continuation BSDF sample that
//! happens to hit an emitter, weighted by the power heuristic (β = 2,
//! [Veach 1997, eq. 9.13]). Delta lights and specular bounces have a single
//! strategy and weight 1 ([`crate::integrator::nee`]). Paths end by Russian
//! roulette on the throughput ([`Roulette::Throughput`]: corrected by the
//! accumulated η² so refraction does not bias it, as pbrt-v4) or at
//! `maxdepth` scattering events.
//!
//! **Glints.** Where the camera ray's first hit is a smooth dielectric, a
//! fork follows its reflection alone (β times the Fresnel factor F) along
//! delta scatterings and counts the emission it reaches; the path itself
//! leaves exactly that emission out when it took the reflection
//! (`splitspecular`, default true; the fork is walked by the one walker,
//! whose module doc, "Splitting", has the argument: [`crate::integrator::subpath`]).
//! A light seen in water or glass is then found on every sample through it.
//!
//! Stochastic layered BSDFs return samples whose pdf is only proportional to
//! the true density (`pdf_is_proportional`): f/p is still the right throughput
//! weight, but MIS on the emitter the sample hits must use the same density
//! that next-event estimation uses, `Bsdf::pdf`, or the two weights of one
//! direction would not sum to one [pbrt-v4 §14.3.3, `PathIntegrator::Li`].

use super::nee::{sample_light, Receiver};
use super::roulette::Roulette;
use super::subpath::{self, Start};
use super::{
    driver, Integrator, IntegratorKind, IntegratorState, PassOutcome, PassWork, PixelEstimator,
    RenderContext,
};
use crate::bsdf::{Bsdf, BsdfSample, SampleFlags, TransportMode};
use crate::film::{PassBlock, SplatBuffer};
use crate::interaction::SurfaceInteraction;
use crate::light::{LightChooser, LightSampleContext};
use crate::math::{Ray, Vec3};
use crate::sampler::Sampler;
use crate::sampling::{power_heuristic, PdfSolidAngle};
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Parameters of `Integrator "path"`.
#[derive(Clone, Debug)]
pub struct PathSettings {
    /// Maximum number of scattering events (pbrt-v4 default 5).
    pub max_depth: u32,
    /// Roughen near-specular lobes after the first non-specular bounce (biased; off by default).
    pub regularize: bool,
    /// Fork at a first smooth dielectric (`splitspecular`; module doc).
    pub split_specular: bool,
}

impl Default for PathSettings {
    fn default() -> Self {
        Self {
            max_depth: 5,
            regularize: false,
            split_specular: true,
        }
    }
}

/// The path tracer.
pub struct PathIntegrator {
    /// Settings.
    pub settings: PathSettings,
}

impl Integrator for PathIntegrator {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Path
    }
    fn pass_work(&self, ctx: &RenderContext<'_>) -> PassWork {
        PassWork {
            units: ctx.film.pixel_count() as u64,
            unit: "samples",
            light_paths: 0,
        }
    }
    fn render_pass(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        _state: &mut IntegratorState,
        block: &mut PassBlock,
    ) -> PassOutcome {
        driver::render_pixels(self, ctx, pass, block)
    }
}

/// State carried from one path vertex to the next.
struct PathState {
    l: SampledSpectrum,
    beta: SampledSpectrum,
    depth: u32,
    specular_bounce: bool,
    any_non_specular: bool,
    /// Solid-angle density of the last BSDF sample (for MIS on emitter hits).
    prev_pdf: f32,
    /// Where the last BSDF sample left from.
    prev_ctx: LightSampleContext,
    /// Product of η² over refractions, to undo radiance scaling in roulette.
    eta_scale: f32,
    /// The first ray was not BSDF-sampled (a camera ray): emission at the
    /// first hit takes no MIS weight.
    unweighted_start: bool,
    /// The path forked at the vertex it is scattering from (module doc).
    forked_here: bool,
    /// Emission reached now is the fork's: the path took the reflection
    /// where it forked and scattered along delta lobes only since.
    fork_emission: bool,
}

impl PixelEstimator for PathIntegrator {
    fn li(
        &self,
        ctx: &RenderContext<'_>,
        ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        _splats: &mut SplatBuffer,
    ) -> SampledSpectrum {
        let start = PathState::start(LightSampleContext::at_point(ray.o), None);
        self.trace(ctx, ray, start, lambda, sampler)
    }
}

impl PathState {
    /// The state before the first vertex of a path leaving the point of
    /// `from`, along a direction of solid-angle density `pdf` (`None`: a
    /// camera ray).
    fn start(from: LightSampleContext, pdf: Option<f32>) -> Self {
        Self {
            l: SampledSpectrum::zero(),
            beta: SampledSpectrum::one(),
            depth: 0,
            specular_bounce: false,
            any_non_specular: false,
            prev_pdf: pdf.unwrap_or(0.0),
            prev_ctx: from,
            eta_scale: 1.0,
            unweighted_start: pdf.is_none(),
            forked_here: false,
            fork_emission: false,
        }
    }
}

impl PathIntegrator {
    /// The radiance arriving at a sensor point `ray.o` along `ray`, whose
    /// direction was sampled with solid-angle density `pdf` (`candela
    /// measure`): as [`PixelEstimator::li`], but emission found at the
    /// first hit is MIS-weighted (power heuristic) against a light sample
    /// taken at the sensor `sensor` (whose point is `ray.o`).
    pub(crate) fn li_sampled(
        &self,
        ctx: &RenderContext<'_>,
        ray: Ray,
        pdf: f32,
        sensor: LightSampleContext,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
    ) -> SampledSpectrum {
        debug_assert_eq!(sensor.p, ray.o);
        let start = PathState::start(sensor, Some(pdf));
        self.trace(ctx, ray, start, lambda, sampler)
    }

    /// The path loop from state `st`.
    fn trace(
        &self,
        ctx: &RenderContext<'_>,
        mut ray: Ray,
        mut st: PathState,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
    ) -> SampledSpectrum {
        let scene = ctx.scene;
        loop {
            let Some(mut si) = scene.intersect(&ray, f32::INFINITY) else {
                self.add_infinite_light(scene, &ray, lambda, &mut st);
                break;
            };
            self.add_surface_emission(scene, &si, lambda, &mut st);
            let Some(mut bsdf) = scene.bsdf(&mut si, lambda) else {
                // Interface material: continue straight through, not a scattering event.
                st.specular_bounce = true;
                ray = si.spawn_ray(ray.d);
                continue;
            };
            if st.depth == self.settings.max_depth {
                break;
            }
            st.depth += 1;
            if self.settings.regularize && st.any_non_specular {
                bsdf.regularize();
            }
            let wo = -ray.d.normalize();
            if st.depth == 1 && self.forks_at(&bsdf) {
                let at = (&bsdf, wo);
                st.l += self.reflection_fork(ctx, &si, at, st.beta, lambda, sampler);
                st.forked_here = true;
            }
            if bsdf.flags().is_non_specular() {
                let r = Receiver::at_hit(&si, &bsdf, wo);
                if let Some(ls) =
                    sample_light(scene, scene.nee_light_sampler(), &r, lambda, sampler)
                {
                    st.l += st.beta * ls.bsdf_mis_weighted(scene, &r);
                }
            }
            let Some(bs) = bsdf.sample_f(
                wo,
                sampler.get_1d(),
                sampler.get_2d(),
                TransportMode::Radiance,
                SampleFlags::ALL,
            ) else {
                break;
            };
            self.scatter(&si, &bsdf, wo, &bs, &mut st);
            ray = si.spawn_ray(bs.wi);
            if !self.russian_roulette(&mut st, sampler) {
                break;
            }
        }
        st.l
    }

    /// Radiance from infinite lights seen along an escaping ray, MIS-weighted.
    fn add_infinite_light(
        &self,
        scene: &Scene,
        ray: &Ray,
        lambda: &SampledWavelengths,
        st: &mut PathState,
    ) {
        if st.fork_emission {
            return;
        }
        for &id in scene.infinite_lights() {
            let light = scene.light(id);
            let le = light.le(ray, lambda);
            if le.is_black() {
                continue;
            }
            if (st.depth == 0 && st.unweighted_start) || st.specular_bounce {
                st.l += st.beta * le;
            } else {
                let pmf = scene.nee_light_sampler().choose_pmf(&st.prev_ctx, id);
                let p_light = pmf * light.pdf_li(&st.prev_ctx, ray.d.normalize()).0;
                st.l += st.beta * le * power_heuristic(1.0, st.prev_pdf, 1.0, p_light);
            }
        }
    }

    /// Radiance emitted by an area light the path hits, MIS-weighted against NEE.
    fn add_surface_emission(
        &self,
        scene: &Scene,
        si: &SurfaceInteraction,
        lambda: &SampledWavelengths,
        st: &mut PathState,
    ) {
        let Some(id) = si.area_light.filter(|_| !st.fork_emission) else {
            return;
        };
        let light = scene.light(id);
        let le = light.l(si.p(), si.n(), si.it.uv, si.wo, lambda);
        if le.is_black() {
            return;
        }
        if (st.depth == 0 && st.unweighted_start) || st.specular_bounce {
            st.l += st.beta * le;
        } else {
            let pmf = scene.nee_light_sampler().choose_pmf(&st.prev_ctx, id);
            let p_light = pmf * light.pdf_li(&st.prev_ctx, -si.wo).0;
            st.l += st.beta * le * power_heuristic(1.0, st.prev_pdf, 1.0, p_light);
        }
    }

    /// Updates throughput and MIS state after a BSDF sample.
    fn scatter(
        &self,
        si: &SurfaceInteraction,
        bsdf: &Bsdf,
        wo: Vec3,
        bs: &BsdfSample,
        st: &mut PathState,
    ) {
        st.beta *= bs.f * (bs.wi.dot(si.shading.n).abs() / bs.pdf.0);
        // A specular bounce takes no MIS, so its density is never needed.
        st.prev_pdf = if bs.pdf_is_proportional && !bs.is_specular() {
            bsdf.pdf(wo, bs.wi, TransportMode::Radiance, SampleFlags::ALL)
                .0
        } else {
            bs.pdf.0
        };
        let forked = std::mem::take(&mut st.forked_here);
        st.fork_emission = bs.is_specular() && (st.fork_emission || (forked && bs.is_reflection()));
        st.specular_bounce = bs.is_specular();
        st.any_non_specular |= !bs.is_specular();
        if bs.is_transmission() {
            st.eta_scale *= bs.eta * bs.eta;
        }
        st.prev_ctx = LightSampleContext::from_surface(si);
    }

    /// Whether the path forks at a first vertex with this BSDF (module doc).
    fn forks_at(&self, bsdf: &Bsdf) -> bool {
        self.settings.split_specular && subpath::forks_at(bsdf)
    }

    /// The fork at `si` with throughput `beta` (module doc): the reflection
    /// alone, then the walker's [`subpath::delta_emission`].
    fn reflection_fork(
        &self,
        ctx: &RenderContext<'_>,
        si: &SurfaceInteraction,
        (bsdf, wo): (&Bsdf, Vec3),
        beta: SampledSpectrum,
        lambda: &SampledWavelengths,
        sampler: &mut Sampler,
    ) -> SampledSpectrum {
        let (u, u2) = (sampler.get_1d(), sampler.get_2d());
        let mode = TransportMode::Radiance;
        let Some(bs) = bsdf.sample_f(wo, u, u2, mode, SampleFlags::REFLECTION) else {
            return SampledSpectrum::zero();
        };
        let start = Start {
            ray: si.spawn_ray(bs.wi),
            beta: beta * bs.f * (bs.wi.dot(si.shading.n).abs() / bs.pdf.0),
            depth: 1,
            from: None,
            pdf_dir: PdfSolidAngle(0.0),
        };
        // The first hit after `max_depth` scatterings still counts, as in
        // the path loop.
        let max_depth = self.settings.max_depth + 1;
        subpath::delta_emission(ctx.scene, lambda, sampler, max_depth, start)
    }

    /// Russian roulette ([`Roulette::Throughput`]); returns false to stop.
    fn russian_roulette(&self, st: &mut PathState, sampler: &mut Sampler) -> bool {
        if st.beta.is_black() {
            return false;
        }
        let before = st.beta;
        Roulette::Throughput.play(st.depth, &before, &mut st.beta, st.eta_scale, sampler)
    }
}
