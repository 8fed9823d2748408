//! Shared helpers for the integration tests: render a scene given as text
//! and measure image statistics.
//!
//! Each test binary includes this module and uses only part of it.
#![allow(dead_code)]

pub mod stats;

use candela_core::build::{build, Overrides};
use candela_core::image::RgbImage;
use std::path::Path;

/// Renders pbrt-v4 scene text with the given overrides; asserts no sample was dropped.
#[allow(dead_code)] // Not every test crate renders from text alone.
pub fn render_str(text: &str, ov: &Overrides) -> RgbImage {
    render_at(text, Path::new("test.pbrt"), ov).0
}

/// Block means (`stats::block_means`) of `k` renders of `text` with the
/// overrides `ov` and seeds `first_seed`, `first_seed` + 1, …, as
/// `[block][render]` (`stats::by_block`): K independent estimates of every
/// block, for `stats::assert_blocks_agree`.
pub fn seeded_block_means(text: &str, ov: &Overrides, first_seed: u64, k: usize) -> Vec<Vec<f64>> {
    let renders: Vec<Vec<f64>> = (0..k as u64)
        .map(|i| {
            let ov = Overrides {
                seed: Some(first_seed + i),
                ..ov.clone()
            };
            stats::block_means(&render_str(text, &ov))
        })
        .collect();
    stats::by_block(&renders)
}

/// Renders scene text as if read from `path` (relative files resolve beside
/// it); returns the image and the build warnings.
pub fn render_at(text: &str, path: &Path, ov: &Overrides) -> (RgbImage, Vec<String>) {
    let desc = candela_scene::parse_str(text, path).expect("scene parses");
    let setup = build(&desc, ov).expect("scene builds");
    let (image, state) = candela_core::render::render_all(&setup);
    assert_eq!(state.film.dropped(), 0, "non-finite samples were produced");
    (image.rgb(), setup.warnings)
}

/// Renders pbrt-v4 scene text and returns the developed film (every layer,
/// BDPT's strategy images included).
#[allow(dead_code)] // Not every test crate needs the layers.
pub fn render_developed(text: &str, ov: &Overrides) -> candela_core::film::Developed {
    let desc = candela_scene::parse_str(text, Path::new("test.pbrt")).expect("scene parses");
    let setup = build(&desc, ov).expect("scene builds");
    let (dev, state) = candela_core::render::render_all(&setup);
    assert_eq!(state.film.dropped(), 0, "non-finite samples were produced");
    dev
}

/// Mean and standard error of the mean of channel `c` over pixels in `[x0,x1)×[y0,y1)`.
/// Pixels are independent estimates (each reseeds its sampler), so the
/// standard error is the pixel standard deviation / √n.
#[allow(dead_code)] // Not every test crate measures regions.
pub fn region_mean(
    img: &RgbImage,
    c: usize,
    x0: usize,
    x1: usize,
    y0: usize,
    y1: usize,
) -> (f64, f64) {
    let vals: Vec<f64> = (y0..y1)
        .flat_map(|y| (x0..x1).map(move |x| (x, y)))
        .map(|(x, y)| img.get(x, y)[c] as f64)
        .collect();
    let n = vals.len() as f64;
    let mean = vals.iter().sum::<f64>() / n;
    let var = vals.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Asserts `|mean − expected| ≤ 5σ + b` for every channel of the region (validation.md's rule).
#[allow(dead_code)] // Not every test crate measures regions.
pub fn assert_region(
    img: &RgbImage,
    region: (usize, usize, usize, usize),
    expected: f64,
    b: f64,
    what: &str,
) {
    for c in 0..3 {
        let (m, se) = region_mean(img, c, region.0, region.1, region.2, region.3);
        eprintln!("{what}: channel {c}: mean {m:.6} ± {se:.6} (expected {expected})");
        assert!(
            (m - expected).abs() <= 5.0 * se + b,
            "{what}: channel {c} mean {m} vs {expected} (σ {se}, b {b})"
        );
    }
}
