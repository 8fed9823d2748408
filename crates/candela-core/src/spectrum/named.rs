//! Spectra that pbrt-v4 scenes name by string: CIE standard illuminants A,
//! D50, D65, F1–F12 and ACES D60 (normalised to luminance Y = 1 as pbrt-v4
//! does), metal optical constants, glass dispersion (Sellmeier equations with
//! Schott's coefficients for BK7, BAF10, FK51A, LASF9; pbrt-v4's tables for
//! SF5, SF10, SF11) and the camera sensitivities `<sensor>_r/_g/_b` — every
//! name in pbrt-v4's list.

use super::data::{cie, daylight, dielectrics, fluorescent, metals};
use super::spectra::{inner_product, PiecewiseLinear, Spectrum};
use super::{cie_xyz, CIE_Y_INTEGRAL};
use std::sync::{Arc, OnceLock};

/// Scales a table so that ∫ȳ s = ∫ȳ (pbrt-v4 `FromInterleaved(normalize = true)`).
fn normalized(p: PiecewiseLinear) -> PiecewiseLinear {
    let y = inner_product(|l| cie_xyz(l)[1], |l| p.eval(l));
    p.scaled(CIE_Y_INTEGRAL / y)
}

/// CIE D65, normalised.
pub fn d65() -> Arc<PiecewiseLinear> {
    static S: OnceLock<Arc<PiecewiseLinear>> = OnceLock::new();
    S.get_or_init(|| {
        Arc::new(normalized(PiecewiseLinear::from_even(
            cie::D65_START,
            5.0,
            &cie::ILLUM_D65,
        )))
    })
    .clone()
}

fn d50() -> Arc<PiecewiseLinear> {
    static S: OnceLock<Arc<PiecewiseLinear>> = OnceLock::new();
    S.get_or_init(|| {
        Arc::new(normalized(PiecewiseLinear::from_even(
            cie::D50_START,
            5.0,
            &cie::ILLUM_D50,
        )))
    })
    .clone()
}

/// ACES D60, normalised (pbrt-v4 `illum-acesD60`, the ACES2065-1 white).
pub fn aces_d60() -> Arc<PiecewiseLinear> {
    static S: OnceLock<Arc<PiecewiseLinear>> = OnceLock::new();
    S.get_or_init(|| {
        Arc::new(normalized(PiecewiseLinear::from_even(
            daylight::S_START,
            5.0,
            &daylight::ACES_D60,
        )))
    })
    .clone()
}

/// CIE fluorescent illuminant F`n` (1–12), normalised.
fn fluorescent(n: usize) -> Option<Spectrum> {
    static S: OnceLock<Vec<Arc<PiecewiseLinear>>> = OnceLock::new();
    let all = S.get_or_init(|| {
        fluorescent::ILLUM_F
            .iter()
            .map(|f| {
                Arc::new(normalized(PiecewiseLinear::from_even(
                    fluorescent::F_START,
                    5.0,
                    f,
                )))
            })
            .collect()
    });
    let f = all.get(n.checked_sub(1)?)?;
    Some(Spectrum::PiecewiseLinear(f.clone()))
}

/// CIE illuminant A by its defining formula (CIE 15: Planck with c₂ = 1.435·10⁷ nm·K, T = 2848 K).
fn illuminant_a() -> Arc<PiecewiseLinear> {
    static S: OnceLock<Arc<PiecewiseLinear>> = OnceLock::new();
    S.get_or_init(|| {
        let f = |l: f64| {
            100.0 * (560.0 / l).powi(5) * ((1.435e7f64 / (2848.0 * 560.0)).exp() - 1.0)
                / ((1.435e7f64 / (2848.0 * l)).exp() - 1.0)
        };
        let pairs: Vec<(f32, f32)> = (300..=830)
            .map(|l| (l as f32, f(l as f64) as f32))
            .collect();
        Arc::new(normalized(PiecewiseLinear::new(&pairs)))
    })
    .clone()
}

