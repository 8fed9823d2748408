//! Probabilistic progressive photon mapping (`Integrator "ppm"`) [Knaus &
//! Zwicker 2011].
//!
//! Pass i (1-based) is an independent photon-mapping estimate with one
//! global radius r_i, r²_{i+1} = r²_i (i + α)/(i + 1), so
//! r²_i = r²_1 Π_{k<i} (k + α)/(k + 1) [Knaus & Zwicker 2011, eq. 16]; the
//! image is the average of the passes. Each pass writes its per-pixel
//! estimate, spectral at the pixel's wavelengths, into the film's direct
//! channels, which the film averages over passes; because the passes are
//! independent, a render can be split into pass ranges and merged exactly.

use super::passes::{
    camera_pass, pass_wavelengths, photon_pass, pixel_list, visible_point_walk, VisitBuffer, Visits,
};
use super::ALPHA;
use crate::film::PassBlock;
use crate::integrator::photon::ShootSettings;
use crate::integrator::{
    Integrator, IntegratorKind, IntegratorState, PassOutcome, PassWork, RenderContext,
};

/// Parameters of `Integrator "ppm"`.
#[derive(Clone, Debug)]
pub struct PpmSettings {
    /// Photons per pass (`photonsperiteration`; ≤ 0: one per pixel).
    pub photons_per_pass: i64,
    /// Radius of the first pass (`radius`, default 1).
    pub radius: f32,
    /// Maximum path depth (`maxdepth`, default 5).
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

/// The PPM integrator.
pub struct PpmIntegrator {
    /// Settings.
    pub settings: PpmSettings,
    /// The camera pass's visits, reused between passes.
    pub visits: VisitBuffer,
}

/// r²_i / r²_1 for pass `i` ≥ 1: Π_{k=1}^{i−1} (k + α)/(k + 1).
pub fn ppm_radius2(i: u64, alpha: f64) -> f64 {
    (1..i)
        .map(|k| (k as f64 + alpha) / (k as f64 + 1.0))
        .product()
}

impl PpmIntegrator {
    fn photons(&self, ctx: &RenderContext<'_>) -> u64 {
        if self.settings.photons_per_pass > 0 {
            self.settings.photons_per_pass as u64
        } else {
            ctx.film.pixel_count() as u64
        }
    }

    /// Squared radius of (0-based) pass `pass`.
    fn radius2(&self, pass: u64) -> f64 {
        (self.settings.radius as f64).powi(2) * ppm_radius2(pass + 1, ALPHA)
    }
}

impl Integrator for PpmIntegrator {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::Ppm
    }

    fn pass_work(&self, ctx: &RenderContext<'_>) -> PassWork {
        PassWork {
            units: self.photons(ctx),
            unit: "photons",
            light_paths: 0,
        }
    }

    fn render_pass(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        _state: &mut IntegratorState,
        block: &mut PassBlock,
    ) -> PassOutcome {
        let st = &self.settings;
        let pixels = pixel_list(ctx.film);
        let n_photons = self.photons(ctx);
        let shoot = ShootSettings {
            max_depth: st.max_depth,
            seed: st.seed,
            caustic_only: false,
        };
        let pw = pass_wavelengths(st.seed, pass, st.wavelength_groups);
        let mut guard = self.visits.lock();
        let cw = visible_point_walk(st.max_depth, st.split_specular);
        if camera_pass(ctx, &pixels, pass as u32, &pw, &cw, &mut guard).is_none() {
            return PassOutcome::Cancelled;
        }
        let mut grids = std::mem::take(&mut guard.grids);
        let r2 = self.radius2(pass);
        let radius = vec![r2.sqrt() as f32; pixels.len()];
        let gathered = photon_pass(
            ctx, &guard, &mut grids, &radius, &pw, &shoot, pass, n_photons,
        );
        guard.grids = grids;
        let Some(gathered) = gathered else {
            return PassOutcome::Cancelled;
        };
        let out: &Visits = &guard;
        let norm = (1.0 / (n_photons as f64 * std::f64::consts::PI * r2)) as f32;
        let mut buf = ctx.film.splat_buffer();
        for (j, (pixel, v)) in pixels.iter().zip(&out.visits).enumerate() {
            buf.add_pixel(*pixel, v.ld, &v.lambda);
            if let (Some(vp), true) = (&v.vp, gathered.m(j) > 0) {
                for (sum, lambda) in gathered.sums(j, v, &pw) {
                    buf.add_pixel(*pixel, vp.beta * sum * norm, lambda);
                }
            }
        }
        block.add_splats(&buf);
        PassOutcome::Done
    }

    fn status(&self, _state: &IntegratorState, next_pass: u64) -> Option<String> {
        Some(format!("radius {:.4}", self.radius2(next_pass).sqrt()))
    }
}
