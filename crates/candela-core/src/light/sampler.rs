//! Light selection [pbrt-v4 §12.6].
//!
//! Two families. [`LightSampler`] is context-free [pbrt-v4 §12.6.1–12.6.2]:
//! it serves light subpaths (light tracing, photons, BDPT and VCM), whose
//! start has no receiver, and, as in pbrt-v4, BDPT's and VCM's light
//! sampling at camera vertices too, so that every MIS density of those
//! estimators comes from one sampler. [`NeeLightSampler`] is what
//! next-event estimation without light subpaths uses (the path tracer, the
//! camera side of the photon estimators, `candela measure`): the
//! context-free sampler or the BVH sampler ([`BvhLightSampler`]), which
//! chooses by the receiving point. `"string lightsampler"` picks it
//! ([`LightSelection`]); `"bvh"`, pbrt-v4's default, pairs the BVH sampler
//! for NEE with power sampling for light subpaths, as pbrt-v4 does.
//!
//! [`LightChooser`] is the one interface of both, taking the receiver; the
//! context-free sampler ignores it.
//!
//! `Uniform` picks each of n lights with probability 1/n. `Power` picks light
//! i with probability Φᵢ/ΣΦ, where Φᵢ is a scalar power: as in pbrt-v4's
//! `PowerLightSampler`, the light's [`Light::phi`] at the fixed wavelengths
//! `SampledWavelengths::sample_visible(0.5)`, divided by their densities and
//! averaged (a Monte Carlo estimate of ∫Φ(λ)dλ over the visible range). With
//! this choice every light subpath starts with β₀ = Φ_total (seed §3.2)
//! whenever the light's own emission sampling is exact in β₀.
//!
//! Build the `Power` sampler after [`Light::preprocess`]: distant and
//! infinite lights' Φ depends on the scene radius.

use super::bounds::scalar;
use super::{BvhLightSampler, Light, LightSampleContext};
use crate::interaction::LightId;
use crate::sampling::Distribution1D;

/// Chooses one light per sample.
#[derive(Clone, Debug)]
pub enum LightSampler {
    /// Equal probability for each of `n` lights.
    Uniform {
        /// Number of lights.
        n: usize,
    },
    /// Probability proportional to the lights' power.
    Power {
        /// Distribution over light indices.
        distrib: Distribution1D,
    },
}

impl LightSampler {
    /// Uniform selection among `lights`.
    pub fn uniform(lights: &[Light]) -> Self {
        LightSampler::Uniform { n: lights.len() }
    }

    /// Power-proportional selection; falls back to uniform when every light
    /// has zero power (pbrt-v4 behaviour).
    pub fn power(lights: &[Light]) -> Self {
        let power: Vec<f32> = lights
            .iter()
            .map(|l| scalar(|lambda| l.phi(lambda)))
            .collect();
        if lights.is_empty() || power.iter().all(|&p| p == 0.0) {
            return Self::uniform(lights);
        }
        LightSampler::Power {
            distrib: Distribution1D::new(&power),
        }
    }

    /// Picks a light with `u ∈ [0,1)`; returns its index and probability.
    pub fn sample(&self, u: f32) -> Option<(LightId, f32)> {
        match self {
            LightSampler::Uniform { n } => {
                if *n == 0 {
                    return None;
                }
                let i = ((u * *n as f32) as usize).min(n - 1);
                Some((LightId(i as u32), 1.0 / *n as f32))
            }
            LightSampler::Power { distrib } => {
                let (i, pmf, _) = distrib.sample_discrete(u);
                (pmf > 0.0).then_some((LightId(i as u32), pmf))
            }
        }
    }

    /// Probability that [`sample`](Self::sample) returns `light`.
    pub fn pmf(&self, light: LightId) -> f32 {
        let i = light.0 as usize;
        match self {
            LightSampler::Uniform { n } => {
                if i < *n {
                    1.0 / *n as f32
                } else {
                    0.0
                }
            }
            LightSampler::Power { distrib } => {
                if i < distrib.len() {
                    distrib.discrete_pmf(i)
                } else {
                    0.0
                }
            }
        }
    }
}

/// The light sampler `"string lightsampler"` names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LightSelection {
    /// Uniform everywhere.
    Uniform,
    /// Power everywhere.
    Power,
    /// BVH for next-event estimation, power for light subpaths (pbrt-v4's default).
    #[default]
    Bvh,
}

impl LightSelection {
    /// The context-free sampler of light subpaths (and of BDPT and VCM).
    pub fn context_free(self, lights: &[Light]) -> LightSampler {
        match self {
            LightSelection::Uniform => LightSampler::uniform(lights),
            LightSelection::Power | LightSelection::Bvh => LightSampler::power(lights),
        }
    }

    /// The sampler of next-event estimation; `free` is [`Self::context_free`]'s.
    pub fn nee(self, lights: &[Light], free: &LightSampler) -> NeeLightSampler {
        match self {
            LightSelection::Uniform | LightSelection::Power => NeeLightSampler::Free(free.clone()),
            LightSelection::Bvh => NeeLightSampler::Bvh(BvhLightSampler::new(lights)),
        }
    }
}

/// Chooses a light for a receiving point.
pub trait LightChooser {
    /// Picks a light for `ctx` with `u ∈ [0,1)`; returns it and its probability.
    fn choose(&self, ctx: &LightSampleContext, u: f32) -> Option<(LightId, f32)>;
    /// Probability that [`choose`](Self::choose) returns `light` at `ctx`.
    fn choose_pmf(&self, ctx: &LightSampleContext, light: LightId) -> f32;
}

impl LightChooser for LightSampler {
    #[inline]
    fn choose(&self, _ctx: &LightSampleContext, u: f32) -> Option<(LightId, f32)> {
        self.sample(u)
    }
    #[inline]
    fn choose_pmf(&self, _ctx: &LightSampleContext, light: LightId) -> f32 {
        self.pmf(light)
    }
}

/// The light sampler of next-event estimation (module doc).
#[derive(Clone, Debug)]
pub enum NeeLightSampler {
    /// A context-free sampler.
    Free(LightSampler),
    /// The BVH light sampler.
    Bvh(BvhLightSampler),
}

impl LightChooser for NeeLightSampler {
    #[inline]
    fn choose(&self, ctx: &LightSampleContext, u: f32) -> Option<(LightId, f32)> {
        match self {
            NeeLightSampler::Free(s) => s.sample(u),
            NeeLightSampler::Bvh(s) => s.sample(ctx, u),
        }
    }
    #[inline]
    fn choose_pmf(&self, ctx: &LightSampleContext, light: LightId) -> f32 {
        match self {
            NeeLightSampler::Free(s) => s.pmf(light),
            NeeLightSampler::Bvh(s) => s.pmf(ctx, light),
        }
    }
}
