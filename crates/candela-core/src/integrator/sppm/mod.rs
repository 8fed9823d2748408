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
//! once per pixel and pass (the pass's wavelengths are shared).
//!
//! **PPM** (Knaus & Zwicker) makes every pass an independent estimate with
//! one global radius r_i, r²_{i+1} = r²_i (i + α)/(i + 1) (closed form in
//! [`ppm_radius2`]), and averages the passes ([`ppm`]).

pub mod passes;
mod ppm;
#[cfg(test)]
mod tests;

pub use ppm::{ppm_radius2, PpmIntegrator, PpmPartial, PpmSettings};

use super::photon::ShootSettings;
use super::{Integrator, RenderContext};
use crate::film::RgbFilm;
use passes::{camera_pass, pass_wavelengths, photon_pass, pixel_list};

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
}

impl Default for SppmSettings {
    fn default() -> Self {
        Self {
            photons_per_iteration: -1,
            radius: 1.0,
            max_depth: 5,
            seed: 0,
        }
    }
}

/// The SPPM integrator.
pub struct SppmIntegrator {
    /// Settings.
    pub settings: SppmSettings,
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
    fn render(&self, ctx: &RenderContext<'_>, film: &mut RgbFilm) {
        let st = &self.settings;
        let pixels = pixel_list(film);
        let n_photons = st.photons(pixels.len());
        let iterations = ctx.sampler.samples_per_pixel();
        let r0 = st.radius as f64;
        let mut stats = vec![
            PixelStats {
                r2: r0 * r0,
                ..Default::default()
            };
            pixels.len()
        ];
        ctx.progress.start(iterations as u64, "iterations");
        let t0 = std::time::Instant::now();
        for iter in 0..iterations {
            let lambda = pass_wavelengths(st.seed, iter as u64);
            let visits = camera_pass(ctx, film, &pixels, iter, &lambda, st.max_depth);
            let radius: Vec<f32> = stats.iter().map(|s| s.r2.sqrt() as f32).collect();
            let shoot = st.shoot();
            let gathered = photon_pass(
                ctx.scene,
                &visits,
                &radius,
                &lambda,
                &shoot,
                iter as u64,
                n_photons,
            );
            for ((s, v), g) in stats.iter_mut().zip(&visits).zip(&gathered) {
                for c in 0..3 {
                    s.ld[c] += v.ld[c] as f64;
                }
                let phi = match &v.vp {
                    Some(vp) if g.m > 0 => film.sensor().to_sensor_rgb(vp.beta * g.phi, &lambda),
                    _ => [0.0; 3],
                };
                *s = sppm_update(s, g.m as f64, phi.map(|v| v as f64), ALPHA);
            }
            ctx.progress.advance(1);
            let mean_r = stats.iter().map(|s| s.r2.sqrt()).sum::<f64>() / stats.len().max(1) as f64;
            let rate = (iter as f64 + 1.0) * n_photons as f64 / t0.elapsed().as_secs_f64();
            ctx.progress.message(&format!(
                "{:.2} M photons/s, mean radius {mean_r:.4}",
                rate / 1e6
            ));
        }
        let np = iterations as f64 * n_photons as f64;
        for (p, s) in pixels.iter().zip(&stats) {
            let rgb = [0, 1, 2].map(|c| {
                s.ld[c] / iterations as f64 + s.tau[c] / (np * std::f64::consts::PI * s.r2)
            });
            film.set_pixel_sensor_rgb(*p, rgb);
        }
        ctx.progress.finish();
    }
}
