//! A precomputed RGB → sigmoid-polynomial table for per-lookup spectral
//! upsampling [Jakob & Hanika 2019, §4; pbrt-v4 `RGBToSpectrumTable`].
//!
//! Constant RGB parameters are fitted exactly and memoised by
//! [`ColorSpace::to_rgb_coeffs`](super::ColorSpace::to_rgb_coeffs), which
//! costs about a millisecond per colour: fine for a scene's few constants,
//! far too slow for image textures and environment maps, whose filtered RGB
//! changes with every lookup. Those go through this table instead, as in
//! pbrt-v4: a lookup costs a trilinear interpolation of coefficients.
//!
//! **Layout** (Jakob & Hanika's). An RGB is addressed by its largest
//! component `l` (3 blocks), the value z of that component, and the other two
//! divided by z, x = c[(l+1)%3]/z and y = c[(l+2)%3]/z, both in [0, 1]. x and y
//! are sampled uniformly at `res` nodes; z at z_k = S(S(k/(res−1))) with
//! S(t) = 3t² − 2t³, which crowds nodes near black and near 1 where the
//! coefficients change fastest.
//!
//! **Fitting.** Each (l, x, y) column is a chain of fits along z: starting at
//! k = res/5 from the zero polynomial (s(λ) ≡ ½), every node is solved for
//! the same objective as the exact fit (the spectrum's RGB under the colour
//! space's illuminant equals the node's RGB) by Newton's method on the 3×3
//! system, falling back to Levenberg–Marquardt damping when a step does not
//! reduce the residual, warm-started by linear extrapolation from the two
//! previous nodes; first upwards, then downwards. The spectral integrals use
//! the 1 nm weights summed into 5 nm bins (a midpoint rule, 5× cheaper).
//! Most nodes take one or two Newton steps; out-of-gamut nodes (which no
//! reflectance reaches) stop when the residual stagnates. The node z = 0
//! (black, where the coefficients diverge) copies its neighbour; the
//! exact-grey case of the lookup makes black itself exact.
//!
//! **Cost.** The table is built on first use, per colour space, in parallel
//! (rayon over columns; serially when first needed on a rayon worker, where a
//! nested parallel build could steal a job that waits for the table) and
//! kept for the process. Scene loading asks for it while building image
//! textures and lights, so renders never wait for it: `res` = 64 as in pbrt-v4,
//! 3·64³ ≈ 786k fits, about 2 s of one core (≈ 2.5M residual evaluations).
//! The round-trip RGB error of interpolated coefficients is measured in the
//! tests: 1.2·10⁻³ worst over random colours (exact fit: 7·10⁻⁶); 32 nodes
//! per axis would give 6.8·10⁻³, 48 give 1.8·10⁻³.

use super::color::{ColorSpace, Rgb};
use super::rgb2spec::{spectral_weights, RgbSigmoidPolynomial};
use super::{LAMBDA_MAX, LAMBDA_MIN};
use rayon::prelude::*;

/// Nodes per axis.
pub const TABLE_RES: usize = 64;

/// Trilinearly interpolated sigmoid coefficients over RGB ∈ [0, 1]³.
pub struct RgbToSpectrumTable {
    res: usize,
    z_nodes: Vec<f32>,
    /// Coefficients (λ in nm) at index ((l·res + k)·res + j)·res + i for
    /// z node k, y node j, x node i.
    coeffs: Vec<[f32; 3]>,
}

impl std::fmt::Debug for RgbToSpectrumTable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "RgbToSpectrumTable({}³)", self.res)
    }
}

/// S(t) = 3t² − 2t³.
fn smoothstep(t: f64) -> f64 {
    t * t * (3.0 - 2.0 * t)
}

impl RgbToSpectrumTable {
    /// Fits the table for colour space `cs` at `res` nodes per axis (≥ 4),
    /// on rayon's pool when `parallel`.
    pub fn build(cs: &ColorSpace, res: usize, parallel: bool) -> Self {
        assert!(res >= 4, "table resolution {res} too small");
        let w = binned_weights(&spectral_weights(cs));
        let z_nodes: Vec<f64> = (0..res)
            .map(|k| smoothstep(smoothstep(k as f64 / (res - 1) as f64)))
            .collect();
        // One chain of fits per (l, y, x) column.
        let column = |c: usize| {
            let (l, j, i) = (c / (res * res), (c / res) % res, c % res);
            let (x, y) = (i as f64 / (res - 1) as f64, j as f64 / (res - 1) as f64);
            fit_column(l, x, y, &z_nodes, &w)
        };
        let columns: Vec<Vec<[f64; 3]>> = if parallel {
            (0..3 * res * res).into_par_iter().map(column).collect()
        } else {
            (0..3 * res * res).map(column).collect()
        };
        let mut coeffs = vec![[0.0f32; 3]; 3 * res * res * res];
        for (c, col) in columns.iter().enumerate() {
            let (l, j, i) = (c / (res * res), (c / res) % res, c % res);
            for (k, cf) in col.iter().enumerate() {
                coeffs[((l * res + k) * res + j) * res + i] = to_nm(*cf);
            }
        }
        Self {
            res,
            z_nodes: z_nodes.iter().map(|&z| z as f32).collect(),
            coeffs,
        }
    }

