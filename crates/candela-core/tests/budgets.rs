//! The render loop's budgets: `--target-error` stops once the estimated
//! relative standard error of the image mean is below the target, and the
//! image is then within 5σ of the closed form; `--time-limit` stops within
//! one pass of the limit.

use candela_core::build::{build, Overrides};
use candela_core::render::{self, RenderOptions, StopReason};
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

/// validation.md T4(b): a point light of I = π at the centre of a diffuse
/// sphere (R = 1, ρ = 0.5) gives L = 1 on every wall point.
const FURNACE: &str = r#"LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [60]
Film "rgb" "integer xresolution" [24] "integer yresolution" [24]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [200]
WorldBegin
LightSource "point" "point3 from" [0 0 0] "rgb I" [3.14159265 3.14159265 3.14159265]
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
ReverseOrientation
Shape "sphere" "float radius" [1]
"#;

fn setup(spp: u32) -> candela_core::build::RenderSetup {
    let desc = candela_scene::parse_str(FURNACE, Path::new("furnace.pbrt")).expect("parses");
    let ov = Overrides {
        spp: Some(spp),
        seed: Some(11),
        ..Default::default()
    };
    build(&desc, &ov).expect("builds")
}

#[test]
fn target_error_stops_below_the_target_with_the_closed_form_inside_5_sigma() {
    let setup = setup(100_000);
    let mut state = render::new_state(&setup, 0, 100_000, "");
    let target = 2e-3;
    let opts = RenderOptions {
        passes: (0, 100_000),
        target_error: Some(target),
        ..Default::default()
    };
    let stop = AtomicBool::new(false);
    let out = render::render(
        &setup,
        &mut state,
        &opts,
        &stop,
        &render::NoProgress,
        &mut |_| {},
    )
    .expect("renders");
    let StopReason::TargetError(reported) = out.reason else {
        panic!("did not stop on the error target: {:?}", out.reason);
    };
    let n = state.film.passes().count();
    assert!(
        reported < target && n >= render::MIN_PASSES_FOR_ERROR,
        "{reported} after {n}"
    );
    assert!(
        n < 100_000,
        "the target should be met long before every pass"
    );
    // The loop's own estimate, recomputed: every channel below the target.
    let rel = state.film.relative_error().expect("estimate");
    assert!(rel.iter().all(|&e| e < target), "{rel:?}");
    // The image mean is the mean of the pass means; its standard error is
    // their spread / √n. 5σ plus the RGB ↔ spectrum round trip (2e-3, as in
    // closed_forms.rs).
    let img = render::develop_state(&setup, &state).rgb();
    let means = state.film.pass_means();
    for c in 0..3 {
        let m = img.channel_means()[c];
        let pm: Vec<f64> = means.iter().map(|(_, v)| v[c]).collect();
        let mu = pm.iter().sum::<f64>() / pm.len() as f64;
        let var = pm.iter().map(|v| (v - mu) * (v - mu)).sum::<f64>() / (pm.len() - 1) as f64;
        let se = (var / pm.len() as f64).sqrt();
        assert!(
            (m - mu).abs() < 1e-6 * mu,
            "image mean {m} vs mean of pass means {mu}"
        );
        assert!(
            (m - 1.0).abs() <= 5.0 * se + 2e-3,
            "channel {c}: {m} ± {se} after {n} passes"
        );
    }
}

#[test]
fn time_limit_stops_within_one_pass_of_the_limit() {
    let setup = setup(1_000_000);
    let mut state = render::new_state(&setup, 0, 1_000_000, "");
    let limit = Duration::from_millis(1500);
    let opts = RenderOptions {
        passes: (0, 1_000_000),
        time_limit: Some(limit),
        ..Default::default()
    };
    let stop = AtomicBool::new(false);
    let out = render::render(
        &setup,
        &mut state,
        &opts,
        &stop,
        &render::NoProgress,
        &mut |_| {},
    )
    .expect("renders");
    assert_eq!(out.reason, StopReason::TimeLimit);
    let n = out.passes_rendered;
    assert!(n > 1 && n == state.film.passes().count(), "{n} passes");
    // The loop never starts a pass that its mean pass time says would end
    // after the limit: it stops at most one (mean) pass short of the limit,
    // and overshoots by at most the spread of one pass's time.
    let pass = out.elapsed / n as u32;
    assert!(
        out.elapsed <= limit + 2 * pass,
        "{:?} for {n} passes",
        out.elapsed
    );
    assert!(
        out.elapsed + 2 * pass >= limit,
        "{:?} for {n} passes",
        out.elapsed
    );
}
