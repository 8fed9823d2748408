//! The tiled, parallel, deterministic render loop for camera-driven estimators.
//!
//! The image is cut into 16×16 tiles rendered in parallel by rayon. Every
//! pixel sample reseeds the sampler from (pixel, sample index, seed), and
//! each pixel is written by exactly one tile, so the image is bit-identical
//! for any thread count and schedule.
//!
//! Estimators that splat (BDPT's t = 1 strategies) write into one of
//! [`LANES`] full-raster splat buffers: tile i goes to lane i mod LANES, the
//! tiles of a lane run in order, and lanes are merged in order. The sum is
//! therefore the same for any thread count too.

use super::{PixelEstimator, RenderContext};
use crate::camera::CameraSample;
use crate::film::{FilmTile, RgbFilm, SplatBuffer};
use crate::math::{UVec2, Vec2};
use crate::sampler::Sampler;
use crate::spectrum::SampledWavelengths;
use rayon::prelude::*;

/// Tile side in pixels.
pub const TILE: u32 = 16;
/// Splat lanes (fixed, so splat sums do not depend on the thread count).
pub const LANES: usize = 8;

/// Renders every pixel of `film` with `estimator`.
pub fn render_pixels(est: &dyn PixelEstimator, ctx: &RenderContext<'_>, film: &mut RgbFilm) {
    let tiles = tiles(film.pixel_bounds());
    let spp = ctx.sampler.samples_per_pixel();
    ctx.progress
        .start(tiles.len() as u64 * spp as u64, "tile·spp");
    let splats = est.splats();
    let lanes: Vec<(Vec<FilmTile>, SplatBuffer)> = (0..LANES)
        .into_par_iter()
        .map(|lane| {
            let mut buf = if splats {
                film.splat_buffer()
            } else {
                SplatBuffer::disabled()
            };
            let done: Vec<FilmTile> = tiles
                .iter()
                .skip(lane)
                .step_by(LANES)
                .map(|&(lo, hi)| {
                    let tile = render_tile(est, ctx, film, lo, hi, &mut buf);
                    ctx.progress.advance(spp as u64);
                    tile
                })
                .collect();
            (done, buf)
        })
        .collect();
    for (done, buf) in lanes {
        for tile in done {
            film.merge_tile(tile);
        }
        film.merge_splats(buf);
    }
    if splats {
        film.set_splat_scale(1.0 / spp as f64);
    }
    ctx.progress.finish();
}

/// The 16×16 tiles covering the pixel bounds, in scanline order.
pub(crate) fn tiles(bounds: (UVec2, UVec2)) -> Vec<(UVec2, UVec2)> {
    let (w, h) = (bounds.1.x - bounds.0.x, bounds.1.y - bounds.0.y);
    (0..h.div_ceil(TILE))
        .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx, ty)))
        .map(|(tx, ty)| {
            let lo = bounds.0 + UVec2::new(tx * TILE, ty * TILE);
            (lo, (lo + UVec2::splat(TILE)).min(bounds.1))
        })
        .collect()
}

fn render_tile(
    est: &dyn PixelEstimator,
    ctx: &RenderContext<'_>,
    film: &RgbFilm,
    lo: UVec2,
    hi: UVec2,
    splats: &mut SplatBuffer,
) -> FilmTile {
    let mut tile = film.tile(lo, hi);
    let mut sampler = ctx.sampler.clone();
    for y in lo.y..hi.y {
        for x in lo.x..hi.x {
            let pixel = UVec2::new(x, y);
            for index in 0..sampler.samples_per_pixel() {
                sampler.start_pixel_sample(pixel, index, 0);
                render_sample(est, ctx, film, &mut tile, pixel, &mut sampler, splats);
            }
        }
    }
    tile
}

fn render_sample(
    est: &dyn PixelEstimator,
    ctx: &RenderContext<'_>,
    film: &RgbFilm,
    tile: &mut FilmTile,
    pixel: UVec2,
    sampler: &mut Sampler,
    splats: &mut SplatBuffer,
) {
    let Some(mut cs) = camera_sample(ctx, film, pixel, sampler) else {
        return;
    };
    let l = est.li(ctx, cs.ray, &mut cs.lambda, sampler, splats) * cs.ray_weight;
    tile.add_sample(pixel, l, &cs.lambda, cs.filter_weight);
}

/// The primary ray of one pixel sample and what the film needs to record it.
pub(crate) struct PixelSample {
    /// The camera ray.
    pub ray: crate::math::Ray,
    /// Its weight (1 for candela's cameras).
    pub ray_weight: f32,
    /// Sampled wavelengths.
    pub lambda: SampledWavelengths,
    /// Filter-sample weight.
    pub filter_weight: f32,
}

/// Draws wavelengths, a filter offset and a lens point for `pixel`, in
/// pbrt-v4's `GetCameraSample` order, and generates the camera ray.
pub(crate) fn camera_sample(
    ctx: &RenderContext<'_>,
    film: &RgbFilm,
    pixel: UVec2,
    sampler: &mut Sampler,
) -> Option<PixelSample> {
    let lambda = SampledWavelengths::sample_visible(sampler.get_1d());
    let fs = film.filter().sample(sampler.get_pixel_2d());
    let p_film = pixel.as_vec2() + Vec2::splat(0.5) + fs.p;
    let time = ctx.scene.sample_time(|| sampler.get_1d());
    let p_lens = sampler.get_2d();
    let cr = ctx.camera.generate_ray(CameraSample { p_film, p_lens })?;
    Some(PixelSample {
        ray: cr.ray.at_time(time),
        ray_weight: cr.weight,
        lambda,
        filter_weight: fs.weight,
    })
}
