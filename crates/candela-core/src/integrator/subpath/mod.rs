//! The one subpath walker: a random walk by BSDF sampling that every
//! estimator traces its light and camera subpaths with [Veach 1997, §10.2;
//! pbrt-v3 `RandomWalk` under `GenerateLightSubpath`; SmallVCM
//! `vertexcm.hxx`, the light-path loop of `RunIteration` with
//! `SampleScattering`].
//!
//! A walk starts from a ray leaving an endpoint ([`start_light_subpath`], a
//! camera ray, or a surface point for final gathering) with throughput β.
//! At each surface hit with a BSDF it makes a [`Vertex`] and hands it to a
//! [`Visitor`], which decides what the vertex is for and how the walk goes
//! on ([`Flow`]): photon shooting deposits a photon, the light tracer
//! connects it to the camera, BDPT stores it, the photon estimators' camera
//! walks ([`crate::integrator::camera_walk`]) shade it or stop there.
//! Interfaces (materials without a BSDF) are crossed without a vertex.
//! Then, unless the visitor stopped it or the vertex is at the walk's
//! deepest allowed depth, the walk samples the BSDF in the walk's transport
//! mode, multiplies β by f·|ωi·ns|/p (times the adjoint shading-normal
//! correction |ωo·ns||ωi·ng|/(|ωo·ng||ωi·ns|) in importance mode [Veach 1997,
//! eq. 5.19]) and plays its [`Roulette`] rule.
//!
//! **Densities.** A visitor with [`Visitor::DENSITIES`] (BDPT now, VCM next)
//! gets each vertex's forward density converted to area at the vertex, and
//! after each scattering a [`Scatter`] record: the solid-angle densities of
//! the sampled direction and of the reverse one (the BSDF evaluated with the
//! adjoint mode), the outgoing cosine, whether the lobe was a delta (then
//! both densities are 0 and the next vertex's forward density too, as in
//! pbrt), and the reverse density converted to area at the previous
//! vertex. That is what pbrt's `pdfFwd`/`pdfRev` and SmallVCM's recursive
//! dVCM, dVC, dVM [Georgiev et al. 2012, tech. rep. eqs. 31–36] are made
//! from: at a hit, d² and |cos θ| follow from the new vertex and the last;
//! at a scattering, the record's densities and cosine. Other visitors skip
//! the reverse BSDF evaluation.
//!
//! **Splitting.** A visitor may fork the walk at a vertex whose BSDF is a
//! pair of delta lobes, a reflection and a transmission (a smooth
//! dielectric): [`Visitor::fork`] gives a copy of it with nothing
//! accumulated, the fork walks the reflection alone (density 1, so its β
//! takes the Fresnel factor F instead of a choice made with probability F)
//! and then along delta lobes only, and [`Visitor::join`] adds what it
//! counted. The walk itself goes on choosing between the lobes as always.
//! The two see the same paths through the reflection, and divide them: the
//! fork counts only the emission it reaches (E S+ L, a light seen in the
//! water or glass), the walk everything else, which it is told by
//! [`Vertex::fork_emission`] and [`Escape::fork_emission`] at the vertices
//! and escapes whose emission is the fork's (reached by the reflection and
//! delta scatterings since) [splitting: Arvo and Kirk 1990, "Particle
//! transport and image synthesis", §4]. What for: a bright light seen in
//! that reflection is then found on every sample through the pixels it
//! lights, at F times its radiance, instead of on one sample in 1 / F at
//! full radiance. A fork folds its dispersion into β ([`Dispersion::Fold`])
//! whatever the walk does, so what it counts is at the wavelengths the walk
//! had at the fork (were the walk to end with its secondary wavelengths
//! terminated, the film would weigh the fork's hero wavelength by their
//! count: the same expectation, as for a fold), and plays no roulette (its
//! walk is delta scatterings to `max_depth` at most). The densities a
//! visitor is told are a delta lobe's (0) either way.
//!
//! **Wavelengths.** The walk carries the path's wavelengths. A dispersive
//! refraction keeps only the hero wavelength; in [`Dispersion::Fold`] (photons,
//! whose power must stay at the wavelengths of their group) that is folded
//! into β (hero ×4, others 0, the same expectation), in [`Dispersion::Keep`]
//! the caller's film divides by the changed wavelength densities instead.

mod fork;
mod start;
mod vertex;

use fork::fork_reflection;
pub use fork::{delta_emission, fork_emission_after, forks_at};
pub use start::{start_light_subpath, LightStart};
pub use vertex::{adjoint_cos, dir, to_area, to_area_at, EndPoint, Vertex, VertexKind};

