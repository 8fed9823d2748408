//! SPPM and probabilistic PPM against validation.md's closed forms.
//!
//! - T1 + Knaus–Zwicker: the disk-kernel irradiance estimate at the foot of a
//!   point light (I = 100, h = 2), with the PPM radius schedule from r₁ = 1,
//!   averaged over 100 passes has expectation 23.5037 (truth 25: the kernel
//!   bias shrinks with the radius).
//! - T4(b), centred point light in a diffuse sphere: L = 1 everywhere and the
//!   wall area within chord r of a wall point is exactly πr², so SPPM and PPM
//!   have zero kernel bias at any radius; a large radius must still give 1.
//! - Partial PPM renders merge into the full render bit for bit.
//!
//! Noise bounds are 5σ, with σ measured in the same run.

mod common;

use candela_core::build::{build, Overrides};
use candela_core::integrator::photon::{trace_photon, ShootSettings};
use candela_core::integrator::sppm::ppm_radius2;
use candela_core::render::{self, RenderOptions};
use candela_core::spectrum::SampledWavelengths;
use common::render_str;
use rayon::prelude::*;
use std::path::Path;
use std::sync::atomic::AtomicBool;

#[test]
fn t1_ppm_mean_after_100_passes_equals_its_biased_expectation() {
    let text = r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective"
WorldBegin
LightSource "point" "point3 from" [0 0 2] "rgb I" [100 100 100]
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "point3 P" [-1000 -1000 0  1000 -1000 0  1000 1000 0  -1000 1000 0]
  "integer indices" [0 1 2 0 2 3]
"#;
    let desc = candela_scene::parse_str(text, Path::new("t1.pbrt")).expect("parses");
    let rs = build(&desc, &Overrides::default()).expect("builds");
    let lambda = SampledWavelengths::sample_visible(0.5);
    let phi = rs.scene.lights()[0].phi(&lambda).0[0] as f64;
    let i_eff = phi / (4.0 * std::f64::consts::PI); // E(0) = I/h²
    let n = 20_000u64;
    let passes = 100u64;
    let estimates: Vec<f64> = (0..passes)
        .into_par_iter()
        .map(|pass| {
            let r2 = ppm_radius2(pass + 1, 2.0 / 3.0); // r₁ = 1 = h/2
            let settings = ShootSettings {
                max_depth: 1,
                seed: 99,
                caustic_only: false,
            };
            let mut sum = 0.0f64;
            for i in 0..n {
                trace_photon(&rs.scene, &lambda, &settings, pass, i, |h| {
                    if (h.v.p().truncate().length_squared() as f64) < r2 {
                        sum += h.v.beta.0[0] as f64 / n as f64;
                    }
                });
            }
            // Irradiance estimate in units of I (so truth = 25 for I = 100).
            sum / (std::f64::consts::PI * r2) / i_eff * 100.0
        })
        .collect();
    let m = estimates.iter().sum::<f64>() / passes as f64;
    let var = estimates.iter().map(|e| (e - m).powi(2)).sum::<f64>() / (passes as f64 - 1.0);
    let se = (var / passes as f64).sqrt();
    eprintln!("PPM T1 mean over 100 passes: {m:.4} ± {se:.4} (expected 23.5037)");
    assert!((m - 23.5037).abs() <= 5.0 * se, "{m} ± {se}");
    assert!(
        (m - 25.0).abs() > 5.0 * se,
        "the test must resolve the kernel bias"
    );
}

/// Centred point light (I = π) in a diffuse sphere (ρ = 0.5, R = 1): L = 1.
fn furnace(integrator: &str, radius: f32) -> String {
    format!(
        r#"LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [60]
Film "rgb" "integer xresolution" [16] "integer yresolution" [16]
PixelFilter "box"
Sampler "independent"
Integrator "{integrator}" "integer maxdepth" [60] "float radius" [{radius}]
  "integer photonsperiteration" [4000]
WorldBegin
LightSource "point" "point3 from" [0 0 0] "rgb I" [3.14159265 3.14159265 3.14159265]
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
ReverseOrientation
Shape "sphere" "float radius" [1]
"#
    )
}

#[test]
fn t4b_sppm_and_ppm_have_no_kernel_bias_in_the_sphere_furnace() {
    // All pixels of one render share its photons, so pixel noise is
    // correlated: σ of the image mean comes from K = 6 independent seeds.
    const K: u64 = 6;
    for integrator in ["sppm", "ppm"] {
        let scene = furnace(integrator, 1.0);
        assert_image_means_are_one(&scene, K, &format!("{integrator} furnace"));
    }
}

