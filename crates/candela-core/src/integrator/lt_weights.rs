//! Variance-aware weights for light tracing [Grittmann, Georgiev, Slusallek
//! & Křivánek 2019, "Variance-aware multiple importance sampling"], shared
//! by `vcm` and `bdpt` (`"string ltweights" "variance"`, their default).
//!
//! The power heuristic weighs techniques by their densities as if each
//! one's variance were its second moment ∫f²/p [Veach 1997, §9.2]. That
//! holds for light tracing (t = 1): the splats a pixel gets in a pass are a
//! Poisson count, unstratified over the image, so its variance in a pixel
//! is nearly its second moment. It does not hold for the camera's
//! techniques, which draw one sample inside each pixel: their variance
//! there is the second moment minus I² (I the pixel's value), and where
//! next-event estimation has almost constant f/p (diffuse surfaces under a
//! small light) that difference is most of it.
//!
//! So light tracing's term in every weight of a path, mis(p_LT) under the
//! power heuristic, is multiplied by a factor c ∈ (0, 1] of the image block
//! and the path length k (scattering vertices) of the path's end seen by
//! the camera: c = V / M, the camera techniques' variance over their second
//! moment, light tracing's own V / M taken as 1. This is the variance-aware
//! heuristic's division of each technique's term by its variance factor.
//! Any factor that is a function of the path alone keeps the weights of all
//! its techniques summing to one, so the estimate stays unbiased whatever
//! the factors are; they only move work between techniques. (Multiplying
//! by c² instead, as the densities are raised, was measured worse in `vcm`.)
//!
//! **The pilot.** Passes 0 and 1 measure the camera's techniques weighed
//! with c = 0: light tracing keeping only the paths no other technique
//! makes (the limit c → 0 of its weight), the camera's techniques alone
//! estimate the rest. (`vcm` renders those passes with c = 0; `bdpt` renders
//! them with c = 1 and weighs each camera-side contribution a second time
//! with c = 0 for the record, see its module doc.) Each of
//! the two passes gives every pixel, per path length k, a sample x of the
//! camera side's estimate (mean over the pass's wavelengths). With the two
//! samples x₁, x₂ of each pixel, (x₁ − x₂)²/2 estimates the pixel's
//! variance V and (x₁² + x₂²)/2 its second moment M without bias, so over
//! the [`BLOCK`]² pixels of a block c = Σ(x₁ − x₂)² / Σ(x₁² + x₂²), free of
//! the image's own variation across the block. It is small where the camera
//! side's estimate is nearly the same in every pass (direct light on a
//! diffuse wall: c ≈ 0.1 on the Cornell box's), near 1 where a few samples
//! carry it (caustics, which the camera finds by chance). A block or length
//! with nothing keeps c = 1, and c stays at least [`C_MIN`]: a pilot that
//! missed a rare effect must not switch light tracing off for it.
//!
//! Passes from 2 on use the factors. A process that did not render passes
//! 0 and 1 (`--pass-range 8..16`, `--resume`) computes their camera side
//! again, by the same code, without adding it to the image ([`Pilot`]):
//! every process finds the same factors, passes stay independent, and a
//! single render pays nothing for the pilot.

use crate::integrator::RenderContext;
use crate::math::{UVec2, Vec2};
use std::sync::atomic::AtomicU64;
use std::sync::{LazyLock, Mutex, OnceLock};

/// Side of an image block, in pixels.
pub const BLOCK: u32 = 8;

/// Path lengths with a factor of their own; longer paths share the last.
pub const LENGTHS: usize = 8;

/// Smallest factor c (module doc).
pub const C_MIN: f32 = 1.0 / 32.0;

/// The passes whose camera side's estimates set the factors (module doc).
pub const PILOT_PASSES: u64 = 2;

/// The factors of the pilot passes: light tracing weighed only where it is
/// the only technique (c → 0).
pub static NO_LT: LazyLock<LtWeights> = LazyLock::new(|| LtWeights::uniform(0.0));

/// Weights by density alone (c = 1 everywhere).
pub static DENSITY: LazyLock<LtWeights> = LazyLock::new(|| LtWeights::uniform(1.0));

/// A camera path's estimate split by path length (scattering vertices
/// 1..=[`LENGTHS`], the last holding all longer ones), mean over
/// wavelengths; index 0 holds emission seen directly.
pub type ByLength = [f32; LENGTHS + 1];

/// The factors c of light tracing's term in the weights, per image block and
/// path length (module doc).
#[derive(Clone, Debug, PartialEq)]
pub struct LtWeights {
    blocks_x: u32,
    blocks_y: u32,
    /// c, `LENGTHS` per block.
    c: Vec<f32>,
}

