//! Warps from the unit square to disks, hemispheres, spheres, cones and
//! triangles, each with its density [pbrt-v4 §A.5; Shirley & Chiu 1997].

use crate::math::{safe_sqrt, Vec2, Vec3, INV_2PI, INV_4PI, INV_PI, PI};

/// Concentric map of the square onto the unit disk [Shirley & Chiu 1997].
#[inline]
pub fn sample_uniform_disk_concentric(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, PI / 4.0 * (o.y / o.x))
    } else {
        (o.y, PI / 2.0 - PI / 4.0 * (o.x / o.y))
    };
    r * Vec2::new(theta.cos(), theta.sin())
}

/// Polar map of the square onto the unit disk.
#[inline]
pub fn sample_uniform_disk_polar(u: Vec2) -> Vec2 {
    let r = u.x.sqrt();
    let theta = 2.0 * PI * u.y;
    Vec2::new(r * theta.cos(), r * theta.sin())
}

/// Cosine-weighted direction on the +z hemisphere (Malley's method).
#[inline]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    let d = sample_uniform_disk_concentric(u);
    let z = safe_sqrt(1.0 - d.x * d.x - d.y * d.y);
    Vec3::new(d.x, d.y, z)
}

/// Density of [`sample_cosine_hemisphere`]: cos θ / π.
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta * INV_PI
}

