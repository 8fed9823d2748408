//! Texture nodes shared by the float and spectrum variants.
//!
//! Each node is generic over its child texture type and is evaluated with a
//! closure that evaluates a child (a float texture ignores the wavelengths,
//! a spectrum texture samples them), so one implementation serves both
//! variants as in pbrt-v4 (`textures.h`, `textures.cpp`). Children that a
//! node's weight makes irrelevant are not evaluated, as in pbrt-v4.

use super::mapping::{TextureMapping2D, TextureMapping3D};
use super::noise::{fbm, noise, turbulence};
use super::{FloatTexture, TextureEvalContext};
use crate::math::{Vec2, Vec3};
use crate::spectrum::SampledSpectrum;
use std::ops::{Add, Mul};

/// A texture value: `f32` or [`SampledSpectrum`].
pub trait TexValue: Copy + Add<Output = Self> + Mul<f32, Output = Self> {
    /// Zero.
    fn zero() -> Self;
}

impl TexValue for f32 {
    fn zero() -> Self {
        0.0
    }
}

impl TexValue for SampledSpectrum {
    fn zero() -> Self {
        SampledSpectrum::zero()
    }
}

/// `(1 − w)·a + w·b`, evaluating `a` only if w ≠ 1 and `b` only if w ≠ 0.
fn blend<V: TexValue>(w: f32, a: impl FnOnce() -> V, b: impl FnOnce() -> V) -> V {
    let va = if w != 1.0 { a() } else { V::zero() };
    let vb = if w != 0.0 { b() } else { V::zero() };
    va * (1.0 - w) + vb * w
}

/// `scale`: tex × scale.
#[derive(Clone, Debug)]
pub struct Scale<T> {
    /// The scaled texture.
    pub tex: T,
    /// The factor.
    pub scale: FloatTexture,
}

impl<T> Scale<T> {
    /// Value at a hit; the child is skipped where the scale is 0.
    pub fn eval<V: TexValue>(&self, ctx: &TextureEvalContext, f: impl Fn(&T) -> V) -> V {
        let s = self.scale.evaluate(ctx);
        if s == 0.0 {
            return V::zero();
        }
        f(&self.tex) * s
    }
}

/// `mix`: (1 − amount)·tex1 + amount·tex2.
#[derive(Clone, Debug)]
pub struct Mix<T> {
    /// Value at amount 0.
    pub tex1: T,
    /// Value at amount 1.
    pub tex2: T,
    /// Blend weight.
    pub amount: FloatTexture,
}

impl<T> Mix<T> {
    /// Value at a hit.
    pub fn eval<V: TexValue>(&self, ctx: &TextureEvalContext, f: impl Fn(&T) -> V) -> V {
        let w = self.amount.evaluate(ctx);
        blend(w, || f(&self.tex1), || f(&self.tex2))
    }
}

/// `directionmix`: |n·dir|·tex1 + (1 − |n·dir|)·tex2.
#[derive(Clone, Debug)]
pub struct DirectionMix<T> {
    /// Value where the normal is along `dir`.
    pub tex1: T,
    /// Value where the normal is perpendicular to `dir`.
    pub tex2: T,
    /// Unit direction in render space.
    pub dir: Vec3,
}

impl<T> DirectionMix<T> {
    /// Value at a hit.
    pub fn eval<V: TexValue>(&self, ctx: &TextureEvalContext, f: impl Fn(&T) -> V) -> V {
        let amt = ctx.n.dot(self.dir).abs();
        blend(1.0 - amt, || f(&self.tex1), || f(&self.tex2))
    }
}

/// Where a checkerboard is laid out.
#[derive(Clone, Debug)]
pub enum CheckerMap {
    /// Squares in (s, t) (`"integer dimension" 2`).
    Planar(TextureMapping2D),
    /// Cubes in texture space (`"integer dimension" 3`).
    Solid(TextureMapping3D),
}

/// `checkerboard`: tex1 on even cells, tex2 on odd ones.
#[derive(Clone, Debug)]
pub struct Checkerboard<T> {
    /// 2D or 3D layout.
    pub map: CheckerMap,
    /// Even cells (the one containing the origin).
    pub tex1: T,
    /// Odd cells.
    pub tex2: T,
}

impl<T> Checkerboard<T> {
    /// Value at a hit.
    pub fn eval<V: TexValue>(&self, ctx: &TextureEvalContext, f: impl Fn(&T) -> V) -> V {
        let w = checkerboard_weight(&self.map, ctx);
        blend(w, || f(&self.tex1), || f(&self.tex2))
    }
}

/// Weight of tex2: 0 on even cells, 1 on odd ones, and in between where the
/// footprint straddles cell edges [pbrt-v4 `Checkerboard`].
pub fn checkerboard_weight(map: &CheckerMap, ctx: &TextureEvalContext) -> f32 {
    match map {
        CheckerMap::Planar(m) => {
            let c = m.map(ctx);
            let ds = 1.5 * c.dsdx.abs().max(c.dsdy.abs());
            let dt = 1.5 * c.dtdx.abs().max(c.dtdy.abs());
            0.5 - 0.5 * filtered_square_wave(c.st.x, ds) * filtered_square_wave(c.st.y, dt)
        }
        CheckerMap::Solid(m) => {
            let c = m.map(ctx);
            let r = |i: usize| 1.5 * c.dpdx[i].abs().max(c.dpdy[i].abs());
            0.5 - 0.5
                * filtered_square_wave(c.p.x, r(0))
                * filtered_square_wave(c.p.y, r(1))
                * filtered_square_wave(c.p.z, r(2))
        }
    }
}

