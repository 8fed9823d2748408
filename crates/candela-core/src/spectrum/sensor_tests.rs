//! Tests of the daylight series, white balancing, the camera sensors and
//! their transcribed data, and the ACES2065-1 colour space.

use super::color::white_balance;
use super::named::named_spectrum;
use super::rgb2spec::{fit_sigmoid, spectral_weights};
use super::sensor::{cameras, parse_curves, swatches, training_pairs};
use super::*;
use glam::{DVec3, Vec3};
use std::sync::Arc;

fn xyz_vec(x: Xyz) -> Vec3 {
    Vec3::new(x.x, x.y, x.z)
}

fn pl(p: PiecewiseLinear) -> Spectrum {
    Spectrum::PiecewiseLinear(Arc::new(p))
}

/// pbrt-v4's 10-digit `Canon_eos5dmkii_R` table.
const R_5D2: [f64; 35] = [
    0.0008013842,
    0.0006220757,
    0.001637148,
    0.0038748426,
    0.0085357673,
    0.0061490957,
    0.0028872172,
    0.0024148706,
    0.0022508639,
    0.0040032296,
    0.0068301998,
    0.0092928829,
    0.0152933769,
    0.0305241911,
    0.0916499483,
    0.1336909081,
    0.1509614473,
    0.130782838,
    0.1628188126,
    0.2568271304,
    0.3849123031,
    0.4693487229,
    0.4692466342,
    0.4421441869,
    0.3902777211,
    0.317328307,
    0.2623859635,
    0.1707236556,
    0.122806183,
    0.0916867133,
    0.051765637,
    0.0147074911,
    0.0025296982,
    0.0016901259,
    0.0008906563,
];

#[test]
fn camera_data_has_every_sensor_with_35_samples_from_380_to_720_nm() {
    let raw = parse_curves(include_str!("../../data/camera_sensitivities.txt"));
    assert_eq!(raw.len(), 17 * 3, "17 cameras × r, g, b");
    for (name, c) in &raw {
        let s: Vec<(f32, f32)> = c.samples().collect();
        assert_eq!(s.len(), 35, "{name}");
        for (i, (l, v)) in s.iter().enumerate() {
            assert_eq!(*l, 380.0 + 10.0 * i as f32, "{name}");
            assert!((0.0..=1.0 + 1e-6).contains(v), "{name} at {l}: {v}");
        }
    }
    assert_eq!(cameras().len(), 17);
    for cam in cameras() {
        // The source data share the 720 nm value between r, g and b, and ḡ peaks at 1:
        // both are transcription checks across the three curves.
        let last = cam.rgb.each_ref().map(|c| c.samples().last().map(|p| p.1));
        assert!(
            last[0] == last[1] && last[1] == last[2],
            "{}: {last:?}",
            cam.name
        );
        assert!((cam.rgb[1].max_value() - 1.0).abs() < 1e-6, "{}", cam.name);
    }
    // pbrt-v4 also carries the Canon 5D Mark II curves as a separate 10-digit
    // table (`Canon_eos5dmkii_R`); the transcribed r̄ must agree with it.
    let cam = cameras().iter().find(|c| c.name == "canon_eos_5d_mkii");
    let cam = cam.expect("canon_eos_5d_mkii is shipped");
    for (i, v) in R_5D2.iter().enumerate() {
        let got = cam.rgb[0].eval(380.0 + 10.0 * i as f32) as f64;
        assert!((got - v).abs() <= 1e-6 * v, "{i}: {got} vs {v}");
    }
    // Sums of a few curves as read from pbrt-v4 (f64 sums of the file's values).
    let sum = |n: &str| {
        named_spectrum(n).map(|s| {
            (0..35)
                .map(|i| s.eval(380.0 + 10.0 * i as f32) as f64)
                .sum::<f64>()
        })
    };
    for (n, expected) in [("nikon_d850_g", 8.621_736), ("sony_ilce_9_b", 7.202_757)] {
        let got = sum(n).expect("named camera curve");
        assert!((got - expected).abs() < 1e-5, "{n}: {got}");
    }
}

