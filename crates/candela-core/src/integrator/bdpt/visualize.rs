//! pbrt's `visualizestrategies` and `visualizeweights`: one image per
//! strategy (s, t), written as `bdpt_d{depth}_s{s}_t{t}.exr` beside the
//! output image [pbrt-v3 `BDPTIntegrator::Render`].
//!
//! With `visualizestrategies` each image holds the strategy's unweighted
//! contribution (what it would estimate alone); with `visualizeweights` its
//! MIS-weighted contribution, so the images of one depth sum to that depth's
//! share of the final image. Every contribution is splatted (camera-side ones
//! at the pixel centre) and averaged over the passes: they are layers
//! of the film, written as separate files when the image is. Pixels are
//! processed in two fixed lanes added in order, so the images are
//! deterministic; memory is 2 × strategies × pixels × 24 bytes per pass.

use super::BdptIntegrator;
use crate::film::{PassBlock, SplatBuffer};
use crate::integrator::driver::{camera_sample, tiles};
use crate::integrator::lt_weights::DENSITY;
use crate::integrator::{PassOutcome, RenderContext};
use crate::math::{UVec2, Vec2};
use rayon::prelude::*;

/// Which per-strategy images to write.
#[derive(Clone, Debug, PartialEq)]
pub struct Visualize {
    /// True: MIS-weighted contributions (`visualizeweights`); false: unweighted.
    pub weighted: bool,
}

impl Visualize {
    /// Number of strategy images for `max_depth`: Σ_{d ≤ max_depth} (d + 3).
    pub fn strategy_count(max_depth: u32) -> usize {
        let d = max_depth as usize;
        (d + 1) * (d + 6) / 2
    }

    /// File name of every strategy image, by strategy index (`None` for the
    /// unused t = 0 slots).
    pub fn file_names(max_depth: u32) -> Vec<Option<String>> {
        let mut names = vec![None; Self::strategy_count(max_depth)];
        for depth in 0..=max_depth as usize {
            for s in 0..=depth + 2 {
                let t = depth + 2 - s;
                if t > 0 {
                    names[index(s, t)] = Some(format!("bdpt_d{depth:02}_s{s:02}_t{t:02}.exr"));
                }
            }
        }
        names
    }
}

const LANES: usize = 2;

/// Index of strategy (s, t): depth d = s + t − 2 has the d + 3 strategies
/// s = 0…d + 2, stored after those of the smaller depths.
fn index(s: usize, t: usize) -> usize {
    let depth = s + t - 2;
    depth * (depth + 5) / 2 + s
}

/// Renders sample `pass` of every pixel into the main layer and the
/// strategy layers of `block`.
pub(super) fn render_pass(
    bdpt: &BdptIntegrator,
    v: &Visualize,
    ctx: &RenderContext<'_>,
    pass: u64,
    block: &mut PassBlock,
) -> PassOutcome {
    let n_strategies = Visualize::strategy_count(bdpt.settings.max_depth);
    let tiles = tiles(ctx.film.pixel_bounds());
    let lanes: Vec<(SplatBuffer, Vec<SplatBuffer>)> = (0..LANES)
        .into_par_iter()
        .map(|lane| {
            let mut main = ctx.film.splat_buffer();
            let mut per: Vec<SplatBuffer> = (0..n_strategies)
                .map(|_| ctx.film.strategy_buffer())
                .collect();
            for &(lo, hi) in tiles.iter().skip(lane).step_by(LANES) {
                if ctx.cancelled() {
                    break;
                }
                let mut sampler = ctx.sampler.clone();
                for y in lo.y..hi.y {
                    for x in lo.x..hi.x {
                        let pixel = UVec2::new(x, y);
                        let centre = pixel.as_vec2() + Vec2::splat(0.5);
                        sampler.start_pixel_sample(pixel, pass as u32, 0);
                        let Some(mut cs) = camera_sample(ctx, pixel, &mut sampler) else {
                            continue;
                        };
                        let w = cs.ray_weight;
                        bdpt.sample_strategies(
                            ctx,
                            cs.ray,
                            &mut cs.lambda,
                            &mut sampler,
                            &DENSITY,
                            false,
                            |s, t, c, lambda| {
                                let p = c.p_raster.unwrap_or(centre);
                                main.add(p, c.weighted * w, lambda);
                                let value = if v.weighted { c.weighted } else { c.unweighted };
                                per[index(s, t)].add(p, value * w, lambda);
                            },
                        );
                    }
                }
                ctx.advance(u64::from((hi.x - lo.x) * (hi.y - lo.y)));
            }
            (main, per)
        })
        .collect();
    if ctx.cancelled() {
        return PassOutcome::Cancelled;
    }
    for (main, per) in lanes {
        block.add_splats(&main);
        for (k, buf) in per.iter().enumerate() {
            block.add_strategy(k, buf);
        }
    }
    PassOutcome::Done
}
