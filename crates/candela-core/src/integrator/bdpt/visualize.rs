//! pbrt's `visualizestrategies` and `visualizeweights`: one image per
//! strategy (s, t), written as `bdpt_d{depth}_s{s}_t{t}.exr` beside the
//! output image [pbrt-v3 `BDPTIntegrator::Render`].
//!
//! With `visualizestrategies` each image holds the strategy's unweighted
//! contribution (what it would estimate alone); with `visualizeweights` its
//! MIS-weighted contribution, so the images of one depth sum to that depth's
//! share of the final image. Every contribution is splatted (camera-side ones
//! at the pixel centre) and scaled by 1/spp. Pixels are processed in two
//! fixed lanes merged in order, so the images are deterministic; memory is
//! 2 × strategies × pixels × 24 bytes.

use super::BdptIntegrator;
use crate::film::{RgbFilm, SplatBuffer};
use crate::image::RgbImage;
use crate::integrator::driver::{camera_sample, tiles};
use crate::integrator::RenderContext;
use crate::math::{UVec2, Vec2};
use rayon::prelude::*;
use std::path::PathBuf;

/// Which per-strategy images to write.
#[derive(Clone, Debug, PartialEq)]
pub struct Visualize {
    /// True: MIS-weighted contributions (`visualizeweights`); false: unweighted.
    pub weighted: bool,
    /// Directory the images are written to.
    pub dir: PathBuf,
}

const LANES: usize = 2;

/// Index of strategy (s, t): depth d = s + t − 2 has the d + 3 strategies
/// s = 0…d + 2, stored after those of the smaller depths.
fn index(s: usize, t: usize) -> usize {
    let depth = s + t - 2;
    depth * (depth + 5) / 2 + s
}

/// Renders the main image and the per-strategy images.
pub(super) fn render(
    bdpt: &BdptIntegrator,
    v: &Visualize,
    ctx: &RenderContext<'_>,
    film: &mut RgbFilm,
) {
    let max_depth = bdpt.settings.max_depth as usize;
    // Σ_{d ≤ max_depth} (d + 3) strategies.
    let n_strategies = (max_depth + 1) * (max_depth + 6) / 2;
    let tiles = tiles(film.pixel_bounds());
    let spp = ctx.sampler.samples_per_pixel();
    ctx.progress.start(tiles.len() as u64, "tiles");
    let lanes: Vec<(SplatBuffer, Vec<SplatBuffer>)> = (0..LANES)
        .into_par_iter()
        .map(|lane| {
            let mut main = film.splat_buffer();
            let mut per: Vec<SplatBuffer> =
                (0..n_strategies).map(|_| film.splat_buffer()).collect();
            for &(lo, hi) in tiles.iter().skip(lane).step_by(LANES) {
                let mut sampler = ctx.sampler.clone();
                for y in lo.y..hi.y {
                    for x in lo.x..hi.x {
                        let pixel = UVec2::new(x, y);
                        let centre = pixel.as_vec2() + Vec2::splat(0.5);
                        for i in 0..spp {
                            sampler.start_pixel_sample(pixel, i, 0);
                            let Some(mut cs) = camera_sample(ctx, film, pixel, &mut sampler) else {
                                continue;
                            };
                            let w = cs.ray_weight;
                            bdpt.sample_strategies(
                                ctx,
                                cs.ray,
                                &mut cs.lambda,
                                &mut sampler,
                                |s, t, c, lambda| {
                                    let p = c.p_raster.unwrap_or(centre);
                                    main.add(p, c.weighted * w, lambda);
                                    let value = if v.weighted { c.weighted } else { c.unweighted };
                                    per[index(s, t)].add(p, value * w, lambda);
                                },
                            );
                        }
                    }
                }
                ctx.progress.advance(1);
            }
            (main, per)
        })
        .collect();
    let mut images: Vec<RgbFilm> = (0..n_strategies).map(|_| film.cleared()).collect();
    for (main, per) in lanes {
        film.merge_splats(main);
        for (img, buf) in images.iter_mut().zip(per) {
            img.merge_splats(buf);
        }
    }
    film.set_splat_scale(1.0 / spp as f64);
    for depth in 0..=max_depth {
        for s in 0..=depth + 2 {
            let t = depth + 2 - s;
            if t == 0 {
                continue;
            }
            let img = &mut images[index(s, t)];
            img.set_splat_scale(1.0 / spp as f64);
            let name = format!("bdpt_d{depth:02}_s{s:02}_t{t:02}.exr");
            write(&img.image(), &v.dir.join(name));
        }
    }
    ctx.progress.finish();
}

fn write(img: &RgbImage, path: &std::path::Path) {
    if let Err(e) = img.write_exr(path) {
        eprintln!("warning: could not write {}: {e}", path.display());
    }
}