    /// Coefficients of an RGB (clamped to [0, 1]³) by trilinear interpolation;
    /// greys are exact [pbrt-v4 `RGBToSpectrumTable::operator()`].
    pub fn coeffs(&self, rgb: Rgb) -> RgbSigmoidPolynomial {
        let c = [rgb.r, rgb.g, rgb.b].map(|v| if v > 0.0 { v.min(1.0) } else { 0.0 });
        if c[0] == c[1] && c[1] == c[2] {
            return RgbSigmoidPolynomial::constant(c[0]);
        }
        let l = if c[0] > c[1] {
            if c[0] > c[2] {
                0
            } else {
                2
            }
        } else if c[1] > c[2] {
            1
        } else {
            2
        };
        let res = self.res;
        let z = c[l];
        let scale = (res - 1) as f32 / z;
        let x = c[(l + 1) % 3] * scale;
        let y = c[(l + 2) % 3] * scale;
        let xi = (x as usize).min(res - 2);
        let yi = (y as usize).min(res - 2);
        // Largest k with z_nodes[k] < z, within [0, res − 2].
        let zi = self
            .z_nodes
            .partition_point(|&n| n < z)
            .saturating_sub(1)
            .min(res - 2);
        let (dx, dy) = (x - xi as f32, y - yi as f32);
        let dz = (z - self.z_nodes[zi]) / (self.z_nodes[zi + 1] - self.z_nodes[zi]);
        let at = |k: usize, j: usize, i: usize| self.coeffs[((l * res + k) * res + j) * res + i];
        let mut out = [0.0f32; 3];
        for (n, o) in out.iter_mut().enumerate() {
            let lerp = |t: f32, a: f32, b: f32| (1.0 - t) * a + t * b;
            let plane = |k: usize| {
                lerp(
                    dy,
                    lerp(dx, at(k, yi, xi)[n], at(k, yi, xi + 1)[n]),
                    lerp(dx, at(k, yi + 1, xi)[n], at(k, yi + 1, xi + 1)[n]),
                )
            };
            *o = lerp(dz, plane(zi), plane(zi + 1));
        }
        RgbSigmoidPolynomial {
            c0: out[0],
            c1: out[1],
            c2: out[2],
        }
    }
}

/// The RGB (largest component `l` = z) of node (x, y, z).
fn node_rgb(l: usize, x: f64, y: f64, z: f64) -> [f64; 3] {
    let mut rgb = [0.0; 3];
    rgb[l] = z;
    rgb[(l + 1) % 3] = x * z;
    rgb[(l + 2) % 3] = y * z;
    rgb
}

/// Fits one column: every z node, warm-started by linear extrapolation
/// from the two previous nodes of the chain.
fn fit_column(l: usize, x: f64, y: f64, z_nodes: &[f64], w: &[(f64, [f64; 3])]) -> Vec<[f64; 3]> {
    let res = z_nodes.len();
    let start = res / 5;
    let mut out = vec![[0.0; 3]; res];
    let fit = |k: usize, prev: usize, prev2: Option<usize>, out: &mut Vec<[f64; 3]>| {
        let guess = match prev2 {
            Some(p2) => {
                let t = (z_nodes[k] - z_nodes[prev]) / (z_nodes[prev] - z_nodes[p2]);
                std::array::from_fn(|m| out[prev][m] + t * (out[prev][m] - out[p2][m]))
            }
            None => out[prev],
        };
        out[k] = gauss_newton(bounded(guess), node_rgb(l, x, y, z_nodes[k]), w);
    };
    fit(start, start, None, &mut out);
    for k in start + 1..res {
        fit(k, k - 1, (k >= start + 2).then(|| k - 2), &mut out);
    }
    for k in (1..start).rev() {
        fit(k, k + 1, Some(k + 2), &mut out);
    }
    out[0] = out[1];
    out
}

/// The 1 nm weights summed into `BIN` nm bins centred on every `BIN`-th
/// wavelength, with each bin's normalised λ: a midpoint rule that is 5×
/// cheaper than the 1 nm sum and differs from it by O(BIN²·s″).
fn binned_weights(w: &[[f64; 3]]) -> Vec<(f64, [f64; 3])> {
    const BIN: usize = 5;
    let n = w.len();
    (0..n.div_ceil(BIN))
        .map(|j| {
            let centre = j * BIN;
            let lo = centre.saturating_sub(BIN / 2);
            let hi = (centre + BIN / 2).min(n - 1);
            let mut sum = [0.0; 3];
            for wi in &w[lo..=hi] {
                for k in 0..3 {
                    sum[k] += wi[k];
                }
            }
            (centre as f64 / (n - 1) as f64, sum)
        })
        .collect()
}

