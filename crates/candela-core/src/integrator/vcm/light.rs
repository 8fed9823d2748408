//! VCM's light pass: N_light light subpaths walked by the one subpath walker
//! ([`crate::integrator::subpath`]) with their MIS quantities, each
//! non-specular vertex stored for connections and merges and, in the modes
//! that connect, joined to a sampled lens point (light tracing, t = 1)
//! [Georgiev et al. 2012, tech. rep. §4; SmallVCM `RunIteration`].
//!
//! A vertex's partial quantities are finished lazily: the walker reports a
//! scattering ([`Scatter`]) before the next hit, whose direction gives the
//! geometric outgoing cosine at the previous vertex; the update of eqs.
//! 34–36 is applied there, then the arrival (distance², cosine) of the new
//! vertex. Chunks of paths run on [`LANES`] fixed lanes and are put back in
//! path order, so the stored vertices and splats do not depend on the
//! thread count.

use super::mis::{weight, Factors, Partial};
use super::{Techniques, VcmIntegrator};
use crate::bsdf::TransportMode;
use crate::film::SplatBuffer;
use crate::integrator::driver::LANES;
use crate::integrator::roulette::Roulette;
use crate::integrator::subpath::{
    start_light_subpath, walk, Dispersion, Flow, Scatter, Vertex, Visitor, Walk,
};
use crate::integrator::RenderContext;
use crate::interaction::{Interaction, LightId};
use crate::light::LightType;
use crate::math::{Ray, Vec3};
use crate::sampling::{hash_u64s, PathRng, StreamRng};
use crate::scene::Scene;
use crate::spatial::HasPosition;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rayon::prelude::*;

/// A stored light-subpath vertex.
#[derive(Clone, Copy, Debug)]
pub struct LightVertex {
    /// The vertex (position, normals, `wo`, BSDF, β, depth).
    pub v: Vertex,
    /// Its partial MIS quantities.
    pub mis: Partial,
    /// Its subpath kept only the hero wavelength (dispersion, folded into β).
    pub terminated: bool,
}

impl HasPosition for LightVertex {
    fn position(&self) -> Vec3 {
        self.v.p()
    }
}

/// The light subpaths of one iteration.
pub struct LightPaths {
    /// Every stored vertex, path after path, each path's in depth order.
    pub vertices: Vec<LightVertex>,
    /// Path i owns `vertices[start[i]..start[i + 1]]`.
    pub start: Vec<u32>,
    /// The light-tracing splats (already scaled to one path per pixel).
    pub splats: Vec<SplatBuffer>,
}

impl LightPaths {
    /// The vertices of path `i`.
    pub fn path(&self, i: usize) -> &[LightVertex] {
        match (self.start.get(i), self.start.get(i + 1)) {
            (Some(&a), Some(&b)) => &self.vertices[a as usize..b as usize],
            _ => &[],
        }
    }
}

/// Next-event and emission densities of light `id` emitting from `it`
/// towards `w` (the direction light travels), each with the light's
/// selection probability, and the cosine at the light (1 off surfaces)
/// [tech. rep. eqs. 31, 43, 45]. The next-event density is per unit area
/// for finite lights and per steradian at infinity; delta positions and
/// directions count as 1.
pub fn light_densities(scene: &Scene, id: LightId, it: &Interaction, w: Vec3) -> (f32, f32, f32) {
    let light = scene.light(id);
    let pmf = scene.light_sampler().pmf(id);
    let (pos, dir, cos) = match light.light_type() {
        LightType::Area => {
            let (pos, dir) = light.pdf_le_area(it, w);
            (pos.0, dir.0, it.n.dot(w).abs())
        }
        LightType::DeltaPosition => (1.0, light.pdf_le(&Ray::new(it.p, w)).1 .0, 1.0),
        LightType::DeltaDirection => (light.pdf_le(&Ray::new(it.p, w)).0 .0, 1.0, 1.0),
        LightType::Infinite => {
            let (pos, dir) = light.pdf_le(&Ray::new(it.p, w));
            (pos.0, dir.0, 1.0)
        }
    };
    let at_infinity = matches!(
        light.light_type(),
        LightType::Infinite | LightType::DeltaDirection
    );
    let direct = if at_infinity { dir } else { pos };
    (pmf * direct, pmf * pos * dir, cos)
}

/// Light paths per parallel chunk.
const CHUNK: u64 = 4096;

