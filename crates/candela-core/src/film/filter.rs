//! Pixel reconstruction filters [pbrt-v4 §8.8].
//!
//! The film estimates each pixel as Σ wᵢ·L(pᵢ) / Σ wᵢ over camera samples
//! whose film offsets pᵢ are drawn by [`Filter::sample`]. As in pbrt-v4:
//! * the box and triangle filters are sampled exactly in proportion to f and
//!   return weight 1 (f/pdf up to the constant ∫f, which the film's division
//!   by Σ w cancels);
//! * the Gaussian, Mitchell and Lanczos filters are tabulated at cell centres
//!   (32 cells per unit of radius) and sampled from the piecewise-constant
//!   density ∝ |f|; the weight is f_cell/pdf = sign(f)·∫|f_table|, negative
//!   in Mitchell's and Lanczos's negative lobes.
//!
//! [`Filter::integral`] is the exact ∫f (the film divides splats by it). For
//! Lanczos, pbrt-v4 estimates it with 4096 jittered samples; we integrate the
//! separable 1D factor by Simpson's rule instead (a more accurate number for
//! the same quantity).

use crate::math::{lerp, Vec2, PI};
use crate::sampling::{sample_linear, Distribution2D};
use std::sync::Arc;

/// A film offset and the weight its sample carries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilterSample {
    /// Offset from the pixel centre, inside `[-radius, radius]`.
    pub p: Vec2,
    /// Weight the film accumulates with this sample (see module docs).
    pub weight: f32,
}

/// Which filter to build (pbrt-v4 names).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilterKind {
    /// `box`.
    Box,
    /// `gaussian`.
    Gaussian,
    /// `mitchell`.
    Mitchell,
    /// `sinc` (Lanczos-windowed sinc).
    LanczosSinc,
    /// `triangle`.
    Triangle,
}

impl FilterKind {
    /// From a pbrt-v4 filter name.
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "box" => FilterKind::Box,
            "gaussian" => FilterKind::Gaussian,
            "mitchell" => FilterKind::Mitchell,
            "sinc" => FilterKind::LanczosSinc,
            "triangle" => FilterKind::Triangle,
            _ => return None,
        })
    }
}

/// Optional scene parameters; `None` takes pbrt-v4's default for the kind.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FilterParams {
    /// Radius (box 0.5, gaussian 1.5, mitchell 2, sinc 4, triangle 2).
    pub radius: Option<Vec2>,
    /// Gaussian standard deviation (0.5).
    pub sigma: Option<f32>,
    /// Mitchell–Netravali B (1/3).
    pub b: Option<f32>,
    /// Mitchell–Netravali C (1/3).
    pub c: Option<f32>,
    /// Lanczos window: number of sinc lobes τ (3).
    pub tau: Option<f32>,
}

/// Tabulated |f| for importance sampling (opaque; shared between clones).
#[derive(Debug)]
pub struct FilterTable {
    f: Vec<f32>,
    n: [usize; 2],
    distrib: Distribution2D,
    integral: f32,
}

/// The pixel filters candela supports (closed set).
#[derive(Clone, Debug)]
pub enum Filter {
    /// Constant 1 inside the radius.
    Box {
        /// Radius.
        radius: Vec2,
    },
    /// Gaussian shifted down to reach 0 at the radius.
    Gaussian {
        /// Radius.
        radius: Vec2,
        /// Standard deviation.
        sigma: f32,
        /// Sampling table.
        table: Arc<FilterTable>,
    },
    /// Mitchell–Netravali cubic.
    Mitchell {
        /// Radius.
        radius: Vec2,
        /// B.
        b: f32,
        /// C.
        c: f32,
        /// Sampling table.
        table: Arc<FilterTable>,
    },
    /// sinc windowed by a stretched sinc.
    LanczosSinc {
        /// Radius.
        radius: Vec2,
        /// Lobes of the window.
        tau: f32,
        /// Sampling table.
        table: Arc<FilterTable>,
    },
    /// Separable tent.
    Triangle {
        /// Radius.
        radius: Vec2,
    },
}

