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
//! vertex. Every chunk of `CHUNK` paths is a task; the chunks are kept in
//! path order and their splats summed in that order by the film's bands
//! ([`PassSplats`]), so the stored vertices and splats do not depend on the
//! thread count. (Until stop 37 chunks of 4096 ran on eight fixed lanes,
//! each with a splat buffer over the whole film: at 128² four tasks for two
//! threads.) The vertices stay in the chunk that made them
//! ([`LightPaths::path`] finds a path's), and chunks are reused by the next
//! iteration (`Pool`): copying the chunks into one array, into freshly
//! faulted pages, was a serial memcpy of ~12 MB per iteration at 128².

use super::densities::light_densities;
use super::field::FactorField;
use super::mis::{thin, weight, Deferred, DirectMerges, Factors, Partial};
use super::variance::LtWeights;
use super::{Techniques, VcmIntegrator};
use crate::bsdf::{Bsdf, LocalPair, TransportMode};
use crate::film::{PassSplats, SplatBuffer};
use crate::integrator::driver::splat_tasks;
use crate::integrator::nee::{nee_area_density, nee_context};
use crate::integrator::roulette::Roulette;
use crate::integrator::subpath::{
    adjoint_cos, start_light_subpath, walk, Dispersion, Flow, Scatter, Vertex, Visitor, Walk,
};
use crate::integrator::RenderContext;
use crate::interaction::SurfaceInteraction;
use crate::interaction::{Interaction, LightId};
use crate::math::{Ray, Vec3};
use crate::sampling::{hash_u64s, PathRng, StreamRng};
use crate::spatial::HasPosition;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use std::sync::Mutex;

/// A stored light-subpath vertex: what a connection reads of it (a
/// [`Vertex`] also carries the walk's bookkeeping, which no join needs).
#[derive(Clone, Copy, Debug)]
pub struct LightVertex {
    /// Position, error bound, geometric normal, time (for the shadow ray).
    pub it: Interaction,
    /// Shading normal.
    pub ns: Vec3,
    /// Unit direction towards the previous vertex (towards the light).
    pub wo: Vec3,
    /// The scattering function there.
    pub bsdf: Bsdf,
    /// The light subpath's throughput (power) at the vertex.
    pub beta: SampledSpectrum,
    /// Its partial MIS quantities.
    pub mis: Partial,
    /// mis(η) of a merge at its position ([`Factors::vm`]; a radius
    /// field's, [`super::field`]).
    pub vm: f32,
    /// Surface vertices of the light subpath up to this one.
    pub depth: u32,
    /// Its subpath kept only the hero wavelength (dispersion, folded into β).
    pub terminated: bool,
}

impl LightVertex {
    /// Position.
    #[inline]
    pub fn p(&self) -> Vec3 {
        self.it.p
    }

    /// f̂ towards `wi` with the adjoint shading-normal correction
    /// ([`Vertex::f_adjoint_cos`]) and the frame-local pair of directions
    /// it was evaluated for (for [`LightVertex::pdfs`]).
    #[inline]
    pub fn f_adjoint_cos(&self, wi: Vec3) -> (SampledSpectrum, LocalPair) {
        let pair = self.bsdf.local_pair(self.wo, wi);
        let f = match adjoint_cos(&self.it, self.ns, self.wo, wi) {
            Some(k) => self.bsdf.f_pair(&pair, TransportMode::Importance) * k,
            None => SampledSpectrum::zero(),
        };
        (f, pair)
    }

    /// The densities of scattering along `pair` (importance, towards `wi`)
    /// and back (radiance, towards `wo`): one end of a connection's weight
    /// [eqs. 40–41].
    #[inline]
    pub fn pdfs(&self, pair: &LocalPair) -> (f32, f32) {
        let (fwd, rev) = self.bsdf.pdfs_pair(pair, TransportMode::Importance);
        (fwd.0, rev.0)
    }
}

impl HasPosition for LightVertex {
    fn position(&self) -> Vec3 {
        self.it.p
    }
}

/// What the MIS bookkeeping of a walk reads of the vertex before the
/// current one (a [`Vertex`] is ten times larger, and copied per vertex).
#[derive(Clone, Copy, Debug)]
pub(super) struct PrevVertex {
    /// Position.
    pub p: Vec3,
    /// Geometric normal (zero off surfaces).
    pub n: Vec3,
    /// A light endpoint at infinity.
    pub at_infinity: bool,
    /// Surface vertices of its subpath up to it (0 at the light or lens).
    pub depth: u32,
}

impl PrevVertex {
    /// The part of `v` the next vertex's update reads.
    pub fn of(v: &Vertex) -> Self {
        Self {
            p: v.p(),
            n: v.it.n,
            at_infinity: v.at_infinity(),
            depth: v.depth,
        }
    }
}

