//! The parallel, deterministic pixel loop of one pass.
//!
//! The image is cut into 16×16 tiles rendered in parallel by rayon. Every
//! pixel sample reseeds the sampler from (pixel, pass, seed) and each pixel
//! is written by exactly one tile, so a pass's block is bit-identical for
//! any thread count and schedule.
//!
//! Estimators that splat (BDPT's t = 1 strategies) record their splats per
//! tile; they are summed into one of [`LANES`] splat buffers over the pixel
//! bounds, tile i into lane i mod LANES, the tiles of a lane in order (the
//! lanes in parallel), and lanes are added to the block in order, so splat
//! sums do not depend on the thread count either. Tiles, not lanes, are
//! the tasks: with lanes as tasks two threads shared eight units of work
//! per pass and waited for each other at its end (from one thread to two
//! on the Cornell box, `bench/peers_speed.py --cases scaling`: the path
//! tracer 1.60× with lanes, 1.92× with tiles; BDPT 1.68×, 1.89×).

use super::{PassOutcome, PixelEstimator, RenderContext};
use crate::camera::CameraSample;
use crate::film::{FilmTile, PassBlock, SplatBuffer, SplatRecord};
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
    // Rendered a batch at a time, so the recorded splats of a batch are all
    // that is held: 512 tiles of 256 pixels, 56 bytes a splat, 7.3 MB per
    // splat per pixel sample (BDPT makes one per light vertex that sees the
    // lens). A batch is enough tiles that its end idles a thread for at most
    // one tile of 256 per thread.
    const BATCH: usize = 64 * LANES;
    let mut lanes: Vec<Option<SplatBuffer>> = (0..LANES).map(|_| None).collect();
    for (b, batch) in tiles.chunks(BATCH).enumerate() {
        let Some(done) = render_batch(est, ctx, pass, batch) else {
            return PassOutcome::Cancelled;
        };
        for (tile, _) in &done {
            block.add_tile(tile);
        }
        if est.splats() {
            replay_lanes(ctx, &mut lanes, b * BATCH, &done);
        }
    }
    for buf in lanes.iter().flatten() {
        block.add_splats(buf);
    }
    PassOutcome::Done
}

/// The tiles of `batch`, each a task of its own, with the splats each
/// recorded, in the batch's order whatever thread rendered them; `None` if
/// the render was cancelled.
fn render_batch(
    est: &dyn PixelEstimator,
    ctx: &RenderContext<'_>,
    pass: u64,
    batch: &[(UVec2, UVec2)],
) -> Option<Vec<(FilmTile, Vec<SplatRecord>)>> {
    batch
        .par_iter()
        .map_init(
            || SplatBuffer::recording(ctx.film),
            |rec, &(lo, hi)| {
                if ctx.cancelled() {
                    return None;
                }
                let tile = render_tile(est, ctx, pass, lo, hi, rec);
                ctx.advance(u64::from((hi.x - lo.x) * (hi.y - lo.y)));
                Some((tile, rec.take_records()))
            },
        )
        .collect()
}

/// Adds the splats of the tiles `done` (the first of them tile `first` of
/// the pass) to the lanes, tile i to lane i mod [`LANES`] in tile order,
/// the lanes in parallel (module doc).
fn replay_lanes(
    ctx: &RenderContext<'_>,
    lanes: &mut [Option<SplatBuffer>],
    first: usize,
    done: &[(FilmTile, Vec<SplatRecord>)],
) {
    lanes.par_iter_mut().enumerate().for_each(|(lane, buf)| {
        let skip = (lane + LANES - first % LANES) % LANES;
        for (_, records) in done.iter().skip(skip).step_by(LANES) {
            if !records.is_empty() {
                buf.get_or_insert_with(|| ctx.film.splat_buffer())
                    .replay(records);
            }
        }
    });
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
