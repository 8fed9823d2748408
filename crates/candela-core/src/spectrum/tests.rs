//! Spectral tests: T8 photometry (validation.md), colour-space round trips,
//! the white-emitter invariant that makes pbrt-v4 scenes render to
//! pbrt-v4's numbers, and named spectra.

use super::*;
use crate::sampling::Pcg32;

/// ∫ ȳ(λ) f(λ) dλ over 360–830 nm at 1 nm steps.
fn y_of(f: impl Fn(f32) -> f32) -> f64 {
    (360..=830)
        .map(|l| cie_xyz(l as f32)[1] as f64 * f(l as f32) as f64)
        .sum()
}

#[test]
fn t8_luminous_efficacy_of_monochromatic_and_flat_spectra() {
    // 1 W at 555 nm → 683 lm; 1 W at 650 nm → 73.08 lm (0.1 %).
    assert!((K_M * cie_xyz(555.0)[1] - 683.0).abs() < 0.683);
    assert!((K_M * cie_xyz(650.0)[1] - 73.08).abs() < 0.0731);
    // Equal-energy spectrum on 380–780 nm, 1 W in total: 182.457 lm/W.
    let lm: f64 = (380..=780)
        .map(|l| K_M as f64 * cie_xyz(l as f32)[1] as f64 / 400.0)
        .sum();
    assert!((lm - 182.457).abs() < 0.182, "{lm}");
}

#[test]
fn t8_chromaticities_of_standard_illuminants() {
    let check = |s: &Spectrum, x: f32, y: f32| {
        let (cx, cy) = spectrum_to_xyz(s).xy();
        assert!(
            (cx - x).abs() < 1e-4 && (cy - y).abs() < 1e-4,
            "({cx}, {cy}) vs ({x}, {y})"
        );
    };
    check(&Spectrum::Constant(1.0), 1.0 / 3.0, 1.0 / 3.0);
    check(&named_spectrum("stdillum-D65").unwrap(), 0.31272, 0.32903);
    check(&named_spectrum("stdillum-A").unwrap(), 0.44757, 0.40745);
}

#[test]
fn t8_isotropic_source_gives_spectrum_independent_photometry() {
    // A 1000 lm isotropic source: I_v = 1000/(4π) = 79.577 cd, E_v = I_v/d² = 19.894 lx at 2 m,
    // whatever its spectrum, once the spectrum is normalised photometrically as lights do.
    for name in ["stdillum-D65", "stdillum-A"] {
        let s = named_spectrum(name).unwrap();
        for spec in [s, Spectrum::Constant(3.0)] {
            let scale = 1000.0 / (4.0 * std::f32::consts::PI) / spectrum_to_photometric(&spec);
            let iv = y_of(|l| spec.eval(l) * scale);
            assert!((iv - 79.577).abs() < 1e-3, "{iv}");
            assert!((iv / 4.0 - 19.894).abs() < 1e-3);
        }
    }
}

#[test]
fn white_rgb_emitter_renders_one_through_the_sensor() {
    // pbrt-v4: a light with "rgb L [1 1 1]" and scale 1/SpectrumToPhotometric must read sRGB (1,1,1).
    let cs = ColorSpace::srgb();
    let l = Spectrum::rgb_illuminant(cs, Rgb::new(1.0, 1.0, 1.0));
    let scale = 1.0 / spectrum_to_photometric(&l);
    let sensor = PixelSensor::cie1931(1.0);
    // Deterministic 1 nm sweep: each λ with pdf 1 contributes its integrand.
    let mut acc = [0.0f64; 3];
    for l0 in 360..=830 {
        let w = SampledWavelengths::from_parts([l0 as f32; 4], [1.0; 4]);
        let rgb = sensor.to_sensor_rgb(l.sample(&w) * scale, &w);
        for k in 0..3 {
            acc[k] += rgb[k] as f64;
        }
    }
    let out = cs.rgb_from_xyz
        * sensor.xyz_from_sensor_rgb()
        * glam::Vec3::new(acc[0] as f32, acc[1] as f32, acc[2] as f32);
    for c in out.to_array() {
        assert!((c - 1.0).abs() < 1e-3, "{out:?}");
    }
}

