//! One VCM iteration, the three phases of the module doc of [`super`]: the
//! light pass, the merge grid over its vertices, the camera pass. Rendered
//! passes and the variance pilot ([`super::variance`]) run the same code, so
//! the pilot recomputes exactly what a rendered pass found.

use super::camera::CameraPass;
use super::merge::MergeGrid;
use super::variance::{ByLength, LtWeights};
use super::VcmIntegrator;
use crate::film::{FilmTile, PassSplats};
use crate::integrator::driver::for_each_tile;
use crate::integrator::sppm::passes::pass_wavelengths;
use crate::integrator::RenderContext;
use crate::math::UVec2;
use std::sync::atomic::Ordering;

/// What an iteration adds to the image, and its camera side's estimates by
/// path length when asked for.
pub(super) struct Iteration {
    /// Light tracing's splats.
    pub splats: Option<PassSplats>,
    /// The camera pass's tiles.
    pub tiles: Vec<FilmTile>,
    /// Every pixel's camera-side estimate by path length (`record`).
    pub samples: Option<Vec<(UVec2, ByLength)>>,
}

impl VcmIntegrator {
    /// Iteration `pass` with light tracing's factors `lt`, keeping the
    /// camera side's estimates by length when `record`; `None` if the render
    /// was cancelled.
    pub(super) fn iteration(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        lt: &LtWeights,
        record: bool,
    ) -> Option<Iteration> {
        let t = self.techniques;
        let n_light = self.light_paths(ctx) as f32;
        let f = self.factors(pass, n_light);
        let radius = f.grid_radius();
        // One wavelength group: every light and camera path of the iteration
        // shares its wavelengths, so merged power stays spectral.
        let lambda = *pass_wavelengths(self.settings.seed, pass, 1).group(0);
        let time = self.time(ctx, pass);
        let mut light = self.light_pass(ctx, pass, &lambda, time, &f, Some(lt))?;
        self.stored.store(light.len() as u64, Ordering::Relaxed);
        let splats = light.splats.take();
        if t.light_only {
            light.recycle(&self.pools.chunks);
            return Some(Iteration {
                splats,
                tiles: Vec::new(),
                samples: None,
            });
        }
        let grid = (t.merge && !light.is_empty() && radius > 0.0)
            .then(|| MergeGrid::build(&light, radius, f.merges_at(true, true)));
        let cp = CameraPass {
            light: &light,
            grid: grid.as_ref(),
            ff: f,
            lambda,
            time,
            pass,
            lt,
            record,
        };
        let tiles = for_each_tile(ctx, |lo, hi| {
            let mut tile = ctx.film.tile(lo, hi);
            let mut xs = Vec::new();
            self.camera_pixels(ctx, &cp, lo, hi, |pixel, cs, l, x| {
                tile.add_sample(pixel, l, &cp.lambda, cs.filter_weight);
                if record {
                    xs.push((pixel, *x));
                }
            });
            ctx.advance(u64::from((hi.x - lo.x) * (hi.y - lo.y)));
            (tile, xs)
        });
        light.recycle(&self.pools.chunks);
        let (tiles, xs): (Vec<FilmTile>, Vec<_>) = tiles?.into_iter().unzip();
        Some(Iteration {
            splats,
            tiles,
            samples: record.then(|| xs.into_iter().flatten().collect()),
        })
    }
}