use super::roulette::Roulette;
use crate::bsdf::{Bsdf, BsdfSample, SampleFlags, TransportMode};
use crate::interaction::SurfaceInteraction;
use crate::math::Ray;
use crate::sampling::{PathRng, PdfArea, PdfSolidAngle};
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// How a walk goes on after a vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    /// Sample the BSDF and go on.
    Continue,
    /// Go on only along a delta lobe: stop at once if the BSDF has none,
    /// and after sampling if the sampled lobe is not one.
    SpecularOnly,
    /// End the walk here.
    Stop,
}

/// What a walk does with dispersion (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dispersion {
    /// The wavelengths' densities change; the film divides by them.
    Keep,
    /// The change is folded into β so the wavelengths' densities stay.
    Fold,
}

/// How a walk scatters and when it ends.
#[derive(Clone, Copy, Debug)]
pub struct Walk {
    /// Transport mode of the BSDF samples.
    pub mode: TransportMode,
    /// Depth of the deepest vertex visited; the walk never scatters there.
    pub max_depth: u32,
    /// Russian roulette after each scattering (`None`: no roulette).
    pub roulette: Option<Roulette>,
    /// Roughen near-specular lobes after the first non-specular scattering.
    pub regularize: bool,
    /// Dispersion handling.
    pub dispersion: Dispersion,
}

/// Where a walk starts.
#[derive(Clone, Copy, Debug)]
pub struct Start {
    /// The ray leaving the start vertex.
    pub ray: Ray,
    /// Throughput carried along it.
    pub beta: SampledSpectrum,
    /// Depth of the start vertex (0 for camera and light endpoints).
    pub depth: u32,
    /// The start vertex, from which the first vertex's forward density is
    /// converted (needed by [`Visitor::DENSITIES`] visitors only).
    pub from: Option<Vertex>,
    /// Solid-angle density of the ray's direction at the start vertex (for
    /// a light at infinity: the density of its origin on the scene's disk).
    pub pdf_dir: PdfSolidAngle,
}

/// One scattering, reported to [`Visitor::DENSITIES`] visitors.
#[derive(Clone, Copy, Debug)]
pub struct Scatter {
    /// The sampled lobe was a delta.
    pub delta: bool,
    /// Density of the sampled direction (0 for a delta).
    pub pdf_fwd: PdfSolidAngle,
    /// Density of the reverse direction with the adjoint mode (0 for a delta).
    pub pdf_rev: PdfSolidAngle,
    /// |ωi·ns| of the sampled direction.
    pub cos_out: f32,
    /// `pdf_rev` converted to area at the previous vertex.
    pub prev_pdf_rev: PdfArea,
}

/// A ray that left the scene.
#[derive(Clone, Copy, Debug)]
pub struct Escape {
    /// The ray.
    pub ray: Ray,
    /// Throughput along it.
    pub beta: SampledSpectrum,
    /// Solid-angle density of its direction (0 after a delta lobe).
    pub pdf_dir: PdfSolidAngle,
    /// It left from the start or by a delta scattering.
    pub after_delta: bool,
    /// Its emission is a fork's to count ([`Vertex::fork_emission`]).
    pub fork_emission: bool,
}

/// How a walk ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum End {
    /// The ray left the scene carrying this throughput.
    Escaped(SampledSpectrum),
    /// Absorbed (the BSDF sample failed, or roulette) with this throughput.
    Absorbed(SampledSpectrum),
    /// The visitor stopped it, it reached the depth limit, or β became zero.
    Ended,
}

/// Decides what each vertex of a walk is for.
pub trait Visitor<R: PathRng + ?Sized> {
    /// True when the walk must compute densities and report each [`Scatter`].
    const DENSITIES: bool = false;

    /// True when [`Visitor::fork`] may fork (module doc, "Splitting").
    const FORKS: bool = false;

    /// Called at every surface vertex, with the hit it was made from (its
    /// BSDF built: differentials set, bump applied); says how the walk goes on.
    fn vertex(
        &mut self,
        v: &Vertex,
        si: &SurfaceInteraction,
        lambda: &mut SampledWavelengths,
        rng: &mut R,
    ) -> Flow;

    /// Called after each scattering when [`Visitor::DENSITIES`] is true.
    fn scattered(&mut self, _s: &Scatter) {}

    /// Called when the walk's ray leaves the scene.
    fn escaped(&mut self, _e: &Escape, _lambda: &SampledWavelengths) {}

    /// Called after [`Visitor::vertex`] at a vertex whose BSDF is a smooth
    /// reflection-and-transmission pair: a copy of the visitor with nothing
    /// accumulated, to walk the reflection alone and count the emission it
    /// reaches (module doc, "Splitting"), or `None` (the default). The
    /// walk treats the copy's [`Flow::Continue`] as [`Flow::SpecularOnly`];
    /// a visitor that forks bounds how often.
    fn fork(&self, _v: &Vertex) -> Option<Self>
    where
        Self: Sized,
    {
        None
    }