#[test]
fn daylight_chromaticity_matches_the_cie_cct_formula() {
    // xy of D(T) integrated against the CIE 1931 tables vs the CIE formula for
    // the CCT D(T) is built at. The spectrum only approximates the locus (the
    // basis is tabulated at 5 nm and the CIE formula is itself a fit), so the
    // bound is 1e-3 as in CIE 15's tolerance on daylight chromaticities.
    for t in [4000.0, 5000.0, 6500.0, 10000.0] {
        let (x, y) = spectrum_to_xyz(&pl(daylight(t))).xy();
        let (xd, yd) = daylight_xy(daylight_cct(t));
        eprintln!("D({t}): xy ({x:.5}, {y:.5}) vs formula ({xd:.5}, {yd:.5})");
        assert!((x - xd).abs() < 1e-3 && (y - yd).abs() < 1e-3, "T {t}");
    }
}

#[test]
fn daylight_6500_and_5000_are_the_tabulated_d65_and_d50() {
    // D(6500) and D(5000) are D65 and D50 by construction (CCT 6503.6 K and
    // 5002.8 K): the CIE tabulates those from the same basis rounded to 4–6
    // digits, so the normalised shapes agree to ~1e-3 of the peak. Compared
    // up to 780 nm: candela's D65/D50 tables repeat their 780 nm value above
    // it (the generator's source stops there), unlike the CIE's.
    for (t, name) in [(6500.0, "stdillum-D65"), (5000.0, "stdillum-D50")] {
        let d = pl(daylight(t));
        let table = named_spectrum(name).expect("tabulated illuminant");
        let k = spectrum_to_photometric(&table) / spectrum_to_photometric(&d);
        let peak = table.max_value();
        let worst = (300..=780)
            .step_by(5)
            .map(|l| ((d.eval(l as f32) * k - table.eval(l as f32)) / peak).abs())
            .fold(0.0f32, f32::max);
        eprintln!("D({t}) vs {name}: worst |Δ|/peak {worst:.2e}");
        assert!(worst < 2e-3, "{name}: {worst}");
    }
}

#[test]
fn daylight_below_4000_k_is_the_blackbody() {
    let d = pl(daylight(3000.0));
    let cct = daylight_cct(3000.0);
    let bb = Spectrum::blackbody(cct);
    for l in [400.0, 555.0, 700.0] {
        assert!(
            (d.eval(l) - bb.eval(l)).abs() < 1e-5 * bb.max_value(),
            "{l}"
        );
    }
}

#[test]
fn white_balance_maps_source_white_to_target_white() {
    // Bradford: XYZ_from_LMS is LMS_from_XYZ⁻¹ rounded to 6 digits, hence 1e-5.
    let src = daylight_xy(4000.0);
    let dst = ColorSpace::srgb().white_xy();
    let m = white_balance(src, dst);
    let w = m * xyz_vec(Xyz::from_xy(src.0, src.1, 1.0));
    let want = xyz_vec(Xyz::from_xy(dst.0, dst.1, 1.0));
    assert!((w - want).abs().max_element() < 1e-5, "{w} vs {want}");
    assert!((white_balance(dst, dst) - glam::Mat3::IDENTITY).abs_diff_eq(glam::Mat3::ZERO, 1e-5));
}