/// Sellmeier dispersion n(λ) with λ in μm.
fn sellmeier(b: [f64; 3], c: [f64; 3]) -> Spectrum {
    let pairs: Vec<(f32, f32)> = (300..=900)
        .step_by(2)
        .map(|l| {
            let x = (l as f64 / 1000.0).powi(2);
            let n2 = 1.0 + (0..3).map(|i| b[i] * x / (x - c[i])).sum::<f64>();
            (l as f32, n2.sqrt() as f32)
        })
        .collect();
    Spectrum::piecewise_linear(&pairs)
}

fn table(l: &[f32], v: &[f32]) -> Spectrum {
    let pairs: Vec<(f32, f32)> = l.iter().zip(v).map(|(a, b)| (*a, *b)).collect();
    Spectrum::piecewise_linear(&pairs)
}

/// The spectrum pbrt-v4 registers under `name`, or `None` if candela does not have it.
pub fn named_spectrum(name: &str) -> Option<Spectrum> {
    Some(match name {
        "stdillum-D65" => Spectrum::PiecewiseLinear(d65()),
        "stdillum-D50" => Spectrum::PiecewiseLinear(d50()),
        "stdillum-A" => Spectrum::PiecewiseLinear(illuminant_a()),
        "illum-acesD60" => Spectrum::PiecewiseLinear(aces_d60()),
        "metal-MgO-eta" => Spectrum::piecewise_linear(&dielectrics::MGO_ETA),
        "metal-MgO-k" => Spectrum::piecewise_linear(&dielectrics::MGO_K),
        "metal-TiO2-eta" => Spectrum::piecewise_linear(&dielectrics::TIO2_ETA),
        "metal-TiO2-k" => Spectrum::piecewise_linear(&dielectrics::TIO2_K),
        "glass-F5" => Spectrum::piecewise_linear(&dielectrics::GLASS_SF5),
        "glass-F10" => Spectrum::piecewise_linear(&dielectrics::GLASS_SF10),
        "glass-F11" => Spectrum::piecewise_linear(&dielectrics::GLASS_SF11),
        "metal-Cu-eta" => table(&metals::CU_LAMBDA, &metals::CU_ETA),
        "metal-Cu-k" => table(&metals::CU_LAMBDA, &metals::CU_K),
        "metal-Ag-eta" => table(&metals::CU_LAMBDA, &metals::AG_ETA),
        "metal-Ag-k" => table(&metals::CU_LAMBDA, &metals::AG_K),
        "metal-Al-eta" => table(&metals::CU_LAMBDA, &metals::AL_ETA),
        "metal-Al-k" => table(&metals::CU_LAMBDA, &metals::AL_K),
        "metal-Au-eta" => table(&metals::CU_LAMBDA, &metals::AU_ETA),
        "metal-Au-k" => table(&metals::CU_LAMBDA, &metals::AU_K),
        "glass-BK7" => sellmeier(
            [1.039_612_12, 0.231_792_344, 1.010_469_45],
            [0.006_000_698_67, 0.020_017_914_4, 103.560_653],
        ),
        "glass-BAF10" => sellmeier(
            [1.585_149_5, 0.143_559_385, 1.085_212_69],
            [0.009_266_812_82, 0.042_448_980_5, 105.613_573],
        ),
        "glass-FK51A" => sellmeier(
            [0.971_247_817, 0.216_901_417, 0.904_651_666],
            [0.004_723_019_95, 0.015_357_561_2, 168.681_33],
        ),
        "glass-LASF9" => sellmeier(
            [2.000_295_47, 0.298_926_886, 1.806_918_43],
            [0.012_142_601_7, 0.053_873_623_6, 156.530_829],
        ),
        _ => {
            if let Some(n) = name.strip_prefix("stdillum-F") {
                return n.parse().ok().and_then(fluorescent);
            }
            return super::sensor::named_sensor_curve(name).map(Spectrum::PiecewiseLinear);
        }
    })
}
