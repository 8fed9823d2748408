//! The coated materials end to end: scene text → builder → integrators.
//!
//! Furnace (validation.md T4(d)): under a uniform sky of radiance 1 a convex
//! object renders its directional albedo ρ(ωo). A white Lambertian under a
//! smooth coating in a vanishing slab is lossless (the BSDF tests show its
//! ρ = 1 to 10⁻⁴), so the sphere must render 1. The path tracer reaches that
//! only if the MIS weights of the layered BSDF's samples, whose pdf is only
//! proportional, are computed from `Bsdf::pdf` like those of light samples.
//! Checks are |mean − 1| ≤ 5σ + b with σ measured over the pixels and
//! b = 2·10⁻³ for the RGB ↔ spectrum round trip, as in closed_forms.rs.

mod common;

use candela_core::build::{build, Overrides};
use common::{assert_region, region_mean, render_str};
use std::path::Path;

/// Builds scene text; returns the build result's warnings or its error message.
fn build_str(text: &str) -> Result<Vec<String>, String> {
    let desc = candela_scene::parse_str(text, Path::new("test.pbrt")).map_err(|e| e.to_string())?;
    build(&desc, &Overrides::default())
        .map(|s| s.warnings)
        .map_err(|e| e.to_string())
}

/// A sphere of `material` (a `Material` directive's body) under a uniform sky.
fn furnace(material: &str, integrator: &str) -> String {
    format!(
        r#"LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective" "float fov" [30]
Film "rgb" "integer xresolution" [32] "integer yresolution" [32]
PixelFilter "box"
Sampler "independent"
Integrator "{integrator}" "integer maxdepth" [5]
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Material {material}
Shape "sphere" "float radius" [1]
"#
    )
}

#[test]
fn coated_materials_build_with_every_pbrt_parameter() {
    let text = r#"WorldBegin
MakeNamedMaterial "plastic" "string type" "coateddiffuse"
    "rgb reflectance" [0.4 0.2 0.2] "float roughness" [0.1] "float thickness" [0.02]
    "float eta" [1.4] "rgb albedo" [0.5 0.5 0.5] "float g" [0.3]
    "integer maxdepth" [12] "integer nsamples" [2] "bool remaproughness" false
MakeNamedMaterial "aniso" "string type" "coateddiffuse"
    "float uroughness" [0.1] "float vroughness" [0.3] "spectrum eta" "glass-BK7"
MakeNamedMaterial "lacquered copper" "string type" "coatedconductor"
    "float interface.roughness" [0.05] "float interface.eta" [1.6]
    "float conductor.uroughness" [0.2] "float conductor.vroughness" [0.1]
    "rgb conductor.eta" [0.2 0.9 1.1] "rgb conductor.k" [3.9 2.4 2.2]
    "float thickness" [0.05] "integer maxdepth" [8]
MakeNamedMaterial "painted metal" "string type" "coatedconductor"
    "rgb reflectance" [0.9 0.6 0.3] "float conductor.roughness" [0.3]
    "float interface.uroughness" [0.01] "float interface.vroughness" [0.02]
Material "coateddiffuse"
Shape "sphere"
Material "coatedconductor"
Shape "sphere"
NamedMaterial "plastic"
Shape "sphere"
NamedMaterial "aniso"
Shape "sphere"
NamedMaterial "lacquered copper"
Shape "sphere"
NamedMaterial "painted metal"
Shape "sphere"
"#;
    let warnings = build_str(text).expect("scene builds");
    let unused: Vec<_> = warnings.iter().filter(|w| w.contains("unused")).collect();
    assert!(unused.is_empty(), "parameters not read: {unused:?}");
}

#[test]
fn coated_material_errors_name_the_problem() {
    let both = r#"WorldBegin
Material "coatedconductor" "rgb reflectance" [0.5 0.5 0.5] "spectrum conductor.eta" "metal-Cu-eta"
Shape "sphere"
"#;
    let e = build_str(both).expect_err("reflectance and eta together");
    assert!(e.contains("not both") && e.contains("test.pbrt:2"), "{e}");
    let zero =
        "WorldBegin\nMaterial \"coateddiffuse\" \"integer nsamples\" [0]\nShape \"sphere\"\n";
    let e = build_str(zero).expect_err("nsamples 0");
    assert!(e.contains("\"nsamples\" must be at least 1"), "{e}");
    let negative =
        "WorldBegin\nMaterial \"coatedconductor\" \"integer maxdepth\" [-1]\nShape \"sphere\"\n";
    assert!(build_str(negative).is_err());
}

/// The lossless coated sphere: white Lambertian, smooth coating, τ = 10⁻⁷, 200 events.
const LOSSLESS: &str = r#""coateddiffuse" "rgb reflectance" [1 1 1] "float thickness" [1e-7] "integer maxdepth" [200]"#;

#[test]
fn lossless_coated_sphere_vanishes_in_the_furnace_path_tracer() {
    let ov = Overrides {
        spp: Some(64),
        seed: Some(1),
        ..Default::default()
    };
    let img = render_str(&furnace(LOSSLESS, "path"), &ov);
    assert_region(&img, (10, 22, 10, 22), 1.0, 2e-3, "coated sphere (path)");
    assert_region(&img, (0, 3, 0, 3), 1.0, 2e-3, "sky (path)");
}

#[test]
fn light_tracer_agrees_with_path_tracer_on_a_rough_coating() {
    // Importance transport: the light tracer carries light paths with
    // sample_f in importance mode and connects them to the camera with f in
    // importance mode; the path tracer uses radiance mode throughout. A
    // smooth coating's delta reflection cannot be connected to a pinhole, so
    // the coating is rough here. The central region's means must agree within
    // 5 combined standard errors (same spectral round trip: no allowance).
    let material = r#""coateddiffuse" "rgb reflectance" [0.8 0.8 0.8] "float roughness" [0.3]"#;
    let render = |integrator: &str, spp: u32| {
        let ov = Overrides {
            spp: Some(spp),
            seed: Some(2),
            integrator: Some(integrator.into()),
            ..Default::default()
        };
        render_str(&furnace(material, integrator), &ov)
    };
    let (pt, lt) = (render("path", 64), render("lightpath", 1024));
    for c in 0..3 {
        let (mp, sp) = region_mean(&pt, c, 10, 22, 10, 22);
        let (ml, sl) = region_mean(&lt, c, 10, 22, 10, 22);
        eprintln!("channel {c}: path {mp:.5} ± {sp:.5}, lightpath {ml:.5} ± {sl:.5}");
        assert!(
            (mp - ml).abs() <= 5.0 * (sp * sp + sl * sl).sqrt(),
            "channel {c}"
        );
        assert!(mp > 0.3 && mp < 1.0, "channel {c}: implausible albedo {mp}");
    }
}
