//! Block statistics for comparing renders [Jung, Hanika & Dachsbacher,
//! JCGT 2020]: each render gives one estimate of every 8×8 block's mean;
//! two sets of renders agree when Welch's t-test finds no block whose
//! two-sided p-value is below the Šidák-corrected level α' = 1 − (1 − α)^(1/m)
//! for m blocks and α = 0.01 overall.

use candela_core::image::RgbImage;

/// Side of a comparison block in pixels.
pub const BLOCK: usize = 8;

/// Mean of the channel sum over each `BLOCK`×`BLOCK` block (row-major;
/// partial blocks at the right and bottom edges are left out).
pub fn block_means(img: &RgbImage) -> Vec<f64> {
    let (nx, ny) = (img.width / BLOCK, img.height / BLOCK);
    let mut out = Vec::with_capacity(nx * ny);
    for by in 0..ny {
        for bx in 0..nx {
            let mut s = 0.0f64;
            for y in by * BLOCK..(by + 1) * BLOCK {
                for x in bx * BLOCK..(bx + 1) * BLOCK {
                    let p = img.get(x, y);
                    s += (p[0] + p[1] + p[2]) as f64;
                }
            }
            out.push(s / (BLOCK * BLOCK) as f64);
        }
    }
    out
}

/// Per block, the estimates of several renders: `renders[k][block]` → `[block][k]`.
pub fn by_block(renders: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let m = renders.first().map_or(0, Vec::len);
    (0..m)
        .map(|b| renders.iter().map(|r| r[b]).collect())
        .collect()
}

/// Sample mean and (unbiased) variance.
pub fn mean_var(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (
        m,
        v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0),
    )
}

/// Regularised incomplete beta I_x(a, b) by Lentz's continued fraction.
pub fn inc_beta(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    if x > (a + 1.0) / (a + b + 2.0) {
        return 1.0 - inc_beta(b, a, 1.0 - x);
    }
    let ln_gamma = candela_core::sampling::chi2::ln_gamma;
    let ln_front =
        a * x.ln() + b * (1.0 - x).ln() - (ln_gamma(a) + ln_gamma(b) - ln_gamma(a + b)) - a.ln();
    let (tiny, mut f, mut c, mut d) = (1e-300, 1.0, 1.0, 0.0);
    for i in 0..400 {
        let m = (i / 2) as f64;
        let num = if i == 0 {
            1.0
        } else if i % 2 == 0 {
            m * (b - m) * x / ((a + 2.0 * m - 1.0) * (a + 2.0 * m))
        } else {
            -(a + m) * (a + b + m) * x / ((a + 2.0 * m) * (a + 2.0 * m + 1.0))
        };
        d = 1.0 + num * d;
        d = if d.abs() < tiny { tiny } else { d };
        d = 1.0 / d;
        c = 1.0 + num / c;
        c = if c.abs() < tiny { tiny } else { c };
        let cd = c * d;
        f *= cd;
        if (cd - 1.0).abs() < 1e-14 {
            break;
        }
    }
    ln_front.exp() * (f - 1.0)
}

/// Two-sided p-value of Student's t with `df` degrees of freedom.
pub fn t_two_sided_p(t: f64, df: f64) -> f64 {
    inc_beta(df / 2.0, 0.5, df / (df + t * t))
}

/// Welch's t statistic, Welch–Satterthwaite degrees of freedom and the
/// two-sided p-value for two samples. Two constant, equal samples give
/// p = 1; constant, different ones p = 0.
pub fn welch(x: &[f64], y: &[f64]) -> (f64, f64, f64) {
    let ((mx, vx), (my, vy)) = (mean_var(x), mean_var(y));
    let (sx, sy) = (vx / x.len() as f64, vy / y.len() as f64);
    if sx + sy == 0.0 {
        return (0.0, 0.0, if mx == my { 1.0 } else { 0.0 });
    }
    let t = (mx - my) / (sx + sy).sqrt();
    let df =
        (sx + sy).powi(2) / (sx * sx / (x.len() as f64 - 1.0) + sy * sy / (y.len() as f64 - 1.0));
    (t, df, t_two_sided_p(t.abs(), df))
}

/// The first block of `a` and `b` (`[block][render]`) whose Welch t-test
/// p-value is below the Šidák-corrected level for α = 0.01 over all
/// blocks, described; `None` when all agree.
pub fn disagreement(a: &[Vec<f64>], b: &[Vec<f64>]) -> Option<String> {
    assert_eq!(a.len(), b.len(), "block counts differ");
    let alpha = 1.0 - (1.0f64 - 0.01).powf(1.0 / a.len() as f64);
    a.iter().zip(b).enumerate().find_map(|(blk, (x, y))| {
        let (t, df, p) = welch(x, y);
        let (mx, my) = (mean_var(x).0, mean_var(y).0);
        (p < alpha).then(|| {
            format!("block {blk}: {mx:.5} vs {my:.5}, t = {t:.2}, df = {df:.1}, p = {p:.2e} < {alpha:.2e}")
        })
    })
}

/// Asserts every block of `a` and `b` agrees (see [`disagreement`]).
pub fn assert_blocks_agree(a: &[Vec<f64>], b: &[Vec<f64>], what: &str) {
    if let Some(d) = disagreement(a, b) {
        panic!("{what}, {d}");
    }
}
