//! Light tracing (`Integrator "lightpath"`): particle tracing from the
//! lights with every vertex connected to the camera [Veach 1997, §10.2 (t = 1
//! strategies); Arvo & Kirk 1990; pbrt-v4 `LightPathIntegrator`].
//!
//! A light subpath starts with β₀ = Le·|cos θ| / (p_light·p_pos·p_dir), its
//! share of the emitted power (seed §2.1, §3.2); every scattering multiplies
//! β by f·|cos θ|/p in importance mode. Each vertex (the light point itself
//! included) is connected to a sampled lens point; the camera's importance
//! We, normalised to 1 over the whole film (seed §2.4), turns power into the
//! pixel measurement. A pass traces one light path per pixel of the film,
//! and the film averages the passes.
//!
//! Shading normals make importance transport non-symmetric; the adjoint
//! correction |wo·ns||wi·ng| / (|wo·ng||wi·ns|) is applied at every
//! scattering and connection [Veach 1997, eq. 5.19].
//!
//! Paths are processed in chunks, each a task that records its splats; they
//! are summed in chunk order ([`driver::splat_tasks`]): the image is
//! bit-identical for any thread count.

use super::driver;
use super::roulette::Roulette;
use super::subpath::{start_light_subpath, walk, Dispersion, Flow, Vertex, Visitor, Walk};
use super::{Integrator, IntegratorKind, IntegratorState, PassOutcome, PassWork, RenderContext};
use crate::bsdf::{Bsdf, TransportMode};
use crate::film::{PassBlock, SplatBuffer};
use crate::interaction::SurfaceInteraction;
use crate::math::Vec2;
use crate::sampling::{hash_u64s, PathRng, StreamRng};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Paths per task: 64 tasks a pass at 256² (the last ones of a pass idle a
/// thread for at most one task), their splats recorded (56 bytes each) and
/// summed in task order ([`driver::splat_tasks`]).
const PATHS_PER_CHUNK: u64 = 1 << 10;
/// Chunks per batch: 128 chunks' records (about 22 MB at three splats a
/// path) are all that is held.
const BATCH_CHUNKS: u64 = 128;

/// Parameters of `Integrator "lightpath"`.
#[derive(Clone, Debug)]
pub struct LightTracerSettings {
    /// Maximum number of scattering events of a path (as the path tracer's `maxdepth`).
    pub max_depth: u32,
    /// Seed of the path random numbers.
    pub seed: u64,
}

/// The light tracer.
pub struct LightTracer {
    /// Settings.
    pub settings: LightTracerSettings,
}

impl Integrator for LightTracer {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::LightPath
    }

    fn pass_work(&self, ctx: &RenderContext<'_>) -> PassWork {
        PassWork {
            units: paths_per_pass(ctx),
            unit: "light paths",
            light_paths: 0,
        }
    }

    /// Traces paths [pass·N, (pass + 1)·N), N the film's full pixel count: the
    /// camera's importance is normalised over the whole film, so one pass is
    /// one path per pixel of the full resolution, and the film's average over
    /// passes is the estimate.
    fn render_pass(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        _state: &mut IntegratorState,
        block: &mut PassBlock,
    ) -> PassOutcome {
        let n = paths_per_pass(ctx);
        let first = pass * n;
        let task = |c: u64, rec: &mut SplatBuffer| {
            let end = ((c + 1) * PATHS_PER_CHUNK).min(n);
            for i in c * PATHS_PER_CHUNK..end {
                self.trace_path(ctx, first + i, rec);
            }
            ctx.advance(end - c * PATHS_PER_CHUNK);
        };
        let n_tasks = n.div_ceil(PATHS_PER_CHUNK);
        match driver::splat_tasks(ctx, n_tasks, BATCH_CHUNKS, task, |_| ()) {
            Some(splats) => {
                splats.add_to(block);
                PassOutcome::Done
            }
            None => PassOutcome::Cancelled,
        }
    }
}

