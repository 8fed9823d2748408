//! `LightSource "infinite" "string filename"` end to end: equal-area EXR maps
//! written at test time beside the scene file, rendered through the path
//! tracer and BDPT, and the build's errors and warnings.
//!
//! A constant map must render exactly like the uniform sky of validation.md
//! T4(d) (diffuse sphere of albedo 0.5 → 0.5, sky → 1). A map with a bright
//! patch has no closed form; the path tracer (NEE + MIS), BDPT and the light
//! tracer (emission sampling) must agree on it within their combined
//! standard errors.

mod common;

use candela_core::build::{build, Overrides};
use candela_core::image::RgbImage;
use common::{assert_region, region_mean, render_at};
use std::path::{Path, PathBuf};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-envmap-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes an n×n EXR map from `f(u, v)` at texel centres.
fn write_map(path: &Path, n: usize, f: impl Fn(f32, f32) -> [f32; 3]) {
    let mut im = RgbImage::new(n, n);
    for y in 0..n {
        for x in 0..n {
            im.pixels[y * n + x] = f((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
        }
    }
    im.write_exr(path).unwrap();
}

fn sphere_scene(light: &str, integrator: &str) -> String {
    format!(
        r#"LookAt 0 0 -5  0 0 0  0 1 0
Camera "perspective" "float fov" [30]
Film "rgb" "integer xresolution" [32] "integer yresolution" [32]
PixelFilter "box"
Sampler "independent"
Integrator "{integrator}" "integer maxdepth" [20]
WorldBegin
AttributeBegin
Rotate 40 1 1 0
{light}
AttributeEnd
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "sphere" "float radius" [1]
"#
    )
}

fn ov(spp: u32, integrator: &str) -> Overrides {
    Overrides {
        spp: Some(spp),
        seed: Some(11),
        integrator: Some(integrator.into()),
        ..Default::default()
    }
}

#[test]
fn constant_map_renders_the_uniform_sky_closed_form() {
    let dir = temp_dir("const");
    write_map(&dir.join("sky.exr"), 8, |_, _| [1.0; 3]);
    let light = r#"LightSource "infinite" "string filename" "sky.exr""#;
    for (integrator, spp) in [("path", 64), ("bdpt", 32)] {
        let scene = sphere_scene(light, integrator);
        let (img, _) = render_at(&scene, &dir.join("scene.pbrt"), &ov(spp, integrator));
        let what = format!("T4d image map, {integrator}");
        assert_region(&img, (10, 22, 10, 22), 0.5, 2e-3 * 0.5, &what);
        assert_region(&img, (0, 3, 0, 3), 1.0, 2e-3, &what);
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bright_patch_path_tracer_bdpt_and_light_tracer_agree() {
    let dir = temp_dir("patch");
    // A dim blue sky with a small, very bright warm patch (about 1 % of the
    // sphere) towards the camera and to the left, lighting part of the sphere.
    write_map(&dir.join("sky.exr"), 32, |u, v| {
        let d2 = (u - 0.1).powi(2) + (v - 0.15).powi(2);
        if d2 < 0.003 {
            [60.0, 40.0, 20.0]
        } else {
            [0.1, 0.15, 0.3]
        }
    });
    let light = r#"LightSource "infinite" "string filename" "sky.exr" "float scale" [0.5]"#;
    let render = |integrator: &str, spp: u32| {
        let scene = sphere_scene(light, integrator);
        render_at(&scene, &dir.join("scene.pbrt"), &ov(spp, integrator)).0
    };
    let pt = render("path", 256);
    let regions = [
        (10, 16, 10, 16),
        (16, 22, 10, 16),
        (10, 16, 16, 22),
        (16, 22, 16, 22),
    ];
    for (name, other) in [
        ("bdpt", render("bdpt", 128)),
        ("lightpath", render("lightpath", 256)),
    ] {
        for r in regions {
            for c in 0..3 {
                let (a, sa) = region_mean(&pt, c, r.0, r.1, r.2, r.3);
                let (b, sb) = region_mean(&other, c, r.0, r.1, r.2, r.3);
                let s = (sa * sa + sb * sb).sqrt();
                eprintln!("{r:?} c{c}: path {a:.4} ± {sa:.4}, {name} {b:.4} ± {sb:.4}");
                assert!(
                    (a - b).abs() <= 5.0 * s + 2e-3 * a,
                    "{name} {r:?} c{c}: {a} vs {b}"
                );
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// The build error (or panics) for a scene read from `dir`.
fn build_error(dir: &Path, light: &str) -> String {
    let text = sphere_scene(light, "path");
    let desc = candela_scene::parse_str(&text, &dir.join("scene.pbrt")).expect("parses");
    match build(&desc, &Overrides::default()) {
        Ok(_) => panic!("built, but should not have: {light}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_maps_are_errors_and_portals_warn() {
    let dir = temp_dir("errors");
    let mut wide = RgbImage::new(4, 2);
    wide.pixels[0] = [1.0; 3];
    wide.write_exr(&dir.join("wide.exr")).unwrap();
    write_map(&dir.join("ok.exr"), 4, |_, _| [0.5; 3]);
    // The filename parameter is on line 10, column 24 of the scene text.
    let e = build_error(
        &dir,
        r#"LightSource "infinite" "string filename" "wide.exr""#,
    );
    assert!(
        e.contains("scene.pbrt:10:24") && e.contains("non-square"),
        "{e}"
    );
    let e = build_error(
        &dir,
        r#"LightSource "infinite" "string filename" "nope.exr""#,
    );
    assert!(e.contains("not found"), "{e}");
    let e = build_error(
        &dir,
        r#"LightSource "infinite" "string filename" "ok.exr" "rgb L" [1 1 1]"#,
    );
    assert!(e.contains("both"), "{e}");
    let light = r#"LightSource "infinite" "string filename" "ok.exr"
    "point3 portal" [0 0 2  1 0 2  1 1 2  0 1 2]"#;
    let (img, warnings) = render_at(
        &sphere_scene(light, "path"),
        &dir.join("scene.pbrt"),
        &ov(16, "path"),
    );
    assert!(
        warnings.iter().any(|w| w.contains("\"portal\" ignored")),
        "{warnings:?}"
    );
    assert_region(&img, (0, 3, 0, 3), 0.5, 2e-3, "sky behind a portal");
    std::fs::remove_dir_all(&dir).ok();
}
