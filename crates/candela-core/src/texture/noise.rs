//! Gradient ("Perlin") noise and its fractal sums.
//!
//! [`noise`] is Perlin's improved noise [Perlin 2002, "Improving Noise"]: the
//! integer lattice around a point picks a pseudo-random gradient at each of
//! the eight cell corners by hashing the corner through Perlin's permutation
//! table; each corner contributes the dot product of its gradient with the
//! offset to the point, and the eight values are blended trilinearly with the
//! quintic fade 6t⁵ − 15t⁴ + 10t³. The value is 0 on the lattice and varies
//! smoothly (C²) in between. The gradients are the twelve cube-edge vectors
//! (with four repeated to make sixteen), chosen from the low four bits of the
//! hash exactly as in Perlin's reference code and pbrt-v4 (`util/noise.cpp`),
//! so candela's noise is the same function as pbrt-v4's.
//!
//! [`fbm`] (fractional Brownian motion) and [`turbulence`] sum octaves of
//! noise at frequencies ×1.99 apart with amplitudes ×ω apart
//! [pbrt-v4 §10.6.1, after Perlin 1985]. The number of octaves is limited by
//! the texture-space footprint (`dpdx`, `dpdy`) so that no octave is finer
//! than the pixel: n = clamp(−1 − ½ log₂ max(|dpdx|², |dpdy|²), 0, max)
//! [pbrt-v4 §10.6.2]. With a zero footprint (no camera footprint known)
//! every octave is summed.

use super::perm::PERM;
use crate::math::Vec3;

/// Perlin noise at (x, y, z); 0 at integer points, in [−1, 1].
pub fn noise(x: f32, y: f32, z: f32) -> f32 {
    // Keep coordinates within i32 range before flooring [as pbrt-v4 does].
    const WRAP: f32 = (1u32 << 30) as f32;
    let (x, y, z) = (x % WRAP, y % WRAP, z % WRAP);
    let (fx, fy, fz) = (x.floor(), y.floor(), z.floor());
    let (dx, dy, dz) = (x - fx, y - fy, z - fz);
    let (ix, iy, iz) = (
        (fx as i32 & 255) as usize,
        (fy as i32 & 255) as usize,
        (fz as i32 & 255) as usize,
    );
    let corner = |cx: usize, cy: usize, cz: usize| {
        gradient(
            ix + cx,
            iy + cy,
            iz + cz,
            dx - cx as f32,
            dy - cy as f32,
            dz - cz as f32,
        )
    };
    let (wx, wy, wz) = (fade(dx), fade(dy), fade(dz));
    let x00 = lerp(wx, corner(0, 0, 0), corner(1, 0, 0));
    let x10 = lerp(wx, corner(0, 1, 0), corner(1, 1, 0));
    let x01 = lerp(wx, corner(0, 0, 1), corner(1, 0, 1));
    let x11 = lerp(wx, corner(0, 1, 1), corner(1, 1, 1));
    lerp(wz, lerp(wy, x00, x10), lerp(wy, x01, x11))
}

/// Perlin noise at a point.
#[inline]
pub fn noise_at(p: Vec3) -> f32 {
    noise(p.x, p.y, p.z)
}

/// Dot product of the hashed corner gradient with the offset (dx, dy, dz).
#[inline]
fn gradient(x: usize, y: usize, z: usize, dx: f32, dy: f32, dz: f32) -> f32 {
    let p = |i: usize| PERM[i & 255] as usize;
    let h = p(p(p(x) + y) + z) & 15;
    // The sixteen cases select ±u ± v from the offset components [Perlin 2002].
    let u = if h < 8 || h == 12 || h == 13 { dx } else { dy };
    let v = if h < 4 || h == 12 || h == 13 { dy } else { dz };
    let u = if h & 1 != 0 { -u } else { u };
    let v = if h & 2 != 0 { -v } else { v };
    u + v
}

/// Perlin's quintic fade curve 6t⁵ − 15t⁴ + 10t³.
#[inline]
fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

#[inline]
fn lerp(t: f32, a: f32, b: f32) -> f32 {
    (1.0 - t) * a + t * b
}

/// Cubic Hermite step from 0 at `a` to 1 at `b`.
fn smooth_step(x: f32, a: f32, b: f32) -> f32 {
    if a == b {
        return if x < a { 0.0 } else { 1.0 };
    }
    let t = ((x - a) / (b - a)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Number of octaves (fractional) that the footprint allows [pbrt-v4 §10.6.2].
pub fn octave_count(dpdx: Vec3, dpdy: Vec3, max_octaves: u32) -> f32 {
    let len2 = dpdx.length_squared().max(dpdy.length_squared());
    // log₂ 0 = −∞ gives +∞ before clamping: a zero footprint allows every octave.
    (-1.0 - 0.5 * len2.log2()).clamp(0.0, max_octaves as f32)
}

/// Fractional Brownian motion: Σ ωⁱ noise(1.99ⁱ p) over the allowed octaves,
/// the last partial octave faded in [pbrt-v4 §10.6.1, `FBm`].
pub fn fbm(p: Vec3, dpdx: Vec3, dpdy: Vec3, omega: f32, max_octaves: u32) -> f32 {
    let n = octave_count(dpdx, dpdy, max_octaves);
    let whole = n.floor() as u32;
    let (mut sum, mut freq, mut amp) = (0.0, 1.0, 1.0);
    for _ in 0..whole {
        sum += amp * noise_at(freq * p);
        freq *= 1.99;
        amp *= omega;
    }
    sum + amp * smooth_step(n - whole as f32, 0.3, 0.7) * noise_at(freq * p)
}

/// Turbulence: like [`fbm`] with |noise|; octaves beyond the footprint add
/// their average magnitude 0.2 instead [pbrt-v4 §10.6.1, `Turbulence`].
pub fn turbulence(p: Vec3, dpdx: Vec3, dpdy: Vec3, omega: f32, max_octaves: u32) -> f32 {
    let n = octave_count(dpdx, dpdy, max_octaves);
    let whole = n.floor() as u32;
    let (mut sum, mut freq, mut amp) = (0.0, 1.0, 1.0);
    for _ in 0..whole {
        sum += amp * noise_at(freq * p).abs();
        freq *= 1.99;
        amp *= omega;
    }
    let partial = smooth_step(n - whole as f32, 0.3, 0.7);
    sum += amp * lerp(partial, 0.2, noise_at(freq * p).abs());
    for _ in whole..max_octaves {
        sum += amp * 0.2;
        amp *= omega;
    }
    sum
}