/// Uniform direction on the +z hemisphere.
#[inline]
pub fn sample_uniform_hemisphere(u: Vec2) -> Vec3 {
    let z = u.x;
    let r = safe_sqrt(1.0 - z * z);
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_uniform_hemisphere`]: 1/(2π).
#[inline]
pub fn uniform_hemisphere_pdf() -> f32 {
    INV_2PI
}

/// Uniform direction on the unit sphere.
#[inline]
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = safe_sqrt(1.0 - z * z);
    let phi = 2.0 * PI * u.y;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Density of [`sample_uniform_sphere`]: 1/(4π).
#[inline]
pub fn uniform_sphere_pdf() -> f32 {
    INV_4PI
}

/// Uniform direction in the cone of half-angle acos(`cos_max`) around +z.
#[inline]
pub fn sample_uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    let cos_t = (1.0 - u.x) + u.x * cos_max;
    let sin_t = safe_sqrt(1.0 - cos_t * cos_t);
    let phi = u.y * 2.0 * PI;
    Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t)
}

/// Density of [`sample_uniform_cone`]: 1 / (2π(1 − cos_max)).
#[inline]
pub fn uniform_cone_pdf(cos_max: f32) -> f32 {
    1.0 / (2.0 * PI * (1.0 - cos_max))
}

/// Uniform barycentrics on a triangle [Heitz 2019, "A low-distortion map
/// between triangle and square"]; returns (b0, b1, b2).
#[inline]
pub fn sample_uniform_triangle(u: Vec2) -> [f32; 3] {
    let (b0, b1) = if u.x < u.y {
        let b0 = u.x / 2.0;
        (b0, u.y - b0)
    } else {
        let b1 = u.y / 2.0;
        (u.x - b1, b1)
    };
    [b0, b1, 1.0 - b0 - b1]
}

/// Exponential distance sample with rate `a`.
#[inline]
pub fn sample_exponential(u: f32, a: f32) -> f32 {
    -(1.0 - u).ln() / a
}

/// Samples the tent / linear density on \[0,1\] proportional to lerp(x, a, b).
#[inline]
pub fn sample_linear(u: f32, a: f32, b: f32) -> f32 {
    if u == 0.0 && a == 0.0 {
        return 0.0;
    }
    let x = u * (a + b) / (a + (crate::math::lerp(u, a * a, b * b)).sqrt());
    x.min(super::ONE_MINUS_EPSILON)
}

/// Largest |g| the Henyey–Greenstein functions use: the inverse CDF below
/// loses all precision as |g| → 1, so both the density and the sampler clamp
/// g to ±0.99 and stay consistent with each other.
const HG_MAX_G: f32 = 0.99;

/// Henyey–Greenstein phase function for directions `wo`, `wi` that both point
/// away from the scattering point [Henyey & Greenstein 1941; pbrt-v4 §11.3.1]:
/// p = (1 − g²) / (4π (1 + g² − 2gμ)^{3/2}), μ = −wo·wi the cosine of the
/// scattering angle (μ = 1 is straight on); g > 0 scatters forward.
#[inline]
pub fn henyey_greenstein(wo: Vec3, wi: Vec3, g: f32) -> f32 {
    let g = g.clamp(-HG_MAX_G, HG_MAX_G);
    let mu = -wo.dot(wi);
    let denom = 1.0 + g * g - 2.0 * g * mu;
    INV_4PI * (1.0 - g * g) / (denom * safe_sqrt(denom))
}

/// Samples `wi` from [`henyey_greenstein`] given `wo`; returns it with its density.
///
/// Inverting the CDF of μ gives μ = (1 + g² − ((1 − g²)/(1 − g + 2gξ))²) / (2g)
/// [Henyey & Greenstein 1941; pbrt-v4 §11.3.1], uniform μ = 2ξ − 1 for |g| < 10⁻³;
/// the azimuth about the propagation direction −wo is uniform.
pub fn sample_henyey_greenstein(wo: Vec3, g: f32, u: Vec2) -> (Vec3, f32) {
    let g = g.clamp(-HG_MAX_G, HG_MAX_G);
    let mu = if g.abs() < 1e-3 {
        2.0 * u.x - 1.0
    } else {
        let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
        ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
    };
    let sin = safe_sqrt(1.0 - mu * mu);
    let phi = 2.0 * PI * u.y;
    let frame = crate::math::Frame::from_z(-wo);
    let wi = frame.from_local(Vec3::new(sin * phi.cos(), sin * phi.sin(), mu));
    (wi, henyey_greenstein(wo, wi, g))
}

/// Inverse of [`sample_linear`]: the CDF x(a(2 − x) + bx)/(a + b) of the
/// density ∝ lerp(x, a, b) on [0, 1] [pbrt-v4 §A.4.2].
#[inline]
pub fn invert_linear_sample(x: f32, a: f32, b: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * (a * (2.0 - x) + b * x) / (a + b)
}

/// Samples the density on \[0,1\]² proportional to the bilinear interpolant of
/// the corner values `w` = [w(0,0), w(1,0), w(0,1), w(1,1)]: the marginal in
/// y is linear, the conditional in x is linear [pbrt-v4 §A.4.3]. Uniform
/// when all weights are zero.
pub fn sample_bilinear(u: Vec2, w: [f32; 4]) -> Vec2 {
    if w.iter().sum::<f32>() <= 0.0 {
        return u;
    }
    let y = sample_linear(u.y, w[0] + w[1], w[2] + w[3]);
    let x = sample_linear(
        u.x,
        crate::math::lerp(y, w[0], w[2]),
        crate::math::lerp(y, w[1], w[3]),
    );
    Vec2::new(x, y)
}

/// Density of [`sample_bilinear`]: 4·bilerp(p, w)/Σw, zero outside \[0,1\]².
pub fn bilinear_pdf(p: Vec2, w: [f32; 4]) -> f32 {
    if !(0.0..=1.0).contains(&p.x) || !(0.0..=1.0).contains(&p.y) {
        return 0.0;
    }
    let sum = w[0] + w[1] + w[2] + w[3];
    if sum <= 0.0 {
        return 1.0;
    }
    let bilerp = (1.0 - p.x) * (1.0 - p.y) * w[0]
        + p.x * (1.0 - p.y) * w[1]
        + (1.0 - p.x) * p.y * w[2]
        + p.x * p.y * w[3];
    4.0 * bilerp / sum
}

/// Inverse of [`sample_bilinear`]: the `u` that maps to `p`.
pub fn invert_bilinear_sample(p: Vec2, w: [f32; 4]) -> Vec2 {
    if w.iter().sum::<f32>() <= 0.0 {
        return p;
    }
    Vec2::new(
        invert_linear_sample(
            p.x,
            crate::math::lerp(p.y, w[0], w[2]),
            crate::math::lerp(p.y, w[1], w[3]),
        ),
        invert_linear_sample(p.y, w[0] + w[1], w[2] + w[3]),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    #[test]
    fn warps_stay_in_domain() {
        let mut r = Pcg32::new(3, 1);
        for _ in 0..10_000 {
            let u = Vec2::new(r.uniform_f32(), r.uniform_f32());
            assert!(sample_uniform_disk_concentric(u).length() <= 1.0 + 1e-6);
            let w = sample_cosine_hemisphere(u);
            assert!(w.z >= 0.0 && (w.length() - 1.0).abs() < 1e-5);
            assert!((sample_uniform_sphere(u).length() - 1.0).abs() < 1e-5);
            let c = sample_uniform_cone(u, 0.9);
            assert!(c.z >= 0.9 - 1e-6);
            let b = sample_uniform_triangle(u);
            assert!(b.iter().all(|&x| (-1e-6..=1.0 + 1e-6).contains(&x)));
        }
    }

    #[test]
    fn cosine_hemisphere_mean_cos_is_two_thirds() {
        // E[cos θ] under cos θ/π is 2/3; per-sample σ² = 1/2 − 4/9.
        let mut r = Pcg32::new(11, 2);
        let n = 400_000;
        let m: f64 = (0..n)
            .map(|_| sample_cosine_hemisphere(Vec2::new(r.uniform_f32(), r.uniform_f32())).z as f64)
            .sum::<f64>()
            / n as f64;
        let sigma = (0.5f64 - 4.0 / 9.0).sqrt() / (n as f64).sqrt();
        assert!((m - 2.0 / 3.0).abs() < 5.0 * sigma, "{m}");
    }

    #[test]
    fn bilinear_warp_round_trips_and_pdf_integrates_to_one() {
        let w = [0.2, 1.5, 0.7, 3.0];
        let mut r = Pcg32::new(7, 4);
        for _ in 0..10_000 {
            let u = Vec2::new(r.uniform_f32(), r.uniform_f32());
            let p = sample_bilinear(u, w);
            assert!((0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y));
            let back = invert_bilinear_sample(p, w);
            assert!(
                (back - u).abs().max_element() < 2e-4,
                "{u} -> {p} -> {back}"
            );
        }
        // Midpoint rule: ∫ pdf = 1 (the pdf is bilinear, so the rule is exact).
        let n = 64;
        let sum: f64 = (0..n * n)
            .map(|k| {
                let p = Vec2::new(
                    ((k % n) as f32 + 0.5) / n as f32,
                    ((k / n) as f32 + 0.5) / n as f32,
                );
                bilinear_pdf(p, w) as f64
            })
            .sum();
        assert!((sum / (n * n) as f64 - 1.0).abs() < 1e-5);
        assert_eq!(bilinear_pdf(Vec2::new(1.2, 0.5), w), 0.0);
    }

    #[test]
    fn bilinear_warp_matches_its_pdf_chi2() {
        // 8×8 histogram of samples against the integrated pdf.
        let w = [0.1, 2.0, 1.0, 0.4];
        let (n, bins) = (200_000usize, 8usize);
        let mut r = Pcg32::new(9, 5);
        let mut hist = vec![0f64; bins * bins];
        for _ in 0..n {
            let p = sample_bilinear(Vec2::new(r.uniform_f32(), r.uniform_f32()), w);
            let (i, j) = (
                ((p.x * bins as f32) as usize).min(bins - 1),
                ((p.y * bins as f32) as usize).min(bins - 1),
            );
            hist[j * bins + i] += 1.0;
        }
        let mut chi2 = 0.0;
        for j in 0..bins {
            for i in 0..bins {
                // The pdf is bilinear: its cell integral is the value at the cell centre / bins².
                let c = Vec2::new(
                    (i as f32 + 0.5) / bins as f32,
                    (j as f32 + 0.5) / bins as f32,
                );
                let expected = bilinear_pdf(c, w) as f64 * n as f64 / (bins * bins) as f64;
                chi2 += (hist[j * bins + i] - expected).powi(2) / expected;
            }
        }
        let p = crate::sampling::chi2::chi2_survival(chi2, bins * bins - 1);
        assert!(p > 1e-4, "χ² = {chi2}, p = {p}");
    }

    #[test]
    fn henyey_greenstein_sampling_matches_its_density() {
        // χ² of the sampler against the density (α = 1 % over the 4 g values,
        // Šidák-corrected), plus the mean cosine E[μ] = g, 5σ with σ measured.
        use crate::sampling::chi2::{chi2_test, sidak_alpha, Chi2Config};
        let wo = Vec3::new(0.3, -0.2, 0.9).normalize();
        for (i, g) in [0.0f32, 0.5, -0.7, 0.95].into_iter().enumerate() {
            let cfg = Chi2Config {
                seed: 40 + i as u64,
                ..Chi2Config::default()
            };
            let report = chi2_test(
                &cfg,
                |_, a, b| Some(sample_henyey_greenstein(wo, g, Vec2::new(a, b)).0),
                |wi| henyey_greenstein(wo, wi, g),
            );
            report.check(sidak_alpha(0.01, 4)).expect("HG χ²");
            let mut r = Pcg32::new(7, i as u64);
            let n = 200_000;
            let (mut s, mut sq) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let u = Vec2::new(r.uniform_f32(), r.uniform_f32());
                let (wi, pdf) = sample_henyey_greenstein(wo, g, u);
                assert!((pdf - henyey_greenstein(wo, wi, g)).abs() <= 1e-5 * pdf);
                let mu = -wo.dot(wi) as f64;
                s += mu;
                sq += mu * mu;
            }
            let m = s / n as f64;
            let se = ((sq / n as f64 - m * m) / n as f64).sqrt();
            assert!(
                (m - g as f64).abs() < 5.0 * se + 1e-6,
                "g={g}: E[μ]={m} ± {se}"
            );
        }
    }
}
