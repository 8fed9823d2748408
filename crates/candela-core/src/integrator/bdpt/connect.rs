//! `connect`: joins the first s light vertices with the first t camera
//! vertices and returns the path's unweighted contribution and its MIS
//! weight [Veach 1997, §10.2; pbrt-v3 `ConnectBDPT`].
//!
//! Four cases:
//! - s = 0: the camera subpath ends on an emitter; C = β_E·Le.
//! - t = 1: a lens point is sampled and the light vertex is splatted onto
//!   the film (light tracing): C = β_L·f̂_L·We/p(ω).
//! - s = 1: a light point is sampled for the camera vertex (next-event
//!   estimation): C = β_E·f·|cos|·Li/(p_light·p(ω)).
//! - otherwise: C = β_L·f̂_L·f_E|cos_E|·β_E/d², with visibility.
//!
//! f̂_L = f·|ωo·ns||ωi·ng|/|ωo·ng| is the light-side BSDF with the adjoint
//! shading-normal correction [Veach 1997, eq. 5.19] and its geometric cosine.

use super::density::{emitted, join_end, pdf, pdf_light_origin};
use super::mis::{mis_weight, JoinDensities, MisHeuristic, PathView};
use crate::bsdf::TransportMode;
use crate::camera::Camera;
use crate::integrator::lt_weights::LtWeights;
use crate::integrator::nee::{sample_light, Receiver};
use crate::integrator::subpath::{Vertex, VertexKind};
use crate::light::LightType;
use crate::math::Vec2;
use crate::sampler::Sampler;
use crate::sampling::PdfArea;
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// One strategy's result.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Contribution {
    /// Contribution before MIS weighting.
    pub unweighted: SampledSpectrum,
    /// MIS-weighted contribution.
    pub weighted: SampledSpectrum,
    /// Raster position for t = 1 (splat), `None` for the current pixel.
    pub p_raster: Option<Vec2>,
    /// With [`ConnectCtx::pilot`], the contribution weighted as in the
    /// limit c → 0 of light tracing's factor (what the variance pilot
    /// measures, [`crate::integrator::lt_weights`]); else zero.
    pub pilot: SampledSpectrum,
}

/// What every connection needs.
pub(crate) struct ConnectCtx<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// The camera.
    pub camera: &'a Camera,
    /// Path wavelengths.
    pub lambda: &'a SampledWavelengths,
    /// MIS heuristic.
    pub heuristic: MisHeuristic,
    /// Light tracing's factors in the weights.
    pub lt: &'a LtWeights,
    /// Film position of the camera subpath's ray (raster units): where the
    /// paths of strategies t ≥ 2 are seen.
    pub p_film: Vec2,
    /// Also weigh every contribution with light tracing's factor 0
    /// ([`Contribution::pilot`]).
    pub pilot: bool,
}

impl ConnectCtx<'_> {
    /// The MIS weights of the strategy that made `view`, seen at film
    /// position `p_raster` (t = 1) or [`Self::p_film`]: with light tracing's
    /// factor there, and with factor 0 when [`Self::pilot`] (else 0).
    pub fn weights(&self, view: &PathView<'_>, p_raster: Option<Vec2>) -> (f32, f32) {
        let row = self.lt.row(p_raster.unwrap_or(self.p_film));
        let c = LtWeights::at(row, (view.n() - 2) as u32);
        let w = mis_weight(self.scene, self.camera, view, self.heuristic, c);
        let w0 = if self.pilot {
            mis_weight(self.scene, self.camera, view, self.heuristic, 0.0)
        } else {
            0.0
        };
        (w, w0)
    }
}

/// Evaluates strategy (s, t); `None` when it contributes nothing.
pub(crate) fn connect(
    cx: &ConnectCtx<'_>,
    light: &[Vertex],
    cam: &[Vertex],
    s: usize,
    t: usize,
    sampler: &mut Sampler,
) -> Option<Contribution> {
    if s == 0 {
        return connect_emitter(cx, cam, t);
    }
    strategy(cx, light, cam, s, t, sampler, |(c, p_raster), view| {
        let (w, w0) = cx.weights(view, p_raster);
        Contribution {
            unweighted: c,
            weighted: c * w,
            p_raster,
            pilot: c * w0,
        }
    })
}

/// Unweighted contribution and raster position (t = 1) of a strategy.
pub(crate) type Unweighted = (SampledSpectrum, Option<Vec2>);

