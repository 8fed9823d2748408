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
//!
//! **Light tracing's weights** (`"string ltweights"`): `variance` (the
//! default) multiplies light tracing's term in every weight by the factor c
//! of the path's image block and length that passes 0 and 1 measure
//! ([`crate::integrator::lt_weights`], as `vcm` does); `density` is pbrt-v4's
//! weighting by the densities alone (the same bits as before the factors
//! existed). Both are unbiased; `visualizestrategies` and `visualizeweights`
//! use `density`. The two pilot passes go into the image with `density`
//! weights, and each of their camera-side contributions is weighed a second
//! time, with c = 0, for what they record: two MIS weights per strategy in
//! two passes, and pilot passes as good as `density`'s instead of the
//! noisier c = 0 images `vcm`'s pilot adds (light tracing kept only where it
//! is the only technique). Measured at half resolution (relMSE against long
//! references): the Cornell box at 64 spp 0.001563, 0.001554, 0.001543
//! against 0.001656, 0.001664, 0.001656 (seeds 1–3, −6 to −7 %), at 32 spp
//! −5 to −7 % (with the pilot's own images at c = 0 it was −0.5 to −3 %
//! there); its direct light alone (`maxdepth 1`, 32 spp, seeds 1–2, against
//! 2048 spp of `path`) 0.000803, 0.000817 against 0.001348, 0.001364
//! (−40 %); caustic-glass, whose caustic light tracing carries (c near 1
//! there), +0.4 % at 16 spp and +0.5 % at 64 (seeds 1–2; +2 % and +0.8 %
//! with c = 0 pilot images).

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
use crate::integrator::lt_weights::{
    ByLength, LtWeights, Pilot, PilotSamples, DENSITY, LENGTHS, PILOT_PASSES,
};
use crate::integrator::subpath::Vertex;
use crate::math::{Ray, UVec2, Vec2};
use crate::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use connect::{connect, ConnectCtx, Contribution};
use std::cell::RefCell;
use std::sync::Mutex;
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
    /// Light tracing's weights by the pilot's variance factors (`"string
    /// ltweights" "variance"`) or by density alone (`"density"`).
    pub variance_lt: bool,
}

impl Default for BdptSettings {
    fn default() -> Self {
        Self {
            max_depth: 5,
            regularize: false,
            heuristic: MisHeuristic::Power,
            visualize: None,
            variance_lt: true,
        }
    }
}

/// The bidirectional path tracer.
pub struct BdptIntegrator {
    /// Settings.
    pub settings: BdptSettings,
    /// Light tracing's factors and their pilot ([`crate::integrator::lt_weights`]).
    pilot: Pilot,
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
        if let Some(v) = &self.settings.visualize {
            return visualize::render_pass(self, v, ctx, pass, block);
        }
        // The first passes are the pilot's: weights by density (c = 1) in
        // the image, c = 0 in what they record (module doc).
        let pilot = self.variance_pilot(ctx) && pass < PILOT_PASSES;
        let lt = if pilot {
            &*DENSITY
        } else {
            match self.lt_weights(ctx) {
                Some(lt) => lt,
                None => return PassOutcome::Cancelled,
            }
        };
        let record = pilot && self.pilot.get().is_none();
        let est = PassEstimator::new(ctx, self, lt, record);
        let out = driver::render_pixels(&est, ctx, pass, block);
        if let (PassOutcome::Done, Some(samples)) = (&out, est.samples()) {
            self.pilot.keep(ctx.film.resolution(), pass, samples);
        }
        out
    }
}

/// Light tracing's factors a sample is weighted with, and whether it also
/// records its factor-0 weighting for the pilot.
#[derive(Clone, Copy)]
struct Weights<'a> {
    lt: &'a LtWeights,
    pilot: bool,
}

/// One pass's estimator: the weights it uses, and the camera side's
/// estimates it keeps per pixel for the pilot.
struct PassEstimator<'a> {
    bdpt: &'a BdptIntegrator,
    lt: &'a LtWeights,
    record: Option<Recorder>,
}

/// Every pixel's camera-side estimate by path length, in the film's row
/// order (0 where a pixel made no camera ray), as both pilot passes must
/// list them; written in place, so a pass holds one such list.
struct Recorder {
    lo: UVec2,
    width: usize,
    samples: Mutex<PilotSamples>,
}

impl Recorder {
    fn new(ctx: &RenderContext<'_>) -> Self {
        let (lo, hi) = ctx.film.pixel_bounds();
        let samples = (lo.y..hi.y)
            .flat_map(|y| (lo.x..hi.x).map(move |x| (UVec2::new(x, y), [0.0; LENGTHS + 1])))
            .collect();
        Self {
            lo,
            width: (hi.x - lo.x) as usize,
            samples: Mutex::new(samples),
        }
    }

