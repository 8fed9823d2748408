//! Points stored coordinate by coordinate, for a distance test eight
//! points at a time.
//!
//! A fixed-radius query over a grid tests every point of the buckets it
//! visits, and most fail (with cells of side 2r a point on a surface finds
//! about one candidate in six within r). Laid out as three arrays (x, y,
//! z) padded by [`LANES`] at the end, any run of entries is tested in
//! steps of [`LANES`] consecutive points: the step's distances and
//! comparisons are straight-line code over fixed-size arrays, which the
//! compiler turns into vector instructions and a bit mask, and only the
//! points within reach (the mask's set bits) reach the caller. Lanes past
//! the run's end read the padding or the next run and are masked off.
//!
//! The test is `(q − p)·(q − p) ≤ r²` evaluated as glam's
//! `Vec3::length_squared` evaluates it (`(dx·dx + dy·dy) + dz·dz`, no fused
//! multiply-add), so it finds exactly the points a scalar loop finds.

use glam::Vec3;
use std::ops::Range;
use wide::{f32x8, CmpLe};

/// Points tested per step.
pub const LANES: usize = 8;

/// Points as three coordinate arrays, each padded by [`LANES`] zeros.
#[derive(Clone, Debug)]
pub struct SoaPoints {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
}

impl SoaPoints {
    /// `n` points at the origin, to be set by [`Self::set`].
    pub fn zeros(n: usize) -> Self {
        SoaPoints {
            x: vec![0.0; n + LANES],
            y: vec![0.0; n + LANES],
            z: vec![0.0; n + LANES],
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.x.len().saturating_sub(LANES)
    }

    /// True when there is no point.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Sets point `i`.
    #[inline]
    pub fn set(&mut self, i: usize, p: Vec3) {
        self.x[i] = p.x;
        self.y[i] = p.y;
        self.z[i] = p.z;
    }

    /// Point `i`.
    #[inline]
    pub fn get(&self, i: usize) -> Vec3 {
        Vec3::new(self.x[i], self.y[i], self.z[i])
    }

    /// Calls `f(i)` for every `i` in `run` (within `0..len()`) whose point
    /// lies within `r2` (squared) of `p`, in increasing order.
    #[inline]
    pub fn for_each_within(&self, run: Range<usize>, p: Vec3, r2: f32, mut f: impl FnMut(usize)) {
        let mut base = run.start;
        while base < run.end {
            let (Some(x), Some(y), Some(z)) = (
                self.x[base..].first_chunk::<LANES>(),
                self.y[base..].first_chunk::<LANES>(),
                self.z[base..].first_chunk::<LANES>(),
            ) else {
                // Unreachable: the padding holds LANES points past any run.
                return;
            };
            let mut mask = within_mask(x, y, z, p, r2);
            let left = run.end - base;
            if left < LANES {
                mask &= (1u32 << left) - 1;
            }
            while mask != 0 {
                f(base + mask.trailing_zeros() as usize);
                mask &= mask - 1;
            }
            base += LANES;
        }
    }
}

/// Bit l set when point l of the step lies within `r2` of `p`.
#[inline]
fn within_mask(x: &[f32; LANES], y: &[f32; LANES], z: &[f32; LANES], p: Vec3, r2: f32) -> u32 {
    let dx = f32x8::from(*x) - f32x8::splat(p.x);
    let dy = f32x8::from(*y) - f32x8::splat(p.y);
    let dz = f32x8::from(*z) - f32x8::splat(p.z);
    let d2 = dx * dx + dy * dy + dz * dz;
    d2.cmp_le(f32x8::splat(r2)).move_mask() as u32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    /// Every run of every start and length (including those ending inside
    /// a step and the empty ones) finds exactly the points the scalar test
    /// finds, in order, with radii that put points on the boundary.
    #[test]
    fn finds_what_the_scalar_test_finds() {
        let mut rng = Pcg32::new(7, 0);
        let n = 37;
        let pts: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()))
            .collect();
        let mut soa = SoaPoints::zeros(n);
        for (i, &q) in pts.iter().enumerate() {
            soa.set(i, q);
        }
        assert_eq!(soa.len(), n);
        let p = Vec3::new(0.4, 0.5, 0.6);
        // r² exactly a point's distance²: the boundary is inclusive.
        let mut radii2 = vec![0.0, 0.05, 0.2, 3.0];
        radii2.push((pts[5] - p).length_squared());
        for r2 in radii2 {
            for a in 0..=n {
                for b in a..=n {
                    let mut found = Vec::new();
                    soa.for_each_within(a..b, p, r2, |i| found.push(i));
                    let want: Vec<usize> = (a..b)
                        .filter(|&i| (pts[i] - p).length_squared() <= r2)
                        .collect();
                    assert_eq!(found, want, "run {a}..{b}, r² {r2}");
                }
            }
        }
    }
}
