//! Emission sampling of an [`IesWeb`] ∝ its interpolated intensity.
//!
//! A cell is chosen by its exact flux, then (ϑ, ψ) inside it with density
//! I(ψ, ϑ)·sin ϑ / F_cell: ϑ from the cell's marginal
//! m(ϑ) = (a + (b − a)t)·sin ϑ, t = (ϑ − ϑ₀)/Δϑ, whose CDF is
//! M(ϑ) = a(cos ϑ₀ − cos ϑ) + ((b − a)/Δϑ)(sin ϑ − sin ϑ₀ − (ϑ − ϑ₀) cos ϑ)
//! (integration by parts), inverted by Newton's method kept inside a
//! shrinking bracket; then ψ from the conditional, linear between the
//! cell's two interpolated edges at that ϑ [pbrt-v4 §A.4.2 `SampleLinear`].

use super::{lerp, Cell, IesWeb};
use crate::math::{Vec2, Vec3};
use crate::sampling::{sample_linear, PdfSolidAngle};

/// A direction drawn by [`IesWeb::sample`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IesSample {
    /// Unit direction in the light frame.
    pub w: Vec3,
    /// Its density per unit solid angle (= [`IesWeb::pdf`]`(w)`).
    pub pdf: PdfSolidAngle,
    /// Intensity towards `w` \[cd\] (= [`IesWeb::intensity`]`(w)`).
    pub intensity: f32,
}

impl IesWeb {
    /// Draws a direction with density ∝ I(ω); `None` if the web emits nothing.
    pub fn sample(&self, u: Vec2) -> Option<IesSample> {
        let (j, pmf_j, ux) = self.columns.sample_discrete(u.x);
        let (i, pmf_i, uy) = self.rows[j].sample_discrete(u.y);
        if pmf_j == 0.0 || pmf_i == 0.0 || self.cell_flux[j * (self.polar.len() - 1) + i] <= 0.0 {
            return None;
        }
        let (t0, t1) = (self.polar[i], self.polar[i + 1]);
        let lower = 0.5 * (self.node(j, i) + self.node(j + 1, i));
        let upper = 0.5 * (self.node(j, i + 1) + self.node(j + 1, i + 1));
        let theta = invert_polar_cdf(uy as f64, t0, t1, lower, upper);
        let t = ((theta - t0) / (t1 - t0)).clamp(0.0, 1.0);
        let a = lerp(t, self.node(j, i), self.node(j, i + 1));
        let b = lerp(t, self.node(j + 1, i), self.node(j + 1, i + 1));
        let s = if a + b > 0.0 {
            sample_linear(ux, a as f32, b as f32) as f64
        } else {
            ux as f64
        };
        let cell = Cell { j, i, s, t };
        let intensity = self.bilinear(cell);
        if intensity <= 0.0 {
            return None;
        }
        let psi = lerp(s, self.azimuth[j], self.azimuth[j + 1]);
        let (st, ct, sp, cp) = (theta.sin(), theta.cos(), psi.sin(), psi.cos());
        let [e1, e2, e3] = self.axes;
        let d = |k: usize| (st * (cp * e1[k] + sp * e2[k]) + ct * e3[k]) as f32;
        Some(IesSample {
            w: Vec3::new(d(0), d(1), d(2)).normalize(),
            pdf: PdfSolidAngle(self.cell_pdf(cell, intensity) as f32),
            intensity: intensity as f32,
        })
    }
}

/// The ϑ ∈ [t0, t1] where the CDF of (lower + (upper − lower)t)·sin ϑ
/// reaches the fraction `u` of its total (module doc).
fn invert_polar_cdf(u: f64, t0: f64, t1: f64, lower: f64, upper: f64) -> f64 {
    let d = t1 - t0;
    let slope = (upper - lower) / d;
    let (c0, s0) = (t0.cos(), t0.sin());
    let cdf = |th: f64| lower * (c0 - th.cos()) + slope * (th.sin() - s0 - (th - t0) * th.cos());
    let target = u * cdf(t1);
    let (mut lo, mut hi) = (t0, t1);
    let mut th = lerp(u, t0, t1);
    for _ in 0..64 {
        let f = cdf(th) - target;
        if f.abs() <= 1e-14 * cdf(t1) || hi - lo < 1e-15 {
            break;
        }
        if f > 0.0 {
            hi = th;
        } else {
            lo = th;
        }
        let density = (lower + slope * (th - t0)) * th.sin();
        let next = th - f / density;
        // Newton while it stays inside the bracket, bisection otherwise.
        th = if density > 0.0 && next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
    }
    th.clamp(t0, t1)
}
