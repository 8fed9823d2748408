//! VCM's camera pass: one camera subpath per pixel, walked by the one
//! subpath walker, that at every vertex collects what each enabled technique
//! gives, MIS-weighted [Georgiev et al. 2012, tech. rep. eqs. 37–45;
//! SmallVCM `RunIteration`, camera loop]:
//! - emission of a hit light, or of every infinite light on escape (s = 0,
//!   eqs. 42–43), in full at the first vertex and after specular chains
//!   when nothing else connects;
//! - next-event estimation ([`crate::integrator::nee`], s = 1, eqs. 44–45);
//! - a connection to each vertex of the light subpath with the pixel's index
//!   (eqs. 40–41);
//! - a merge with every light vertex of the iteration within the radius
//!   (eqs. 38–39), L += β_E Σ f·β_L / (π r² N_light); which light vertices
//!   count, with which incident direction, is the rule shared with SPPM and
//!   the photon map ([`crate::integrator::gather`]: the chord kernel on
//!   smooth surfaces, the unfolded one across creases, nothing from a thin
//!   wall's far side).
//!
//! **Splitting** (`splitspecular`, on by default; module doc of
//! [`crate::integrator::subpath`], "Splitting"). At a first vertex that is
//! a smooth dielectric, a fork of the camera subpath follows the reflection
//! alone (β times F) along delta scatterings only, and counts only the
//! emission it reaches that way (E S+ L, the bright light seen in water or
//! glass); the subpath itself chooses reflection or transmission as always
//! and counts everything else, leaving that emission out when it took the
//! reflection. Nothing is counted twice or lost, and E S+ L is found on every
//! sample through the pixels it lights, at F times its radiance, instead of
//! on one sample in 1 / F: only the camera subpath samples those paths
//! (nothing joins or merges at a delta vertex or at the lens), so their
//! weight is 1 either way and no other weight changes. The fork costs about
//! one ray per camera subpath that meets water or glass first.
//!
//! The pixel's β includes the camera ray's weight; everything found is added
//! with the film's filter weight to a [`FilmTile`], so the camera side
//! filters exactly as the path tracer does.

mod next_event;

use super::densities::light_densities;
use super::field::FactorField;
use super::light::{LightPaths, LightVertex, PrevVertex};
use super::merge::{MergeGrid, Photon};
use super::mis::{mis, thin, weight, CameraDeferred, CameraPartial, Factors, Partial};
use super::resample::Resampler;
use super::variance::{ByLength, LtWeights, LENGTHS};
use super::{Connections, VcmIntegrator};
use crate::bsdf::{Bsdf, TransportMode};
use crate::integrator::driver::{camera_sample, PixelSample};
use crate::integrator::gather::{gather, Surfel};
use crate::integrator::nee::{nee_area_density, nee_context};
use crate::integrator::roulette::Roulette;
use crate::integrator::subpath::{
    walk, Dispersion, Escape, Flow, Scatter, Start, Vertex, Visitor, Walk,
};
use crate::integrator::RenderContext;
use crate::interaction::Interaction;
use crate::interaction::SurfaceInteraction;
use crate::light::LightSampleContext;
use crate::math::{UVec2, Vec3};
use crate::sampler::Sampler;
use crate::sampling::PathRng;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// What the camera pass of one iteration shares.
pub(super) struct CameraPass<'a> {
    /// The light subpaths.
    pub light: &'a LightPaths,
    /// Grid over `light.vertices` as photons (merging modes).
    pub grid: Option<&'a MergeGrid>,
    /// MIS constants and merge radii, everywhere.
    pub ff: FactorField<'a>,
    /// The iteration's wavelengths.
    pub lambda: SampledWavelengths,
    /// The iteration's time.
    pub time: f32,
    /// The pass index.
    pub pass: u64,
    /// Light tracing's factors in the weights ([`super::variance`]).
    pub lt: &'a LtWeights,
    /// Split each path's estimate by length (the variance pilot).
    pub record: bool,
}

