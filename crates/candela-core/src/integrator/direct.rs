//! Next-event estimation by light sampling alone, for estimators in which
//! nothing else samples the direct paths of a non-specular vertex (SPPM's
//! and the photon map's camera paths count emission only after specular
//! bounces), so no MIS weight is needed: L_d ≈ f·|cos θ|·Li / (p_light·p(ω)).

use crate::bsdf::{Bsdf, TransportMode};
use crate::interaction::SurfaceInteraction;
use crate::light::LightSampleContext;
use crate::math::Vec3;
use crate::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// One light sample at `si` (BSDF `bsdf`, outgoing `wo`), visibility included.
pub(crate) fn light_sampled_direct(
    scene: &Scene,
    si: &SurfaceInteraction,
    bsdf: &Bsdf,
    wo: Vec3,
    lambda: &SampledWavelengths,
    sampler: &mut Sampler,
) -> SampledSpectrum {
    let (u_light, u) = (sampler.get_1d(), sampler.get_2d());
    let Some((id, pmf)) = scene.light_sampler().sample(u_light) else {
        return SampledSpectrum::zero();
    };
    let ctx = LightSampleContext::from_surface(si);
    let Some(ls) = scene.light(id).sample_li(&ctx, u, lambda) else {
        return SampledSpectrum::zero();
    };
    if ls.l.is_black() || ls.pdf.0 == 0.0 {
        return SampledSpectrum::zero();
    }
    let f = bsdf.f(wo, ls.wi, TransportMode::Radiance) * ls.wi.dot(bsdf.ns()).abs();
    if f.is_black() || !scene.unoccluded(&si.it, &ls.p_light) {
        return SampledSpectrum::zero();
    }
    f * ls.l / (pmf * ls.pdf.0)
}