impl LtWeights {
    /// One factor c everywhere: 1 is the density-only weight, 0 leaves light
    /// tracing out of the weights (the pilot).
    pub fn uniform(c: f32) -> Self {
        Self {
            blocks_x: 1,
            blocks_y: 1,
            c: vec![c; LENGTHS],
        }
    }

    /// Whether the factors differ between image blocks (else [`Self::row`]
    /// ignores its position).
    pub fn per_block(&self) -> bool {
        self.blocks_x * self.blocks_y > 1
    }

    /// The factors of the block holding film position `p_film` (raster
    /// units), one per path length.
    #[inline]
    pub fn row(&self, p_film: Vec2) -> &[f32] {
        let bx = ((p_film.x.max(0.0) as u32) / BLOCK).min(self.blocks_x - 1);
        let by = ((p_film.y.max(0.0) as u32) / BLOCK).min(self.blocks_y - 1);
        let i = (by * self.blocks_x + bx) as usize * LENGTHS;
        &self.c[i..i + LENGTHS]
    }

    /// c in `row` for a path of `k` scattering vertices (1 for k = 0, a
    /// light seen directly: the pilot does not measure it, and there the
    /// camera's variance is that of a light's edges, which light tracing's
    /// joins of the light's points render without).
    #[inline]
    pub fn at(row: &[f32], k: u32) -> f32 {
        if k == 0 {
            return 1.0;
        }
        row[(k as usize - 1).min(LENGTHS - 1)]
    }

    /// The factors from the two pilot passes' estimates, in the same pixel
    /// order.
    pub fn from_pilot(resolution: UVec2, a: &[(UVec2, ByLength)], b: &[(UVec2, ByLength)]) -> Self {
        Self::from_samples(
            resolution,
            a.iter().zip(b).map(|((p, x1), (_, x2))| (*p, x1, x2)),
        )
    }

    /// The factors from the pilot's two samples per pixel (module doc):
    /// `samples` yields (pixel, x per length of the first, of the second).
    pub fn from_samples<'a>(
        resolution: UVec2,
        samples: impl Iterator<Item = (UVec2, &'a ByLength, &'a ByLength)>,
    ) -> Self {
        let blocks_x = resolution.x.div_ceil(BLOCK).max(1);
        let blocks_y = resolution.y.div_ceil(BLOCK).max(1);
        let n_blocks = (blocks_x * blocks_y) as usize;
        // Per block and length: Σ(x₁ − x₂)², Σ(x₁² + x₂²).
        let mut m = vec![[0f64; 2]; n_blocks * LENGTHS];
        for (p, x1, x2) in samples {
            let (bx, by) = (
                (p.x / BLOCK).min(blocks_x - 1),
                (p.y / BLOCK).min(blocks_y - 1),
            );
            let b = (by * blocks_x + bx) as usize;
            for (k, (&a, &b2)) in x1[1..].iter().zip(&x2[1..]).enumerate() {
                let s = &mut m[b * LENGTHS + k];
                let (a, b2) = (a as f64, b2 as f64);
                s[0] += (a - b2) * (a - b2);
                s[1] += a * a + b2 * b2;
            }
        }
        let c = m.iter().map(variance_factor).collect();
        Self {
            blocks_x,
            blocks_y,
            c,
        }
    }
}

/// c = V / M from Σ(x₁ − x₂)² = 2 Σ V̂ and Σ(x₁² + x₂²) = 2 Σ M̂ over a
/// block's pixels, at least [`C_MIN`]; 1 where nothing was found.
fn variance_factor(s: &[f64; 2]) -> f32 {
    let [d2, m2] = *s;
    if m2 <= 0.0 {
        return 1.0;
    }
    ((d2 / m2) as f32).clamp(C_MIN, 1.0)
}

/// Every pixel's camera-side estimate of one pilot pass, by path length.
pub type PilotSamples = Vec<(UVec2, ByLength)>;

/// Memory per rendered pixel of one pilot pass's estimates, kept until the
/// second pilot pass ends.
pub const PILOT_BYTES_PER_PIXEL: usize = std::mem::size_of::<(UVec2, ByLength)>();

/// An integrator's factors once known, and the pilot passes' estimates
/// until then (module doc).
#[derive(Debug, Default)]
pub struct Pilot {
    weights: OnceLock<LtWeights>,
    samples: Mutex<[Option<PilotSamples>; PILOT_PASSES as usize]>,
}

impl Pilot {
    /// The factors, if known.
    pub fn get(&self) -> Option<&LtWeights> {
        self.weights.get()
    }