impl VcmIntegrator {
    /// Walks one camera subpath per pixel in [lo, hi) and hands `sink` the
    /// pixel, its sample, its estimate and (when `cp.record`) that estimate
    /// split by path length.
    pub(super) fn camera_pixels(
        &self,
        ctx: &RenderContext<'_>,
        cp: &CameraPass<'_>,
        lo: UVec2,
        hi: UVec2,
        mut sink: impl FnMut(UVec2, &PixelSample, SampledSpectrum, &ByLength),
    ) {
        let mut sampler = ctx.sampler.clone();
        let res_x = ctx.film.resolution().x as u64;
        let n_light = self.light_paths(ctx);
        for y in lo.y..hi.y {
            for x in lo.x..hi.x {
                let pixel = UVec2::new(x, y);
                sampler.start_pixel_sample(pixel, cp.pass as u32, 0);
                let Some(cs) = camera_sample(ctx, pixel, &mut sampler) else {
                    continue;
                };
                let index = (y as u64 * res_x + x as u64) % n_light.max(1);
                let path = cp.light.path(index as usize);
                let (l, by_length) = self.camera_path(ctx, cp, &cs, path, &mut sampler);
                sink(pixel, &cs, l, &by_length);
            }
        }
    }

    /// The estimate of one camera subpath from pixel sample `cs`, and that
    /// estimate split by path length when `cp.record`.
    fn camera_path(
        &self,
        ctx: &RenderContext<'_>,
        cp: &CameraPass<'_>,
        cs: &PixelSample,
        path: &[LightVertex],
        sampler: &mut Sampler,
    ) -> (SampledSpectrum, ByLength) {
        let (ray, ray_weight) = (cs.ray.at_time(cp.time), cs.ray_weight);
        let lens = Vertex::camera(
            Interaction {
                time: cp.time,
                ..Interaction::at_point(ray.o)
            },
            SampledSpectrum::splat(ray_weight),
        );
        let pdf_dir = ctx.camera.pdf_we(&ray).1;
        let pdf_pixel = self.pixel_density(pdf_dir, ctx);
        let n_light = self.light_paths(ctx) as f32;
        let mut v = CameraVisitor {
            vcm: self,
            ctx,
            cp,
            path,
            mis: CameraPartial::camera(pdf_pixel, n_light, ctx.camera.is_connectable()),
            lt_row: cp.lt.row(cs.camera_sample.p_film),
            prev: PrevVertex::of(&lens),
            pending: None,
            arrived_delta: false,
            last: CameraDeferred::default(),
            last_after_delta: false,
            specular: true,
            vertices: 0,
            specular_fork: false,
            nee_ctx: LightSampleContext::at_point(ray.o),
            f_here: cp.ff.at(ray.o),
            l: SampledSpectrum::zero(),
            by_length: [0.0; LENGTHS + 1],
        };
        // A path of maxdepth scattering vertices may end on a light one
        // vertex further; mode ppm limits each subpath instead, as `ppm`
        // does (module doc of [`super`], "Depth").
        // In both, the first hit's emission counts even at maxdepth 0.
        let extra = u32::from(!self.techniques.ppm);
        let w = Walk {
            mode: TransportMode::Radiance,
            max_depth: (self.settings.max_depth + extra).max(1),
            roulette: Some(Roulette::Bidirectional),
            regularize: self.settings.regularize,
            dispersion: Dispersion::Fold,
        };
        let start = Start {
            ray,
            beta: SampledSpectrum::splat(ray_weight),
            depth: 0,
            from: Some(lens),
            pdf_dir,
        };
        let mut lambda = cp.lambda;
        walk(ctx.scene, &mut lambda, sampler, &w, start, &mut v);
        (v.l, v.by_length)
    }
}

/// The camera pass's visitor.
#[derive(Clone)]
struct CameraVisitor<'a, 'b> {
    vcm: &'a VcmIntegrator,
    ctx: &'a RenderContext<'b>,
    cp: &'a CameraPass<'a>,
    path: &'a [LightVertex],
    /// The partials, light tracing's part apart ([`CameraPartial`]).
    mis: CameraPartial,
    /// Light tracing's factors c by path length for this pixel.
    lt_row: &'a [f32],
    prev: PrevVertex,
    pending: Option<Scatter>,
    /// The scattering that reached the current vertex was a delta (not
    /// at the first vertex).
    arrived_delta: bool,
    /// The terms of a merge at the vertex left last, and whether that
    /// vertex had been reached by a delta scattering.
    last: CameraDeferred,
    last_after_delta: bool,
    /// Every scattering so far was a delta.
    specular: bool,
    /// Surface vertices visited.
    vertices: u32,
    /// A fork following a first vertex's reflection: it counts only
    /// emission (module doc, "Splitting").
    specular_fork: bool,
    /// Where next-event estimation at the vertex left last would have
    /// sampled a light from (its emission weight, [`nee_area_density`]).
    nee_ctx: LightSampleContext,
    /// The MIS factors at the current vertex (at the one left last until
    /// the pending scattering is applied).
    f_here: Factors,
    l: SampledSpectrum,
    /// `l` split by path length, when `cp.record`.
    by_length: ByLength,
}

