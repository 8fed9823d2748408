//! Stochastic progressive photon mapping (`Integrator "sppm"`) [Hachisuka &
//! Jensen 2009; pbrt-v3 §16.2; pbrt-v4 `SPPMIntegrator`] and probabilistic
//! progressive photon mapping (`Integrator "ppm"`) [Knaus & Zwicker 2011].
//!
//! Each iteration (`--spp` of them, as in pbrt-v4) runs a camera pass that
//! finds one visible point per pixel and a photon pass that gathers photons
//! at them ([`passes`]). Photons carry power (seed §3): β₀ = Φ's share, and
//! L ≈ Σ f·ΔΦ/(πr²) with ΔΦ = β/N_emitted.
//!
//! **SPPM** keeps per pixel a photon count N, a radius R and an unnormalised
//! flux τ, updated after each pass that brought M photons and flux Φ
//! [Hachisuka & Jensen 2009, eqs. 6–7 with α = 2/3]:
//! N' = N + αM, R'² = R²(N + αM)/(N + M), τ' = (τ + Φ)·R'²/R²,
//! and the pixel is L = Ld/I + τ/(I·N_p·πR²) after I iterations of N_p
//! photons. Φ is summed spectrally within a pass and converted to sensor RGB
//! once per pixel and pass (a pixel gathers only photons of its wavelength
//! group, [`crate::integrator::wavelengths`]).
//!
//! **PPM** (Knaus & Zwicker) makes every pass an independent estimate with
//! one global radius r_i, r²_{i+1} = r²_i (i + α)/(i + 1) (closed form in
//! [`ppm_radius2`]), and averages the passes (`ppm`).

pub mod passes;
mod ppm;
#[cfg(test)]
mod tests;

pub use ppm::{ppm_radius2, PpmIntegrator, PpmSettings};

use super::photon::ShootSettings;
use super::{Integrator, IntegratorKind, IntegratorState, PassOutcome, PassWork, RenderContext};
use crate::film::PassBlock;
use passes::{
    camera_pass, pass_wavelengths, photon_pass, pixel_list, visible_point_walk, VisitBuffer, Visits,
};
use rayon::prelude::*;

/// α of the radius reduction (Hachisuka & Jensen recommend 2/3).
pub const ALPHA: f64 = 2.0 / 3.0;

/// Parameters of `Integrator "sppm"` (pbrt-v4's names).
#[derive(Clone, Debug)]
pub struct SppmSettings {
    /// Photons per iteration (`photonsperiteration`; ≤ 0: one per pixel).
    pub photons_per_iteration: i64,
    /// Initial gather radius (`radius`, default 1).
    pub radius: f32,
    /// Maximum path depth of camera and photon paths (`maxdepth`, default 5).
    pub max_depth: u32,
    /// Seed (`seed`).
    pub seed: u64,
    /// Wavelength groups per pass (`wavelengthgroups`, default 4; see
    /// [`crate::integrator::wavelengths`]).
    pub wavelength_groups: u32,
    /// Fork camera walks at a first smooth dielectric (`splitspecular`,
    /// default true; [`crate::integrator::camera_walk`]).
    pub split_specular: bool,
}

impl Default for SppmSettings {
    fn default() -> Self {
        Self {
            photons_per_iteration: -1,
            radius: 1.0,
            max_depth: 5,
            seed: 0,
            wavelength_groups: super::wavelengths::DEFAULT_GROUPS,
            split_specular: true,
        }
    }
}

/// The SPPM integrator.
pub struct SppmIntegrator {
    /// Settings.
    pub settings: SppmSettings,
    /// The camera pass's visits, reused between passes.
    pub visits: VisitBuffer,
}

impl SppmIntegrator {
    /// One iteration: the camera pass into `visits`, the photon pass, and
    /// the per-pixel radius and flux update (see the module doc).
    fn iteration(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        st: &mut SppmState,
        out: &mut Visits,
    ) -> PassOutcome {
        let s = &self.settings;
        let pixels = pixel_list(ctx.film);
        let pw = pass_wavelengths(s.seed, pass, s.wavelength_groups);
        let cw = visible_point_walk(s.max_depth, s.split_specular);
        if camera_pass(ctx, &pixels, pass as u32, &pw, &cw, out).is_none() {
            return PassOutcome::Cancelled;
        }
        let mut grids = std::mem::take(&mut out.grids);
        let radius: Vec<f32> = st.stats.iter().map(|p| p.r2.sqrt() as f32).collect();
        let n = st.photons_per_iteration;
        let gathered = photon_pass(ctx, out, &mut grids, &radius, &pw, &s.shoot(), pass, n);
        out.grids = grids;
        let Some(gathered) = gathered else {
            return PassOutcome::Cancelled;
        };
        let out: &Visits = out;
        let sensor = ctx.film.sensor();
        // Every pixel's update is its own: in parallel (this loop was the
        // largest serial part of an iteration).
        let stats = st.stats.par_iter_mut().zip(&out.visits).enumerate();
        stats.for_each(|(j, (p, v))| {
            let ld = sensor.to_sensor_rgb(v.ld, &v.lambda);
            for (sum, v) in p.ld.iter_mut().zip(ld) {
                *sum += v as f64;
            }
            let m = gathered.m(j);
            let mut phi = [0.0f64; 3];
            if let (Some(vp), true) = (&v.vp, m > 0) {
                for (sum, lambda) in gathered.sums(j, v, &pw) {
                    let rgb = sensor.to_sensor_rgb(vp.beta * sum, lambda);
                    for (c, x) in phi.iter_mut().zip(rgb) {
                        *c += x as f64;
                    }
                }
            }
            *p = sppm_update(p, m as f64, phi, ALPHA);
        });
        PassOutcome::Done
    }
}