impl Default for Filter {
    /// pbrt-v4's default filter: Gaussian, radius 1.5, σ = 0.5.
    fn default() -> Self {
        Filter::new(FilterKind::Gaussian, &FilterParams::default())
    }
}

impl Filter {
    /// pbrt-v4's default radius of `kind`.
    pub fn default_radius(kind: FilterKind) -> Vec2 {
        Vec2::splat(match kind {
            FilterKind::Box => 0.5,
            FilterKind::Gaussian => 1.5,
            FilterKind::Mitchell | FilterKind::Triangle => 2.0,
            FilterKind::LanczosSinc => 4.0,
        })
    }

    /// Bytes of the sampling table [`Filter::new`] would build: 32 cells per
    /// unit of radius along each axis, each a tabulated value, the sampling
    /// distribution's density and CDF entry and the f64 CDF it is summed in
    /// (0 for box and triangle).
    pub fn table_bytes(kind: FilterKind, p: &FilterParams) -> u64 {
        if matches!(kind, FilterKind::Box | FilterKind::Triangle) {
            return 0;
        }
        let r = p.radius.unwrap_or(Self::default_radius(kind));
        let cells = |x: f32| (32.0 * x as f64).max(1.0);
        (cells(r.x) * cells(r.y) * 20.0) as u64
    }

    /// Builds a filter, filling unset parameters with pbrt-v4's defaults.
    pub fn new(kind: FilterKind, p: &FilterParams) -> Self {
        let r = |d: f32| p.radius.unwrap_or(Vec2::splat(d));
        match kind {
            FilterKind::Box => Filter::Box { radius: r(0.5) },
            FilterKind::Triangle => Filter::Triangle { radius: r(2.0) },
            FilterKind::Gaussian => {
                let (radius, sigma) = (r(1.5), p.sigma.unwrap_or(0.5));
                let integral =
                    gaussian_1d_integral(radius.x, sigma) * gaussian_1d_integral(radius.y, sigma);
                let eval = |q: Vec2| gaussian_eval(q, radius, sigma);
                let table = FilterTable::new(radius, integral, eval);
                Filter::Gaussian {
                    radius,
                    sigma,
                    table,
                }
            }
            FilterKind::Mitchell => {
                let (radius, b, c) = (r(2.0), p.b.unwrap_or(1.0 / 3.0), p.c.unwrap_or(1.0 / 3.0));
                // ∫ Mitchell1D over [−2, 2] is 1, stretched by r/2 per axis.
                let integral = radius.x * radius.y / 4.0;
                let eval = |q: Vec2| mitchell_eval(q, radius, b, c);
                let table = FilterTable::new(radius, integral, eval);
                Filter::Mitchell {
                    radius,
                    b,
                    c,
                    table,
                }
            }
            FilterKind::LanczosSinc => {
                let (radius, tau) = (r(4.0), p.tau.unwrap_or(3.0));
                let integral =
                    windowed_sinc_integral(radius.x, tau) * windowed_sinc_integral(radius.y, tau);
                let eval =
                    |q: Vec2| windowed_sinc(q.x, radius.x, tau) * windowed_sinc(q.y, radius.y, tau);
                let table = FilterTable::new(radius, integral, eval);
                Filter::LanczosSinc { radius, tau, table }
            }
        }
    }

    /// Half-width of the support along x and y.
    pub fn radius(&self) -> Vec2 {
        match self {
            Filter::Box { radius }
            | Filter::Triangle { radius }
            | Filter::Gaussian { radius, .. }
            | Filter::Mitchell { radius, .. }
            | Filter::LanczosSinc { radius, .. } => *radius,
        }
    }