#[test]
fn cie1931_white_balance_makes_the_daylight_neutral() {
    let cs = ColorSpace::srgb();
    for t in [3000.0, 4500.0, 10000.0] {
        let d = daylight(t);
        let s = PixelSensor::from_name("cie1931", cs, t, 1.0).expect("cie1931");
        let raw = s.response_of(|l| d.eval(l));
        let rgb = cs.rgb_from_xyz * s.xyz_from_sensor_rgb() * Vec3::from(raw);
        let plain = cs.rgb_from_xyz * Vec3::from(raw);
        let spread = |v: Vec3| (v.max_element() - v.min_element()) / v.y;
        eprintln!(
            "T {t}: balanced {:.2e}, unbalanced {:.3}",
            spread(rgb),
            spread(plain)
        );
        // Exact up to the 6-digit Bradford inverse: 1e-4.
        assert!(spread(rgb) < 1e-4, "{rgb}");
        assert!(spread(plain) > 0.05, "{plain}");
    }
}

/// Residuals of a camera's fit over the 24 patches: (rms, worst) of
/// ‖M c_i − t_i‖ / t_i.y, and the chromaticity error of the sensor white.
fn fit_quality(cam: &'static CameraCurves, cs: &'static ColorSpace, t: f32) -> (f64, f64, f64) {
    let d = pl(daylight(t));
    let s = PixelSensor::camera(cam, cs, &d, 1.0);
    let m = s.xyz_from_sensor_rgb().as_dmat3();
    let pairs = training_pairs(cam, cs, &d);
    let res: Vec<f64> = pairs
        .iter()
        .map(|(c, tt)| (m * *c - *tt).length() / tt.y)
        .collect();
    let rms = (res.iter().map(|r| r * r).sum::<f64>() / res.len() as f64).sqrt();
    let worst = res.iter().copied().fold(0.0, f64::max);
    // The sensor white: a perfect reflector under D(T), seen by the sensor and mapped by M.
    let white = m * DVec3::from(s.response_of(|l| d.eval(l)).map(|v| v as f64));
    let (wx, wy) = (white.x / white.element_sum(), white.y / white.element_sum());
    let (cx, cy) = cs.white_xy();
    let werr = (wx - cx as f64).hypot(wy - cy as f64);
    (rms, worst, werr)
}

#[test]
fn every_camera_fit_maps_the_patches_to_xyz_and_its_white_to_the_output_white() {
    // A 3×3 matrix cannot map a camera's responses to XYZ exactly (no camera
    // meets the Luther condition); the fit leaves a few per cent on the
    // saturated patches. The bounds are 1.5× the worst measured values over
    // the 17 cameras and two output spaces (printed below), so a wrong
    // patch, curve or normalisation, which moves them by far more, fails.
    let mut worst_rms: f64 = 0.0;
    let mut worst_white: f64 = 0.0;
    for cs in [ColorSpace::srgb(), ColorSpace::aces2065_1()] {
        for cam in cameras() {
            for t in [6500.0, 5000.0] {
                let (rms, worst, werr) = fit_quality(cam, cs, t);
                eprintln!(
                    "{:20} {:10} D({t}): rms {rms:.4} worst {worst:.4} white Δxy {werr:.2e}",
                    cam.name, cs.name
                );
                worst_rms = worst_rms.max(rms);
                worst_white = worst_white.max(werr);
            }
        }
    }
    eprintln!("worst rms {worst_rms:.4}, worst white Δxy {worst_white:.2e}");
    assert!(worst_rms < RMS_BOUND, "{worst_rms}");
    assert!(worst_white < WHITE_BOUND, "{worst_white}");
}
/// 1.5 × the worst rms residual measured (0.112, nikon_d850 under D(5000) to sRGB).
const RMS_BOUND: f64 = 0.17;
/// 1.5 × the worst white chromaticity error measured (2.36e-3).
const WHITE_BOUND: f64 = 3.5e-3;

