//! The parallel, deterministic pixel loop of one pass.
//!
//! The image is cut into 16×16 tiles rendered in parallel by rayon. Every
//! pixel sample reseeds the sampler from (pixel, pass, seed) and each pixel
//! is written by exactly one tile, so a pass's block is bit-identical for
//! any thread count and schedule.
//!
//! Estimators that splat (BDPT's t = 1 strategies) write into one of
//! [`LANES`] splat buffers over the pixel bounds: tile i goes to lane
//! i mod LANES, the tiles of a lane run in order, and lanes are added to the
//! block in order, so splat sums do not depend on the thread count either.

use super::{PassOutcome, PixelEstimator, RenderContext};
use crate::camera::CameraSample;
use crate::film::{Film, FilmTile, PassBlock, SplatBuffer};
use crate::math::{UVec2, Vec2};
use crate::sampler::Sampler;
use crate::spectrum::SampledWavelengths;
use rayon::prelude::*;

/// Tile side in pixels.
pub const TILE: u32 = 16;
/// Splat lanes (fixed, so splat sums do not depend on the thread count).
pub const LANES: usize = 8;

/// Renders sample `pass` of every pixel with `est` into `block`.
pub fn render_pixels(
    est: &dyn PixelEstimator,
    ctx: &RenderContext<'_>,
    pass: u64,
    block: &mut PassBlock,
) -> PassOutcome {
    let tiles = tiles(ctx.film.pixel_bounds());
    let splats = est.splats();
    let lanes: Vec<(Vec<FilmTile>, Option<SplatBuffer>)> = (0..LANES)
        .into_par_iter()
        .map(|lane| {
            let mut buf = splats.then(|| ctx.film.splat_buffer());
            let mut disabled = None;
            let done: Vec<FilmTile> = tiles
                .iter()
                .skip(lane)
                .step_by(LANES)
                .map_while(|&(lo, hi)| {
                    if ctx.cancelled() {
                        return None;
                    }
                    let splat = match buf.as_mut() {
                        Some(b) => b,
                        None => disabled.get_or_insert_with(|| empty_splats(ctx.film)),
                    };
                    let tile = render_tile(est, ctx, pass, lo, hi, splat);
                    ctx.advance(u64::from((hi.x - lo.x) * (hi.y - lo.y)));
                    Some(tile)
                })
                .collect();
            (done, buf)
        })
        .collect();
    if ctx.cancelled() {
        return PassOutcome::Cancelled;
    }
    for (done, buf) in lanes {
        for tile in &done {
            block.add_tile(tile);
        }
        if let Some(b) = &buf {
            block.add_splats(b);
        }
    }
    PassOutcome::Done
}

/// A splat buffer with no pixels, for estimators that never splat.
fn empty_splats(film: &Film) -> SplatBuffer {
    let lo = film.pixel_bounds().0;
    SplatBuffer::empty_at(lo, film)
}

/// Runs `f` on every tile of the film in parallel; the results come back in
/// scanline tile order, or `None` if the render was cancelled meanwhile.
pub fn for_each_tile<T: Send>(
    ctx: &RenderContext<'_>,
    f: impl Fn(UVec2, UVec2) -> T + Sync,
) -> Option<Vec<T>> {
    let out: Vec<Option<T>> = tiles(ctx.film.pixel_bounds())
        .into_par_iter()
        .map(|(lo, hi)| (!ctx.cancelled()).then(|| f(lo, hi)))
        .collect();
    out.into_iter().collect()
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
    pass: u64,
    lo: UVec2,
    hi: UVec2,
    splats: &mut SplatBuffer,
) -> FilmTile {
    let mut tile = ctx.film.tile(lo, hi);
    let mut sampler = ctx.sampler.clone();
    for y in lo.y..hi.y {
        for x in lo.x..hi.x {
            let pixel = UVec2::new(x, y);
            sampler.start_pixel_sample(pixel, pass as u32, 0);
            let Some(mut cs) = camera_sample(ctx, pixel, &mut sampler) else {
                continue;
            };
            let l = est.li(ctx, cs.ray, &mut cs.lambda, &mut sampler, splats) * cs.ray_weight;
            tile.add_sample(pixel, l, &cs.lambda, cs.filter_weight);
        }
    }
    tile
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
    /// The film and lens points the ray was generated from.
    pub camera_sample: CameraSample,
}

/// Draws wavelengths, a filter offset and a lens point for `pixel`, in
/// pbrt-v4's `GetCameraSample` order, and generates the camera ray.
pub(crate) fn camera_sample(
    ctx: &RenderContext<'_>,
    pixel: UVec2,
    sampler: &mut Sampler,
) -> Option<PixelSample> {
    let lambda = SampledWavelengths::sample_visible(sampler.get_1d());
    let fs = ctx.film.filter().sample(sampler.get_pixel_2d());
    let p_film = pixel.as_vec2() + Vec2::splat(0.5) + fs.p;
    let time = ctx.scene.sample_time(|| sampler.get_1d());
    let p_lens = sampler.get_2d();
    let camera_sample = CameraSample { p_film, p_lens };
    let cr = ctx.camera.generate_ray(camera_sample)?;
    Some(PixelSample {
        ray: cr.ray.at_time(time),
        ray_weight: cr.weight,
        lambda,
        filter_weight: fs.weight,
        camera_sample,
    })
}