    /// Adds what a [`Visitor::fork`] found on its branch.
    fn join(&mut self, _branch: Self)
    where
        Self: Sized,
    {
    }
}

/// Walk state between vertices.
#[derive(Clone)]
struct State {
    ray: Ray,
    beta: SampledSpectrum,
    depth: u32,
    pdf_dir: PdfSolidAngle,
    /// What the density conversions read of the previous vertex.
    prev: Option<EndPoint>,
    after_delta: bool,
    scattered: bool,
    any_non_specular: bool,
    eta_scale: f32,
    /// 1 / max_λ of the starting β: roulette weighs the share of it the
    /// walk still carries, whatever the light's power ([`Roulette`]).
    roulette_norm: f32,
    /// This is a fork's walk: it goes on along delta lobes only.
    fork: bool,
    /// The walk forked at the vertex it is scattering from.
    forked_here: bool,
    /// Emission reached now is a fork's ([`Vertex::fork_emission`]).
    fork_emission: bool,
}

/// Walks from `start` until the visitor, the depth limit, absorption or an
/// escape ends it (module doc).
pub fn walk<R, V>(
    scene: &Scene,
    lambda: &mut SampledWavelengths,
    rng: &mut R,
    w: &Walk,
    start: Start,
    visitor: &mut V,
) -> End
where
    R: PathRng + ?Sized,
    V: Visitor<R>,
{
    if start.depth >= w.max_depth {
        return End::Ended;
    }
    let initial = *lambda;
    let st = State {
        ray: start.ray,
        beta: start.beta,
        depth: start.depth,
        pdf_dir: start.pdf_dir,
        prev: start.from.as_ref().map(EndPoint::of),
        after_delta: true,
        scattered: false,
        any_non_specular: false,
        eta_scale: 1.0,
        roulette_norm: roulette_norm(&start.beta),
        fork: false,
        forked_here: false,
        fork_emission: false,
    };
    let fixed = Fixed { scene, w, initial };
    run(&fixed, lambda, rng, st, visitor)
}

/// What stays the same along a walk and its forks.
struct Fixed<'a> {
    scene: &'a Scene,
    w: &'a Walk,
    /// The walk's wavelengths at its start.
    initial: SampledWavelengths,
}

/// The walk from state `st` on.
fn run<R, V>(
    fixed: &Fixed<'_>,
    lambda: &mut SampledWavelengths,
    rng: &mut R,
    mut st: State,
    visitor: &mut V,
) -> End
where
    R: PathRng + ?Sized,
    V: Visitor<R>,
{
    let Fixed { scene, w, initial } = fixed;
    while !st.beta.is_black() {
        let Some(mut si) = scene.intersect(&st.ray, f32::INFINITY) else {
            let e = Escape {
                ray: st.ray,
                beta: st.beta,
                pdf_dir: st.pdf_dir,
                after_delta: st.after_delta,
                fork_emission: st.fork_emission,
            };
            visitor.escaped(&e, lambda);
            return End::Escaped(st.beta);
        };
        let was_terminated = lambda.secondary_terminated();
        let Some(mut bsdf) = scene.bsdf(&mut si, lambda) else {
            st.ray = si.spawn_ray(st.ray.d);
            continue;
        };
        if w.dispersion == Dispersion::Fold && lambda.secondary_terminated() && !was_terminated {
            st.beta *= initial.pdf().safe_div(lambda.pdf());
        }
        if w.regularize && st.any_non_specular {
            bsdf.regularize();
        }
        st.depth += 1;
        let mut v = Vertex::surface(&si, bsdf, w.mode, st.beta);
        v.depth = st.depth;
        v.after_delta = st.after_delta;
        v.caustic = st.scattered && !st.any_non_specular;
        v.fork_emission = st.fork_emission;
        if V::DENSITIES {
            v.pdf_fwd = match &st.prev {
                Some(p) if p.at_infinity => {
                    PdfArea(st.pdf_dir.0 * si.n().dot(st.ray.d.normalize()).abs())
                }
                Some(p) => to_area_at(st.pdf_dir, p.p, &EndPoint::of(&v)),
                None => PdfArea(0.0),
            };
        }
        let flow = match visitor.vertex(&v, &si, lambda, rng) {
            Flow::Continue if st.fork => Flow::SpecularOnly,
            flow => flow,
        };
        if flow == Flow::Stop || st.depth >= w.max_depth {
            return End::Ended;
        }
        fork_reflection(fixed, lambda, rng, flow, &v, &mut st, visitor);
        if let Some(end) = scatter(&v, w, flow, SampleFlags::ALL, &mut st, visitor, rng) {
            return end;
        }
    }
    End::Ended
}

