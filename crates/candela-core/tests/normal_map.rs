//! pbrt-v4's `normalmap` material parameter end to end: a PNG written at test
//! time (read with linear encoding, as pbrt-v4 reads normal maps) tilts the
//! shading normal of a diffuse quad lit head-on by a distant light of
//! irradiance π. A Lambertian of albedo ρ then reflects ρ·cos α, α the angle
//! between the mapped normal and the light. The image's left half is flat
//! (128, 128, 255) and its right half tilted by about 60° (238, 128, 191);
//! cos α is computed from the 8-bit codes. Direct light only (`maxdepth` 1),
//! so the only noise is the film's; tolerance 5σ of the region mean plus
//! b = 0.01 for the spectral round trip of the grey albedo.

mod common;

use candela_core::build::Overrides;
use common::{assert_region, render_at};
use std::path::PathBuf;

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-nmap-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("temp dir");
    d
}

/// cos α of the tangent-space normal encoded by 8-bit `rgb` (z is the normal).
fn cos_of(rgb: [u8; 3]) -> f64 {
    let v = rgb.map(|c| 2.0 * c as f64 / 255.0 - 1.0);
    v[2] / (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

const FLAT: [u8; 3] = [128, 128, 255];
const TILTED: [u8; 3] = [238, 128, 191];

fn scene(material: &str) -> String {
    format!(
        r#"LookAt 0 0 -3  0 0 0  0 1 0
Camera "orthographic"
Film "rgb" "integer xresolution" [16] "integer yresolution" [16]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [1]
WorldBegin
LightSource "distant" "point3 from" [0 0 -1] "point3 to" [0 0 0] "rgb L" [3.14159265 3.14159265 3.14159265]
{material}
Shape "trianglemesh" "point3 P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]
    "point2 uv" [0 0  1 0  1 1  0 1] "integer indices" [0 1 2  0 2 3]
"#
    )
}

#[test]
fn a_normal_map_tilts_the_shading_normal_by_its_encoded_angle() {
    let dir = temp_dir("tilt");
    // 8×1: texels 0–3 flat, 4–7 tilted; bilinear lookups at u ∈ [1/16, 7/16]
    // and [9/16, 15/16] see one kind only (pixel columns 2–6 and 10–14).
    let raw: Vec<u8> = (0..8)
        .flat_map(|i| if i < 4 { FLAT } else { TILTED })
        .collect();
    image::RgbImage::from_raw(8, 1, raw)
        .expect("8×1 image")
        .save(dir.join("n.png"))
        .expect("write png");
    let ov = Overrides {
        spp: Some(64),
        seed: Some(3),
        ..Default::default()
    };
    let material =
        r#"Material "diffuse" "rgb reflectance" [0.5 0.5 0.5] "string normalmap" "n.png""#;
    let (img, warnings) = render_at(&scene(material), &dir.join("scene.pbrt"), &ov);
    assert!(
        warnings.iter().all(|w| !w.contains("normalmap")),
        "{warnings:?}"
    );
    assert_region(&img, (2, 7, 1, 15), 0.5 * cos_of(FLAT), 0.01, "flat half");
    assert_region(
        &img,
        (10, 15, 1, 15),
        0.5 * cos_of(TILTED),
        0.01,
        "tilted half",
    );
    // The same material without the map is flat everywhere: the map is what
    // darkens the right half.
    let plain = r#"Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]"#;
    let (img, _) = render_at(&scene(plain), &dir.join("scene.pbrt"), &ov);
    assert_region(&img, (10, 15, 1, 15), 0.5, 0.01, "no map");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_missing_or_grey_normal_map_is_a_located_error() {
    let dir = temp_dir("err");
    let build = |material: &str| {
        let desc =
            candela_scene::parse_str(&scene(material), &dir.join("scene.pbrt")).expect("parses");
        candela_core::build::build(&desc, &Overrides::default())
            .err()
            .map(|e| e.to_string())
    };
    let e = build(r#"Material "diffuse" "string normalmap" "none.png""#).expect("must fail");
    assert!(
        e.contains("scene.pbrt:9:") && e.contains("not found"),
        "{e}"
    );
    image::GrayImage::from_pixel(2, 2, image::Luma([128]))
        .save(dir.join("grey.png"))
        .expect("write png");
    let e = build(r#"Material "diffuse" "string normalmap" "grey.png""#).expect("must fail");
    assert!(e.contains("R, G and B"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
