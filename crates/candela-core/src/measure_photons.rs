//! Photon density estimates of illuminance for `candela measure
//! --integrator ppm|sppm`.
//!
//! Photons are shot by the shared photon tracer
//! ([`crate::integrator::photon::trace_photon`], the one light-subpath
//! walker), each at its own four wavelengths drawn from the visible-range
//! density, so a deposit's luminous power is K_m·(1/4) Σ_k ȳ(λ_k) β_k/p(λ_k)
//! \[lm\] ([`crate::measure`]'s `luminous`), a scalar: irradiance needs no
//! BSDF, so nothing spectral outlives the deposit. Every surface hit counts,
//! the first one too (direct light; there is no next-event part here).
//!
//! At a point x with normal n and radius r, a pass of N photons estimates
//! E_v ≈ Σ_p Φ_p / (N π r²) [Jensen 2001, eq. 7.6 with f = 1/π·π: the
//! irradiance form] over the photon hits p within r of x that arrive from
//! the side n faces (ω_p·n > 0) on a surface facing that side (the hit's
//! geometric normal, turned towards ω_p, has a positive dot with n: the
//! other wall of a corner does not leak in) [Jensen 2001, §7.1]. The points
//! are indexed by a [`HashGrid`] built with the largest radius, and each
//! photon hit queries it, so no photon is stored.
//!
//! - **PPM** [Knaus & Zwicker 2011]: pass i (1-based) uses the radius
//!   r²_i = r²_1·Π_{k<i}(k + α)/(k + 1); passes are independent, the result
//!   is their mean and the standard error √(s²/K) from the spread s² of the
//!   K pass estimates (conservative: the passes' means differ by their
//!   shrinking kernel bias, which only adds to s²).
//! - **SPPM** [Hachisuka & Jensen 2009, eqs. 6–7]: per point N, R and τ
//!   follow [`sppm_update`] and the estimate is τ/(I·N_p·πR²). Successive
//!   iterations are not independent, so the iterations are dealt to B = 8
//!   (or fewer, one per iteration) independent chains (chain c runs passes
//!   c, c + B, …); the result is the chains' mean and the standard error
//!   comes from their spread.
//!
//! Photon `i` of pass `p` uses the streams of (seed, p, i): reproducible
//! whatever the threads. Photon density estimates see only surfaces that
//! photons can be deposited on (non-specular ones): a point must lie on
//! such a surface (within r) to measure anything.

use crate::integrator::photon::{trace_photon, PhotonHit, ShootSettings};
use crate::integrator::sppm::{ppm_radius2, sppm_update, PixelStats, ALPHA};
use crate::math::Vec3;
use crate::measure::{luminous, Measurement};
use crate::sampling::hash_u64s;
use crate::scene::Scene;
use crate::spatial::HashGrid;
use crate::spectrum::SampledWavelengths;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Which photon estimator `measure` uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhotonEstimator {
    /// Probabilistic PPM: independent passes with a shrinking global radius.
    Ppm,
    /// Stochastic PPM: per-point radius and flux statistics, in chains.
    Sppm,
}

/// Settings of a photon measurement.
#[derive(Clone, Copy, Debug)]
pub struct PhotonMeasureSettings {
    /// The estimator.
    pub estimator: PhotonEstimator,
    /// Passes (iterations), K ≥ 2 for a standard error.
    pub passes: u32,
    /// Photons per pass.
    pub photons: u64,
    /// Initial gather radius (world units).
    pub radius: f32,
    /// Maximum surfaces a photon hits.
    pub max_depth: u32,
    /// Seed.
    pub seed: u64,
}

/// Largest number of independent SPPM chains.
const SPPM_CHAINS: u32 = 8;

/// Photons per parallel chunk.
const CHUNK: u64 = 4096;

/// Illuminance at each `(point, unit normal)` by the photon estimator of
/// `s` (module doc); `None` if `s` is unusable (no passes, no photons, a
/// radius that is not positive and finite).
pub fn measure_photons(
    scene: &Scene,
    s: &PhotonMeasureSettings,
    points: &[(Vec3, Vec3)],
) -> Option<Vec<Measurement>> {
    let usable = s.passes > 0 && s.photons > 0 && s.radius.is_finite() && s.radius > 0.0;
    if !usable {
        return None;
    }
    if points.is_empty() {
        return Some(Vec::new());
    }
    let per_pass: Vec<Vec<f64>> = match s.estimator {
        PhotonEstimator::Ppm => ppm_passes(scene, s, points),
        PhotonEstimator::Sppm => sppm_chains(scene, s, points),
    };
    Some(
        (0..points.len())
            .map(|j| mean_and_stderr(per_pass.iter().map(|e| e[j])))
            .collect(),
    )
}

