//! Tests of the IES web: flux against closed forms and quadrature, the
//! symmetry expansions, the light-frame orientation of types A, B and C, and
//! sampling (χ², pdf normalisation, sample/pdf/intensity agreement).
//!
//! Test files live in `candela-scene/tests/data/ies/` (hand-written, known
//! distributions); small variants are written inline.

use super::*;
use crate::math::Vec2;
use crate::sampling::chi2::{chi2_test, sidak_alpha, Chi2Config};
use crate::sampling::{sample_uniform_sphere, Pcg32};
use candela_scene::ies::parse_ies;
use std::f64::consts::PI;
use std::path::Path;

fn load(name: &str) -> IesWeb {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../candela-scene/tests/data/ies")
        .join(name);
    IesWeb::new(&candela_scene::read_ies(&path).unwrap()).unwrap()
}

/// A web from IES `text`.
fn web(text: &str) -> IesWeb {
    IesWeb::new(&parse_ies(text.as_bytes(), Path::new("t.ies")).unwrap()).unwrap()
}

/// An LM-63-2002 file of photometric type `ty` with the given angles and
/// planes (one row of candela values per horizontal angle).
fn ies_text(ty: u8, v: &[f64], h: &[f64], planes: &[Vec<f64>]) -> String {
    let join = |x: &[f64]| x.iter().map(f64::to_string).collect::<Vec<_>>().join(" ");
    let rows: Vec<String> = planes.iter().map(|p| join(p)).collect();
    format!(
        "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 {} {} {ty} 2 0 0 0\n1 1 0\n{}\n{}\n{}\n",
        v.len(),
        h.len(),
        join(v),
        join(h),
        rows.join("\n")
    )
}

/// Uniformly distributed unit directions (fixed seed).
fn directions(n: usize, seed: u64) -> Vec<Vec3> {
    let mut r = Pcg32::new(seed, 7);
    (0..n)
        .map(|_| sample_uniform_sphere(Vec2::new(r.uniform_f32(), r.uniform_f32())))
        .collect()
}

/// ∫ f dω over the web's support by 6-point Gauss–Legendre rules in ψ and
/// ϑ on each cell of its own grid, f evaluated through light-frame
/// directions. On a cell the web's intensity is (linear in ψ)·(linear in ϑ)
/// and the measure sin ϑ is smooth, so the rule is exact in ψ and accurate
/// to ~Δϑ¹² in ϑ: the error is the f32 rounding of the directions.
fn web_quadrature(w: &IesWeb, f: &dyn Fn(Vec3) -> f64) -> f64 {
    const X: [f64; 3] = [
        0.238_619_186_083_196_9,
        0.661_209_386_466_264_5,
        0.932_469_514_203_152,
    ];
    const W: [f64; 3] = [
        0.467_913_934_572_691,
        0.360_761_573_048_138_6,
        0.171_324_492_379_170_3,
    ];
    let nodes: Vec<(f64, f64)> = (0..6)
        .map(|k| {
            (
                0.5 + 0.5 * X[k % 3] * if k < 3 { -1.0 } else { 1.0 },
                0.5 * W[k % 3],
            )
        })
        .collect();
    let [e1, e2, e3] = w.axes;
    let mut sum = 0.0;
    for j in 0..w.azimuth.len() - 1 {
        let (p0, p1) = (w.azimuth[j], w.azimuth[j + 1]);
        for i in 0..w.polar.len() - 1 {
            let (t0, t1) = (w.polar[i], w.polar[i + 1]);
            for &(a, wa) in &nodes {
                let psi = p0 + a * (p1 - p0);
                for &(b, wb) in &nodes {
                    let th = t0 + b * (t1 - t0);
                    let d = |k: usize| {
                        (th.sin() * (psi.cos() * e1[k] + psi.sin() * e2[k]) + th.cos() * e3[k])
                            as f32
                    };
                    let jac = th.sin() * (p1 - p0) * (t1 - t0);
                    sum += wa * wb * jac * f(Vec3::new(d(0), d(1), d(2)));
                }
            }
        }
    }
    sum
}

