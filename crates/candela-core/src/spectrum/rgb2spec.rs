//! RGB → spectrum by the sigmoid-polynomial model [Jakob & Hanika 2019,
//! "A Low-Dimensional Function Space for Efficient Spectral Upsampling"].
//!
//! A reflectance is s(λ) = S(c₀λ² + c₁λ + c₂) with S(x) = ½ + x / (2√(1 + x²)),
//! smooth and bounded in [0, 1]. The three coefficients are chosen so that the
//! spectrum's RGB under the colour space's illuminant equals the input RGB.
//! pbrt-v4 tabulates the fit on a 64³ grid; candela solves it directly for
//! each distinct RGB (Gauss–Newton with Levenberg damping, continued from
//! grey towards the target so that saturated colours converge) and memoises
//! it, so no table is needed and the result is the exact fit rather than an
//! interpolation of fits.

use super::color::{ColorSpace, Rgb};
use super::{
    cie_xyz, SampledSpectrum, SampledWavelengths, LAMBDA_MAX, LAMBDA_MIN, N_SPECTRUM_SAMPLES,
};

/// Coefficients of s(λ) = S(c₀λ² + c₁λ + c₂), λ in nm.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RgbSigmoidPolynomial {
    /// λ² coefficient.
    pub c0: f32,
    /// λ coefficient.
    pub c1: f32,
    /// Constant.
    pub c2: f32,
}

/// S(x) = ½ + x / (2√(1 + x²)), with the limits at ±∞.
#[inline]
pub fn sigmoid(x: f64) -> f64 {
    if x.is_infinite() {
        return if x > 0.0 { 1.0 } else { 0.0 };
    }
    0.5 + x / (2.0 * (1.0 + x * x).sqrt())
}

impl RgbSigmoidPolynomial {
    /// The constant spectrum `v` ∈ [0, 1] (S⁻¹(v) = (v − ½)/√(v(1 − v))).
    pub fn constant(v: f32) -> Self {
        let v = v as f64;
        let c2 = if v <= 0.0 {
            f64::NEG_INFINITY
        } else if v >= 1.0 {
            f64::INFINITY
        } else {
            (v - 0.5) / (v * (1.0 - v)).sqrt()
        };
        Self {
            c0: 0.0,
            c1: 0.0,
            c2: c2 as f32,
        }
    }
    /// s(λ).
    #[inline]
    pub fn eval(&self, lambda: f32) -> f32 {
        let l = lambda as f64;
        let x = if self.c2.is_infinite() && self.c0 == 0.0 && self.c1 == 0.0 {
            self.c2 as f64
        } else {
            (self.c0 as f64 * l + self.c1 as f64) * l + self.c2 as f64
        };
        sigmoid(x) as f32
    }
    /// s(λ) at the path's wavelengths: [`Self::eval`] lane by lane (the
    /// same f64 arithmetic, so the same bits), with the constant-spectrum
    /// test made once and the sigmoid written without branches so that the
    /// four lanes run as vector instructions.
    #[inline]
    pub fn sample(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        if self.c2.is_infinite() && self.c0 == 0.0 && self.c1 == 0.0 {
            return SampledSpectrum::splat(sigmoid(self.c2 as f64) as f32);
        }
        let (c0, c1, c2) = (self.c0 as f64, self.c1 as f64, self.c2 as f64);
        let l = lambda.lambdas();
        let mut out = [0.0f32; N_SPECTRUM_SAMPLES];
        for k in 0..N_SPECTRUM_SAMPLES {
            let l = l[k] as f64;
            let x = (c0 * l + c1) * l + c2;
            let s = 0.5 + x / (2.0 * (1.0 + x * x).sqrt());
            // `sigmoid`'s limits at ±∞, as a select rather than a branch.
            let limit = if x > 0.0 { 1.0 } else { 0.0 };
            out[k] = (if x.is_infinite() { limit } else { s }) as f32;
        }
        SampledSpectrum(out)
    }
    /// Maximum over 360–830 nm (endpoints or the parabola's vertex).
    pub fn max_value(&self) -> f32 {
        let mut m = self.eval(LAMBDA_MIN).max(self.eval(LAMBDA_MAX));
        if self.c0 != 0.0 {
            let v = -self.c1 / (2.0 * self.c0);
            if (LAMBDA_MIN..=LAMBDA_MAX).contains(&v) {
                m = m.max(self.eval(v));
            }
        }
        m
    }
}

const N: usize = 471;

