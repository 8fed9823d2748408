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
//! Paths are processed in chunks assigned to a fixed number of splat lanes,
//! added in lane order: the image is bit-identical for any thread count.

use super::driver::LANES;
use super::{Integrator, IntegratorKind, IntegratorState, PassOutcome, PassWork, RenderContext};
use crate::bsdf::{Bsdf, SampleFlags, TransportMode};
use crate::film::{PassBlock, SplatBuffer};
use crate::interaction::SurfaceInteraction;
use crate::math::Vec2;
use crate::sampling::{hash_u64s, Pcg32};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rayon::prelude::*;

/// Paths per work item.
const PATHS_PER_CHUNK: u64 = 1 << 14;

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
        let n_chunks = n.div_ceil(PATHS_PER_CHUNK);
        let lanes: Vec<SplatBuffer> = (0..LANES as u64)
            .into_par_iter()
            .map(|lane| {
                let mut buf = ctx.film.splat_buffer();
                for c in (lane..n_chunks).step_by(LANES) {
                    if ctx.cancelled() {
                        break;
                    }
                    let end = ((c + 1) * PATHS_PER_CHUNK).min(n);
                    for i in c * PATHS_PER_CHUNK..end {
                        self.trace_path(ctx, first + i, &mut buf);
                    }
                    ctx.advance(end - c * PATHS_PER_CHUNK);
                }
                buf
            })
            .collect();
        if ctx.cancelled() {
            return PassOutcome::Cancelled;
        }
        for b in &lanes {
            block.add_splats(b);
        }
        PassOutcome::Done
    }
}

/// Light paths per pass: the film's full resolution.
fn paths_per_pass(ctx: &RenderContext<'_>) -> u64 {
    let res = ctx.film.resolution();
    res.x as u64 * res.y as u64
}

/// Uniform numbers of one path, seeded from (seed, path index).
struct PathRng(Pcg32);

impl PathRng {
    fn new(seed: u64, index: u64) -> Self {
        Self(Pcg32::new(hash_u64s(&[seed, index]), 0))
    }
    fn u1(&mut self) -> f32 {
        self.0.uniform_f32()
    }
    fn u2(&mut self) -> Vec2 {
        Vec2::new(self.0.uniform_f32(), self.0.uniform_f32())
    }
}

impl LightTracer {
    /// Traces light path `index` and splats its camera connections.
    fn trace_path(&self, ctx: &RenderContext<'_>, index: u64, buf: &mut SplatBuffer) {
        let scene = ctx.scene;
        let mut rng = PathRng::new(self.settings.seed, index);
        let lambda = SampledWavelengths::sample_visible(rng.u1());
        let Some((id, p_light)) = scene.light_sampler().sample(rng.u1()) else {
            return;
        };
        let light = scene.light(id);
        let Some(les) = light.sample_le(rng.u2(), rng.u2(), &lambda) else {
            return;
        };
        let les = les.at_time(scene.sample_time(|| rng.u1()));
        if les.pdf_pos.0 == 0.0 || les.pdf_dir.0 == 0.0 || les.l.is_black() {
            return;
        }
        // s = 1: the light point seen directly by the camera (visible area lights only).
        if let Some(it) = les.intr.filter(|it| it.is_surface() && light.is_hittable()) {
            if let Some(cs) = ctx.camera.sample_wi(&it, rng.u2()) {
                if cs.pdf.0 > 0.0 && scene.unoccluded(&it, &cs.p_lens) {
                    let le = light.l(it.p, it.n, it.uv, cs.wi, &lambda);
                    let l =
                        le * (cs.wi.dot(it.n).abs() * cs.we / (p_light * les.pdf_pos.0 * cs.pdf.0));
                    buf.add(cs.p_raster, l, &lambda);
                }
            }
        }
        let mut beta = les.beta0(p_light);
        let mut ray = les.ray;
        let mut depth = 0;
        let mut lambda = lambda;
        while !beta.is_black() {
            let Some(mut si) = scene.intersect(&ray, f32::INFINITY) else {
                break;
            };
            // A connection here closes a path with `depth` scattering events, as
            // many as the path tracer allows for the same maxdepth.
            depth += 1;
            if depth > self.settings.max_depth {
                break;
            }
            let Some(bsdf) = scene.bsdf(&mut si, &mut lambda) else {
                ray = si.spawn_ray(ray.d);
                depth -= 1;
                continue;
            };
            if bsdf.flags().is_non_specular() {
                self.connect_to_camera(ctx, &si, &bsdf, beta, &lambda, rng.u2(), buf);
            }
            let Some(bs) = bsdf.sample_f(
                si.wo,
                rng.u1(),
                rng.u2(),
                TransportMode::Importance,
                SampleFlags::ALL,
            ) else {
                break;
            };
            beta *= bs.f
                * (si.importance_shading_correction(si.wo, bs.wi) * bs.wi.dot(bsdf.ns()).abs()
                    / bs.pdf.0);
            ray = si.spawn_ray(bs.wi);
            // Russian roulette on the carried power after a few bounces.
            let m = beta.max_component();
            if depth > 3 && m < 1.0 {
                let q = (1.0 - m).max(0.05);
                if rng.u1() < q {
                    break;
                }
                beta /= 1.0 - q;
            }
        }
    }

    /// t = 1 connection of a surface vertex to a sampled lens point.
    fn connect_to_camera(
        &self,
        ctx: &RenderContext<'_>,
        si: &SurfaceInteraction,
        bsdf: &Bsdf,
        beta: SampledSpectrum,
        lambda: &SampledWavelengths,
        u: Vec2,
        buf: &mut SplatBuffer,
    ) {
        let Some(cs) = ctx.camera.sample_wi(&si.it, u) else {
            return;
        };
        if cs.pdf.0 == 0.0 || cs.we == 0.0 {
            return;
        }
        let f = bsdf.f(si.wo, cs.wi, TransportMode::Importance);
        if f.is_black() || !ctx.scene.unoccluded(&si.it, &cs.p_lens) {
            return;
        }
        let g = si.importance_shading_correction(si.wo, cs.wi) * cs.wi.dot(bsdf.ns()).abs();
        buf.add(cs.p_raster, beta * f * (g * cs.we / cs.pdf.0), lambda);
    }
}
