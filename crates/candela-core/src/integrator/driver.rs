//! The parallel, deterministic pixel loop of one pass.
//!
//! The image is cut into 16×16 tiles rendered in parallel by rayon. Every
//! pixel sample reseeds the sampler from (pixel, pass, seed) and each pixel
//! is written by exactly one tile, so a pass's block is bit-identical for
//! any thread count and schedule.
//!
//! Estimators that splat (BDPT's t = 1 strategies) record their splats per
//! tile; they are summed by horizontal bands of the film in tile order
//! ([`crate::film::SplatBands`]), so splat sums do not depend on the thread
//! count either. (Until stop 37 tile i went to one of eight lanes, i mod 8,
//! each a buffer over the whole film: 12.6 MB made, zeroed and added to the
//! block per pass at 256², on the Cornell box's BDPT four fifths of the
//! process's page faults.) Tiles are the rendering tasks: with eight lanes
//! as tasks two threads shared eight units of work per pass and waited for
//! each other at its end (from one thread to two on the Cornell box,
//! `bench/peers_speed.py --cases scaling`: the path tracer 1.60× with lanes,
//! 1.92× with tiles; BDPT 1.68×, 1.89×).
//!
//! Passes that trace from the lights instead of the pixels (light tracing,
//! VCM's light subpaths) split their paths into chunks, each a task, and
//! sum the chunks' splats the same way in chunk order ([`splat_tasks`]).

use super::{PassOutcome, PixelEstimator, RenderContext};
use crate::camera::CameraSample;
use crate::film::{FilmTile, PassBlock, PassSplats, SplatBuffer, SplatRecord};
use crate::math::{UVec2, Vec2};
use crate::sampler::Sampler;
use crate::spectrum::SampledWavelengths;
use rayon::prelude::*;

/// Tile side in pixels.
pub const TILE: u32 = 16;
/// Horizontal bands of the film that sum a pass's splats in parallel.
pub const BANDS: usize = 8;

/// Renders sample `pass` of every pixel with `est` into `block`.
pub fn render_pixels(
    est: &dyn PixelEstimator,
    ctx: &RenderContext<'_>,
    pass: u64,
    block: &mut PassBlock,
) -> PassOutcome {
    let tiles = tiles(ctx.film.pixel_bounds());
    // A batch of 512 tiles of 256 pixels holds 7.3 MB of records per splat
    // per pixel sample (BDPT makes one per light vertex that sees the lens),
    // and its end idles a thread for at most one tile of 256 per thread.
    const BATCH: u64 = 512;
    let task = |i: u64, rec: &mut SplatBuffer| {
        let (lo, hi) = tiles[i as usize];
        let tile = render_tile(est, ctx, pass, lo, hi, rec);
        ctx.advance(u64::from((hi.x - lo.x) * (hi.y - lo.y)));
        tile
    };
    let add_tiles = |done: Vec<FilmTile>| done.iter().for_each(|t| block.add_tile(t));
    let Some(splats) = splat_tasks(ctx, tiles.len() as u64, BATCH, task, add_tiles) else {
        return PassOutcome::Cancelled;
    };
    splats.add_to(block);
    PassOutcome::Done
}

/// Runs tasks `0..n_tasks` in parallel, `batch` at a time (only a batch's
/// recorded splats are held), `task(i, recorder)` recording its splats;
/// hands each batch's results, in task order, to `batch_done`, and returns
/// the splats summed by bands in task order (so the sums do not depend on
/// the thread count), or `None` if the render was cancelled.
pub fn splat_tasks<T: Send>(
    ctx: &RenderContext<'_>,
    n_tasks: u64,
    batch: u64,
    task: impl Fn(u64, &mut SplatBuffer) -> T + Sync,
    mut batch_done: impl FnMut(Vec<T>),
) -> Option<PassSplats> {
    let mut splats = PassSplats::new(ctx.film, BANDS);
    for first in (0..n_tasks).step_by(batch.max(1) as usize) {
        let rows = splats.rows();
        let done: Option<Vec<(T, Vec<Vec<SplatRecord>>)>> = (first..(first + batch).min(n_tasks))
            .into_par_iter()
            .map_init(
                || SplatBuffer::recording(ctx.film),
                |rec, i| {
                    if ctx.cancelled() {
                        return None;
                    }
                    let out = task(i, rec);
                    Some((out, rows.split(&rec.take_records())))
                },
            )
            .collect();
        let (outs, split): (Vec<T>, Vec<_>) = done?.into_iter().unzip();
        splats.add(ctx.film, split.iter().map(Vec::as_slice));
        batch_done(outs);
    }
    Some(splats)
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
            let l = est.li_pixel(ctx, pixel, cs.ray, &mut cs.lambda, &mut sampler, splats)
                * cs.ray_weight;
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