/// Light paths per pass: the film's full resolution.
fn paths_per_pass(ctx: &RenderContext<'_>) -> u64 {
    let res = ctx.film.resolution();
    res.x as u64 * res.y as u64
}

impl LightTracer {
    /// Traces light path `index` and splats its camera connections.
    fn trace_path(&self, ctx: &RenderContext<'_>, index: u64, buf: &mut SplatBuffer) {
        let scene = ctx.scene;
        let mut rng = StreamRng::with_hash(hash_u64s(&[self.settings.seed, index]));
        let mut lambda = SampledWavelengths::sample_visible(rng.u1());
        let Some(ls) = start_light_subpath(scene, &lambda, &mut rng, None) else {
            return;
        };
        // s = 1: the light point seen directly by the camera (visible area lights only).
        let it = ls.vertex.it;
        let hittable = ls
            .vertex
            .light_id()
            .is_some_and(|id| scene.light(id).is_hittable());
        if it.is_surface() && hittable {
            if let Some(cs) = ctx.camera.sample_wi(&it, rng.u2()) {
                if cs.pdf.0 > 0.0 && scene.unoccluded(&it, &cs.p_lens) {
                    let le = ls.vertex.light_id().map_or(SampledSpectrum::zero(), |id| {
                        scene.light(id).l(it.p, it.n, it.uv, cs.wi, &lambda)
                    });
                    let l =
                        le * (cs.wi.dot(it.n).abs() * cs.we / (ls.pmf * ls.pdf_pos.0 * cs.pdf.0));
                    buf.add(cs.p_raster, l, &lambda);
                }
            }
        }
        let w = Walk {
            mode: TransportMode::Importance,
            max_depth: self.settings.max_depth,
            roulette: Some(Roulette::Bidirectional),
            regularize: false,
            dispersion: Dispersion::Keep,
        };
        let mut splat = Splat { ctx, buf };
        walk(scene, &mut lambda, &mut rng, &w, ls.start, &mut splat);
    }
}

/// The light tracer's visitor: every non-specular vertex is connected to the camera.
struct Splat<'a, 'b> {
    ctx: &'a RenderContext<'b>,
    buf: &'a mut SplatBuffer,
}

impl Visitor<StreamRng> for Splat<'_, '_> {
    fn vertex(
        &mut self,
        v: &Vertex,
        _: &SurfaceInteraction,
        lambda: &mut SampledWavelengths,
        rng: &mut StreamRng,
    ) -> Flow {
        if let Some(bsdf) = &v.bsdf {
            if bsdf.flags().is_non_specular() {
                connect_to_camera(self.ctx, v, bsdf, lambda, rng.u2(), self.buf);
            }
        }
        Flow::Continue
    }
}

/// t = 1 connection of a surface vertex to a sampled lens point.
fn connect_to_camera(
    ctx: &RenderContext<'_>,
    v: &Vertex,
    bsdf: &Bsdf,
    lambda: &SampledWavelengths,
    u: Vec2,
    buf: &mut SplatBuffer,
) {
    let Some(cs) = ctx.camera.sample_wi(&v.it, u) else {
        return;
    };
    if cs.pdf.0 == 0.0 || cs.we == 0.0 {
        return;
    }
    let f = bsdf.f(v.wo, cs.wi, TransportMode::Importance);
    if f.is_black() || !ctx.scene.unoccluded(&v.it, &cs.p_lens) {
        return;
    }
    let (ns, ng) = (v.ns, v.it.n);
    let den = v.wo.dot(ng).abs() * cs.wi.dot(ns).abs();
    let corr = if den == 0.0 {
        0.0
    } else {
        v.wo.dot(ns).abs() * cs.wi.dot(ng).abs() / den
    };
    let g = corr * cs.wi.dot(bsdf.ns()).abs();
    buf.add(cs.p_raster, v.beta * f * (g * cs.we / cs.pdf.0), lambda);
}