/// Light paths per chunk: the unit of parallel work of the light pass (a
/// task, run [`BATCH_CHUNKS`] at a time) and of storage.
pub(super) const CHUNK: usize = 1024;
/// Chunks per batch of the light pass (only a batch's splat records are held).
const BATCH_CHUNKS: u64 = 128;

/// The stored vertices of [`CHUNK`] consecutive light paths.
#[derive(Default)]
pub(super) struct PathChunk {
    /// Every stored vertex, path after path, each path's in depth order.
    vertices: Vec<LightVertex>,
    /// Path j of the chunk owns `vertices[ends[j - 1]..ends[j]]` (from 0 for j = 0).
    ends: Vec<u32>,
}

/// The light subpaths of one iteration, kept in the chunks that made them
/// (no copy into one array; their memory is reused by the next iteration
/// through a `Pool`).
pub struct LightPaths {
    chunks: Vec<PathChunk>,
    /// The light-tracing splats (already scaled to one path per pixel),
    /// until the iteration takes them.
    pub splats: Option<PassSplats>,
}

impl LightPaths {
    /// The vertices of path `i`.
    pub fn path(&self, i: usize) -> &[LightVertex] {
        let Some(c) = self.chunks.get(i / CHUNK) else {
            return &[];
        };
        let j = i % CHUNK;
        let a = if j == 0 { 0 } else { c.ends[j - 1] as usize };
        match c.ends.get(j) {
            Some(&b) => &c.vertices[a..b as usize],
            None => &[],
        }
    }

    /// Every stored vertex, path after path, chunk by chunk.
    pub fn chunks(&self) -> Vec<&[LightVertex]> {
        self.chunks.iter().map(|c| c.vertices.as_slice()).collect()
    }

    /// Number of stored vertices.
    pub fn len(&self) -> usize {
        self.chunks.iter().map(|c| c.vertices.len()).sum()
    }

    /// True when no vertex is stored.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Hands the chunks' memory back to `pool`.
    pub(super) fn recycle(self, pool: &Pool<PathChunk>) {
        pool.give(self.chunks);
    }
}

/// Buffers kept from one iteration to the next (the vertex chunks), so a
/// pass does not allocate (and fault in) its storage anew; the image never
/// depends on it.
pub(super) struct Pool<T>(Mutex<Vec<T>>);

impl<T> Default for Pool<T> {
    fn default() -> Self {
        Self(Mutex::new(Vec::new()))
    }
}

impl<T> Pool<T> {
    /// A buffer handed back earlier, if any.
    fn take(&self) -> Option<T> {
        self.0.lock().ok().and_then(|mut p| p.pop())
    }

    /// Keeps `items` for later passes.
    pub(super) fn give(&self, items: impl IntoIterator<Item = T>) {
        if let Ok(mut p) = self.0.lock() {
            p.extend(items);
        }
    }
}

impl Pool<PathChunk> {
    /// An empty chunk, with the memory of an earlier one when there is one.
    fn chunk(&self) -> PathChunk {
        let mut c = self.take().unwrap_or_default();
        c.vertices.clear();
        c.ends.clear();
        c
    }
}

impl VcmIntegrator {
    /// Walks the `n_light` light subpaths of pass `pass` at wavelengths
    /// `lambda` and time `time`, splatting their camera connections weighed
    /// with light tracing's factors `lt` when given (the radius pilot wants
    /// only the vertices); `None` if the render was cancelled.
    pub(super) fn light_pass(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        lambda: &SampledWavelengths,
        time: f32,
        f: &FactorField<'_>,
        lt: Option<&LtWeights>,
    ) -> Option<LightPaths> {
        let n = self.light_paths(ctx);
        let chunk = CHUNK as u64;
        let n_chunks = n.div_ceil(chunk);
        let task = |c: u64, rec: &mut SplatBuffer| {
            let mut out = self.pools.chunks.chunk();
            let end = ((c + 1) * chunk).min(n);
            for i in c * chunk..end {
                let buf = lt.map(|lt| (&mut *rec, lt));
                self.trace_light(ctx, pass, i, lambda, time, f, &mut out.vertices, buf);
                out.ends.push(out.vertices.len() as u32);
            }
            ctx.advance(end - c * chunk);
            out
        };
        let mut chunks = Vec::with_capacity(n_chunks as usize);
        let splats = splat_tasks(ctx, n_chunks, BATCH_CHUNKS, task, |done| {
            chunks.extend(done)
        })?;
        Some(LightPaths {
            chunks,
            splats: Some(splats),
        })
    }