    /// Filter value at offset `p` from the pixel centre.
    pub fn evaluate(&self, p: Vec2) -> f32 {
        match self {
            Filter::Box { radius } => {
                if p.x.abs() <= radius.x && p.y.abs() <= radius.y {
                    1.0
                } else {
                    0.0
                }
            }
            Filter::Triangle { radius } => {
                (radius.x - p.x.abs()).max(0.0) * (radius.y - p.y.abs()).max(0.0)
            }
            Filter::Gaussian { radius, sigma, .. } => gaussian_eval(p, *radius, *sigma),
            Filter::Mitchell { radius, b, c, .. } => mitchell_eval(p, *radius, *b, *c),
            Filter::LanczosSinc { radius, tau, .. } => {
                windowed_sinc(p.x, radius.x, *tau) * windowed_sinc(p.y, radius.y, *tau)
            }
        }
    }

    /// ∫ f over the support.
    pub fn integral(&self) -> f32 {
        match self {
            Filter::Box { radius } => 4.0 * radius.x * radius.y,
            Filter::Triangle { radius } => radius.x * radius.x * radius.y * radius.y,
            Filter::Gaussian { table, .. }
            | Filter::Mitchell { table, .. }
            | Filter::LanczosSinc { table, .. } => table.integral,
        }
    }

    /// Draws a film offset for `u ∈ [0,1)²` and its weight.
    pub fn sample(&self, u: Vec2) -> FilterSample {
        match self {
            Filter::Box { radius } => FilterSample {
                p: Vec2::new(
                    lerp(u.x, -radius.x, radius.x),
                    lerp(u.y, -radius.y, radius.y),
                ),
                weight: 1.0,
            },
            Filter::Triangle { radius } => FilterSample {
                p: Vec2::new(sample_tent(u.x, radius.x), sample_tent(u.y, radius.y)),
                weight: 1.0,
            },
            Filter::Gaussian { radius, table, .. }
            | Filter::Mitchell { radius, table, .. }
            | Filter::LanczosSinc { radius, table, .. } => table.sample(*radius, u),
        }
    }
}

impl FilterTable {
    /// Tabulates `eval` at the centres of 32 cells per unit radius [pbrt-v4 §8.8.1].
    fn new(radius: Vec2, integral: f32, eval: impl Fn(Vec2) -> f32) -> Arc<Self> {
        let n = [
            ((32.0 * radius.x) as usize).max(1),
            ((32.0 * radius.y) as usize).max(1),
        ];
        let mut f = Vec::with_capacity(n[0] * n[1]);
        for y in 0..n[1] {
            for x in 0..n[0] {
                let t = Vec2::new(
                    (x as f32 + 0.5) / n[0] as f32,
                    (y as f32 + 0.5) / n[1] as f32,
                );
                f.push(eval((2.0 * t - Vec2::ONE) * radius));
            }
        }
        let distrib = Distribution2D::new(&f, n[0], n[1]);
        Arc::new(Self {
            f,
            n,
            distrib,
            integral,
        })
    }

    /// Samples ∝ |f_table|; weight = f_cell / pdf over the filter's domain.
    fn sample(&self, radius: Vec2, u: Vec2) -> FilterSample {
        let (t, pdf_unit) = self.distrib.sample(u);
        let p = (2.0 * t - Vec2::ONE) * radius;
        let ix = ((t.x * self.n[0] as f32) as usize).min(self.n[0] - 1);
        let iy = ((t.y * self.n[1] as f32) as usize).min(self.n[1] - 1);
        let pdf = pdf_unit / (4.0 * radius.x * radius.y);
        let weight = if pdf > 0.0 {
            self.f[iy * self.n[0] + ix] / pdf
        } else {
            0.0
        };
        FilterSample { p, weight }
    }
}

/// Samples the tent of half-width r on [−r, r].
fn sample_tent(u: f32, r: f32) -> f32 {
    if u < 0.5 {
        -r + r * sample_linear(u * 2.0, 0.0, 1.0)
    } else {
        r * sample_linear(u * 2.0 - 1.0, 1.0, 0.0)
    }
}