    fn set(&self, pixel: UVec2, x: ByLength) {
        let i = (pixel.y - self.lo.y) as usize * self.width + (pixel.x - self.lo.x) as usize;
        if let Ok(mut s) = self.samples.lock() {
            if let Some(slot) = s.get_mut(i) {
                slot.1 = x;
            }
        }
    }
}

impl<'a> PassEstimator<'a> {
    fn new(
        ctx: &RenderContext<'_>,
        bdpt: &'a BdptIntegrator,
        lt: &'a LtWeights,
        record: bool,
    ) -> Self {
        Self {
            bdpt,
            lt,
            record: record.then(|| Recorder::new(ctx)),
        }
    }

    /// The recorded estimates ([`Recorder`]), if recording.
    fn samples(self) -> Option<PilotSamples> {
        self.record?.samples.into_inner().ok()
    }
}

impl PixelEstimator for PassEstimator<'_> {
    fn li(
        &self,
        ctx: &RenderContext<'_>,
        ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        splats: &mut SplatBuffer,
    ) -> SampledSpectrum {
        self.bdpt
            .li(ctx, ray, lambda, sampler, splats, self.lt, false)
            .0
    }

    fn li_pixel(
        &self,
        ctx: &RenderContext<'_>,
        pixel: UVec2,
        ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        splats: &mut SplatBuffer,
    ) -> SampledSpectrum {
        let record = self.record.is_some();
        let (l, x) = self
            .bdpt
            .li(ctx, ray, lambda, sampler, splats, self.lt, record);
        if let Some(r) = &self.record {
            r.set(pixel, x);
        }
        l
    }

    fn splats(&self) -> bool {
        true
    }
}

impl BdptIntegrator {
    /// The integrator with `settings`.
    pub fn new(settings: BdptSettings) -> Self {
        Self {
            settings,
            pilot: Pilot::default(),
        }
    }

    /// Whether light tracing's factors come from the pilot: `ltweights
    /// variance`, with a camera light tracing can reach.
    fn variance_pilot(&self, ctx: &RenderContext<'_>) -> bool {
        self.settings.variance_lt && ctx.camera.is_connectable()
    }

    /// Light tracing's factors: from the pilot passes' estimates, those this
    /// process did not render made now (not added to the image); 1
    /// everywhere without the pilot. `None` if cancelled.
    fn lt_weights(&self, ctx: &RenderContext<'_>) -> Option<&LtWeights> {
        let enabled = self.variance_pilot(ctx);
        self.pilot.weights(ctx, enabled, |quiet, pass| {
            let est = PassEstimator::new(ctx, self, &DENSITY, true);
            let mut scratch = ctx.film.block();
            match driver::render_pixels(&est, quiet, pass, &mut scratch) {
                PassOutcome::Done => est.samples(),
                PassOutcome::Cancelled => None,
            }
        })
    }

    /// One camera ray's estimate (the t = 1 strategies splatted) and, when
    /// `pilot`, its camera-side part by path length weighted with light
    /// tracing's factor 0, mean over the wavelengths.
    fn li(
        &self,
        ctx: &RenderContext<'_>,
        ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        splats: &mut SplatBuffer,
        lt: &LtWeights,
        pilot: bool,
    ) -> (SampledSpectrum, ByLength) {
        let mut l = SampledSpectrum::zero();
        let mut x: ByLength = [0.0; LENGTHS + 1];
        self.sample_strategies(
            ctx,
            ray,
            lambda,
            sampler,
            lt,
            pilot,
            |s, t, c, lambda| match c.p_raster {
                Some(p) => splats.add(p, c.weighted, lambda),
                None => {
                    l += c.weighted;
                    x[(s + t - 2).min(LENGTHS)] += c.pilot.average();
                }
            },
        );
        (l, x)
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
        lt: &LtWeights,
        pilot: bool,
        mut visit: impl FnMut(usize, usize, &Contribution, &SampledWavelengths),
    ) {
        SCRATCH.with(|cell| {
            let mut scratch = cell.borrow_mut();
            let w = Weights { lt, pilot };
            self.sample_strategies_in(ctx, ray, lambda, sampler, w, &mut scratch, &mut visit);
        });
    }

    /// [`Self::sample_strategies`] with the thread's reused buffers.
    #[allow(clippy::too_many_arguments)]
    fn sample_strategies_in(
        &self,
        ctx: &RenderContext<'_>,
        ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        weights: Weights<'_>,
        scratch: &mut Scratch,
        visit: &mut impl FnMut(usize, usize, &Contribution, &SampledWavelengths),
    ) {
        let max_depth = self.settings.max_depth as usize;
        // Where the camera's ray is seen on the film, when light tracing's
        // factors depend on it.
        let p_film = match weights.lt.per_block() {
            true => ctx.camera.we(ray.o, ray.d).1.unwrap_or(Vec2::ZERO),
            false => Vec2::ZERO,
        };
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
            lt: weights.lt,
            p_film,
            pilot: weights.pilot,
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
