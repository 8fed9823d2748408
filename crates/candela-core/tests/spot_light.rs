//! pbrt-v4's spot light reads its falloff width from `conedeltaangle`
//! (`coneangle` 30° and `conedeltaangle` 5° by default). The intensity is full
//! inside coneangle − conedeltaangle and smooth-steps to zero at coneangle.

use candela_core::build::{build, Overrides};
use candela_core::light::LightSampleContext;
use candela_core::math::{Vec2, Vec3};
use candela_core::spectrum::SampledWavelengths;
use std::path::Path;

/// Intensity ratio I(θ)/I(0) of the scene's spot light, seen from 1 unit away.
fn falloff(params: &str, theta_deg: f32) -> (f32, Vec<String>) {
    let text = format!(
        "Camera \"perspective\"\nWorldBegin\nLightSource \"spot\" \"point3 from\" [0 0 0] \"point3 to\" [0 0 1] {params}\n"
    );
    let desc = candela_scene::parse_str(&text, Path::new("spot.pbrt")).expect("parses");
    let setup = build(&desc, &Overrides::default()).expect("builds");
    let light = &setup.scene.lights()[0];
    let lambda = SampledWavelengths::sample_visible(0.5);
    let at = |deg: f32| {
        let t = deg.to_radians();
        let ctx = LightSampleContext::at_point(Vec3::new(t.sin(), 0.0, t.cos()));
        // No sample outside the cone: zero intensity.
        light
            .sample_li(&ctx, Vec2::splat(0.5), &lambda)
            .map_or(0.0, |s| s.l.average())
    };
    (at(theta_deg) / at(0.0), setup.warnings)
}

#[test]
fn conedeltaangle_sets_the_falloff_width() {
    // Start of the falloff at 30 − 20 = 10°: at 20° the light is dimmed.
    let (wide, warnings) = falloff(
        "\"float coneangle\" [30] \"float conedeltaangle\" [20]",
        20.0,
    );
    assert!(
        warnings.iter().all(|w| !w.contains("conedeltaangle")),
        "{warnings:?}"
    );
    assert!(wide > 0.05 && wide < 0.95, "I(20°)/I(0) = {wide}");
    // With the default 5° the falloff starts at 25°: full intensity at 20°.
    let (default, _) = falloff("\"float coneangle\" [30]", 20.0);
    assert!((default - 1.0).abs() < 1e-5, "I(20°)/I(0) = {default}");
    // Outside the cone: nothing.
    let (outside, _) = falloff(
        "\"float coneangle\" [30] \"float conedeltaangle\" [20]",
        31.0,
    );
    assert_eq!(outside, 0.0);
}