/// Asserts ∫ f dω = `want` to the quadrature's f32 direction round-off (1e-6).
fn assert_integral(w: &IesWeb, f: &dyn Fn(Vec3) -> f64, want: f64, what: &str) {
    let q = web_quadrature(w, f);
    assert!(rel_close(q, want, 1e-6), "{what}: quadrature {q} vs {want}");
}

fn rel_close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs())
}

#[test]
fn isotropic_flux_is_four_pi_i() {
    let w = load("isotropic.ies");
    let i = 79.5775;
    assert!(rel_close(w.flux(), 4.0 * PI * i, 1e-12), "{}", w.flux());
    assert_eq!(w.lamp_lumens(), Some(1000.0));
    // The file rounds 1000/(4π) cd to 79.5775: its lamp is 1000.0003 lm.
    let fraction = w.flux_fraction().unwrap();
    assert!((fraction - 4.0 * PI * i / 1000.0).abs() < 1e-12 && (fraction - 1.0).abs() < 1e-6);
    for d in directions(1000, 1) {
        assert_eq!(w.intensity(d), i as f32);
    }
}

#[test]
fn cosine_flux_is_pi_i0() {
    // I = 1000 cos V on 1° steps: linear interpolation of the concave cos
    // lies below it by at most Δ²/8·max|I''| = Δ²/8·1000, so
    // πI₀ − 2π·1000·Δ²/8 ≤ Φ ≤ πI₀ (Δ = 1° in radians; values to 1e-6).
    let w = load("cosine.ies");
    let exact = PI * 1000.0;
    let bound = 2.0 * PI * 1000.0 * (1f64.to_radians()).powi(2) / 8.0;
    assert!(
        w.flux() <= exact + 1e-5 && w.flux() >= exact - bound - 1e-5,
        "{}",
        w.flux()
    );
    assert_eq!(w.flux_fraction(), None);
    assert_eq!(w.intensity(Vec3::new(0.0, 0.6, -0.8)), 0.0);
    assert!((w.intensity(Vec3::Z) - 1000.0).abs() < 1e-3);
}

#[test]
fn hand_computed_flux() {
    // I = 300, 120, 30 at V = 0°, 90°, 180°, linear in V between:
    // Φ = 2π ∫ I sin V dV = (2π − 4)(a + c) + 8b (by parts, see the file).
    let w = load("hand.ies");
    let want = (2.0 * PI - 4.0) * (300.0 + 30.0) + 8.0 * 120.0;
    assert!(rel_close(w.flux(), want, 1e-12), "{} vs {want}", w.flux());
    assert!(rel_close(w.flux_fraction().unwrap(), want / 2000.0, 1e-12));
    // Piecewise linear in H too: columns constant in V with values c_k at
    // H = 0, 90, 180, 270, 360: Φ = 2·(π/2)·(c₀/2 + c₁ + c₂ + c₃ + c₄/2).
    let c = [10.0, 40.0, 20.0, 0.0, 10.0];
    let planes: Vec<Vec<f64>> = c.iter().map(|&x| vec![x; 3]).collect();
    let text = ies_text(
        1,
        &[0.0, 90.0, 180.0],
        &[0.0, 90.0, 180.0, 270.0, 360.0],
        &planes,
    );
    let want = PI * (c[0] / 2.0 + c[1] + c[2] + c[3] + c[4] / 2.0);
    assert!(rel_close(web(&text).flux(), want, 1e-12));
}

#[test]
fn flux_matches_quadrature_of_intensity() {
    let names = [
        "quad_0-90.ies",
        "quad_90-270.ies",
        "cosine.ies",
        "type_a.ies",
        "type_b.ies",
        "tilt_include.ies",
    ];
    for name in names {
        let w = load(name);
        assert_integral(&w, &|d| w.intensity(d) as f64, w.flux(), name);
    }
    let w = random_web(3);
    assert_integral(&w, &|d| w.intensity(d) as f64, w.flux(), "random web");
}