/// Hands the unweighted contribution of strategy (s ≥ 1, t) and the path
/// it made to `k` (the path is built in place, never moved); `None` when
/// the strategy contributes nothing.
pub(crate) fn strategy<R>(
    cx: &ConnectCtx<'_>,
    light: &[Vertex],
    cam: &[Vertex],
    s: usize,
    t: usize,
    sampler: &mut Sampler,
    k: impl FnOnce(Unweighted, &PathView<'_>) -> R,
) -> Option<R> {
    debug_assert!(s >= 1 && t >= 1);
    if cam[t - 1].at_infinity() {
        return None;
    }
    if t == 1 {
        connect_camera(cx, light, cam, s, sampler, k)
    } else if s == 1 {
        connect_light(cx, light, cam, t, sampler, k)
    } else {
        connect_inner(cx, light, cam, s, t, k)
    }
}

/// s = 0: emission of the last camera vertex (every infinite light for an escaped ray).
fn connect_emitter(cx: &ConnectCtx<'_>, cam: &[Vertex], t: usize) -> Option<Contribution> {
    let v = &cam[t - 1];
    let mut out = Contribution {
        unweighted: SampledSpectrum::zero(),
        weighted: SampledSpectrum::zero(),
        p_raster: None,
        pilot: SampledSpectrum::zero(),
    };
    let mut add = |e: Vertex| {
        let le = emitted(cx.scene, &e, e.wo, cx.lambda);
        if le.is_black() {
            return;
        }
        let c = v.beta * le;
        let view = PathView {
            light: &[],
            cam,
            s: 0,
            t,
            light_end: None,
            cam_end: Some(e),
            join: None,
        };
        out.unweighted += c;
        let (w, w0) = cx.weights(&view, None);
        out.weighted += c * w;
        out.pilot += c * w0;
    };
    if v.at_infinity() {
        for &id in cx.scene.infinite_lights() {
            let mut e = *v;
            e.kind = VertexKind::Light(id);
            add(e);
        }
    } else if v.area_light.is_some() {
        add(*v);
    }
    (!out.unweighted.is_black()).then_some(out)
}

/// t = 1: connects light vertex s − 1 to a sampled lens point.
fn connect_camera<R>(
    cx: &ConnectCtx<'_>,
    light: &[Vertex],
    cam: &[Vertex],
    s: usize,
    sampler: &mut Sampler,
    k: impl FnOnce(Unweighted, &PathView<'_>) -> R,
) -> Option<R> {
    let v = &light[s - 1];
    let u = sampler.get_2d();
    if !cx.camera.is_connectable() {
        return None;
    }
    // The light end's f̂ and, for a surface vertex, its pair densities
    // (`join_end`; the lens's density of the vertex is the camera's).
    let (f, cs, end) = match v.kind {
        VertexKind::Light(id) => {
            let l = cx.scene.light(id);
            if l.light_type() != LightType::Area || !l.is_hittable() {
                return None; // Only a visible area light is seen directly.
            }
            let cs = cx.camera.sample_wi(&v.it, u)?;
            let le = emitted(cx.scene, v, cs.wi, cx.lambda) * cs.wi.dot(v.it.n).abs();
            (le, cs, None)
        }
        _ => {
            let bsdf = v.bsdf.as_ref()?;
            if !bsdf.flags().is_non_specular() {
                return None;
            }
            let cs = cx.camera.sample_wi(&v.it, u)?;
            let d2 = (cs.p_lens.p - v.p()).length_squared();
            let end = join_end(v, bsdf, cs.wi, cs.p_lens.n, d2);
            (end.f_cos, cs, Some(end))
        }
    };
    if cs.pdf.0 == 0.0 || f.is_black() {
        return None;
    }
    let c = v.beta * f * (cs.we / cs.pdf.0);
    if c.is_black() || !cx.scene.unoccluded(&v.it, &cs.p_lens) {
        return None;
    }
    let mut lens = Vertex::camera(cs.p_lens, SampledSpectrum::splat(cs.we / cs.pdf.0));
    lens.pdf_fwd = PdfArea(0.0);
    let join = end.map(|end| {
        let p_lens = pdf(cx.scene, cx.camera, &lens, None, v, TransportMode::Radiance);
        JoinDensities::of_lens(&end, p_lens)
    });
    let view = PathView {
        light,
        cam,
        s,
        t: 1,
        light_end: None,
        cam_end: Some(lens),
        join,
    };
    Some(k((c, Some(cs.p_raster)), &view))
}

/// s = 1: next-event estimation from camera vertex t − 1 ([`sample_light`]).
fn connect_light<R>(
    cx: &ConnectCtx<'_>,
    light: &[Vertex],
    cam: &[Vertex],
    t: usize,
    sampler: &mut Sampler,
    k: impl FnOnce(Unweighted, &PathView<'_>) -> R,
) -> Option<R> {
    let v = &cam[t - 1];
    let r = Receiver::at_vertex(v)?;
    let ls = sample_light(cx.scene, cx.scene.light_sampler(), &r, cx.lambda, sampler)?;
    let c = v.beta * ls.f_cos * ls.li / (ls.pmf * ls.pdf.0);
    if c.is_black() {
        return None;
    }
    let mut e = ls.vertex(cx.scene);
    e.pdf_fwd = PdfArea(pdf_light_origin(cx.scene, &e, v));
    let view = PathView {
        light,
        cam,
        s: 1,
        t,
        light_end: Some(e),
        cam_end: None,
        join: None,
    };
    Some(k((c, None), &view))
}

/// s, t ≥ 2: joins two surface vertices with a shadow ray.
fn connect_inner<R>(
    cx: &ConnectCtx<'_>,
    light: &[Vertex],
    cam: &[Vertex],
    s: usize,
    t: usize,
    k: impl FnOnce(Unweighted, &PathView<'_>) -> R,
) -> Option<R> {
    let (lv, cv) = (&light[s - 1], &cam[t - 1]);
    let (lb, cb) = (lv.bsdf.as_ref()?, cv.bsdf.as_ref()?);
    if !lb.flags().is_non_specular() || !cb.flags().is_non_specular() {
        return None;
    }
    let d = cv.p() - lv.p();
    let d2 = d.length_squared();
    if d2 == 0.0 {
        return None;
    }
    let w = d / d2.sqrt();
    let (l_end, c_end) = (
        join_end(lv, lb, w, cv.it.n, d2),
        join_end(cv, cb, -w, lv.it.n, d2),
    );
    let c = lv.beta * l_end.f_cos * c_end.f_cos * cv.beta / d2;
    if c.is_black() || !cx.scene.unoccluded(&lv.it, &cv.it) {
        return None;
    }
    let view = PathView {
        light,
        cam,
        s,
        t,
        light_end: None,
        cam_end: None,
        join: Some(JoinDensities::of_ends(&l_end, &c_end)),
    };
    Some(k((c, None), &view))
}