#[test]
fn a_camera_with_the_cie_curves_fits_exactly() {
    // The fitting machinery itself: a "camera" whose curves are x̄, ȳ, z̄, lit
    // by the output illuminant, must give M = I with zero residual. Lit by
    // D(4000) the fit is a chromatic adaptation learned from the 24 patches,
    // not an exact von Kries one: it maps the six neutral patches from D(4000)'s
    // chromaticity, 0.1 away, to within 6e-3 of the output white (measured);
    // the bound is 1e-2.
    let cie = |k: usize| {
        let pairs: Vec<(f32, f32)> = (360..=830)
            .map(|l| (l as f32, cie_xyz(l as f32)[k]))
            .collect();
        Arc::new(PiecewiseLinear::new(&pairs))
    };
    let cam = CameraCurves {
        name: "cie".into(),
        rgb: [cie(0), cie(1), cie(2)],
    };
    let cs = ColorSpace::srgb();
    let m = super::sensor::fit_xyz_from_sensor_rgb(&cam, cs, &cs.illuminant);
    assert!(m.abs_diff_eq(glam::Mat3::IDENTITY, 1e-5), "{m}");
    let d = pl(daylight(4000.0));
    let m = super::sensor::fit_xyz_from_sensor_rgb(&cam, cs, &d).as_dmat3();
    let (cx, cy) = cs.white_xy();
    for (c, _) in &training_pairs(&cam, cs, &d)[18..] {
        let w = m * *c;
        let (x, y) = (w.x / w.element_sum(), w.y / w.element_sum());
        assert!((x - cx as f64).hypot(y - cy as f64) < 1e-2, "({x}, {y})");
    }
}

#[test]
fn every_shipped_sensor_builds_by_name() {
    for cs in [ColorSpace::srgb(), ColorSpace::aces2065_1()] {
        for name in sensor_names() {
            for wb in [0.0, 3200.0, 5500.0] {
                let s = PixelSensor::from_name(name, cs, wb, 1.0).expect("known sensor");
                let m = s.xyz_from_sensor_rgb();
                assert!(m.is_finite() && m.determinant().abs() > 1e-6, "{name}");
                assert_eq!(s.name(), name);
            }
        }
    }
    let err = PixelSensor::from_name("nikon_d9000", ColorSpace::srgb(), 0.0, 1.0).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("nikon_d9000") && text.contains("canon_eos_5d_mkiv"),
        "{text}"
    );
    assert_eq!(swatches().len(), 24);
}

#[test]
fn aces_round_trips_and_has_the_d60_white() {
    let aces = ColorSpace::aces2065_1();
    // The white is computed from the D60 spectrum, as pbrt-v4 does; SMPTE ST
    // 2065-1 gives (0.32168, 0.33767). 5e-4 covers the 5 nm table.
    let (x, y) = aces.white_xy();
    assert!(
        (x - 0.32168).abs() < 5e-4 && (y - 0.33767).abs() < 5e-4,
        "({x}, {y})"
    );
    assert!(std::ptr::eq(
        ColorSpace::by_name("aces2065-1").expect("known"),
        aces
    ));
    // sRGB → XYZ → ACES → XYZ → sRGB is the identity to f32 rounding.
    let srgb = ColorSpace::srgb();
    for rgb in [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.2, 0.7, 0.1),
        Vec3::new(0.05, 0.1, 0.9),
    ] {
        let xyz = srgb.xyz_from_rgb * rgb;
        let a = aces.rgb_from_xyz * xyz;
        let back = srgb.rgb_from_xyz * (aces.xyz_from_rgb * a);
        assert!(
            (back - rgb).abs().max_element() < 1e-5,
            "{rgb} → {a} → {back}"
        );
        // Every sRGB colour is inside AP0: non-negative ACES components.
        assert!(a.min_element() > -1e-6, "{a}");
    }
    // ACES RGB (1, 1, 1) is the white: Y = 1 at the white chromaticity.
    let w = aces.xyz_from_rgb * Vec3::ONE;
    assert!((w.y - 1.0).abs() < 1e-5 && (w.x / w.element_sum() - x).abs() < 1e-5);
}

/// RGB (under the colour space's illuminant) of the exactly fitted reflectance, and its range.
fn fitted_rgb(cs: &ColorSpace, rgb: Rgb) -> (Vec3, f32, f32) {
    rgb_of_poly(cs, fit_sigmoid(cs, rgb))
}