/// Per-wavelength RGB weights: rgb = Σ_λ w(λ) s(λ) for an albedo s under the illuminant.
pub(super) fn spectral_weights(cs: &ColorSpace) -> Vec<[f64; 3]> {
    let ill: Vec<f64> = (0..N)
        .map(|i| cs.illuminant.eval(LAMBDA_MIN + i as f32) as f64)
        .collect();
    let norm: f64 = (0..N)
        .map(|i| cie_xyz(LAMBDA_MIN + i as f32)[1] as f64 * ill[i])
        .sum();
    (0..N)
        .map(|i| {
            let c = cie_xyz(LAMBDA_MIN + i as f32);
            let rgb = cs.rgb_from_xyz * glam::Vec3::new(c[0], c[1], c[2]);
            [
                rgb.x as f64 * ill[i] / norm,
                rgb.y as f64 * ill[i] / norm,
                rgb.z as f64 * ill[i] / norm,
            ]
        })
        .collect()
}

/// RGB of the sigmoid spectrum with normalised-λ coefficients `c` (t = (λ − 360)/470).
fn rgb_of(c: [f64; 3], w: &[[f64; 3]]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (i, wi) in w.iter().enumerate() {
        let t = i as f64 / (N - 1) as f64;
        let s = sigmoid((c[0] * t + c[1]) * t + c[2]);
        for k in 0..3 {
            out[k] += wi[k] * s;
        }
    }
    out
}

fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let m = glam::DMat3::from_cols_array_2d(&a).transpose();
    if m.determinant().abs() < 1e-300 {
        return None;
    }
    let x = m.inverse() * glam::DVec3::from_array(b);
    Some(x.to_array())
}

/// Damped Gauss–Newton on the RGB residual; returns the refined coefficients.
fn gauss_newton(mut c: [f64; 3], target: [f64; 3], w: &[[f64; 3]]) -> [f64; 3] {
    let mut lambda_damp = 1e-3;
    let resid = |c: [f64; 3]| {
        let r = rgb_of(c, w);
        [r[0] - target[0], r[1] - target[1], r[2] - target[2]]
    };
    let norm2 = |r: [f64; 3]| r.iter().map(|v| v * v).sum::<f64>();
    let mut r = resid(c);
    for _ in 0..60 {
        if norm2(r) < 1e-14 {
            break;
        }
        // Jacobian by central differences.
        let mut j = [[0.0; 3]; 3];
        for k in 0..3 {
            let h = 1e-5 * (1.0 + c[k].abs());
            let (mut cp, mut cm) = (c, c);
            cp[k] += h;
            cm[k] -= h;
            let (rp, rm) = (rgb_of(cp, w), rgb_of(cm, w));
            for i in 0..3 {
                j[i][k] = (rp[i] - rm[i]) / (2.0 * h);
            }
        }
        // (JᵀJ + μ diag) δ = −Jᵀ r
        let mut a = [[0.0; 3]; 3];
        let mut g = [0.0; 3];
        for p in 0..3 {
            for q in 0..3 {
                a[p][q] = (0..3).map(|i| j[i][p] * j[i][q]).sum();
            }
            g[p] = -(0..3).map(|i| j[i][p] * r[i]).sum::<f64>();
        }
        for (p, row) in a.iter_mut().enumerate() {
            row[p] *= 1.0 + lambda_damp;
        }
        let Some(d) = solve3(a, g) else { break };
        let cn = [c[0] + d[0], c[1] + d[1], c[2] + d[2]];
        let rn = resid(cn);
        if norm2(rn) < norm2(r) {
            c = cn;
            r = rn;
            lambda_damp = (lambda_damp * 0.3).max(1e-9);
        } else {
            lambda_damp *= 10.0;
            if lambda_damp > 1e8 {
                break;
            }
        }
    }
    c
}

/// Fits the sigmoid polynomial of an RGB in \[0,1\]³ for colour space `cs`.
pub fn fit_sigmoid(cs: &ColorSpace, rgb: Rgb) -> RgbSigmoidPolynomial {
    let w = spectral_weights(cs);
    let target = [rgb.r as f64, rgb.g as f64, rgb.b as f64];
    let mean = (target[0] + target[1] + target[2]) / 3.0;
    let mut c = [
        0.0,
        0.0,
        RgbSigmoidPolynomial::constant(mean.clamp(0.02, 0.98) as f32).c2 as f64,
    ];
    // Continuation from grey to the target keeps Gauss–Newton in its basin.
    const STEPS: usize = 16;
    for s in 1..=STEPS {
        let a = s as f64 / STEPS as f64;
        let t = [0, 1, 2].map(|k| mean + a * (target[k] - mean));
        c = gauss_newton(c, t, &w);
    }
    // Back from normalised t = (λ − λmin)/Δ to λ in nm.
    let (lmin, d) = (LAMBDA_MIN as f64, (LAMBDA_MAX - LAMBDA_MIN) as f64);
    RgbSigmoidPolynomial {
        c0: (c[0] / (d * d)) as f32,
        c1: (c[1] / d - 2.0 * c[0] * lmin / (d * d)) as f32,
        c2: (c[2] - c[1] * lmin / d + c[0] * lmin * lmin / (d * d)) as f32,
    }
}
