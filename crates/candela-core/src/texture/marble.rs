//! `marble`: veins from a sine of height perturbed by fractal noise.
//!
//! pbrt-v4 (`MarbleTexture::Evaluate`) computes t = ½ + ½ sin(y + variation ·
//! fbm(p)) at the scaled texture-space point and looks up an RGB on a
//! piecewise cubic Bézier spline through nine fixed colours (×1.5), which it
//! lifts to a reflectance spectrum in sRGB at every hit.
//!
//! candela's RGB → spectrum fit is an optimisation, too slow to run per hit,
//! but the colour depends on the single number t, so the fit is tabulated
//! once along the spline and the spectrum at t is interpolated between the
//! two nearest entries (pbrt-v4 likewise interpolates tabulated fits, over
//! an RGB grid).

use super::nodes::NoiseSum;
use super::noise::fbm;
use super::TextureEvalContext;
use crate::spectrum::{ColorSpace, Rgb, RgbSigmoidPolynomial, SampledSpectrum, SampledWavelengths};
use std::sync::OnceLock;

/// The spline's control colours [pbrt-v4 `MarbleTexture::Evaluate`].
const COLORS: [[f32; 3]; 9] = [
    [0.58, 0.58, 0.6],
    [0.58, 0.58, 0.6],
    [0.58, 0.58, 0.6],
    [0.5, 0.5, 0.5],
    [0.6, 0.59, 0.58],
    [0.58, 0.58, 0.6],
    [0.58, 0.58, 0.6],
    [0.2, 0.2, 0.33],
    [0.58, 0.58, 0.6],
];

/// Table intervals along t (32 per spline segment).
const TABLE_STEPS: usize = 192;

/// The `marble` spectrum texture.
#[derive(Clone, Debug)]
pub struct Marble {
    /// Mapping, octaves and roughness of the perturbing fbm.
    pub noise: NoiseSum,
    /// Texture-space scale (`scale`, default 1).
    pub scale: f32,
    /// Perturbation strength (`variation`, default 0.2).
    pub variation: f32,
}

impl Marble {
    /// The spline parameter t ∈ [0, 1] at a hit.
    pub fn spline_parameter(&self, ctx: &TextureEvalContext) -> f32 {
        let c = self.noise.map.map(ctx);
        let p = self.scale * c.p;
        let (dpdx, dpdy) = (self.scale * c.dpdx, self.scale * c.dpdy);
        let m = p.y + self.variation * fbm(p, dpdx, dpdy, self.noise.omega, self.noise.octaves);
        0.5 + 0.5 * m.sin()
    }

    /// Reflectance at a hit.
    pub fn eval(&self, ctx: &TextureEvalContext, lambda: &SampledWavelengths) -> SampledSpectrum {
        marble_spectrum(self.spline_parameter(ctx), lambda)
    }
}

/// The marble colour at spline parameter t ∈ [0, 1].
pub fn marble_rgb(t: f32) -> Rgb {
    let segments = COLORS.len() - 3;
    let x = t.clamp(0.0, 1.0) * segments as f32;
    let first = (x.floor() as usize).min(segments - 1);
    let u = x - first as f32;
    // Cubic Bernstein basis on the four control colours of the segment.
    let w = [
        (1.0 - u).powi(3),
        3.0 * (1.0 - u).powi(2) * u,
        3.0 * (1.0 - u) * u * u,
        u * u * u,
    ];
    let c = |k: usize| 1.5 * (0..4).map(|i| w[i] * COLORS[first + i][k]).sum::<f32>();
    Rgb::new(c(0), c(1), c(2))
}

/// Sigmoid fits of `marble_rgb` at t = i / TABLE_STEPS (sRGB albedo).
fn table() -> &'static [RgbSigmoidPolynomial] {
    static TABLE: OnceLock<Vec<RgbSigmoidPolynomial>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let cs = ColorSpace::srgb();
        (0..=TABLE_STEPS)
            .map(|i| cs.to_rgb_coeffs(marble_rgb(i as f32 / TABLE_STEPS as f32)))
            .collect()
    })
}

/// The marble reflectance at spline parameter t, linearly interpolated
/// between the tabulated fits.
pub fn marble_spectrum(t: f32, lambda: &SampledWavelengths) -> SampledSpectrum {
    let table = table();
    let x = t.clamp(0.0, 1.0) * TABLE_STEPS as f32;
    let i = (x.floor() as usize).min(TABLE_STEPS - 1);
    let f = x - i as f32;
    let (a, b) = (&table[i], &table[i + 1]);
    SampledSpectrum::from_fn(|k| {
        let l = lambda.lambda(k);
        (1.0 - f) * a.eval(l) + f * b.eval(l)
    })
}