#[test]
fn aces_rgb2spec_fits_in_gamut_colours_and_stays_bounded_outside() {
    let aces = ColorSpace::aces2065_1();
    // Reflectance colours (ACES RGB of sRGB albedos and of ColorChecker
    // patches) are reachable by the sigmoid model and round-trip like sRGB
    // fits do (7e-6 measured for sRGB; bound 1e-4).
    let srgb = ColorSpace::srgb();
    let mut inside: Vec<Vec3> = [
        [0.8, 0.1, 0.1],
        [0.1, 0.6, 0.2],
        [0.1, 0.2, 0.7],
        [0.9, 0.8, 0.1],
    ]
    .iter()
    .map(|c| {
        let xyz = srgb.xyz_from_rgb * Vec3::from(*c);
        // Von Kries to D60 so that the albedo keeps its appearance.
        aces.rgb_from_xyz * (white_balance(srgb.white_xy(), aces.white_xy()) * xyz)
    })
    .collect();
    for rho in swatches() {
        let s = Spectrum::PiecewiseLinear(Arc::new(rho.clone()));
        let xyz =
            |k: usize| inner_product(|l| cie_xyz(l)[k] * aces.illuminant.eval(l), |l| s.eval(l));
        let y_w = inner_product(|l| cie_xyz(l)[1], |l| aces.illuminant.eval(l));
        inside.push(aces.rgb_from_xyz * Vec3::new(xyz(0), xyz(1), xyz(2)) / y_w);
    }
    let mut worst = 0.0f32;
    for a in inside {
        let rgb = Rgb::new(a.x, a.y, a.z);
        let (got, lo, hi) = fitted_rgb(aces, rgb);
        worst = worst.max((got - a).abs().max_element());
        assert!(lo >= 0.0 && hi <= 1.0);
    }
    eprintln!("ACES in-gamut round trip: worst {worst:.2e}");
    assert!(worst < 1e-4, "{worst}");
    // The AP0 primaries are not reflectances (green and blue lie outside the
    // spectral locus): pbrt-v4's table optimiser, like ours, then stops at the
    // closest spectrum it reaches. What must hold is a finite, bounded spectrum.
    for a in [
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 0.5, 0.5],
    ] {
        let rgb = Rgb::new(a[0], a[1], a[2]);
        let (got, lo, hi) = fitted_rgb(aces, rgb);
        eprintln!("ACES {a:?} → {got} (spectrum in [{lo:.3}, {hi:.3}])");
        assert!(got.is_finite() && lo >= 0.0 && hi <= 1.0);
    }
}

#[test]
fn aces_rgb_table_round_trips_in_gamut_colours() {
    // Image textures and maps in ACES go through the tabulated fit. For
    // reflectance colours (random sRGB albedos, adapted to D60) its round trip
    // must match the sRGB table's (1.2e-3 measured; bound 2e-3); AP0 corners
    // that no reflectance reaches must still give finite, bounded spectra.
    let aces = ColorSpace::aces2065_1();
    let srgb = ColorSpace::srgb();
    let t0 = std::time::Instant::now();
    let table = aces.rgb_table();
    eprintln!("ACES table built in {:.2?}", t0.elapsed());
    let adapt =
        aces.rgb_from_xyz * white_balance(srgb.white_xy(), aces.white_xy()) * srgb.xyz_from_rgb;
    let mut r = crate::sampling::Pcg32::new(5, 9);
    let mut worst = 0.0f32;
    for _ in 0..300 {
        let a = adapt * Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32());
        let p = table.coeffs(Rgb::new(a.x, a.y, a.z));
        let (got, _, _) = rgb_of_poly(aces, p);
        worst = worst.max((got - a).abs().max_element());
    }
    eprintln!("ACES table: worst |Δrgb| {worst:.2e}");
    assert!(worst < 2e-3, "{worst}");
    for c in [
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0],
        [1.0, 0.0, 1.0],
        [0.9, 0.0, 0.05],
    ] {
        let p = table.coeffs(Rgb::new(c[0], c[1], c[2]));
        let (got, lo, hi) = rgb_of_poly(aces, p);
        assert!(got.is_finite() && lo >= 0.0 && hi <= 1.0, "{c:?}: {got}");
    }
}