    /// Walks light path `i`, storing its vertices in `out` and splatting its
    /// camera connections into `buf` with light tracing's factors (none
    /// without one).
    #[allow(clippy::too_many_arguments)]
    fn trace_light(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        i: u64,
        lambda: &SampledWavelengths,
        time: f32,
        f: &FactorField<'_>,
        out: &mut Vec<LightVertex>,
        buf: Option<(&mut SplatBuffer, &LtWeights)>,
    ) {
        let (mut buf, lt) = buf.unzip();
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
        // A sphere light's next-event density depends on the receiver x_1:
        // it enters d_VCM when the walk reaches x_1 (`LightVisitor::vertex`).
        let by_area = scene.light(id).samples_li_by_area();
        let nee_from = (!by_area).then_some((id, ls.vertex.it));
        if let Some(buf) = buf.as_deref_mut() {
            if self.techniques.connect || self.techniques.light_only {
                // An area light's `direct` is its position density here.
                self.splat_light_point(ctx, &ls, direct, lambda, &mut rng, buf);
            }
        }
        let direct = if nee_from.is_some() { 1.0 } else { direct };
        let f_prev = f.at(ls.vertex.p());
        let mis = Partial::light(direct, emission, cos, ty.is_delta(), &f_prev);
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
            f_prev,
            lambda,
            mis,
            prev: PrevVertex::of(&ls.vertex),
            nee_from,
            pending: None,
            first: None,
            out,
            buf,
            lt,
        };
        walk(scene, &mut lam, &mut rng, &w, ls.start, &mut visitor);
    }

    /// Light tracing's s = 1, t = 1: a visible area light's point x_0,
    /// sampled with position density `pos` (selection × area), joined to a
    /// lens point. Against the camera's ray hitting x_0 (camera.rs,
    /// `seen_directly_weight`) its weight is 1/(1 + mis(p_cam / pos)), p_cam
    /// the camera's density of x_0 per light path [eqs. 37, 46 with no
    /// light vertex before x_0]; 1 in mode `lt`. The splats render a light
    /// seen directly without the pixel-edge noise of the camera's rays
    /// (a pixel half on the light's edge is hit in half its rays).
    fn splat_light_point(
        &self,
        ctx: &RenderContext<'_>,
        ls: &crate::integrator::subpath::LightStart,
        pos: f32,
        lambda: &SampledWavelengths,
        rng: &mut StreamRng,
        buf: &mut SplatBuffer,
    ) {
        let v = &ls.vertex;
        let it = v.it;
        let u = rng.u2();
        if !it.is_surface() || !v.is_hittable_light(ctx.scene) || !ctx.camera.is_connectable() {
            return;
        }
        let Some(cs) = ctx.camera.sample_wi(&it, u) else {
            return;
        };
        if cs.pdf.0 <= 0.0 || cs.we == 0.0 {
            return;
        }
        let le = v.light_id().map_or(SampledSpectrum::zero(), |id| {
            ctx.scene.light(id).l(it.p, it.n, it.uv, cs.wi, lambda)
        });
        if le.is_black() {
            return;
        }
        let cos = cs.wi.dot(it.n).abs();
        let w = if self.techniques.light_only {
            1.0
        } else {
            weight(
                super::mis::mis(self.lens_join_density(ctx, &cs, &it) / pos),
                0.0,
            )
        };
        let Some(w) = thin(w, self.settings.join_roulette, || rng.u1()) else {
            return;
        };
        if !ctx.scene.unoccluded(&it, &cs.p_lens) {
            return;
        }
        let g = cos * cs.we / (ls.pmf * ls.pdf_pos.0 * cs.pdf.0);
        buf.add(cs.p_raster, le * (g * w * self.splat_scale(ctx)), lambda);
    }
}

impl VcmIntegrator {
    /// The density with which the camera's ray would have found the point
    /// `it` that light tracing joined to the lens sample `cs`, per unit
    /// area there and per light path [tech. rep. eq. 46]: the pixel density
    /// of the ray's direction times |cos| / d², over N_light.
    fn lens_join_density(
        &self,
        ctx: &RenderContext<'_>,
        cs: &crate::camera::CameraWiSample,
        it: &Interaction,
    ) -> f32 {
        let d2 = (cs.p_lens.p - it.p).length_squared();
        let pdf_dir = ctx.camera.pdf_we(&Ray::new(cs.p_lens.p, -cs.wi)).1;
        self.pixel_density(pdf_dir, ctx) * cs.wi.dot(it.n).abs()
            / (d2 * self.light_paths(ctx) as f32)
    }
}