#[test]
fn pdf_integrates_to_one_and_is_intensity_over_flux() {
    for w in [load("quad_0-360.ies"), load("type_b.ies"), random_web(4)] {
        assert_integral(&w, &|d| w.pdf(d).0 as f64, 1.0, "∫pdf");
        for d in directions(2000, 5) {
            let (p, i) = (w.pdf(d).0 as f64, w.intensity(d) as f64);
            assert!((p * w.flux() - i).abs() <= 1e-5 * i + 1e-9, "{d}: {p} {i}");
        }
    }
}

#[test]
fn sample_pdf_and_intensity_agree() {
    let webs = [
        load("quad_0-90.ies"),
        load("cosine.ies"),
        load("type_a.ies"),
        random_web(6),
    ];
    for w in webs {
        let mut r = Pcg32::new(9, 1);
        for _ in 0..20_000 {
            let s = w
                .sample(Vec2::new(r.uniform_f32(), r.uniform_f32()))
                .unwrap();
            assert!((s.w.length() - 1.0).abs() < 1e-5);
            let (p, i) = (w.pdf(s.w).0, w.intensity(s.w));
            assert!(
                (s.pdf.0 - p).abs() <= 1e-4 * p,
                "pdf {} vs {p} at {}",
                s.pdf.0,
                s.w
            );
            assert!(
                (s.intensity - i).abs() <= 1e-4 * i + 1e-4,
                "I {} vs {i}",
                s.intensity
            );
            // β₀ = I/p is the flux for every sample.
            let beta = s.intensity as f64 / s.pdf.0 as f64;
            assert!(rel_close(beta, w.flux(), 1e-4), "{beta} vs {}", w.flux());
        }
    }
}