/// One illuminance estimate per point and PPM pass \[lx\].
fn ppm_passes(scene: &Scene, s: &PhotonMeasureSettings, points: &[(Vec3, Vec3)]) -> Vec<Vec<f64>> {
    (0..u64::from(s.passes))
        .map(|pass| {
            let r2 = f64::from(s.radius).powi(2) * ppm_radius2(pass + 1, ALPHA);
            let radius = vec![r2.sqrt() as f32; points.len()];
            let norm = 1.0 / (s.photons as f64 * PI * r2);
            gather_pass(scene, s, pass, points, &radius)
                .into_iter()
                .map(|(lm, _)| lm * norm)
                .collect()
        })
        .collect()
}

/// One illuminance estimate per point and SPPM chain \[lx\].
fn sppm_chains(scene: &Scene, s: &PhotonMeasureSettings, points: &[(Vec3, Vec3)]) -> Vec<Vec<f64>> {
    let chains = s.passes.min(SPPM_CHAINS);
    let r0 = f64::from(s.radius);
    (0..chains)
        .map(|c| {
            let start = PixelStats {
                r2: r0 * r0,
                ..Default::default()
            };
            let mut stats = vec![start; points.len()];
            let mut iterations = 0u64;
            for pass in (c..s.passes).step_by(chains as usize) {
                let radius: Vec<f32> = stats.iter().map(|p| p.r2.sqrt() as f32).collect();
                let got = gather_pass(scene, s, u64::from(pass), points, &radius);
                for (st, (lm, m)) in stats.iter_mut().zip(got) {
                    *st = sppm_update(st, m as f64, [lm, 0.0, 0.0], ALPHA);
                }
                iterations += 1;
            }
            let np = iterations as f64 * s.photons as f64;
            stats
                .iter()
                .map(|st| st.tau[0] / (np * PI * st.r2))
                .collect()
        })
        .collect()
}

/// Shoots the photons of `pass` and returns, per point, the luminous power
/// [lm, not yet divided by the photon count] of the hits gathered within
/// `radius[j]` and their number.
fn gather_pass(
    scene: &Scene,
    s: &PhotonMeasureSettings,
    pass: u64,
    points: &[(Vec3, Vec3)],
    radius: &[f32],
) -> Vec<(f64, u64)> {
    let r_max = radius.iter().copied().fold(0.0f32, f32::max).max(1e-30);
    let positions: Vec<Vec3> = points.iter().map(|p| p.0).collect();
    let grid = HashGrid::build(&positions, r_max);
    let shoot = ShootSettings {
        max_depth: s.max_depth,
        seed: s.seed,
        caustic_only: false,
    };
    let lists: Vec<Vec<(u32, f64)>> = (0..s.photons.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut out = Vec::new();
            for i in c * CHUNK..((c + 1) * CHUNK).min(s.photons) {
                let h = hash_u64s(&[s.seed, pass, i, 0x4d45_4153]);
                let lambda = SampledWavelengths::sample_visible(unit_f32(h));
                trace_photon(scene, &lambda, &shoot, pass, i, |hit| {
                    grid.for_each_within(hit.v.p(), r_max, |j, d2| {
                        let (_, n) = points[j as usize];
                        let r = radius[j as usize];
                        if d2 <= r * r && arrives_from_front(hit, n) {
                            out.push((j, luminous(&hit.v.beta, &lambda)));
                        }
                    });
                });
            }
            out
        })
        .collect();
    let mut sums = vec![(0.0, 0u64); points.len()];
    for (j, lm) in lists.into_iter().flatten() {
        sums[j as usize].0 += lm;
        sums[j as usize].1 += 1;
    }
    sums
}

/// The photon arrives from the side `n` faces, on a surface facing it.
fn arrives_from_front(hit: &PhotonHit<'_>, n: Vec3) -> bool {
    let wo = hit.v.wo;
    let ng = hit.v.it.n;
    let facing = if ng.dot(wo) >= 0.0 { ng } else { -ng };
    wo.dot(n) > 0.0 && facing.dot(n) > 0.0
}

/// A uniform number in [0, 1) from the top 24 bits of `h`.
fn unit_f32(h: u64) -> f32 {
    (h >> 40) as f32 / (1u64 << 24) as f32
}

/// Mean of the estimates and its standard error √(s²/K).
fn mean_and_stderr(values: impl Iterator<Item = f64>) -> Measurement {
    let v: Vec<f64> = values.collect();
    let k = v.len().max(1) as f64;
    let mean = v.iter().sum::<f64>() / k;
    let var = if v.len() > 1 {
        v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (k - 1.0)
    } else {
        0.0
    };
    Measurement {
        illuminance: mean,
        stderr: (var / k).sqrt(),
    }
}