/// What one chunk of paths made.
type Chunk = (u64, Vec<LightVertex>, Vec<u32>);

impl VcmIntegrator {
    /// Walks the `n_light` light subpaths of pass `pass` at wavelengths
    /// `lambda` and time `time`; `None` if the render was cancelled.
    pub(super) fn light_pass(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        lambda: &SampledWavelengths,
        time: f32,
        f: &Factors,
    ) -> Option<LightPaths> {
        let n = self.light_paths(ctx);
        let n_chunks = n.div_ceil(CHUNK);
        let lanes: Vec<(SplatBuffer, Vec<Chunk>)> = (0..LANES as u64)
            .into_par_iter()
            .map(|lane| {
                let mut buf = ctx.film.splat_buffer();
                let mut chunks = Vec::new();
                for c in (lane..n_chunks).step_by(LANES) {
                    if ctx.cancelled() {
                        break;
                    }
                    let (mut verts, mut lens) = (Vec::new(), Vec::new());
                    let end = ((c + 1) * CHUNK).min(n);
                    for i in c * CHUNK..end {
                        let before = verts.len();
                        self.trace_light(ctx, pass, i, lambda, time, f, &mut verts, &mut buf);
                        lens.push((verts.len() - before) as u32);
                    }
                    ctx.advance(end - c * CHUNK);
                    chunks.push((c, verts, lens));
                }
                (buf, chunks)
            })
            .collect();
        if ctx.cancelled() {
            return None;
        }
        let mut splats = Vec::with_capacity(LANES);
        let mut chunks = Vec::new();
        for (buf, c) in lanes {
            splats.push(buf);
            chunks.extend(c);
        }
        chunks.sort_by_key(|c| c.0);
        let mut out = LightPaths {
            vertices: Vec::new(),
            start: vec![0],
            splats,
        };
        for (_, verts, lens) in chunks {
            out.vertices.extend(verts);
            for l in lens {
                let last = *out.start.last().unwrap_or(&0);
                out.start.push(last + l);
            }
        }
        Some(out)
    }

    /// Walks light path `i`, storing its vertices in `out` and splatting its
    /// camera connections into `buf`.
    #[allow(clippy::too_many_arguments)]
    fn trace_light(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        i: u64,
        lambda: &SampledWavelengths,
        time: f32,
        f: &Factors,
        out: &mut Vec<LightVertex>,
        buf: &mut SplatBuffer,
    ) {
        let scene = ctx.scene;
        let mut rng = StreamRng::with_hash(hash_u64s(&[self.settings.seed, pass, i, 0x5643_4d4c]));
        let mut lam = *lambda;
        let Some(ls) = start_light_subpath(scene, &lam, &mut rng, Some(time)) else {
            return;
        };
        let Some(id) = ls.vertex.light_id() else {
            return;
        };
        let ty = scene.light(id).light_type();
        let (direct, emission, cos) = light_densities(scene, id, &ls.vertex.it, ls.start.ray.d);
        if emission <= 0.0 {
            return;
        }
        let mis = Partial::light(direct, emission, cos, ty.is_delta(), f);
        if self.techniques.light_only {
            self.splat_light_point(ctx, &ls.vertex, &ls, lambda, &mut rng, buf);
        }
        let w = Walk {
            mode: TransportMode::Importance,
            max_depth: self.settings.max_depth,
            roulette: Some(Roulette::Bidirectional),
            regularize: false,
            dispersion: Dispersion::Fold,
        };
        let mut visitor = LightVisitor {
            vcm: self,
            ctx,
            f,
            lambda,
            mis,
            prev: ls.vertex,
            pending: None,
            out,
            buf,
        };
        walk(scene, &mut lam, &mut rng, &w, ls.start, &mut visitor);
    }