/// χ² of the sampler against its pdf: 10⁶ samples each, α = 0.01 over the
/// six webs (Šidák). The harness grid is (cos θ, φ) about the light's
/// z; every support boundary here (z = 0, z = 0.5) is a cell boundary.
#[test]
fn sampling_passes_chi2() {
    let webs = [
        ("quad_0-360", load("quad_0-360.ies")),
        ("quad_90-270", load("quad_90-270.ies")),
        ("cosine", load("cosine.ies")),
        ("type_a", load("type_a.ies")),
        ("type_b", load("type_b.ies")),
        ("random", random_web(8)),
    ];
    let alpha = sidak_alpha(0.01, webs.len());
    for (name, w) in webs {
        let r = chi2_test(
            &Chi2Config::default(),
            |u1, u2, _| w.sample(Vec2::new(u1, u2)).map(|s| s.w),
            |d| w.pdf(d).0,
        );
        r.check(alpha).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
}

/// A laterally asymmetric type C web with irregular angles: V in [0°, 60°]
/// (so z = cos 60° = 0.5 bounds the support), H in [0°, 360°], random
/// intensities with some zeros.
fn random_web(seed: u64) -> IesWeb {
    let mut r = Pcg32::new(seed, 3);
    let mut grid = |n: usize, hi: f64| {
        let mut a: Vec<f64> = (0..n)
            .map(|_| (r.uniform_f32() as f64 * hi).round())
            .collect();
        a.extend([0.0, hi]);
        a.sort_by(f64::total_cmp);
        a.dedup();
        a
    };
    let v = grid(9, 60.0);
    let h = grid(14, 360.0);
    let mut r = Pcg32::new(seed, 4);
    let planes: Vec<Vec<f64>> = h
        .iter()
        .map(|_| {
            v.iter()
                .map(|_| {
                    let x = r.uniform_f32() as f64;
                    if x < 0.2 {
                        0.0
                    } else {
                        (100.0 * x).round()
                    }
                })
                .collect()
        })
        .collect();
    web(&ies_text(1, &v, &h, &planes))
}

/// Asserts that every web gives the first one's intensity, pdf and flux.
fn assert_same_light(webs: &[IesWeb], what: &str) {
    for (k, w) in webs.iter().enumerate().skip(1) {
        assert!(
            rel_close(w.flux(), webs[0].flux(), 1e-12),
            "{what} #{k}: flux"
        );
        for d in directions(20_000, 11) {
            let (a, b) = (webs[0].intensity(d), w.intensity(d));
            assert!(
                (a - b).abs() <= 1e-5 * a.max(1.0),
                "{what} #{k} at {d}: {a} vs {b}"
            );
            let (a, b) = (webs[0].pdf(d).0, w.pdf(d).0);
            assert!(
                (a - b).abs() <= 1e-5 * a.max(1e-6),
                "{what} #{k} pdf at {d}"
            );
        }
    }
}

#[test]
fn every_symmetry_encoding_gives_the_same_light() {
    // One quadrant-symmetric light in its four encodings.
    let quad = [
        "quad_0-360.ies",
        "quad_0-90.ies",
        "quad_0-180.ies",
        "quad_90-270.ies",
    ];
    assert_same_light(&quad.map(load), "quadrant light");
    // A rotationally symmetric light in all five type C encodings.
    let v = [0.0, 40.0, 90.0, 180.0];
    let p = vec![70.0, 50.0, 20.0, 3.0];
    let enc = |h: &[f64]| web(&ies_text(1, &v, h, &vec![p.clone(); h.len()]));
    let axial = [
        enc(&[0.0]),
        enc(&[0.0, 90.0]),
        enc(&[0.0, 30.0, 180.0]),
        enc(&[90.0, 270.0]),
        enc(&[0.0, 120.0, 360.0]),
    ];
    assert_same_light(&axial, "axial light");
    // Bilateral about the 0–180° plane only: 0–180 against 0–360.
    let v = [0.0, 90.0, 180.0];
    let col = |a: f64| vec![a, 2.0 * a, 1.0];
    let half: Vec<Vec<f64>> = [10.0, 20.0, 40.0].map(col).to_vec();
    let full: Vec<Vec<f64>> = [10.0, 20.0, 40.0, 20.0, 10.0].map(col).to_vec();
    assert_same_light(
        &[
            web(&ies_text(1, &v, &[0.0, 90.0, 180.0, 270.0, 360.0], &full)),
            web(&ies_text(1, &v, &[0.0, 90.0, 180.0], &half)),
        ],
        "0-180 light",
    );
    // Bilateral about the 90–270° plane only: I(180° − H) = I(H).
    let half: Vec<Vec<f64>> = [5.0, 30.0, 60.0, 45.0, 5.0].map(col).to_vec();
    let full: Vec<Vec<f64>> = [60.0, 30.0, 5.0, 30.0, 60.0, 45.0, 5.0, 45.0, 60.0]
        .map(col)
        .to_vec();
    let h360: Vec<f64> = (0..9).map(|k| 45.0 * k as f64).collect();
    assert_same_light(
        &[
            web(&ies_text(1, &v, &h360, &full)),
            web(&ies_text(1, &v, &[90.0, 135.0, 180.0, 225.0, 270.0], &half)),
        ],
        "90-270 light",
    );
    // Types A and B: 0–90 against −90–90.
    let v = [-90.0, 0.0, 45.0, 90.0];
    let col = |a: f64| vec![0.0, a, 2.0 * a, 0.0];
    for ty in [2, 3] {
        let half: Vec<Vec<f64>> = [30.0, 20.0, 5.0].map(col).to_vec();
        let full: Vec<Vec<f64>> = [5.0, 20.0, 30.0, 20.0, 5.0].map(col).to_vec();
        assert_same_light(
            &[
                web(&ies_text(ty, &v, &[-90.0, -45.0, 0.0, 45.0, 90.0], &full)),
                web(&ies_text(ty, &v, &[0.0, 45.0, 90.0], &half)),
            ],
            "A/B lateral",
        );
    }
}

/// Unit vector from spherical angles in degrees about z (θ from +z, φ from +x).
fn dir(theta: f64, phi: f64) -> Vec3 {
    let (t, p) = (theta.to_radians(), phi.to_radians());
    Vec3::new(
        (t.sin() * p.cos()) as f32,
        (t.sin() * p.sin()) as f32,
        t.cos() as f32,
    )
}

#[test]
fn type_c_orientation() {
    // One bright node at V = 90°, H = 90°; 10 cd at nadir; zero at the zenith.
    let v = [0.0, 90.0, 180.0];
    let h = [0.0, 90.0, 180.0, 270.0, 360.0];
    let planes: Vec<Vec<f64>> = (0..5)
        .map(|k| vec![10.0, if k == 1 { 1000.0 } else { 0.0 }, 0.0])
        .collect();
    let w = web(&ies_text(1, &v, &h, &planes));
    assert!(
        (w.intensity(-Vec3::Y) - 1000.0).abs() < 1e-3,
        "H = 90° is −y"
    );
    assert_eq!(w.intensity(Vec3::Y), 0.0);
    assert_eq!(w.intensity(Vec3::X), 0.0);
    assert!((w.intensity(Vec3::Z) - 10.0).abs() < 1e-4, "V = 0 is +z");
    assert_eq!(w.intensity(-Vec3::Z), 0.0);
    // Between nodes, bilinear in (V, H): V = 45°, H = 45° (φ = −45°).
    let want = 0.25 * (10.0 + 10.0 + 1000.0 + 0.0);
    assert!((w.intensity(dir(45.0, -45.0)) - want).abs() < 1e-2);
    // The quadrant file at V = 15°, H = 22.5°: (100 + 90 + 100 + 80)/4.
    let q = load("quad_0-90.ies");
    assert!((q.intensity(dir(15.0, -22.5)) - 92.5).abs() < 1e-3);
}

#[test]
fn types_a_and_b_orientation() {
    // Both files: 1000 cd at (H 0°, V 45°), 500 at (45°, 0°), 250 at (45°, 45°).
    let (b, a) = (load("type_b.ies"), load("type_a.ies"));
    let s = std::f32::consts::FRAC_1_SQRT_2;
    for w in [&a, &b] {
        assert!(
            (w.intensity(Vec3::new(s, 0.0, s)) - 1000.0).abs() < 1e-2,
            "V = 45° towards +x"
        );
        assert!(
            (w.intensity(Vec3::new(0.0, s, s)) - 500.0).abs() < 1e-2,
            "H = 45° towards +y"
        );
        assert_eq!(w.intensity(Vec3::new(0.0, -s, s)), 0.0);
        assert_eq!(w.intensity(Vec3::new(-s, 0.0, s)), 0.0);
        assert_eq!(w.intensity(-Vec3::Z), 0.0, "nothing behind the beam");
        // Halfway from (0°, 0°) to (0°, 45°) along V, bilinear: 500.
        assert!((w.intensity(dir(22.5, 0.0)) - 500.0).abs() < 1e-2);
    }
    // Off the axes the two systems differ: B ω = (cos H sin V, sin H, cos H cos V),
    // A ω = (sin V, cos V sin H, cos V cos H), at H = V = 45°.
    assert!((b.intensity(Vec3::new(0.5, s, 0.5)) - 250.0).abs() < 1e-2);
    assert!((a.intensity(Vec3::new(s, 0.5, 0.5)) - 250.0).abs() < 1e-2);
}

#[test]
fn dark_webs_and_invalid_structs() {
    let dark = web(&ies_text(1, &[0.0, 90.0], &[0.0], &[vec![0.0, 0.0]]));
    assert_eq!(dark.flux(), 0.0);
    assert!(dark.sample(Vec2::new(0.3, 0.7)).is_none());
    assert_eq!(dark.pdf(Vec3::Z).0, 0.0);
    let good = candela_scene::read_ies(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../candela-scene/tests/data/ies/hand.ies"),
    )
    .unwrap();
    let mut bad = good.clone();
    bad.candela.pop();
    assert!(IesWeb::new(&bad).is_err());
    let mut bad = good.clone();
    bad.vertical_angles = vec![0.0, 90.0, 90.0];
    assert!(IesWeb::new(&bad).is_err());
    let mut bad = good.clone();
    bad.candela[1] = f64::NAN;
    assert!(IesWeb::new(&bad).is_err());
    let mut bad = good;
    bad.horizontal_angles = vec![45.0];
    let e = IesWeb::new(&bad).unwrap_err();
    assert_eq!(
        e.to_string(),
        "invalid IES photometric web: horizontal angles are not an LM-63 range"
    );
}
