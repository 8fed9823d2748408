//! Image comparison metrics: per-channel mean ratio, relMSE (ε = 0.01),
//! MAE, and the worst ratio of 32×32-block means.

use super::{ImageError, RgbImage};

/// The numbers `candela diff` prints.
#[derive(Clone, Debug, PartialEq)]
pub struct Comparison {
    /// Mean of A / mean of B, per channel.
    pub mean_ratio: [f64; 3],
    /// ⟨(A − B)² / (B² + ε)⟩ with ε = 0.01, over pixels and channels.
    pub rel_mse: f64,
    /// The same without the [`TRIM`] share of pixels with the largest
    /// error (at least one): a robust companion for heavy-tailed noise, where
    /// one rare sample can carry most of `rel_mse`.
    pub rel_mse_trimmed: f64,
    /// ⟨|A − B|⟩.
    pub mae: f64,
    /// The 32×32 block (of luminance-like channel sums) whose mean ratio
    /// A/B is farthest from 1: (ratio, block x, block y).
    pub worst_block: (f64, usize, usize),
}

/// The NaN or infinite pixels of an image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NonFinite {
    /// How many pixels have at least one non-finite channel.
    pub count: usize,
    /// The first such pixel in row order, as (x, y).
    pub first: (usize, usize),
}

/// The pixels of `img` with a NaN or infinite channel, or `None` if there
/// are none. Metrics over such pixels are NaN, so `candela diff` reports
/// these instead.
pub fn non_finite(img: &RgbImage) -> Option<NonFinite> {
    let bad = |p: &[f32; 3]| p.iter().any(|c| !c.is_finite());
    let first = img.pixels.iter().position(bad)?;
    let width = img.width.max(1);
    Some(NonFinite {
        count: img.pixels.iter().filter(|p| bad(p)).count(),
        first: (first % width, first / width),
    })
}

/// Share of pixels [`Comparison::rel_mse_trimmed`] leaves out.
pub const TRIM: f64 = 0.001;

/// Side of the blocks in [`Comparison::worst_block`].
pub const BLOCK: usize = 32;

/// Compares `a` against the reference `b`.
pub fn compare(a: &RgbImage, b: &RgbImage) -> Result<Comparison, ImageError> {
    if a.width != b.width || a.height != b.height {
        return Err(ImageError::SizeMismatch(
            a.width, a.height, b.width, b.height,
        ));
    }
    let (ma, mb) = (a.channel_means(), b.channel_means());
    let mean_ratio = std::array::from_fn(|c| {
        if mb[c] != 0.0 {
            ma[c] / mb[c]
        } else {
            f64::NAN
        }
    });
    let mut abs = 0.0f64;
    let mut per_pixel = Vec::with_capacity(a.pixels.len());
    for (pa, pb) in a.pixels.iter().zip(&b.pixels) {
        let mut rel = 0.0f64;
        for c in 0..3 {
            let (x, y) = (pa[c] as f64, pb[c] as f64);
            rel += (x - y) * (x - y) / (y * y + 0.01);
            abs += (x - y).abs();
        }
        per_pixel.push(rel);
    }
    let n = (a.pixels.len() * 3).max(1) as f64;
    let rel: f64 = per_pixel.iter().sum();
    per_pixel.sort_by(f64::total_cmp);
    let drop = ((per_pixel.len() as f64 * TRIM) as usize).max(1);
    let kept = &per_pixel[..per_pixel.len().saturating_sub(drop)];
    Ok(Comparison {
        mean_ratio,
        rel_mse: rel / n,
        rel_mse_trimmed: kept.iter().sum::<f64>() / (kept.len() * 3).max(1) as f64,
        mae: abs / n,
        worst_block: worst_block(a, b),
    })
}

fn block_sum(img: &RgbImage, bx: usize, by: usize) -> f64 {
    let mut s = 0.0;
    for y in by * BLOCK..((by + 1) * BLOCK).min(img.height) {
        for x in bx * BLOCK..((bx + 1) * BLOCK).min(img.width) {
            let p = img.get(x, y);
            s += (p[0] + p[1] + p[2]) as f64;
        }
    }
    s
}

fn worst_block(a: &RgbImage, b: &RgbImage) -> (f64, usize, usize) {
    let mut worst = (1.0f64, 0, 0);
    for by in 0..a.height.div_ceil(BLOCK) {
        for bx in 0..a.width.div_ceil(BLOCK) {
            let (sa, sb) = (block_sum(a, bx, by), block_sum(b, bx, by));
            if sb <= 0.0 {
                continue;
            }
            let r = sa / sb;
            if (r.ln()).abs() > worst.0.ln().abs() || !r.is_finite() {
                worst = (r, bx, by);
            }
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn metrics_of_a_scaled_image() {
        let mut b = RgbImage::new(64, 64);
        for (i, p) in b.pixels.iter_mut().enumerate() {
            *p = [1.0 + (i % 7) as f32, 2.0, 0.5];
        }
        let mut a = b.clone();
        // Brighten one block by 10 %.
        for y in 32..64 {
            for x in 0..32 {
                let p = &mut a.pixels[y * 64 + x];
                *p = p.map(|v| v * 1.1);
            }
        }
        let c = compare(&a, &b).unwrap();
        assert!((c.worst_block.0 - 1.1).abs() < 1e-5);
        assert_eq!((c.worst_block.1, c.worst_block.2), (0, 1));
        // Channels 1 and 2 are constant, so a quarter of the image at +10 % gives +2.5 %.
        assert!((c.mean_ratio[1] - 1.025).abs() < 1e-5 && (c.mean_ratio[2] - 1.025).abs() < 1e-5);
        assert!(c.mae > 0.0 && c.rel_mse > 0.0);
        let same = compare(&b, &b).unwrap();
        assert_eq!((same.rel_mse, same.mae), (0.0, 0.0));
        // One wild pixel of 4096: it carries the relMSE, the trimmed one drops it.
        let mut c1 = b.clone();
        c1.pixels[100] = [1e3; 3];
        let c1 = compare(&c1, &b).unwrap();
        assert!(c1.rel_mse > 1.0 && c1.rel_mse_trimmed == 0.0, "{c1:?}");
        let t = compare(&a, &b).unwrap().rel_mse_trimmed;
        assert!(
            t > 0.0 && t >= c.rel_mse * 0.99 && t <= c.rel_mse * 1.01,
            "{t}"
        );
        assert!(compare(&a, &RgbImage::new(3, 3)).is_err());
    }

    #[test]
    fn non_finite_pixels_are_counted_with_the_first_position() {
        let mut img = RgbImage::new(5, 4);
        assert_eq!(non_finite(&img), None);
        img.pixels[2 * 5 + 3][1] = f32::NAN;
        img.pixels[3 * 5][2] = f32::INFINITY;
        img.pixels[3 * 5 + 1] = [f32::NEG_INFINITY, f32::NAN, 0.0];
        let nf = non_finite(&img).unwrap();
        assert_eq!(
            nf,
            NonFinite {
                count: 3,
                first: (3, 2)
            }
        );
    }
}
