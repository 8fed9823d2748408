//! Context-free light selection [pbrt-v4 §12.6.1–12.6.2].
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

use super::Light;
use crate::interaction::LightId;
use crate::sampling::Distribution1D;
use crate::spectrum::SampledWavelengths;

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
        let lambda = SampledWavelengths::sample_visible(0.5);
        let power: Vec<f32> = lights
            .iter()
            .map(|l| l.phi(&lambda).safe_div(lambda.pdf()).average().max(0.0))
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