/// RGB of the sigmoid spectrum `p` under the colour space's illuminant, and its range.
fn rgb_of_poly(cs: &ColorSpace, p: RgbSigmoidPolynomial) -> (Vec3, f32, f32) {
    let w = spectral_weights(cs);
    let mut out = [0.0f64; 3];
    let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
    for (i, wi) in w.iter().enumerate() {
        let s = p.eval(LAMBDA_MIN + i as f32);
        lo = lo.min(s);
        hi = hi.max(s);
        for k in 0..3 {
            out[k] += wi[k] * s as f64;
        }
    }
    (
        Vec3::new(out[0] as f32, out[1] as f32, out[2] as f32),
        lo,
        hi,
    )
}

#[test]
fn every_pbrt_named_spectrum_exists_and_fluorescents_have_the_cie_chromaticities() {
    // pbrt-v4's namedSpectra list (src/pbrt/util/spectrum.cpp).
    let mut names: Vec<String> = [
        "glass-BK7",
        "glass-BAF10",
        "glass-FK51A",
        "glass-LASF9",
        "glass-F5",
        "glass-F10",
        "glass-F11",
        "metal-Ag-eta",
        "metal-Ag-k",
        "metal-Al-eta",
        "metal-Al-k",
        "metal-Au-eta",
        "metal-Au-k",
        "metal-Cu-eta",
        "metal-Cu-k",
        "metal-MgO-eta",
        "metal-MgO-k",
        "metal-TiO2-eta",
        "metal-TiO2-k",
        "stdillum-A",
        "stdillum-D50",
        "stdillum-D65",
        "illum-acesD60",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    names.extend((1..=12).map(|n| format!("stdillum-F{n}")));
    for cam in cameras() {
        names.extend(["r", "g", "b"].map(|c| format!("{}_{c}", cam.name)));
    }
    for n in &names {
        let s = named_spectrum(n).unwrap_or_else(|| panic!("{n} missing"));
        assert!(s.max_value() > 0.0 || n.ends_with("-k"), "{n}");
    }
    assert!(named_spectrum("stdillum-F13").is_none() && named_spectrum("stdillum-F0").is_none());
    // CIE 15:2004 Table T.8, 2° observer, given to 5 digits: the transcribed
    // tables reproduce every one of them to that precision (measured), so the
    // bound is 2e-5 — a wrong digit in any peak would move them by far more.
    let cie_xy = [
        (0.31310, 0.33727),
        (0.37208, 0.37529),
        (0.40910, 0.39430),
        (0.44018, 0.40329),
        (0.31379, 0.34531),
        (0.37790, 0.38835),
        (0.31292, 0.32933),
        (0.34588, 0.35875),
        (0.37417, 0.37281),
        (0.34609, 0.35896),
        (0.38052, 0.37713),
        (0.43695, 0.40441),
    ];
    for (i, (x, y)) in cie_xy.iter().enumerate() {
        let s = named_spectrum(&format!("stdillum-F{}", i + 1)).expect("F illuminant");
        let (cx, cy) = spectrum_to_xyz(&s).xy();
        eprintln!("F{}: ({cx:.5}, {cy:.5}) vs ({x}, {y})", i + 1);
        assert!((cx - x).abs() < 2e-5 && (cy - y).abs() < 2e-5, "F{}", i + 1);
        assert!((spectrum_to_photometric(&s) / CIE_Y_INTEGRAL - 1.0).abs() < 1e-5);
    }
}