    /// Keeps the estimates of rendered pilot pass `pass` and sets the
    /// factors once both passes' are there.
    pub fn keep(&self, resolution: UVec2, pass: u64, samples: PilotSamples) {
        let Ok(mut kept) = self.samples.lock() else {
            return;
        };
        if let Some(slot) = kept.get_mut(pass as usize) {
            *slot = Some(samples);
        }
        if let [Some(a), Some(b)] = &*kept {
            let w = LtWeights::from_pilot(resolution, a, b);
            self.weights.get_or_init(|| w);
            *kept = [None, None];
        }
    }

    /// The factors: known ones, `uniform(1)` when `enabled` is false, else
    /// from the pilot passes' estimates, those not rendered by this process
    /// made now by `render(quiet, pass)` (not added to any image; `quiet` is
    /// `ctx` with a work counter of its own, so the progress of the pass
    /// being rendered counts only its own work). `None` if that was
    /// cancelled.
    pub fn weights(
        &self,
        ctx: &RenderContext<'_>,
        enabled: bool,
        mut render: impl FnMut(&RenderContext<'_>, u64) -> Option<PilotSamples>,
    ) -> Option<&LtWeights> {
        if let Some(w) = self.weights.get() {
            return Some(w);
        }
        if !enabled {
            return Some(self.weights.get_or_init(|| LtWeights::uniform(1.0)));
        }
        let work = AtomicU64::new(0);
        let quiet = RenderContext {
            work: &work,
            ..*ctx
        };
        let mut kept = self.samples.lock().ok()?;
        for (pass, slot) in kept.iter_mut().enumerate() {
            if slot.is_none() {
                *slot = Some(render(&quiet, pass as u64)?);
            }
        }
        let [Some(a), Some(b)] = &*kept else {
            return None;
        };
        let w = LtWeights::from_pilot(ctx.film.resolution(), a, b);
        *kept = [None, None];
        Some(self.weights.get_or_init(|| w))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_are_the_variance_share_of_the_second_moment() {
        // 16×8 pixels, two samples each. Block 0, length 1: the same value
        // twice in every pixel though it varies over the block (no noise:
        // the floor). Block 1, length 2: one pixel found 64 once and 0 once.
        let res = UVec2::new(16, 8);
        let mut xs = Vec::new();
        for y in 0..8 {
            for x in 0..16 {
                let (mut a, mut b): (ByLength, ByLength) = ([0.0; LENGTHS + 1], [0.0; LENGTHS + 1]);
                if x < 8 {
                    (a[1], b[1]) = (0.1 * (x + y) as f32 + 0.5, 0.1 * (x + y) as f32 + 0.5);
                } else if x == 12 && y == 3 {
                    a[2] = 64.0;
                }
                xs.push((UVec2::new(x, y), a, b));
            }
        }
        let w = LtWeights::from_samples(res, xs.iter().map(|(p, a, b)| (*p, a, b)));
        let r0 = w.row(Vec2::new(3.5, 2.5));
        assert_eq!(LtWeights::at(r0, 1), C_MIN);
        assert_eq!(LtWeights::at(r0, 2), 1.0);
        let r1 = w.row(Vec2::new(12.5, 7.9));
        // (64 − 0)² / (64² + 0²) = 1: all of it is variance.
        assert_eq!(LtWeights::at(r1, 2), 1.0);
        assert_eq!(LtWeights::at(r1, 1), 1.0);
        // A pixel at 1 ± 0.5 (samples 0.5 and 1.5): V/M = 1/(2·1.25) = 0.4.
        let one = [(
            UVec2::new(0, 0),
            {
                let mut a: ByLength = [0.0; LENGTHS + 1];
                a[3] = 0.5;
                a
            },
            {
                let mut b: ByLength = [0.0; LENGTHS + 1];
                b[3] = 1.5;
                b
            },
        )];
        let w1 = LtWeights::from_samples(UVec2::new(1, 1), one.iter().map(|(p, a, b)| (*p, a, b)));
        let r = w1.row(Vec2::new(0.5, 0.5));
        assert!((LtWeights::at(r, 3) - 0.4).abs() < 1e-6);
        // Lengths beyond the table share its last factor; k = 0 has none.
        assert_eq!(LtWeights::at(r1, 40), LtWeights::at(r1, LENGTHS as u32));
        assert_eq!(LtWeights::at(r0, 0), 1.0);
        // Positions off the film clamp to the border blocks.
        assert_eq!(w.row(Vec2::new(-3.0, 100.0)), w.row(Vec2::new(0.0, 7.0)));
    }
}
