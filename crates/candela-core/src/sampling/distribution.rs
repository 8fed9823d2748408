//! Piecewise-constant 1D and 2D distributions (light selection, image maps).

use crate::math::Vec2;

/// A piecewise-constant density on [0, 1) with `n` equal cells.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    func: Vec<f32>,
    cdf: Vec<f32>,
    integral: f32,
}

impl Distribution1D {
    /// From non-negative cell values; an all-zero function becomes uniform.
    pub fn new(func: &[f32]) -> Self {
        let n = func.len().max(1);
        let func: Vec<f32> = if func.is_empty() {
            vec![1.0]
        } else {
            func.iter().map(|v| v.abs()).collect()
        };
        let mut cdf = vec![0.0f64; n + 1];
        for i in 1..=n {
            cdf[i] = cdf[i - 1] + func[i - 1] as f64 / n as f64;
        }
        let integral = cdf[n];
        let cdf: Vec<f32> = if integral == 0.0 {
            (0..=n).map(|i| i as f32 / n as f32).collect()
        } else {
            cdf.iter().map(|&c| (c / integral) as f32).collect()
        };
        Self {
            func,
            cdf,
            integral: integral as f32,
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// True if there are no cells (never: an empty input gets one cell).
    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }

    /// ∫ f over [0, 1).
    pub fn integral(&self) -> f32 {
        self.integral
    }

    /// Probability of choosing cell `i` by [`sample_discrete`](Self::sample_discrete).
    pub fn discrete_pmf(&self, i: usize) -> f32 {
        if self.integral == 0.0 {
            return 1.0 / self.len() as f32;
        }
        self.func[i] / (self.integral * self.len() as f32)
    }

    /// Density at continuous `x ∈ [0,1)`.
    pub fn pdf(&self, x: f32) -> f32 {
        let i = ((x * self.len() as f32) as usize).min(self.len() - 1);
        if self.integral == 0.0 {
            1.0
        } else {
            self.func[i] / self.integral
        }
    }

    fn find_cell(&self, u: f32) -> usize {
        // Largest i with cdf[i] <= u, clamped to a valid cell.
        let i = self.cdf.partition_point(|&c| c <= u);
        i.saturating_sub(1).min(self.len() - 1)
    }

    /// Chooses a cell with probability ∝ its value; returns (cell, pmf, remapped u).
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let i = self.find_cell(u);
        let w = self.cdf[i + 1] - self.cdf[i];
        let u_remap = if w > 0.0 {
            ((u - self.cdf[i]) / w).clamp(0.0, super::ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        (i, self.discrete_pmf(i), u_remap)
    }

    /// Continuous sample in [0,1); returns (x, pdf, cell).
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let i = self.find_cell(u);
        let w = self.cdf[i + 1] - self.cdf[i];
        let du = if w > 0.0 { (u - self.cdf[i]) / w } else { 0.0 };
        let x = ((i as f32 + du) / self.len() as f32).min(super::ONE_MINUS_EPSILON);
        (x, self.pdf(x), i)
    }
}

/// Piecewise-constant 2D density on [0,1)² (marginal in v, conditional in u).
#[derive(Clone, Debug)]
pub struct Distribution2D {
    conditional: Vec<Distribution1D>,
    marginal: Distribution1D,
}

impl Distribution2D {
    /// From row-major values `f[v * nu + u]`.
    pub fn new(f: &[f32], nu: usize, nv: usize) -> Self {
        let conditional: Vec<Distribution1D> = (0..nv)
            .map(|v| Distribution1D::new(&f[v * nu..(v + 1) * nu]))
            .collect();
        let marg: Vec<f32> = conditional.iter().map(|c| c.integral()).collect();
        Self {
            conditional,
            marginal: Distribution1D::new(&marg),
        }
    }

    /// Samples a point; returns (point, pdf).
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (v, pdf_v, iv) = self.marginal.sample_continuous(u.y);
        let (x, pdf_u, _) = self.conditional[iv].sample_continuous(u.x);
        (Vec2::new(x, v), pdf_u * pdf_v)
    }

