//! Bidirectional path tracing (`Integrator "bdpt"`) [Veach & Guibas 1995;
//! Veach 1997, ch. 10; pbrt-v3/v4 `BDPTIntegrator`].
//!
//! For each pixel sample the estimator
//! 1. traces a camera subpath from the primary ray (radiance mode, β starts at 1: a primary
//!    camera ray has weight 1, seed §2.4),
//! 2. traces a light subpath from a light chosen in proportion to its power
//!    (importance mode, β₀ = Le|cos θ|/(p_light·p_pos·p_dir), the path's
//!    share of Φ, seed §2.1),
//! 3. evaluates every strategy (s, t) with s + t − 2 ≤ `maxdepth`
//!    scattering events: s = 0 (the camera path hits an emitter), s = 1
//!    (next-event estimation), t = 1 (light tracing, splatted) and the
//!    general connections, each weighted by MIS over every strategy that
//!    could have made the same path ([`mis`]).
//!
//! The pieces are free functions: [`walk::generate_camera_subpath`],
//! [`walk::generate_light_subpath`], [`connect::connect`] and
//! [`mis::mis_weight`]. Splats (t = 1) go through the driver's
//! deterministic splat lanes and are averaged over the passes.

mod connect;
mod density;
mod mis;
#[cfg(test)]
mod tests;
mod visualize;
mod walk;

pub use mis::MisHeuristic;
pub use visualize::Visualize;

use super::{
    driver, Integrator, IntegratorKind, IntegratorState, PassOutcome, PassWork, PixelEstimator,
    RenderContext,
};
use crate::film::{PassBlock, SplatBuffer};
use crate::integrator::subpath::Vertex;
use crate::math::Ray;
use crate::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use connect::{connect, ConnectCtx, Contribution};
use std::cell::RefCell;
use walk::{generate_camera_subpath, generate_light_subpath, WalkSettings};

/// Storage every sample of a thread reuses: both subpaths (no allocation
/// per sample once the buffers have grown).
#[derive(Default)]
struct Scratch {
    cam: Vec<Vertex>,
    light: Vec<Vertex>,
}

thread_local! {
    static SCRATCH: RefCell<Scratch> = RefCell::default();
}

/// Parameters of `Integrator "bdpt"`.
#[derive(Clone, Debug)]
pub struct BdptSettings {
    /// Maximum number of scattering events of a path (pbrt-v4 default 5).
    pub max_depth: u32,
    /// Roughen near-specular lobes after the first non-specular bounce (biased).
    pub regularize: bool,
    /// MIS heuristic (power by default).
    pub heuristic: MisHeuristic,
    /// Write one image per strategy (pbrt-v4 `visualizestrategies` / `visualizeweights`).
    pub visualize: Option<Visualize>,
}

impl Default for BdptSettings {
    fn default() -> Self {
        Self {
            max_depth: 5,
            regularize: false,
            heuristic: MisHeuristic::Power,
            visualize: None,
        }
    }
}

/// The bidirectional path tracer.
pub struct BdptIntegrator {
    /// Settings.
    pub settings: BdptSettings,
}

impl Integrator for BdptIntegrator {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Bdpt
    }
    fn pass_work(&self, ctx: &RenderContext<'_>) -> PassWork {
        PassWork {
            units: ctx.film.pixel_count() as u64,
            unit: "samples",
            light_paths: ctx.film.pixel_count() as u64,
        }
    }
    fn render_pass(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        _state: &mut IntegratorState,
        block: &mut PassBlock,
    ) -> PassOutcome {
        match &self.settings.visualize {
            Some(v) => visualize::render_pass(self, v, ctx, pass, block),
            None => driver::render_pixels(self, ctx, pass, block),
        }
    }
}

impl PixelEstimator for BdptIntegrator {
    fn li(
        &self,
        ctx: &RenderContext<'_>,
        ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        splats: &mut SplatBuffer,
    ) -> SampledSpectrum {
        let mut l = SampledSpectrum::zero();
        self.sample_strategies(ctx, ray, lambda, sampler, |_, _, c, lambda| {
            match c.p_raster {
                Some(p) => splats.add(p, c.weighted, lambda),
                None => l += c.weighted,
            }
        });
        l
    }

    fn splats(&self) -> bool {
        true
    }
}

impl BdptIntegrator {
    /// Traces both subpaths for one camera ray and calls `visit(s, t, c, λ)`
    /// for every strategy that contributes.
    fn sample_strategies(
        &self,
        ctx: &RenderContext<'_>,
        ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        mut visit: impl FnMut(usize, usize, &Contribution, &SampledWavelengths),
    ) {
        SCRATCH.with(|cell| {
            let mut scratch = cell.borrow_mut();
            self.sample_strategies_in(ctx, ray, lambda, sampler, &mut scratch, &mut visit);
        });
    }

    /// [`Self::sample_strategies`] with the thread's reused buffers.
    fn sample_strategies_in(
        &self,
        ctx: &RenderContext<'_>,
        ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        scratch: &mut Scratch,
        visit: &mut impl FnMut(usize, usize, &Contribution, &SampledWavelengths),
    ) {
        let max_depth = self.settings.max_depth as usize;
        let Scratch { cam, light } = scratch;
        let walk = |max_vertices| WalkSettings {
            max_vertices,
            regularize: self.settings.regularize,
        };
        generate_camera_subpath(
            ctx.scene,
            ctx.camera,
            ray,
            lambda,
            sampler,
            walk(max_depth + 1),
            cam,
        );
        let time = ray.time;
        generate_light_subpath(ctx.scene, time, lambda, sampler, walk(max_depth), light);
        let lambda = *lambda;
        let cx = ConnectCtx {
            scene: ctx.scene,
            camera: ctx.camera,
            lambda: &lambda,
            heuristic: self.settings.heuristic,
        };
        // s = 1 resamples the light (`connect_light`) and does not use the
        // light subpath, so it runs even when that subpath is empty because
        // its emission sample found no light (a black texel, an alpha-masked
        // point): otherwise the s = 1 share of the MIS weights would be lost
        // with the probability of that failure. (pbrt-v4 loops s to the
        // subpath's length and loses it: its BDPT is dark on such emitters.)
        let s_max = light.len().max(1);
        for t in 1..=cam.len() {
            for s in 0..=s_max {
                if s + t < 2 || s + t - 2 > max_depth || (s == 0 && t == 1) {
                    continue;
                }
                if s > light.len() && t == 1 {
                    continue; // s = 1, t = 1 joins the subpath's own vertex.
                }
                if let Some(c) = connect(&cx, light, cam, s, t, sampler) {
                    visit(s, t, &c, &lambda);
                }
            }
        }
    }
}