/// Divides a join of two subpaths that both kept only the hero wavelength
/// by the wavelength count: each side's β carries the fold's factor, the
/// path only one [module doc of `crate::integrator::subpath`].
fn unfold(c: SampledSpectrum, cam: bool, light: bool) -> SampledSpectrum {
    if cam && light {
        c * (1.0 / c.0.len() as f32)
    } else {
        c
    }
}

impl Visitor<Sampler> for CameraVisitor<'_, '_> {
    const DENSITIES: bool = true;
    const FORKS: bool = true;

    fn vertex(
        &mut self,
        v: &Vertex,
        _: &SurfaceInteraction,
        lambda: &mut SampledWavelengths,
        rng: &mut Sampler,
    ) -> Flow {
        self.apply_scatter(v.wo.dot(self.prev.n).abs());
        self.f_here = self.cp.ff.at(v.p());
        let d2 = (v.p() - self.prev.p).length_squared();
        let cos_in = v.wo.dot(v.it.n).abs();
        self.mis.hit(d2, cos_in);
        self.last.hit(cos_in);
        self.prev = PrevVertex::of(v);
        self.vertices += 1;
        self.emission(v, lambda);
        if self.specular_fork {
            return Flow::SpecularOnly;
        }
        self.nee_ctx = nee_context(v);
        let max_depth = self.vcm.settings.max_depth;
        let Some(bsdf) = &v.bsdf else {
            return Flow::Continue;
        };
        if v.depth > max_depth || !bsdf.flags().is_non_specular() {
            return Flow::Continue;
        }
        let t = self.vcm.techniques;
        let terminated = lambda.secondary_terminated();
        if t.connect {
            self.next_event(v, bsdf, lambda, rng);
            self.connect(v, bsdf, terminated, rng);
        }
        if t.merge {
            self.merge(v, bsdf, terminated);
            if t.ppm {
                return Flow::Stop;
            }
        }
        Flow::Continue
    }

    fn scattered(&mut self, s: &Scatter) {
        self.pending = Some(*s);
        self.specular &= s.delta;
    }

    /// Forks at the first vertex when `splitspecular` is on (module doc,
    /// "Splitting").
    fn fork(&self, v: &Vertex) -> Option<Self> {
        if !self.vcm.settings.split_specular || v.depth != 1 {
            return None;
        }
        Some(Self {
            l: SampledSpectrum::zero(),
            by_length: [0.0; LENGTHS + 1],
            specular_fork: true,
            ..self.clone()
        })
    }

    fn join(&mut self, branch: Self) {
        self.l += branch.l;
        for (a, b) in self.by_length.iter_mut().zip(branch.by_length) {
            *a += b;
        }
    }

    fn escaped(&mut self, e: &Escape, lambda: &SampledWavelengths) {
        self.apply_scatter(e.ray.d.normalize().dot(self.prev.n).abs());
        if e.fork_emission {
            return;
        }
        let scene = self.ctx.scene;
        for &id in scene.infinite_lights() {
            let le = scene.light(id).le(&e.ray, lambda);
            if le.is_black() {
                continue;
            }
            let w_inf = -e.ray.d.normalize();
            let it = Interaction::at_point(self.prev.p);
            let (direct, emission, _) = light_densities(scene, id, &it, w_inf);
            // Seen straight from the lens: only the camera finds it.
            let w = if self.vertices == 0 {
                1.0
            } else {
                self.emission_weight(direct, emission, self.prev.depth)
            };
            self.add(self.prev.depth, e.beta * le * w);
        }
    }
}

impl CameraVisitor<'_, '_> {
    /// Applies the pending scattering, leaving the previous vertex with
    /// geometric cosine `cos_out`, to the partials [eqs. 34–36], keeping
    /// the terms of a merge at the vertex left (module doc of [`super::mis`]).
    fn apply_scatter(&mut self, cos_out: f32) {
        let Some(s) = self.pending.take() else { return };
        let f = &self.f_here;
        self.last = self
            .mis
            .scatter(s.delta, s.pdf_fwd.0, s.pdf_rev.0, cos_out, f);
        self.last_after_delta = self.arrived_delta;
        self.arrived_delta = s.delta;
    }