fn albedo_rgb(cs: &ColorSpace, s: &Spectrum) -> [f32; 3] {
    let ill = |l: f32| cs.illuminant.eval(l);
    let norm = y_of(ill);
    let xyz: [f64; 3] = std::array::from_fn(|k| {
        (360..=830)
            .map(|l| cie_xyz(l as f32)[k] as f64 * (s.eval(l as f32) * ill(l as f32)) as f64)
            .sum::<f64>()
            / norm
    });
    let v = cs.rgb_from_xyz * glam::Vec3::new(xyz[0] as f32, xyz[1] as f32, xyz[2] as f32);
    v.to_array()
}

#[test]
fn rgb_albedo_round_trips_through_the_spectrum() {
    let cs = ColorSpace::srgb();
    let colours = [
        [0.5, 0.5, 0.5],
        [0.885809, 0.698859, 0.666422],
        [0.570068, 0.0430135, 0.0443706],
        [0.105421, 0.37798, 0.076425],
        [0.1, 0.2, 0.9],
        [0.9, 0.9, 0.1],
        [0.02, 0.6, 0.6],
    ];
    for c in colours {
        let s = Spectrum::rgb_albedo(cs, Rgb::new(c[0], c[1], c[2]));
        assert!(s.max_value() <= 1.0 + 1e-6);
        let back = albedo_rgb(cs, &s);
        for k in 0..3 {
            assert!((back[k] - c[k]).abs() < 1e-3, "{c:?} -> {back:?}");
        }
    }
    // Grey is exactly constant.
    let g = Spectrum::rgb_albedo(cs, Rgb::new(0.5, 0.5, 0.5));
    assert!((g.eval(400.0) - 0.5).abs() < 1e-6 && (g.eval(700.0) - 0.5).abs() < 1e-6);
}

#[test]
fn monte_carlo_xyz_matches_exact_integral_within_5_sigma() {
    let d65 = named_spectrum("stdillum-D65").unwrap();
    let exact = spectrum_to_xyz(&d65);
    let mut r = Pcg32::new(5, 0);
    let n = 200_000;
    let (mut s, mut s2) = ([0.0f64; 3], [0.0f64; 3]);
    for _ in 0..n {
        let w = SampledWavelengths::sample_visible(r.uniform_f32());
        let x = d65.sample(&w).to_xyz(&w);
        for (k, v) in [x.x, x.y, x.z].into_iter().enumerate() {
            s[k] += v as f64;
            s2[k] += (v as f64).powi(2);
        }
    }
    for (k, e) in [exact.x, exact.y, exact.z].into_iter().enumerate() {
        let m = s[k] / n as f64;
        let sigma = ((s2[k] / n as f64 - m * m) / n as f64).sqrt();
        // b = 2e-3 relative: the 1 nm rectangle rule of the exact value vs the continuous MC integral.
        assert!(
            (m - e as f64).abs() < 5.0 * sigma + 2e-3 * e as f64,
            "channel {k}: {m} vs {e} (σ {sigma})"
        );
    }
}

#[test]
fn named_glasses_and_metals() {
    for (name, nd) in [
        ("glass-BK7", 1.5168),
        ("glass-BAF10", 1.6700),
        ("glass-FK51A", 1.4866),
        ("glass-LASF9", 1.8503),
        // pbrt-v4's names for Schott SF5, SF10 and SF11 (catalogue n_d)
        ("glass-F5", 1.6727),
        ("glass-F10", 1.7283),
        ("glass-F11", 1.7847),
    ] {
        let n = named_spectrum(name).unwrap().eval(587.6);
        assert!((n - nd).abs() < 1e-3, "{name}: {n} vs {nd}");
    }
    let (eta, k) = (
        named_spectrum("metal-Cu-eta").unwrap(),
        named_spectrum("metal-Cu-k").unwrap(),
    );
    assert!(eta.eval(600.0) > 0.0 && k.eval(600.0) > 2.0);
    assert!(named_spectrum("no-such-spectrum").is_none());
}

