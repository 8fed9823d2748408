//! The CIE daylight series D(T) [CIE 15:2004 §3.1; pbrt-v4 `Spectra::D`].
//!
//! A daylight spectrum of correlated colour temperature T_cct is
//! S(λ) = S₀(λ) + M₁ S₁(λ) + M₂ S₂(λ), with the basis S₀, S₁, S₂ tabulated at
//! 5 nm and weights from the chromaticity of daylight at that temperature:
//!
//! x_D = −4.6070·10⁹/T³ + 2.9678·10⁶/T² + 0.09911·10³/T + 0.244063   (4000 K ≤ T ≤ 7000 K)
//! x_D = −2.0064·10⁹/T³ + 1.9018·10⁶/T² + 0.24748·10³/T + 0.237040   (T > 7000 K)
//! y_D = −3 x_D² + 2.870 x_D − 0.275
//! M = 0.0241 + 0.2562 x_D − 0.7341 y_D,
//! M₁ = (−1.3515 − 1.7703 x_D + 5.9114 y_D)/M,  M₂ = (0.0300 − 31.4424 x_D + 30.0717 y_D)/M.
//!
//! As in pbrt-v4, the nominal temperature T is first converted to the CCT on
//! the current radiation-constant scale, T_cct = T · 1.4388/1.4380 (so
//! D(6500) is D65 and D(5000) is D50), the result is scaled by 0.01 (value
//! ≈ 1 at 560 nm), and below 4000 K, where the daylight locus is undefined,
//! the blackbody of T_cct normalised to peak 1 is used instead.

use super::data::daylight::{CIE_S0, CIE_S1, CIE_S2, S_START};
use super::spectra::{planck, PiecewiseLinear};
use super::{LAMBDA_MAX, LAMBDA_MIN};

/// The CCT pbrt-v4 uses for a nominal daylight temperature (c₂ 1.4380 → 1.4388 ·10⁻² m·K).
pub fn daylight_cct(t: f32) -> f32 {
    t * 1.4388 / 1.4380
}

/// Chromaticity (x_D, y_D) of CIE daylight at correlated colour temperature
/// `cct` \[K\] (the CIE formula; meaningful for 4000 K ≤ cct ≤ 25000 K).
pub fn daylight_xy(cct: f32) -> (f32, f32) {
    let t = cct as f64;
    let x = if t <= 7000.0 {
        -4.607e9 / (t * t * t) + 2.9678e6 / (t * t) + 0.09911e3 / t + 0.244063
    } else {
        -2.0064e9 / (t * t * t) + 1.9018e6 / (t * t) + 0.24748e3 / t + 0.23704
    };
    let y = -3.0 * x * x + 2.870 * x - 0.275;
    (x as f32, y as f32)
}

/// pbrt-v4's `Spectra::D(t)`: the daylight spectrum for nominal temperature
/// `t` \[K\], scaled to ≈ 1 at 560 nm (a peak-normalised blackbody below 4000 K).
pub fn daylight(t: f32) -> PiecewiseLinear {
    let cct = daylight_cct(t);
    if cct < 4000.0 {
        // Wien's displacement law gives the peak, as for `Spectrum::blackbody`.
        let peak = planck(2.897_772e-3 / cct * 1e9, cct);
        let pairs: Vec<(f32, f32)> = (LAMBDA_MIN as i32..=LAMBDA_MAX as i32)
            .map(|l| {
                let v = if peak > 0.0 {
                    planck(l as f32, cct) / peak
                } else {
                    0.0
                };
                (l as f32, v)
            })
            .collect();
        return PiecewiseLinear::new(&pairs);
    }
    let (x, y) = daylight_xy(cct);
    let m = 0.0241 + 0.2562 * x - 0.7341 * y;
    let m1 = (-1.3515 - 1.7703 * x + 5.9114 * y) / m;
    let m2 = (0.0300 - 31.4424 * x + 30.0717 * y) / m;
    let values: Vec<f32> = (0..CIE_S0.len())
        .map(|i| (CIE_S0[i] + m1 * CIE_S1[i] + m2 * CIE_S2[i]) * 0.01)
        .collect();
    PiecewiseLinear::from_even(S_START, 5.0, &values)
}