    /// The camera side's partials on a path of `k` scattering vertices,
    /// light tracing weighed by its factor there ([`super::variance`]).
    #[inline]
    fn partial(&self, k: u32) -> Partial {
        self.mis.with_lt(LtWeights::at(self.lt_row, k))
    }

    /// Adds `c`, found on a path of `k` scattering vertices.
    #[inline]
    fn add(&mut self, k: u32, c: SampledSpectrum) {
        self.l += c;
        if self.cp.record {
            self.by_length[(k as usize).min(LENGTHS)] += c.average();
        }
    }

    /// The weight of emission found by the camera subpath after `k`
    /// scattering vertices [eq. 43]: the vertex it left last is next to the
    /// light, and a merge there counts only where it exists.
    fn emission_weight(&self, direct: f32, emission: f32, k: u32) -> f32 {
        if !self.vcm.techniques.connect {
            return if self.specular { 1.0 } else { 0.0 };
        }
        let mut mis = self.partial(k);
        if !self.cp.ff.merges_at(true, self.last_after_delta) {
            mis.d_vc = self.last.d_vc_without(LtWeights::at(self.lt_row, k));
        }
        weight(0.0, mis.emission_weight(direct, emission))
    }

    /// s = 0 at a surface vertex that emits.
    fn emission(&mut self, v: &Vertex, lambda: &SampledWavelengths) {
        let Some(id) = v.area_light else { return };
        if v.fork_emission {
            return;
        }
        let scene = self.ctx.scene;
        let le = scene.light(id).l(v.p(), v.it.n, v.it.uv, v.wo, lambda);
        if le.is_black() {
            return;
        }
        // For an area light the first density is its emission's position
        // density (selection × area).
        let (pos, emission, _) = light_densities(scene, id, &v.it, v.wo);
        let w = if v.depth == 1 {
            self.seen_directly_weight(pos)
        } else {
            // Next-event estimation at the vertex left would have sampled
            // this point with its own density (nee.rs, `nee_area_density`).
            let direct = if scene.light(id).samples_li_by_area() {
                pos
            } else {
                nee_area_density(scene, id, &v.it, &self.nee_ctx)
            };
            self.emission_weight(direct, emission, v.depth - 1)
        };
        self.add(v.depth - 1, v.beta * le * w);
    }

    /// The weight of an area light's point seen straight from the lens
    /// against light tracing's s = 1, t = 1, which samples the same point
    /// with the emission's position density `pos` (light.rs,
    /// `splat_light_point`) [eq. 43 with d_VC = 0]: the camera's
    /// d_VCM after the hit is mis(N_light d² / (p_pixel cos)). Light
    /// tracing's factor c is 1 at k = 0 ([`LtWeights::at`]).
    fn seen_directly_weight(&self, pos: f32) -> f32 {
        if !self.vcm.techniques.connect {
            return 1.0;
        }
        weight(0.0, mis(pos) * self.partial(0).d_vcm)
    }

    /// Connections to the vertices of the pixel's light subpath [eqs.
    /// 40–41]: to every one, or to one resampled in proportion to its
    /// unoccluded contribution ([`Connections`], module doc of [`super`]).
    fn connect(&mut self, v: &Vertex, cb: &Bsdf, terminated: bool, rng: &mut Sampler) {
        let max_depth = self.vcm.settings.max_depth;
        let tau = self.vcm.settings.join_roulette;
        let path = self.path;
        let wo_local = cb.to_local(v.wo);
        let joinable = path.iter().take_while(|lv| lv.depth + v.depth <= max_depth);
        let scene = self.ctx.scene;
        match self.vcm.settings.connections {
            Connections::All => {
                for lv in joinable {
                    let Some((x, w)) = self.connection(v, cb, wo_local, lv, terminated) else {
                        continue;
                    };
                    let Some(kept) = thin(w, tau, || rng.u1()) else {
                        continue;
                    };
                    if scene.unoccluded(&lv.it, &v.it) {
                        self.add(v.depth + lv.depth, x * (kept / w));
                    }
                }
            }
            Connections::One => {
                let mut r = Resampler::new(rng.u1());
                for lv in joinable {
                    if let Some((x, w)) = self.connection(v, cb, wo_local, lv, terminated) {
                        r.offer((lv, x, w), x.average());
                    }
                }
                let Some(((lv, x, _), inv_p)) = r.pick() else {
                    return;
                };
                if scene.unoccluded(&lv.it, &v.it) {
                    self.add(v.depth + lv.depth, x * inv_p);
                }
            }
        }
    }