/// Asserts that every channel's image mean of `scene` (64 spp) is 1 within
/// 5σ + 2e-3 over `k` seeds: σ from the seeds' spread (an image's pixels
/// may share photons or wavelengths, so they are not independent), 2e-3
/// the RGB ↔ spectrum round trip (as in closed_forms.rs).
fn assert_image_means_are_one(scene: &str, k: u64, what: &str) {
    let means: Vec<[f64; 3]> = (0..k)
        .map(|seed| {
            let ov = Overrides {
                spp: Some(64),
                seed: Some(seed + 1),
                ..Default::default()
            };
            render_str(scene, &ov).channel_means()
        })
        .collect();
    for c in 0..3 {
        let m = means.iter().map(|v| v[c]).sum::<f64>() / k as f64;
        let var = means.iter().map(|v| (v[c] - m).powi(2)).sum::<f64>() / (k - 1) as f64;
        let se = (var / k as f64).sqrt();
        eprintln!("{what}, channel {c}: {m:.5} ± {se:.5} (expected 1)");
        assert!((m - 1.0).abs() <= 5.0 * se + 2e-3, "{what}: {m} ± {se}");
    }
}

#[test]
fn ppm_partial_renders_merge_into_the_full_render_bit_for_bit() {
    let text = furnace("ppm", 0.3).replace(
        "\"integer maxdepth\"",
        "\"integer seed\" [4] \"integer maxdepth\"",
    );
    let desc = candela_scene::parse_str(&text, Path::new("f.pbrt")).expect("parses");
    let ov = Overrides {
        spp: Some(6),
        ..Default::default()
    };
    let setup = build(&desc, &ov).expect("builds");
    let run = |range: (u64, u64)| {
        let mut state = render::new_state(&setup, 1, 6, "");
        let opts = RenderOptions {
            passes: range,
            ..Default::default()
        };
        let stop = AtomicBool::new(false);
        render::render(
            &setup,
            &mut state,
            &opts,
            &stop,
            &render::NoProgress,
            &mut |_| {},
        )
        .expect("renders");
        state
    };
    let full = run((0, 6));
    let mut first = run((0, 2));
    first.merge(&run((2, 6))).expect("disjoint");
    assert_eq!(first, full, "fixed-point sums add associatively");
    assert_eq!(
        render::develop_state(&setup, &first),
        render::develop_state(&setup, &full)
    );
}

/// The gather radius is checked against the scene's scale: in the unit-sphere
/// furnace (diagonal 2√3 ≈ 3.46) pbrt-v4's default radius 1 is 29 % of it and
/// warned about, 0.02 (0.6 %) is not, 1e-6 is warned about as tiny.
#[test]
fn photon_radius_far_from_the_scene_scale_is_warned_about() {
    let warned = |integrator: &str, radius: f32| {
        let desc = candela_scene::parse_str(&furnace(integrator, radius), Path::new("f.pbrt"))
            .expect("scene parses");
        let setup = build(&desc, &Overrides::default()).expect("scene builds");
        setup
            .warnings
            .iter()
            .any(|w| w.contains("\"radius\"") && w.contains("f.pbrt:6:"))
    };
    for integrator in ["sppm", "ppm"] {
        assert!(warned(integrator, 1.0), "{integrator}: radius 1");
        assert!(!warned(integrator, 0.02), "{integrator}: radius 0.02");
        assert!(warned(integrator, 1e-6), "{integrator}: radius 1e-6");
    }
}

/// Inside a sphere that emits L = 1 (RGB) towards its centre, seen from the
/// centre: every pixel's value is 1 in each channel (up to the RGB ↔
/// spectrum round trip, 2e-3, as in the furnace above), whatever the depth.
/// pbrt-v4's SPPM counts the emission of the camera ray's first hit even at
/// `maxdepth` 0 (its camera loop adds it before testing the depth); candela's
/// photon camera pass visited no vertex there and rendered black (found by
/// an edge-case battery; pbrt-v4 and candela now agree to 0.5 % on the
/// Cornell box at depth 0). vcm's mode `ppm` bounds depth as `ppm` does.
/// Noise: wavelength sampling only (vcm's iterations share their
/// wavelengths over the whole image, so its image means vary most); 5σ
/// over K = 8 seeds.
#[test]
fn emission_seen_directly_counts_at_maxdepth_0() {
    const K: u64 = 8;
    for integrator in [
        "\"sppm\"",
        "\"ppm\"",
        "\"vcm\" \"string mode\" \"ppm\"",
        "\"path\"",
    ] {
        let scene = format!(
            r#"LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [60]
Film "rgb" "integer xresolution" [8] "integer yresolution" [8]
Sampler "independent"
Integrator {integrator} "integer maxdepth" [0] "float radius" [0.1]
WorldBegin
AreaLightSource "diffuse" "rgb L" [1 1 1]
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
ReverseOrientation
Shape "sphere" "float radius" [1]
"#
        );
        assert_image_means_are_one(&scene, K, &format!("{integrator} maxdepth 0"));
    }
}