/// Normal density with mean 0.
fn gaussian(x: f32, sigma: f32) -> f32 {
    (-x * x / (2.0 * sigma * sigma)).exp() / (2.0 * PI * sigma * sigma).sqrt()
}

/// Gaussian minus its value at the radius, clamped at 0, per axis.
fn gaussian_eval(p: Vec2, r: Vec2, sigma: f32) -> f32 {
    (gaussian(p.x, sigma) - gaussian(r.x, sigma)).max(0.0)
        * (gaussian(p.y, sigma) - gaussian(r.y, sigma)).max(0.0)
}

/// ∫_{−r}^{r} (g(x) − g(r)) dx = erf(r/(σ√2)) − 2r·g(r).
fn gaussian_1d_integral(r: f32, sigma: f32) -> f32 {
    let (r, s) = (r as f64, sigma as f64);
    let g_r = (-r * r / (2.0 * s * s)).exp() / (2.0 * std::f64::consts::PI * s * s).sqrt();
    (erf(r / (s * std::f64::consts::SQRT_2)) - 2.0 * r * g_r) as f32
}

/// erf by Abramowitz & Stegun 7.1.26 (|error| ≤ 1.5e−7).
fn erf(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x.abs());
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736
                + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    (1.0 - poly * (-x * x).exp()).copysign(x)
}

/// Mitchell–Netravali cubic on [−2, 2] [Mitchell & Netravali 1988].
fn mitchell_1d(x: f32, b: f32, c: f32) -> f32 {
    let x = x.abs();
    let v = if x <= 1.0 {
        (12.0 - 9.0 * b - 6.0 * c) * x * x * x
            + (-18.0 + 12.0 * b + 6.0 * c) * x * x
            + (6.0 - 2.0 * b)
    } else if x <= 2.0 {
        (-b - 6.0 * c) * x * x * x
            + (6.0 * b + 30.0 * c) * x * x
            + (-12.0 * b - 48.0 * c) * x
            + (8.0 * b + 24.0 * c)
    } else {
        0.0
    };
    v / 6.0
}

/// Mitchell filter stretched so [−2, 2] covers [−r, r].
fn mitchell_eval(p: Vec2, r: Vec2, b: f32, c: f32) -> f32 {
    mitchell_1d(2.0 * p.x / r.x, b, c) * mitchell_1d(2.0 * p.y / r.y, b, c)
}

/// sin(πx)/(πx).
fn sinc(x: f32) -> f32 {
    if (1.0 + x * x) == 1.0 {
        return 1.0;
    }
    (PI * x).sin() / (PI * x)
}

/// sinc windowed by sinc(x/τ), zero beyond the radius.
fn windowed_sinc(x: f32, radius: f32, tau: f32) -> f32 {
    if x.abs() > radius {
        return 0.0;
    }
    sinc(x) * sinc(x / tau)
}