    /// The MIS-weighted contribution of joining `v` (its `wo` in `cb`'s
    /// frame: `wo_local`) to light vertex `lv` if nothing lies between them
    /// [eqs. 40–41], and its weight; `None` when it is zero.
    fn connection(
        &self,
        v: &Vertex,
        cb: &Bsdf,
        wo_local: Vec3,
        lv: &LightVertex,
        terminated: bool,
    ) -> Option<(SampledSpectrum, f32)> {
        let d = lv.p() - v.p();
        let d2 = d.length_squared();
        if d2 == 0.0 {
            return None;
        }
        let w = d / d2.sqrt();
        let cam = cb.local_pair_from(wo_local, w);
        let f_cam = cb.f_pair(&cam, TransportMode::Radiance) * w.dot(v.ns).abs();
        let (f_light, light) = lv.f_adjoint_cos(-w);
        let c = v.beta * f_cam * f_light * lv.beta / d2;
        if c.is_black() {
            return None;
        }
        let (cam_dir, cam_rev) = cb.pdfs_pair(&cam, TransportMode::Radiance);
        let (light_dir, light_rev) = lv.pdfs(&light);
        let cam_dir_a = cam_dir.0 * w.dot(lv.it.n).abs() / d2;
        let light_dir_a = light_dir * w.dot(v.it.n).abs() / d2;
        // Merges at either end, each with its own vertex's η: not next to
        // the light at the camera's; at a light vertex x_1 its camera-side
        // neighbour is v, not specular.
        let merge_light = self.cp.ff.merges_at(lv.depth == 1, false);
        let w_light =
            lv.mis
                .connect_weight_vm(cam_dir_a, light_rev, if merge_light { lv.vm } else { 0.0 });
        let w_cam = self.partial(v.depth + lv.depth).connect_weight(
            light_dir_a,
            cam_rev.0,
            &self.f_here,
            true,
        );
        let mw = weight(w_light, w_cam);
        (mw != 0.0).then(|| (unfold(c * mw, terminated, lv.terminated), mw))
    }

    /// Merges with the iteration's light vertices around `v` [eqs. 38–39].
    fn merge(&mut self, v: &Vertex, cb: &Bsdf, terminated: bool) {
        let Some(grid) = self.cp.grid else { return };
        let max_depth = self.vcm.settings.max_depth;
        // The kernel and the weights of a merge are those of its camera
        // vertex (module doc of [`super::field`]).
        let (f, ppm) = (&self.f_here, self.vcm.techniques.ppm);
        let radius = f.radius;
        // Light vertices next to the light merge here only where that merge
        // exists ([`Factors::merges_at`]); the rest always do. The grid
        // hands out the former only when asked to.
        let merge_direct = f.merges_at(true, self.arrived_delta);
        let r2 = radius * radius;
        let x = Surfel {
            p: v.p(),
            n: v.it.n,
            w: v.wo,
        };
        let wo_local = cb.to_local(v.wo);
        let mut sum = SampledSpectrum::zero();
        let mut by_length: ByLength = [0.0; LENGTHS + 1];
        // The whole path has at most maxdepth scattering vertices; in mode
        // ppm each subpath (module doc of [`super`], "Depth").
        let too_deep = |ph: &Photon| {
            if ppm {
                ph.depth > max_depth
            } else {
                ph.depth + v.depth > max_depth + 1
            }
        };
        grid.for_each_within(v.p(), radius, merge_direct, |ph| {
            if too_deep(ph) {
                return;
            }
            let k = v.depth + ph.depth - 1;
            let Some(c) = gather(&x, &ph.surfel, r2) else {
                return;
            };
            let pair = cb.local_pair_from(wo_local, c.wi);
            let fv = cb.f_pair(&pair, TransportMode::Radiance);
            if fv.is_black() {
                return;
            }
            let w = if ppm {
                1.0
            } else {
                let (cam_dir, cam_rev) = cb.pdfs_pair(&pair, TransportMode::Radiance);
                weight(
                    ph.mis.merge_weight(cam_dir.0, f),
                    self.partial(k).merge_weight(cam_rev.0, f),
                )
            };
            let c = unfold(fv * ph.beta * w, terminated, ph.terminated);
            sum += c;
            if self.cp.record {
                by_length[(k as usize).min(LENGTHS)] += (v.beta * c).average() * f.merge_norm;
            }
        });
        self.l += v.beta * sum * f.merge_norm;
        for (a, b) in self.by_length.iter_mut().zip(by_length) {
            *a += b;
        }
    }
}
