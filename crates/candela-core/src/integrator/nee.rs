//! Next-event estimation: one light sample for a surface point, shared by
//! every estimator that connects a camera-side vertex to a light [Veach
//! 1997, §10.2, s = 1; pbrt-v4 `PathIntegrator::SampleLd`].
//!
//! A light is chosen by the caller's light sampler for the receiving point
//! (pmf p_light: the scene's NEE sampler for the path tracer and the photon
//! estimators, its context-free one for BDPT and VCM), a point or
//! direction on it by the light itself (density p(ω) per unit solid angle at
//! the receiver, 1 for delta lights), and the record holds what each caller
//! needs: f·|cos θ| at the receiver, Li, both densities with their measure,
//! and the light's point, from which BDPT builds the light endpoint of its
//! s = 1 strategy. Visibility is tested here, after the cheap zero checks.
//!
//! The unweighted estimate is f·|cos θ|·Li / (p_light·p(ω)). The callers add
//! their weights:
//! - the path tracer, MIS against BSDF sampling with the power heuristic
//!   ([`LightSample::bsdf_mis_weighted`]);
//! - SPPM's and PPM's camera side, the same weight, with one BSDF sample
//!   at the visible point that looks only for emission
//!   ([`crate::integrator::camera_walk`]);
//! - the photon map's camera side, none: its camera paths never continue
//!   along a non-specular lobe, so nothing else samples these paths;
//! - BDPT's s = 1 strategy, its MIS over all strategies.
//!
//! Both random numbers are drawn first, whatever the outcome, so a caller's
//! later sampler dimensions do not depend on whether a light was found.

use super::subpath::Vertex;
use crate::bsdf::{Bsdf, SampleFlags, TransportMode};
use crate::interaction::{Interaction, LightId, SurfaceInteraction};
use crate::light::{LightChooser, LightSampleContext, LightType};
use crate::math::Vec3;
use crate::sampling::{power_heuristic, PathRng, PdfSolidAngle};
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// The surface point that receives a light sample.
#[derive(Clone, Copy)]
pub struct Receiver<'a> {
    /// Position, error bound and geometric normal.
    pub it: &'a Interaction,
    /// Shading normal.
    pub ns: Vec3,
    /// Direction towards the previous vertex.
    pub wo: Vec3,
    /// The BSDF there.
    pub bsdf: &'a Bsdf,
}

impl<'a> Receiver<'a> {
    /// The receiver at hit `si` with BSDF `bsdf`, viewed from `wo`.
    pub fn at_hit(si: &'a SurfaceInteraction, bsdf: &'a Bsdf, wo: Vec3) -> Self {
        Self {
            it: &si.it,
            ns: si.shading.n,
            wo,
            bsdf,
        }
    }

    /// The receiver at a surface vertex (`None` for endpoints).
    pub fn at_vertex(v: &'a Vertex) -> Option<Self> {
        Some(Self {
            it: &v.it,
            ns: v.ns,
            wo: v.wo,
            bsdf: v.bsdf.as_ref()?,
        })
    }
}

/// One light sample at a receiver, visibility tested.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// The light chosen.
    pub light: LightId,
    /// Unit direction from the receiver towards the light.
    pub wi: Vec3,
    /// Incident radiance along `wi` (for delta-position lights I/d²).
    pub li: SampledSpectrum,
    /// f(ωo, ωi)·|ωi·ns| at the receiver (radiance mode).
    pub f_cos: SampledSpectrum,
    /// Probability of choosing the light.
    pub pmf: f32,
    /// Density of `wi` given the light (1 for delta lights).
    pub pdf: PdfSolidAngle,
    /// The sampled point on the light (beyond the scene for lights at infinity).
    pub p_light: Interaction,
}