    /// Light tracing's s = 1, t = 1 (mode `lt` only): a visible area light's
    /// point seen directly by the camera.
    fn splat_light_point(
        &self,
        ctx: &RenderContext<'_>,
        v: &Vertex,
        ls: &crate::integrator::subpath::LightStart,
        lambda: &SampledWavelengths,
        rng: &mut StreamRng,
        buf: &mut SplatBuffer,
    ) {
        let it = v.it;
        let hittable = v.is_hittable_light(ctx.scene);
        let u = rng.u2();
        if !it.is_surface() || !hittable {
            return;
        }
        let Some(cs) = ctx.camera.sample_wi(&it, u) else {
            return;
        };
        if cs.pdf.0 <= 0.0 || !ctx.scene.unoccluded(&it, &cs.p_lens) {
            return;
        }
        let le = v.light_id().map_or(SampledSpectrum::zero(), |id| {
            ctx.scene.light(id).l(it.p, it.n, it.uv, cs.wi, lambda)
        });
        let g = cs.wi.dot(it.n).abs() * cs.we / (ls.pmf * ls.pdf_pos.0 * cs.pdf.0);
        buf.add(cs.p_raster, le * (g * self.splat_scale(ctx)), lambda);
    }
}

/// The light pass's visitor: MIS bookkeeping, storage, light tracing.
struct LightVisitor<'a, 'b> {
    vcm: &'a VcmIntegrator,
    ctx: &'a RenderContext<'b>,
    f: &'a Factors,
    lambda: &'a SampledWavelengths,
    mis: Partial,
    prev: Vertex,
    pending: Option<Scatter>,
    out: &'a mut Vec<LightVertex>,
    buf: &'a mut SplatBuffer,
}

impl Visitor<StreamRng> for LightVisitor<'_, '_> {
    const DENSITIES: bool = true;

    fn vertex(&mut self, v: &Vertex, lam: &mut SampledWavelengths, rng: &mut StreamRng) -> Flow {
        if let Some(s) = self.pending.take() {
            let cos_out = v.wo.dot(self.prev.it.n).abs();
            self.mis
                .scatter(s.delta, s.pdf_fwd.0, s.pdf_rev.0, cos_out, self.f);
        }
        let d2 = if self.prev.at_infinity() {
            1.0
        } else {
            (v.p() - self.prev.p()).length_squared()
        };
        self.mis.hit(d2, v.wo.dot(v.it.n).abs());
        self.prev = *v;
        let Some(bsdf) = &v.bsdf else {
            return Flow::Continue;
        };
        if !bsdf.flags().is_non_specular() {
            return Flow::Continue;
        }
        let t: &Techniques = &self.vcm.techniques;
        if t.connect || t.merge {
            self.out.push(LightVertex {
                v: *v,
                mis: self.mis,
                terminated: lam.secondary_terminated(),
            });
        }
        if t.connect || t.light_only {
            self.connect_to_camera(v, rng);
        }
        Flow::Continue
    }

    fn scattered(&mut self, s: &Scatter) {
        self.pending = Some(*s);
    }
}

impl LightVisitor<'_, '_> {
    /// t = 1: joins `v` to a sampled lens point and splats it, weighted
    /// against the other techniques [tech. rep. eq. 46] unless only light
    /// tracing runs.
    fn connect_to_camera(&mut self, v: &Vertex, rng: &mut StreamRng) {
        let (ctx, u) = (self.ctx, rng.u2());
        if !ctx.camera.is_connectable() {
            return;
        }
        let Some(cs) = ctx.camera.sample_wi(&v.it, u) else {
            return;
        };
        if cs.pdf.0 <= 0.0 || cs.we == 0.0 {
            return;
        }
        let c = v.beta * v.f_adjoint_cos(cs.wi) * (cs.we / cs.pdf.0);
        if c.is_black() {
            return;
        }
        let w = if self.vcm.techniques.light_only {
            1.0
        } else {
            let d2 = (cs.p_lens.p - v.p()).length_squared();
            let pdf_pixel = self.vcm.pixel_density(ctx, &Ray::new(cs.p_lens.p, -cs.wi));
            let n_light = self.vcm.light_paths(ctx) as f32;
            let pdf_cam_a = pdf_pixel * cs.wi.dot(v.it.n).abs() / (d2 * n_light);
            let pdf_rev = v.bsdf.as_ref().map_or(0.0, |b| {
                b.pdf(
                    cs.wi,
                    v.wo,
                    TransportMode::Radiance,
                    crate::bsdf::SampleFlags::ALL,
                )
                .0
            });
            weight(self.mis.connect_weight(pdf_cam_a, pdf_rev, self.f), 0.0)
        };
        if w == 0.0 || !ctx.scene.unoccluded(&v.it, &cs.p_lens) {
            return;
        }
        let scale = w * self.vcm.splat_scale(ctx);
        self.buf.add(cs.p_raster, c * scale, self.lambda);
    }
}