    /// Chooses a cell with probability ∝ its value (row by `u.y`, column by
    /// `u.x`); returns its (column, row) and probability.
    pub fn sample_discrete(&self, u: Vec2) -> ((usize, usize), f32) {
        let (iv, pmf_v, _) = self.marginal.sample_discrete(u.y);
        let (iu, pmf_u, _) = self.conditional[iv].sample_discrete(u.x);
        ((iu, iv), pmf_u * pmf_v)
    }

    /// Probability that [`sample_discrete`](Self::sample_discrete) returns cell (iu, iv).
    pub fn discrete_pmf(&self, iu: usize, iv: usize) -> f32 {
        self.marginal.discrete_pmf(iv) * self.conditional[iv].discrete_pmf(iu)
    }

    /// Density at `p`.
    pub fn pdf(&self, p: Vec2) -> f32 {
        let nv = self.conditional.len();
        let iv = ((p.y * nv as f32) as usize).min(nv - 1);
        let cond = &self.conditional[iv];
        if self.marginal.integral() == 0.0 {
            return 1.0;
        }
        cond.pdf(p.x) * cond.integral() / self.marginal.integral()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn discrete_sampling_follows_weights() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0]);
        assert_eq!(d.sample_discrete(0.1).0, 0);
        assert_eq!(d.sample_discrete(0.3).0, 2);
        assert!((d.discrete_pmf(2) - 0.75).abs() < 1e-6);
        assert_eq!(d.discrete_pmf(1), 0.0);
        let (x, pdf, _) = d.sample_continuous(0.5);
        assert!(x >= 2.0 / 3.0 && (pdf - d.pdf(x)).abs() < 1e-6);
    }

    #[test]
    fn two_d_discrete_sampling_follows_weights() {
        // 3×3 cells with a zero cell and a zero row; the frequencies of a
        // 240×240 stratified grid (whose lines fall on every CDF step, all
        // multiples of 1/24) match the pmfs to 1e-3, and the pmfs are f/Σf.
        let f = [1.0, 0.0, 3.0, 0.0, 0.0, 0.0, 2.0, 2.0, 4.0];
        let d = Distribution2D::new(&f, 3, 3);
        let mut count = [0.0f64; 9];
        let (nx, ny) = (240, 240);
        for j in 0..ny {
            for i in 0..nx {
                let u = Vec2::new((i as f32 + 0.5) / nx as f32, (j as f32 + 0.5) / ny as f32);
                let ((iu, iv), pmf) = d.sample_discrete(u);
                assert_eq!(pmf, d.discrete_pmf(iu, iv));
                count[iv * 3 + iu] += 1.0 / (nx * ny) as f64;
            }
        }
        for k in 0..9 {
            let want = f[k] as f64 / 12.0;
            assert!(
                (d.discrete_pmf(k % 3, k / 3) as f64 - want).abs() < 1e-6,
                "pmf {k}"
            );
            assert!(
                (count[k] - want).abs() < 1e-3,
                "cell {k}: {} vs {want}",
                count[k]
            );
        }
    }

    #[test]
    fn two_d_pdf_integrates_to_one() {
        let f: Vec<f32> = (0..12).map(|i| (i % 5) as f32 + 0.5).collect();
        let d = Distribution2D::new(&f, 4, 3);
        let n = 200;
        let mut s = 0.0f64;
        for j in 0..n {
            for i in 0..n {
                s += d.pdf(Vec2::new(
                    (i as f32 + 0.5) / n as f32,
                    (j as f32 + 0.5) / n as f32,
                )) as f64;
            }
        }
        assert!((s / (n * n) as f64 - 1.0).abs() < 1e-4);
        let (p, pdf) = d.sample(Vec2::new(0.3, 0.8));
        assert!((pdf - d.pdf(p)).abs() < 1e-4);
    }
}
