//! Evaluation of the layered BxDF: f(ωo, ωi) by random walks with two
//! MIS-combined ways to leave through the coating (see the parent module).

use super::{dir_bits, query_rng, sample_layer, tr, u2, weight, LayerBxdf, LayeredBxdf, TAG_F};
use crate::bsdf::{BsdfSample, SampleFlags, TransportMode};
use crate::math::{local, Vec3};
use crate::sampling::{
    henyey_greenstein, power_heuristic, sample_exponential, sample_henyey_greenstein, Pcg32,
};
use crate::spectrum::SampledSpectrum;

/// Quantities fixed for the walks of one evaluation f(ωo, ωi).
struct EvalQuery {
    wi: Vec3,
    mode: TransportMode,
    /// Adjoint transmission sample from ωi into the slab (the virtual light).
    wis: BsdfSample,
}

/// State of one evaluation walk.
struct EvalWalk {
    beta: SampledSpectrum,
    w: Vec3,
    z: f32,
    f: SampledSpectrum,
}

impl<B: LayerBxdf> LayeredBxdf<B> {
    /// Stochastic estimate of f(wo, wi), deterministic for given directions.
    pub fn f(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> SampledSpectrum {
        let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        let mut rng = query_rng(TAG_F, dir_bits(wo), dir_bits(wi));
        self.f_estimate(wo, wi, mode, &mut rng)
    }

    /// [`Self::f`] with the caller's random numbers (tests draw independent estimates).
    pub(crate) fn f_estimate(
        &self,
        wo: Vec3,
        wi: Vec3,
        mode: TransportMode,
        rng: &mut Pcg32,
    ) -> SampledSpectrum {
        let (wo, wi) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        if wo.z == 0.0 || !local::same_hemisphere(wo, wi) {
            return SampledSpectrum::zero();
        }
        let mut sum = SampledSpectrum::zero();
        for _ in 0..self.params.n_samples {
            sum += self.eval_walk(wo, wi, mode, rng);
        }
        self.top.f(wo, wi, mode) + sum / self.params.n_samples as f32
    }

    /// One walk's estimate of the light that enters at ωo and leaves at ωi.
    fn eval_walk(
        &self,
        wo: Vec3,
        wi: Vec3,
        mode: TransportMode,
        rng: &mut Pcg32,
    ) -> SampledSpectrum {
        let zero = SampledSpectrum::zero();
        let Some(wos) = sample_layer(&self.top, wo, rng, mode, SampleFlags::TRANSMISSION) else {
            return zero;
        };
        let Some(wis) = sample_layer(
            &self.top,
            wi,
            rng,
            mode.adjoint(),
            SampleFlags::TRANSMISSION,
        ) else {
            return zero;
        };
        let q = EvalQuery { wi, mode, wis };
        let (thickness, has_medium) = (self.params.thickness, !self.params.albedo.is_black());
        let mut st = EvalWalk {
            beta: weight(&wos),
            w: wos.wi,
            z: thickness,
            f: zero,
        };
        for depth in 0..self.params.max_depth {
            // Russian roulette [pbrt-v4 §14.3.2].
            let m = st.beta.max_component();
            if depth > 3 && m < 0.25 {
                let q_rr = (1.0 - m).max(0.0);
                if rng.uniform_f32() < q_rr {
                    break;
                }
                st.beta /= 1.0 - q_rr;
            }
            if has_medium {
                if !self.eval_medium(&q, &mut st, rng) {
                    continue;
                }
            } else {
                st.z = if st.z == thickness { 0.0 } else { thickness };
                st.beta *= tr(thickness, st.w);
            }
            let alive = if st.z == thickness {
                self.eval_coating_reflection(&q, &mut st, rng)
            } else {
                self.eval_base(&q, &mut st, rng)
            };
            if !alive {
                break;
            }
        }
        st.f
    }

    /// Moves the walk through the medium. Returns true when it reached an
    /// interface; false after a scattering event (both strategies added) or a
    /// failed phase sample.
    fn eval_medium(&self, q: &EvalQuery, st: &mut EvalWalk, rng: &mut Pcg32) -> bool {
        let (thickness, g) = (self.params.thickness, self.params.g);
        let dz = sample_exponential(rng.uniform_f32(), 1.0 / st.w.z.abs());
        let zp = if st.w.z > 0.0 { st.z + dz } else { st.z - dz };
        if zp == st.z {
            return false;
        }
        if zp <= 0.0 || zp >= thickness {
            st.z = zp.clamp(0.0, thickness);
            return true;
        }
        let albedo = self.params.albedo;
        let coating_specular = self.top.flags().is_specular();
        // Strategy 1: connect to the virtual light ω̃ through the coating.
        let p_phase = henyey_greenstein(-st.w, -q.wis.wi, g);
        let wt = if coating_specular {
            1.0
        } else {
            power_heuristic(1.0, q.wis.pdf.0, 1.0, p_phase)
        };
        st.f += st.beta
            * albedo
            * q.wis.f
            * (p_phase * wt * tr(zp - thickness, q.wis.wi) / q.wis.pdf.0);
        // Scatter: the HG sample's value equals its density, so β only takes the albedo.
        let (w, p) = sample_henyey_greenstein(-st.w, g, u2(rng));
        if p == 0.0 || w.z == 0.0 {
            return false;
        }
        st.beta *= albedo;
        st.w = w;
        st.z = zp;
        // Strategy 2: the phase sample heads up; evaluate the coating towards ωi.
        if w.z > 0.0 && !coating_specular {
            self.add_exit(q, st, p, tr(zp - thickness, w));
        }
        false
    }

    /// Adds the light leaving through the coating along the sampled inner
    /// direction `st.w` (density `p_sampled`), MIS-weighted against ω̃.
    fn add_exit(&self, q: &EvalQuery, st: &mut EvalWalk, p_sampled: f32, transmittance: f32) {
        let f_exit = self.top.f(-st.w, q.wi, q.mode);
        if f_exit.is_black() {
            return;
        }
        // Density with which ω̃ sampling would have produced this inner direction.
        let p_exit = self
            .top
            .pdf(q.wi, -st.w, q.mode.adjoint(), SampleFlags::TRANSMISSION)
            .0;
        let wt = if p_sampled > 0.0 {
            power_heuristic(1.0, p_sampled, 1.0, p_exit)
        } else {
            1.0
        };
        st.f += st.beta * f_exit * (transmittance * wt);
    }

    /// Internal reflection under the coating; false ends the walk.
    fn eval_coating_reflection(&self, q: &EvalQuery, st: &mut EvalWalk, rng: &mut Pcg32) -> bool {
        let Some(bs) = sample_layer(&self.top, -st.w, rng, q.mode, SampleFlags::REFLECTION) else {
            return false;
        };
        st.beta *= weight(&bs);
        st.w = bs.wi;
        true
    }

    /// Scattering at the base with both exit strategies; false ends the walk.
    fn eval_base(&self, q: &EvalQuery, st: &mut EvalWalk, rng: &mut Pcg32) -> bool {
        let thickness = self.params.thickness;
        let coating_specular = self.top.flags().is_specular();
        let base_specular = self.bottom.flags().is_specular();
        if !base_specular {
            // Strategy 1: connect to the virtual light ω̃.
            let (wo_b, wi_b) = (-st.w, -q.wis.wi);
            let wt = if coating_specular {
                1.0
            } else {
                let p_base = self.bottom.pdf(wo_b, wi_b, q.mode, SampleFlags::ALL).0;
                power_heuristic(1.0, q.wis.pdf.0, 1.0, p_base)
            };
            let fb = self.bottom.f(wo_b, wi_b, q.mode);
            st.f += st.beta
                * fb
                * q.wis.f
                * (q.wis.wi.z.abs() * wt * tr(thickness, q.wis.wi) / q.wis.pdf.0);
        }
        let Some(bs) = sample_layer(&self.bottom, -st.w, rng, q.mode, SampleFlags::REFLECTION)
        else {
            return false;
        };
        st.beta *= weight(&bs);
        st.w = bs.wi;
        // Strategy 2: the base sample, then the coating towards ωi.
        if !coating_specular {
            let p = if base_specular { 0.0 } else { bs.pdf.0 };
            self.add_exit(q, st, p, tr(thickness, bs.wi));
        }
        true
    }
}