/// Samples one light for `r`, chosen by `chooser`, and tests visibility;
/// `None` when the receiver has no non-specular lobe or the sample carries
/// nothing.
pub fn sample_light<R: PathRng + ?Sized, C: LightChooser + ?Sized>(
    scene: &Scene,
    chooser: &C,
    r: &Receiver<'_>,
    lambda: &SampledWavelengths,
    rng: &mut R,
) -> Option<LightSample> {
    let (u_light, u) = (rng.u1(), rng.u2());
    if !r.bsdf.flags().is_non_specular() {
        return None;
    }
    let ctx = LightSampleContext {
        p: r.it.p,
        p_error: r.it.p_error,
        n: r.it.n,
        ns: r.ns,
    };
    let (light, pmf) = chooser.choose(&ctx, u_light)?;
    let ls = scene.light(light).sample_li(&ctx, u, lambda)?;
    if ls.l.is_black() || ls.pdf.0 == 0.0 {
        return None;
    }
    let f_cos = r.bsdf.f(r.wo, ls.wi, TransportMode::Radiance) * ls.wi.dot(r.bsdf.ns()).abs();
    if f_cos.is_black() || !scene.unoccluded(r.it, &ls.p_light) {
        return None;
    }
    Some(LightSample {
        light,
        wi: ls.wi,
        li: ls.l,
        f_cos,
        pmf,
        pdf: ls.pdf,
        p_light: ls.p_light,
    })
}

impl LightSample {
    /// The light endpoint of the sample, for BDPT's s = 1 strategy (its
    /// densities are the caller's to set): for a light at infinity, a
    /// direction; on a delta-position light, a bare point.
    pub fn vertex(&self, scene: &Scene) -> Vertex {
        let at_infinity = matches!(
            scene.light(self.light).light_type(),
            LightType::Infinite | LightType::DeltaDirection
        );
        let w_inf = if at_infinity { -self.wi } else { Vec3::ZERO };
        let it = if self.p_light.is_surface() || at_infinity {
            self.p_light
        } else {
            Interaction::at_point(self.p_light.p)
        };
        Vertex::light(self.light, it, w_inf, SampledSpectrum::zero())
    }

    /// f·|cos θ|·Li / (p_light·p(ω)): the estimate when nothing else samples these paths.
    #[inline]
    pub fn unweighted(&self) -> SampledSpectrum {
        self.f_cos * self.li / (self.pmf * self.pdf.0)
    }

    /// The path tracer's estimate: MIS-weighted against the BSDF sampling
    /// that could also hit the light (power heuristic, [Veach 1997, eq.
    /// 9.13]); full weight for lights BSDF sampling cannot find.
    pub fn bsdf_mis_weighted(&self, scene: &Scene, r: &Receiver<'_>) -> SampledSpectrum {
        let p_l = self.pmf * self.pdf.0;
        if !scene.light(self.light).is_hittable() {
            return self.f_cos * self.li / p_l;
        }
        let p_bsdf = r
            .bsdf
            .pdf(r.wo, self.wi, TransportMode::Radiance, SampleFlags::ALL)
            .0;
        self.f_cos * self.li * (power_heuristic(1.0, p_l, 1.0, p_bsdf) / p_l)
    }
}

/// The density with which next-event estimation at `ctx` (the receiver)
/// samples the point `x0` of area light `id`: the selection probability
/// times the light's own [`Light::pdf_li`] (a sphere's cone sampling),
/// taken to area measure at `x0` [Veach 1997, eq. 8.10].
///
/// The MIS weights of VCM and BDPT use this density for the next-event
/// technique of a path that starts at a light whose next-event sampling is
/// not by area ([`crate::light::Light::samples_li_by_area`]), not the
/// emission's uniform-area one (module doc of
/// [`crate::integrator::vcm::mis`], "Next-event density").
///
/// [`Light::pdf_li`]: crate::light::Light::pdf_li
pub fn nee_area_density(
    scene: &Scene,
    id: LightId,
    x0: &Interaction,
    ctx: &LightSampleContext,
) -> f32 {
    let d = x0.p - ctx.p;
    let d2 = d.length_squared();
    if d2 <= 0.0 {
        return 0.0;
    }
    let wi = d / d2.sqrt();
    let pdf = scene.light(id).pdf_li(ctx, wi).0;
    scene.light_sampler().pmf(id) * pdf * x0.n.dot(wi).abs() / d2
}

/// The next-event context at vertex `v` (as [`Receiver::at_vertex`] makes it).
///
/// [`Receiver::at_vertex`]: crate::integrator::nee::Receiver::at_vertex
pub fn nee_context(v: &Vertex) -> LightSampleContext {
    LightSampleContext {
        p: v.it.p,
        p_error: v.it.p_error,
        n: v.it.n,
        ns: v.ns,
    }
}