/// Samples the BSDF at `v` and advances `st`; `Some` when the walk ends.
fn scatter<R, V>(
    v: &Vertex,
    w: &Walk,
    flow: Flow,
    allowed: SampleFlags,
    st: &mut State,
    visitor: &mut V,
    rng: &mut R,
) -> Option<End>
where
    R: PathRng + ?Sized,
    V: Visitor<R>,
{
    let bsdf = v.bsdf.as_ref()?;
    let only_delta = flow == Flow::SpecularOnly;
    if only_delta && !bsdf.flags().is_specular() {
        return Some(End::Ended);
    }
    let wo = v.wo;
    let Some(bs) = bsdf.sample_f(wo, rng.u1(), rng.u2(), w.mode, allowed) else {
        return Some(End::Absorbed(st.beta));
    };
    if only_delta && !bs.is_specular() {
        return Some(End::Ended);
    }
    let cos = bs.wi.dot(bsdf.ns()).abs();
    let correction = match w.mode {
        TransportMode::Radiance => 1.0,
        TransportMode::Importance => importance_correction(v, bs.wi),
    };
    let before = st.beta;
    st.beta *= bs.f * (cos * correction / bs.pdf.0);
    if V::DENSITIES {
        report_densities(v, bsdf, &bs, w.mode, cos, st, visitor);
    } else if bs.is_specular() {
        st.pdf_dir = PdfSolidAngle(0.0);
    }
    let forked = std::mem::take(&mut st.forked_here);
    st.fork_emission = fork_emission_after(st.fork_emission, forked, &bs);
    st.after_delta = bs.is_specular();
    st.scattered = true;
    st.any_non_specular |= !bs.is_specular();
    if bs.is_transmission() {
        st.eta_scale *= bs.eta * bs.eta;
    }
    st.ray = v.it.spawn_ray(bs.wi);
    match w.roulette {
        Some(rule)
            if !rule.play(
                st.depth,
                &before,
                &mut st.beta,
                st.eta_scale * st.roulette_norm,
                rng,
            ) =>
        {
            Some(End::Absorbed(before))
        }
        _ => None,
    }
}

/// Tells a [`Visitor::DENSITIES`] visitor the [`Scatter`] of sample `bs`
/// at `v` (|ωi·ns| `cos`), and keeps the forward density and `v` in `st`
/// for the next vertex's conversion.
fn report_densities<R, V>(
    v: &Vertex,
    bsdf: &Bsdf,
    bs: &BsdfSample,
    mode: TransportMode,
    cos: f32,
    st: &mut State,
    visitor: &mut V,
) where
    R: PathRng + ?Sized,
    V: Visitor<R>,
{
    let wo = v.wo;
    let (pdf_fwd, pdf_rev) = if bs.is_specular() {
        (PdfSolidAngle(0.0), PdfSolidAngle(0.0))
    } else {
        let pdf_fwd = if bs.pdf_is_proportional {
            bsdf.pdf(wo, bs.wi, mode, SampleFlags::ALL)
        } else {
            bs.pdf
        };
        (
            pdf_fwd,
            bsdf.pdf(bs.wi, wo, mode.adjoint(), SampleFlags::ALL),
        )
    };
    let prev_pdf_rev = match &st.prev {
        Some(p) => to_area_at(pdf_rev, v.p(), p),
        None => PdfArea(0.0),
    };
    visitor.scattered(&Scatter {
        delta: bs.is_specular(),
        pdf_fwd,
        pdf_rev,
        cos_out: cos,
        prev_pdf_rev,
    });
    st.pdf_dir = pdf_fwd;
    st.prev = Some(EndPoint::of(v));
}

/// 1 / max_λ β of a walk's start, or 1 when that is not a positive finite
/// number.
fn roulette_norm(beta: &SampledSpectrum) -> f32 {
    let m = beta.max_component();
    if m > 0.0 && m.is_finite() {
        1.0 / m
    } else {
        1.0
    }
}

/// |ωo·ns||ωi·ng| / (|ωo·ng||ωi·ns|): the adjoint shading-normal correction
/// of importance transport at `v` [Veach 1997, eq. 5.19].
#[inline]
fn importance_correction(v: &Vertex, wi: crate::math::Vec3) -> f32 {
    let (ns, ng) = (v.ns, v.it.n);
    let den = v.wo.dot(ng).abs() * wi.dot(ns).abs();
    if den == 0.0 {
        return 0.0;
    }
    v.wo.dot(ns).abs() * wi.dot(ng).abs() / den
}

#[cfg(test)]
mod tests;