/// The square wave +1 on even cells, −1 on odd ones, averaged under a tent
/// of radius `r`. A tent is a box convolved with itself, so the average is
/// the second central difference of the wave's second antiderivative D:
/// (D(x + r) − 2D(x) + D(x − r)) / r² [pbrt-v4 §10.5.1]. A footprint inside
/// one cell (including r = 0, where the hit has no footprint)
/// is the exact point value.
fn filtered_square_wave(x: f32, r: f32) -> f32 {
    if (x - r).floor() == (x + r).floor() {
        return if (x.floor() as i64) & 1 == 0 {
            1.0
        } else {
            -1.0
        };
    }
    // D(x) = x/2 + y(1 − 2|y|) with y = frac(x/2) − ½ (the periodic part).
    let d = |x: f32| {
        let y = x / 2.0 - (x / 2.0).floor() - 0.5;
        x / 2.0 + y * (1.0 - 2.0 * y.abs())
    };
    (d(x + r) - 2.0 * d(x) + d(x - r)) / (r * r)
}

/// `bilerp`: bilinear interpolation of four corner values over (s, t).
#[derive(Clone, Debug)]
pub struct Bilerp<S> {
    /// The (s, t) mapping.
    pub map: TextureMapping2D,
    /// Corner values v00, v01, v10, v11 (vST: first digit s, second t).
    pub v: [S; 4],
}

impl<S> Bilerp<S> {
    /// Value at a hit, with `f` turning a corner into a texture value.
    pub fn eval<V: TexValue>(&self, ctx: &TextureEvalContext, f: impl Fn(&S) -> V) -> V {
        let st = self.map.map(ctx).st;
        let (s, t) = (st.x, st.y);
        let [v00, v01, v10, v11] = &self.v;
        f(v00) * ((1.0 - s) * (1.0 - t))
            + f(v01) * ((1.0 - s) * t)
            + f(v10) * (s * (1.0 - t))
            + f(v11) * (s * t)
    }
}

/// `dots`: randomly placed polka dots over (s, t).
///
/// pbrt-v4 hands its `"inside"` texture to the node's *outside* slot and
/// `"outside"` to the inside one (`FloatDotsTexture::Create`,
/// `SpectrumDotsTexture::Create`); the scene builder reproduces that so
/// images agree with pbrt-v4's.
#[derive(Clone, Debug)]
pub struct Dots<T> {
    /// The (s, t) mapping.
    pub map: TextureMapping2D,
    /// Value inside dots.
    pub inside: T,
    /// Value elsewhere.
    pub outside: T,
}

impl<T> Dots<T> {
    /// Value at a hit.
    pub fn eval<V: TexValue>(&self, ctx: &TextureEvalContext, f: impl Fn(&T) -> V) -> V {
        if inside_polka_dot(self.map.map(ctx).st) {
            f(&self.inside)
        } else {
            f(&self.outside)
        }
    }
}

/// Whether (s, t) is inside the dot of its unit cell: half the cells (by
/// the sign of noise at the cell centre) hold a dot of radius 0.35, jittered
/// by noise within the cell [pbrt-v4 `InsidePolkaDot`].
pub fn inside_polka_dot(st: Vec2) -> bool {
    let (sc, tc) = ((st.x + 0.5).floor(), (st.y + 0.5).floor());
    if noise(sc + 0.5, tc + 0.5, 0.5) <= 0.0 {
        return false;
    }
    const RADIUS: f32 = 0.35;
    let max_shift = 0.5 - RADIUS;
    let centre = Vec2::new(
        sc + max_shift * noise(sc + 1.5, tc + 2.8, 0.5),
        tc + max_shift * noise(sc + 4.5, tc + 9.8, 0.5),
    );
    (st - centre).length_squared() < RADIUS * RADIUS
}

/// Parameters of the `fbm`, `wrinkled` and `marble` noise sums.
#[derive(Clone, Debug)]
pub struct NoiseSum {
    /// The 3D mapping.
    pub map: TextureMapping3D,
    /// Maximum number of octaves (`octaves`, default 8).
    pub octaves: u32,
    /// Amplitude ratio between octaves (`roughness`, default 0.5).
    pub omega: f32,
}

impl NoiseSum {
    /// Fractional Brownian motion at a hit (`fbm`).
    pub fn fbm(&self, ctx: &TextureEvalContext) -> f32 {
        let c = self.map.map(ctx);
        fbm(c.p, c.dpdx, c.dpdy, self.omega, self.octaves)
    }
    /// Turbulence at a hit (`wrinkled`).
    pub fn turbulence(&self, ctx: &TextureEvalContext) -> f32 {
        let c = self.map.map(ctx);
        turbulence(c.p, c.dpdx, c.dpdy, self.omega, self.octaves)
    }
}

/// `windy`: wave height (6-octave fbm) modulated by wind strength (a
/// 3-octave fbm at a tenth of the frequency) [pbrt-v4 `WindyTexture`].
pub fn windy(map: &TextureMapping3D, ctx: &TextureEvalContext) -> f32 {
    let c = map.map(ctx);
    let wind = fbm(0.1 * c.p, 0.1 * c.dpdx, 0.1 * c.dpdy, 0.5, 3);
    let wave = fbm(c.p, c.dpdx, c.dpdy, 0.5, 6);
    wind.abs() * wave
}