/// The light pass's visitor: MIS bookkeeping, storage, light tracing.
struct LightVisitor<'a, 'b> {
    vcm: &'a VcmIntegrator,
    ctx: &'a RenderContext<'b>,
    f: &'a FactorField<'a>,
    /// The factors at the vertex reached last.
    f_prev: Factors,
    lambda: &'a SampledWavelengths,
    mis: Partial,
    prev: PrevVertex,
    /// An area light's id and point x_0, until x_1 gives d_VCM its
    /// next-event density ([`nee_area_density`]).
    nee_from: Option<(LightId, Interaction)>,
    pending: Option<Scatter>,
    /// The terms of a merge at x_1, until x_2 scatters (module doc of
    /// [`super::mis`]).
    first: Option<Deferred>,
    out: &'a mut Vec<LightVertex>,
    /// Where camera connections are splatted (`None`: not made).
    buf: Option<&'a mut SplatBuffer>,
    /// Light tracing's factors in the weights, with `buf`.
    lt: Option<&'a LtWeights>,
}

impl Visitor<StreamRng> for LightVisitor<'_, '_> {
    const DENSITIES: bool = true;

    fn vertex(
        &mut self,
        v: &Vertex,
        _: &SurfaceInteraction,
        lam: &mut SampledWavelengths,
        rng: &mut StreamRng,
    ) -> Flow {
        if let Some(s) = self.pending.take() {
            // x_2 scattered: the merge at x_1 exists if it did so specularly.
            if let Some(first) = self.first.take() {
                if s.delta {
                    self.mis.add(&first);
                }
            }
            let cos_out = v.wo.dot(self.prev.n).abs();
            let next_to_light = self.prev.depth == 1;
            // Leaving x_1, whether its merge exists waits for x_2 (module
            // doc of `mis`).
            let merge_here = self.f.merges_at(next_to_light, false);
            // The merge at the vertex left has that vertex's η.
            let merge = self.mis.scatter(
                s.delta,
                s.pdf_fwd.0,
                s.pdf_rev.0,
                cos_out,
                &self.f_prev,
                merge_here,
            );
            let waits = next_to_light && self.f.direct() == DirectMerges::AfterSpecular;
            self.first = waits.then_some(merge);
        }
        let d2 = if self.prev.at_infinity {
            1.0
        } else {
            (v.p() - self.prev.p).length_squared()
        };
        let cos_in = v.wo.dot(v.it.n).abs();
        self.mis.hit(d2, cos_in);
        if let Some((id, x0)) = self.nee_from.take() {
            // x_1: d_VCM = mis(p_NEE(x_0 | x_1) / p_emission) · mis(d²/cos)
            // [tech. rep. eq. 31], started with p_NEE = 1.
            let p = nee_area_density(self.ctx.scene, id, &x0, &nee_context(v));
            self.mis.d_vcm *= super::mis::mis(p);
        }
        if let Some(first) = &mut self.first {
            first.hit(cos_in);
        }
        self.prev = PrevVertex::of(v);
        self.f_prev = self.f.at(v.p());
        let Some(bsdf) = &v.bsdf else {
            return Flow::Continue;
        };
        if !bsdf.flags().is_non_specular() {
            return Flow::Continue;
        }
        let t: &Techniques = &self.vcm.techniques;
        if t.connect || t.merge {
            self.out.push(LightVertex {
                it: v.it,
                ns: v.ns,
                wo: v.wo,
                bsdf: *bsdf,
                beta: v.beta,
                mis: self.mis,
                vm: self.f_prev.vm,
                depth: v.depth,
                terminated: lam.secondary_terminated(),
            });
        }
        if (t.connect || t.light_only) && self.buf.is_some() {
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
            let pdf_cam_a = self.vcm.lens_join_density(ctx, &cs, &v.it);
            let pdf_rev = v.bsdf.as_ref().map_or(0.0, |b| {
                b.pdf(
                    cs.wi,
                    v.wo,
                    TransportMode::Radiance,
                    crate::bsdf::SampleFlags::ALL,
                )
                .0
            });
            // A merge here exists unless next to the light: the lens is
            // the camera-side neighbour.
            let merge = self.f.merges_at(v.depth == 1, false);
            // Light tracing's term times its factor c on this path: the
            // others relative to it divide by c ([`super::variance`]); as
            // c → 0 it keeps the paths no other technique makes.
            let c = self
                .lt
                .map_or(1.0, |lt| LtWeights::at(lt.row(cs.p_raster), v.depth));
            let w_light = self
                .mis
                .connect_weight(pdf_cam_a, pdf_rev, &self.f_prev, merge);
            if w_light == 0.0 {
                1.0
            } else {
                weight(w_light / c, 0.0)
            }
        };
        // Light tracing alone has w = 1, which no τ ≤ 1 thins.
        let Some(w) = thin(w, self.vcm.settings.join_roulette, || rng.u1()) else {
            return;
        };
        if !ctx.scene.unoccluded(&v.it, &cs.p_lens) {
            return;
        }
        let scale = w * self.vcm.splat_scale(ctx);
        if let Some(buf) = self.buf.as_deref_mut() {
            buf.add(cs.p_raster, c * scale, self.lambda);
        }
    }
}