#[test]
fn silver_aluminium_and_gold_reflect_like_the_metals_they_are() {
    // Normal-incidence reflectance ((n − 1)² + k²) / ((n + 1)² + k²).
    let r = |metal: &str, lambda: f32| {
        let n = named_spectrum(&format!("metal-{metal}-eta"))
            .unwrap()
            .eval(lambda);
        let k = named_spectrum(&format!("metal-{metal}-k"))
            .unwrap()
            .eval(lambda);
        ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
    };
    // Silver and aluminium are bright and nearly neutral; gold is dark in
    // the blue and bright in the red (published values ≈ 0.97, 0.92, 0.38, 0.95).
    assert!((r("Ag", 550.0) - 0.97).abs() < 0.02, "{}", r("Ag", 550.0));
    assert!((r("Al", 550.0) - 0.92).abs() < 0.02, "{}", r("Al", 550.0));
    assert!((r("Au", 450.0) - 0.38).abs() < 0.04, "{}", r("Au", 450.0));
    assert!((r("Au", 650.0) - 0.95).abs() < 0.02, "{}", r("Au", 650.0));
}

#[test]
fn blackbody_is_normalised_to_its_peak() {
    let b = Spectrum::blackbody(6500.0);
    let peak = 2.897_772e-3 / 6500.0 * 1e9;
    assert!((b.eval(peak) - 1.0).abs() < 1e-4);
    assert!(b.eval(peak - 30.0) < 1.0 && b.eval(peak + 30.0) < 1.0);
}

#[test]
fn rgb_table_round_trips_random_colours() {
    let cs = ColorSpace::srgb();
    let t0 = std::time::Instant::now();
    let table = cs.rgb_table();
    eprintln!("sRGB table built (or found) in {:.2?}", t0.elapsed());
    let mut r = Pcg32::new(11, 3);
    let (mut worst, mut worst_exact) = (0.0f32, 0.0f32);
    for i in 0..400 {
        // Random colours, plus dark and saturated ones.
        let mut c = [r.uniform_f32(), r.uniform_f32(), r.uniform_f32()];
        if i % 4 == 1 {
            c = c.map(|v| 0.02 * v);
        } else if i % 4 == 2 {
            c[i % 3] *= 0.05;
        }
        let rgb = Rgb::new(c[0], c[1], c[2]);
        let s = Spectrum::RgbAlbedo(table.coeffs(rgb));
        let back = albedo_rgb(cs, &s);
        let exact = albedo_rgb(cs, &Spectrum::rgb_albedo(cs, rgb));
        for k in 0..3 {
            worst = worst.max((back[k] - c[k]).abs());
            worst_exact = worst_exact.max((exact[k] - c[k]).abs());
        }
    }
    eprintln!("worst |Δrgb| table {worst:.2e}, exact fit {worst_exact:.2e}");
    assert!(worst < 2e-3, "table round trip off by {worst}");
    // Greys are exact.
    let g = Spectrum::RgbAlbedo(table.coeffs(Rgb::new(0.3, 0.3, 0.3)));
    assert!((g.eval(500.0) - 0.3).abs() < 1e-6);
}