/// Per-pixel statistics of SPPM.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PixelStats {
    /// Accumulated photon count N.
    pub n: f64,
    /// Squared radius R².
    pub r2: f64,
    /// Unnormalised flux τ (sensor RGB).
    pub tau: [f64; 3],
    /// Sum of direct light over iterations (sensor RGB).
    pub ld: [f64; 3],
}

/// SPPM's state between iterations: the statistics of every pixel of the
/// film's pixel bounds, in scanline order.
#[derive(Clone, Debug, PartialEq)]
pub struct SppmState {
    /// Photons shot per iteration.
    pub photons_per_iteration: u64,
    /// Per-pixel statistics.
    pub stats: Vec<PixelStats>,
}

/// One SPPM update after a pass with `m` photons of flux `phi` (sensor RGB)
/// [Hachisuka & Jensen 2009, eqs. 6–7]; the radius stays when m = 0.
pub fn sppm_update(s: &PixelStats, m: f64, phi: [f64; 3], alpha: f64) -> PixelStats {
    if m == 0.0 {
        return PixelStats { tau: s.tau, ..*s };
    }
    let n_new = s.n + alpha * m;
    let r2_new = s.r2 * n_new / (s.n + m);
    let shrink = r2_new / s.r2;
    PixelStats {
        n: n_new,
        r2: r2_new,
        tau: [0, 1, 2].map(|c| (s.tau[c] + phi[c]) * shrink),
        ld: s.ld,
    }
}

impl SppmSettings {
    fn photons(&self, pixels: usize) -> u64 {
        if self.photons_per_iteration > 0 {
            self.photons_per_iteration as u64
        } else {
            pixels as u64
        }
    }
    fn shoot(&self) -> ShootSettings {
        ShootSettings {
            max_depth: self.max_depth,
            seed: self.seed,
            caustic_only: false,
        }
    }
}

impl Integrator for SppmIntegrator {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Sppm
    }

    fn pass_work(&self, ctx: &RenderContext<'_>) -> PassWork {
        PassWork {
            units: self.settings.photons(ctx.film.pixel_count()),
            unit: "photons",
            light_paths: 0,
        }
    }

    fn initial_state(&self, ctx: &RenderContext<'_>) -> IntegratorState {
        let r0 = self.settings.radius as f64;
        IntegratorState::Sppm(SppmState {
            photons_per_iteration: self.settings.photons(ctx.film.pixel_count()),
            stats: vec![
                PixelStats {
                    r2: r0 * r0,
                    ..Default::default()
                };
                ctx.film.pixel_count()
            ],
        })
    }

    fn render_pass(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        state: &mut IntegratorState,
        _block: &mut PassBlock,
    ) -> PassOutcome {
        let IntegratorState::Sppm(st) = state else {
            return PassOutcome::Cancelled;
        };
        self.iteration(ctx, pass, st, &mut self.visits.lock())
    }

    /// L = Ld/I + τ/(I·N_p·πR²) after I iterations of N_p photons.
    fn develop_overlay(&self, state: &IntegratorState, passes: u64) -> Option<Vec<[f64; 3]>> {
        let IntegratorState::Sppm(st) = state else {
            return None;
        };
        let i = passes.max(1) as f64;
        let np = i * st.photons_per_iteration as f64;
        Some(
            st.stats
                .iter()
                .map(|s| {
                    [0, 1, 2].map(|c| s.ld[c] / i + s.tau[c] / (np * std::f64::consts::PI * s.r2))
                })
                .collect(),
        )
    }

    fn status(&self, state: &IntegratorState, _next_pass: u64) -> Option<String> {
        let IntegratorState::Sppm(st) = state else {
            return None;
        };
        let mean_r =
            st.stats.iter().map(|s| s.r2.sqrt()).sum::<f64>() / st.stats.len().max(1) as f64;
        Some(format!("mean radius {mean_r:.4}"))
    }
}