/// ∫_{−r}^{r} windowed sinc by composite Simpson (4096 intervals).
fn windowed_sinc_integral(r: f32, tau: f32) -> f32 {
    let n = 4096;
    let h = 2.0 * r as f64 / n as f64;
    let sum: f64 = (0..=n)
        .map(|i| {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * windowed_sinc((-r as f64 + i as f64 * h) as f32, r, tau) as f64
        })
        .sum();
    (sum * h / 3.0) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    fn all() -> Vec<Filter> {
        let kinds = [
            FilterKind::Box,
            FilterKind::Gaussian,
            FilterKind::Mitchell,
            FilterKind::LanczosSinc,
            FilterKind::Triangle,
        ];
        let mut v: Vec<Filter> = kinds
            .iter()
            .map(|&k| Filter::new(k, &FilterParams::default()))
            .collect();
        let wide = FilterParams {
            radius: Some(Vec2::new(1.0, 2.5)),
            ..Default::default()
        };
        v.extend(kinds.iter().map(|&k| Filter::new(k, &wide)));
        v
    }

    /// Midpoint quadrature of `h` over the filter's support (f64, m² cells).
    fn quad(f: &Filter, m: usize, h: impl Fn(Vec2) -> f64) -> f64 {
        let r = f.radius();
        let cell = 4.0 * (r.x * r.y) as f64 / (m * m) as f64;
        let mut s = 0.0;
        for j in 0..m {
            for i in 0..m {
                let t = Vec2::new((i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32);
                s += h((2.0 * t - Vec2::ONE) * r);
            }
        }
        s * cell
    }

    #[test]
    fn integral_matches_quadrature() {
        for f in all() {
            let q = quad(&f, 1000, |p| f.evaluate(p) as f64);
            let rel = (q / f.integral() as f64 - 1.0).abs();
            assert!(rel < 1e-3, "{f:?}: quadrature {q} vs {}", f.integral());
        }
    }

    /// Σ w g / Σ w estimates ∫ f g / ∫ f. Tolerance: 5σ by the delta method
    /// (residuals wᵢ(gᵢ − R)) plus b: 0 for the exactly sampled box/triangle,
    /// 1e−3 for tables, ≥ 10× their midpoint error ≈ h²/12·∫|f′g′|/∫fg with h = 1/32.
    #[test]
    fn sampling_is_unbiased_for_smooth_integrands() {
        let g = |p: Vec2| ((0.4 * p.x - 0.3 * p.y).exp() * (1.0 + 0.2 * p.x * p.y)) as f64;
        let mut rng = Pcg32::new(9, 1);
        for f in all() {
            let want = quad(&f, 1000, |p| f.evaluate(p) as f64 * g(p)) / f.integral() as f64;
            let n = 200_000;
            let s: Vec<FilterSample> = (0..n)
                .map(|_| f.sample(Vec2::new(rng.uniform_f32(), rng.uniform_f32())))
                .collect();
            let sw: f64 = s.iter().map(|s| s.weight as f64).sum();
            let r = s.iter().map(|s| s.weight as f64 * g(s.p)).sum::<f64>() / sw;
            let var = s
                .iter()
                .map(|s| (s.weight as f64 * (g(s.p) - r)).powi(2))
                .sum::<f64>()
                / (n as f64 - 1.0);
            let tol = 5.0 * var.sqrt() * n as f64 / sw / (n as f64).sqrt();
            let b = if matches!(f, Filter::Box { .. } | Filter::Triangle { .. }) {
                0.0
            } else {
                1e-3 * want.abs()
            };
            assert!(
                (r - want).abs() <= tol + b,
                "{f:?}: {r} vs {want} (±{tol} + {b})"
            );
            for s in &s {
                let r = f.radius();
                assert!(s.p.x.abs() <= r.x && s.p.y.abs() <= r.y);
            }
            // Table weights are sign(f)·∫|f_table|, so E[w] ≈ ∫ f.
            if let Filter::Gaussian { .. } = f {
                assert!((sw / n as f64 / f.integral() as f64 - 1.0).abs() < 1e-3);
            }
        }
    }

    #[test]
    fn box_weight_is_exactly_one_and_mitchell_has_negative_weights() {
        let bx = Filter::new(FilterKind::Box, &FilterParams::default());
        let mi = Filter::new(FilterKind::Mitchell, &FilterParams::default());
        let mut rng = Pcg32::new(4, 4);
        let mut negative = 0;
        for _ in 0..10_000 {
            let u = Vec2::new(rng.uniform_f32(), rng.uniform_f32());
            let s = bx.sample(u);
            assert_eq!(s.weight, 1.0);
            assert_eq!(bx.evaluate(s.p), 1.0);
            negative += (mi.sample(u).weight < 0.0) as u32;
        }
        assert!(negative > 0);
        assert_eq!(FilterKind::from_name("sinc"), Some(FilterKind::LanczosSinc));
    }
}