/// RGB residual of normalised-λ coefficients `c` and its Jacobian, in one pass.
fn residual(c: [f64; 3], target: [f64; 3], w: &[(f64, [f64; 3])]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut r = [-target[0], -target[1], -target[2]];
    let mut jac = [[0.0; 3]; 3];
    for &(t, wi) in w {
        let x = (c[0] * t + c[1]) * t + c[2];
        // S(x) = ½ + ½x/√(1 + x²) and S'(x) = ½(1 + x²)^(−3/2), one root.
        let inv = 1.0 / (1.0 + x * x).sqrt();
        let s = 0.5 + 0.5 * x * inv;
        let ds = 0.5 * inv * inv * inv;
        let dx = [t * t, t, 1.0];
        for k in 0..3 {
            r[k] += wi[k] * s;
            for (m, d) in dx.iter().enumerate() {
                jac[k][m] += wi[k] * ds * d;
            }
        }
    }
    (r, jac)
}

/// The Newton step −J⁻¹r when `damp` is 0 (J is square), otherwise the
/// Levenberg–Marquardt step (JᵀJ + damp·diag(JᵀJ))⁻¹(−Jᵀr).
fn step(jac: &[[f64; 3]; 3], r: &[f64; 3], damp: f64) -> Option<glam::DVec3> {
    let j = glam::DMat3::from_cols_array_2d(jac).transpose();
    let r = glam::DVec3::from_array(*r);
    let (a, g) = if damp == 0.0 {
        (j, -r)
    } else {
        let jtj = j.transpose() * j;
        let diag =
            glam::DMat3::from_diagonal(glam::DVec3::new(jtj.x_axis.x, jtj.y_axis.y, jtj.z_axis.z));
        (jtj + diag * damp, -(j.transpose() * r))
    };
    let det = a.determinant();
    (det.is_finite() && det.abs() > 1e-300).then(|| a.inverse() * g)
}

/// Largest |coefficient| (normalised λ) a fit may reach. Nodes outside the
/// reflectance gamut (most of ACES2065-1's AP0 triangle, whose green and blue
/// primaries are not physical colours) have their optimum at infinity: the
/// fit keeps sharpening a step spectrum, and extrapolated warm starts along
/// a column compound that to overflow (10⁴⁷ measured, NaN once stored in
/// f32). Scaling c by a positive factor keeps the polynomial's roots, so
/// capping ‖c‖∞ only stops the sharpening: beyond 10⁶ the step is within
/// 10⁻⁶ nm of a jump. The sRGB table peaks at 4.2·10⁴ and is unaffected.
const MAX_COEFF: f64 = 1e6;

/// `c` scaled down to ‖c‖∞ ≤ [`MAX_COEFF`] (non-finite → the flat ½ spectrum).
fn bounded(c: [f64; 3]) -> [f64; 3] {
    let m = c.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if !m.is_finite() {
        [0.0; 3]
    } else if m > MAX_COEFF {
        c.map(|v| v * (MAX_COEFF / m))
    } else {
        c
    }
}

/// Iteration cap per node (warm starts converge in a handful).
const MAX_ITERATIONS: usize = 30;

/// Levenberg-damped Gauss–Newton from `c` towards `target`.
fn gauss_newton(mut c: [f64; 3], target: [f64; 3], w: &[(f64, [f64; 3])]) -> [f64; 3] {
    let norm2 = |r: &[f64; 3]| r.iter().map(|v| v * v).sum::<f64>();
    // Relative tolerance, so dark colours are fitted as well as bright ones.
    let scale = target.iter().fold(0.0f64, |m, &v| m.max(v)).max(1e-6);
    let tol2 = (1e-5 * scale) * (1e-5 * scale);
    let (mut r, mut jac) = residual(c, target, w);
    let mut damp = 0.0;
    for _ in 0..MAX_ITERATIONS {
        if norm2(&r) < tol2 {
            break;
        }
        let Some(d) = step(&jac, &r, damp) else { break };
        let cn = bounded([c[0] + d.x, c[1] + d.y, c[2] + d.z]);
        let (rn, jn) = residual(cn, target, w);
        if norm2(&rn) < norm2(&r) {
            // Stagnation: out-of-gamut nodes only creep towards the boundary.
            let done = norm2(&rn) > 0.999 * norm2(&r);
            (c, r, jac) = (cn, rn, jn);
            if done {
                break;
            }
            damp *= 0.1;
        } else {
            damp = (damp * 10.0).max(1e-6);
            if damp > 1e8 {
                break;
            }
        }
    }
    c
}

/// Normalised-λ coefficients (t = (λ − 360)/470) → coefficients in nm.
fn to_nm(c: [f64; 3]) -> [f32; 3] {
    let (lmin, d) = (LAMBDA_MIN as f64, (LAMBDA_MAX - LAMBDA_MIN) as f64);
    [
        (c[0] / (d * d)) as f32,
        (c[1] / d - 2.0 * c[0] * lmin / (d * d)) as f32,
        (c[2] - c[1] * lmin / d + c[0] * lmin * lmin / (d * d)) as f32,
    ]
}