/// `Spectrum::sample` evaluates all wavelengths with one `match`; it must
/// give exactly the bits of `eval` at each wavelength, for every variant
/// (tables evenly and unevenly spaced, RGB spectra of every kind, the
/// constant-sigmoid limits) and for wavelengths inside, at the ends of and
/// outside the tables' ranges.
#[test]
fn sampled_spectra_equal_pointwise_evaluation_bit_for_bit() {
    let cs = ColorSpace::srgb();
    let spectra = [
        Spectrum::Constant(0.25),
        named_spectrum("stdillum-D65").unwrap(),
        named_spectrum("metal-Cu-eta").unwrap(),
        named_spectrum("glass-BK7").unwrap(),
        Spectrum::piecewise_linear(&[(400.0, 1.0), (401.5, 2.0), (500.0, 0.5), (700.0, 3.0)]),
        Spectrum::blackbody(3200.0),
        Spectrum::rgb_albedo(cs, Rgb::new(0.8, 0.2, 0.1)),
        Spectrum::rgb_albedo(cs, Rgb::new(0.0, 0.0, 0.0)),
        Spectrum::rgb_albedo(cs, Rgb::new(1.0, 1.0, 1.0)),
        Spectrum::rgb_unbounded(cs, Rgb::new(3.0, 0.5, 1.5)),
        Spectrum::rgb_illuminant(cs, Rgb::new(18.387, 13.9873, 6.75357)),
    ];
    let mut rng = Pcg32::new(7, 0);
    let mut sets: Vec<[f32; N_SPECTRUM_SAMPLES]> = vec![
        [LAMBDA_MIN, LAMBDA_MAX, 300.0, 900.0],
        [400.0, 401.5, 700.0, 700.5],
    ];
    for _ in 0..2000 {
        sets.push(std::array::from_fn(|_| 340.0 + 510.0 * rng.uniform_f32()));
    }
    for s in &spectra {
        for l in &sets {
            let lambda = SampledWavelengths::from_parts(*l, [1.0; N_SPECTRUM_SAMPLES]);
            let got = s.sample(&lambda);
            for i in 0..N_SPECTRUM_SAMPLES {
                assert_eq!(
                    got[i].to_bits(),
                    s.eval(l[i]).to_bits(),
                    "{s:?} at {}",
                    l[i]
                );
            }
        }
    }
    // The colour space's lift of image texels (through its coefficient
    // table) takes the same paths.
    let lambda = SampledWavelengths::sample_visible(0.3);
    let rgb = Rgb::new(0.3, 0.6, 0.9);
    let scale = 2.0 * rgb.b;
    let poly = cs
        .rgb_table()
        .coeffs(Rgb::new(rgb.r / scale, rgb.g / scale, rgb.b / scale));
    let got = cs.sample_rgb(rgb, SpectrumKind::Illuminant, &lambda);
    for i in 0..N_SPECTRUM_SAMPLES {
        let l = lambda.lambda(i);
        let want = scale * poly.eval(l) * cs.illuminant_table.eval(l);
        assert_eq!(got[i].to_bits(), want.to_bits(), "illuminant lift at {l}");
    }
}

/// `cie_xyz_sampled` is `cie_xyz` lane by lane, bit for bit, inside the
/// visible range, at its ends, just outside it and for NaN.
#[test]
fn cie_xyz_sampled_equals_cie_xyz_bit_for_bit() {
    use super::cie_xyz_sampled;
    let mut rng = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        300.0 + (rng >> 40) as f32 / (1u64 << 24) as f32 * 600.0
    };
    let mut cases: Vec<[f32; 4]> = (0..50_000)
        .map(|_| [next(), next(), next(), next()])
        .collect();
    cases.push([LAMBDA_MIN, LAMBDA_MAX, LAMBDA_MIN - 1e-3, LAMBDA_MAX + 1e-3]);
    cases.push([f32::NAN, 830.0f32.next_down(), 360.0f32.next_up(), 555.5]);
    for lambda in cases {
        let got = cie_xyz_sampled(&lambda);
        for k in 0..4 {
            let want = cie_xyz(lambda[k]);
            let same = (0..3).all(|c| got[k][c].to_bits() == want[c].to_bits());
            assert!(same, "λ {}: {:?} vs {:?}", lambda[k], got[k], want);
        }
    }
}
