//! Textures, bump mapping and the mix material end to end: scene text →
//! parser → builder → path tracer → image.
//!
//! Every texture type, mapping and texture-valued material parameter is
//! rendered on a small image, which must be finite (the film also counts
//! non-finite samples, which `render_str` requires to be zero). Two scenes
//! check values: a black/white checkerboard must show both, and a `mix` of a
//! black and a white diffuse material under a uniform sky must average the
//! white one's probability `amount`.

mod common;

use candela_core::build::{build, Overrides};
use common::{assert_region, render_str};
use std::path::Path;

fn ov(spp: u32) -> Overrides {
    Overrides {
        spp: Some(spp),
        seed: Some(1),
        ..Default::default()
    }
}

/// A unit-uv quad in z = 0 spanning [−1, 1]² facing the camera, and a sphere
/// behind it to the side, under a uniform white sky; `world` goes before the
/// shapes (textures and the current material).
fn scene(world: &str, res: u32) -> String {
    format!(
        r#"LookAt 0 0 -3  0 0 0  0 1 0
Camera "perspective" "float fov" [45]
Film "rgb" "integer xresolution" [{res}] "integer yresolution" [{res}]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [4]
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
{world}
Shape "trianglemesh" "point3 P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]
    "point2 uv" [0 0  1 0  1 1  0 1] "integer indices" [0 1 2  0 2 3]
AttributeBegin
Translate 1.2 1.2 1.5
Shape "sphere" "float radius" [0.6]
AttributeEnd
"#
    )
}

fn assert_finite(world: &str) {
    let img = render_str(&scene(world, 12), &ov(4));
    for y in 0..12 {
        for x in 0..12 {
            let p = img.get(x, y);
            // Saturated colours may map slightly outside the sRGB gamut
            // (negative channels), so only finiteness is required.
            assert!(
                p.iter().all(|v| v.is_finite()),
                "pixel ({x}, {y}) = {p:?} for\n{world}"
            );
        }
    }
}

#[test]
fn every_texture_type_renders_finite_images() {
    let cases = [
        // constant, both kinds; float as roughness.
        r#"Texture "r" "spectrum" "constant" "rgb value" [0.2 0.4 0.6]
Texture "f" "float" "constant" "float value" [0.3]
Material "conductor" "texture reflectance" "r" "texture roughness" "f""#,
        // scale of a spectrum by a float texture; float scale of two textures.
        r#"Texture "s" "float" "constant" "float value" [0.5]
Texture "s2" "float" "scale" "texture tex" "s" "float scale" [0.4]
Texture "r" "spectrum" "scale" "rgb tex" [0.8 0.6 0.4] "texture scale" "s2"
Material "diffuse" "texture reflectance" "r""#,
        // mix with a nested noise amount.
        r#"Texture "amt" "float" "fbm" "integer octaves" [4] "float roughness" [0.6]
Texture "c" "spectrum" "checkerboard" "float uscale" [4] "float vscale" [4]
Texture "r" "spectrum" "mix" "rgb tex1" [0.9 0.1 0.1] "texture tex2" "c" "texture amount" "amt"
Material "diffuse" "texture reflectance" "r""#,
        // directionmix, spectrum and float.
        r#"Texture "d" "spectrum" "directionmix" "rgb tex1" [0.1 0.8 0.1] "rgb tex2" [0.8 0.1 0.1] "vector3 dir" [0 0 1]
Texture "rf" "float" "directionmix" "float tex1" [0.05] "float tex2" [0.5]
Material "conductor" "texture reflectance" "d" "texture uroughness" "rf" "float vroughness" [0.2]"#,
        // 2D checkerboards under each mapping.
        r#"Texture "r" "spectrum" "checkerboard" "string mapping" "spherical"
Material "diffuse" "texture reflectance" "r""#,
        r#"Texture "r" "spectrum" "checkerboard" "string mapping" "cylindrical"
Material "diffuse" "texture reflectance" "r""#,
        r#"Texture "r" "spectrum" "checkerboard" "string mapping" "planar" "vector3 v1" [4 0 0] "vector3 v2" [0 4 0] "float udelta" [0.5]
Material "diffuse" "texture reflectance" "r""#,
        // 3D checkerboard in a scaled texture space.
        r#"AttributeBegin
Scale 4 4 4
Texture "r" "spectrum" "checkerboard" "integer dimension" [3] "rgb tex1" [0.9 0.9 0.2] "rgb tex2" [0.1 0.1 0.5]
AttributeEnd
Material "diffuse" "texture reflectance" "r""#,
        // bilerp, spectrum and float.
        r#"Texture "r" "spectrum" "bilerp" "rgb v00" [1 0 0] "rgb v01" [0 1 0] "rgb v10" [0 0 1] "rgb v11" [1 1 1]
Texture "k" "spectrum" "bilerp" "rgb v00" [1 2 3] "rgb v11" [4 4 4]
Texture "ro" "float" "bilerp" "float v00" [0.01] "float v11" [0.6]
Material "conductor" "texture eta" "r" "texture k" "k" "texture roughness" "ro""#,
        // dots with nested textures inside and out.
        r#"Texture "c" "spectrum" "checkerboard" "float uscale" [16] "float vscale" [16]
Texture "r" "spectrum" "dots" "float uscale" [6] "float vscale" [6] "texture inside" "c" "rgb outside" [0.2 0.3 0.9]
Texture "f" "float" "dots" "float uscale" [6] "float vscale" [6]
Material "diffuse" "texture reflectance" "r" "texture displacement" "f""#,
        // marble.
        r#"Texture "r" "spectrum" "marble" "float scale" [3] "float variation" [0.5] "integer octaves" [6]
Material "diffuse" "texture reflectance" "r""#,
        // wrinkled and windy as bump maps, fbm as roughness, on a dielectric.
        r#"Texture "w" "float" "wrinkled" "integer octaves" [5]
Texture "wd" "float" "scale" "texture tex" "w" "float scale" [0.02]
Material "diffuse" "rgb reflectance" [0.7 0.7 0.7] "texture displacement" "wd""#,
        r#"Texture "wi" "float" "windy"
Texture "wd" "float" "scale" "texture tex" "wi" "float scale" [0.05]
Texture "fb" "float" "fbm"
Texture "ro" "float" "scale" "texture tex" "fb" "float scale" [0.3]
Material "dielectric" "float eta" [1.5] "texture roughness" "ro" "texture displacement" "wd""#,
    ];
    for world in cases {
        assert_finite(world);
    }
}

#[test]
fn mix_material_of_textured_and_bumped_materials_renders_finite_images() {
    assert_finite(
        r#"Texture "c" "spectrum" "checkerboard" "float uscale" [8] "float vscale" [8]
Texture "w" "float" "wrinkled"
Texture "wd" "float" "scale" "texture tex" "w" "float scale" [0.03]
Texture "amt" "float" "bilerp"
MakeNamedMaterial "a" "string type" "diffuse" "texture reflectance" "c"
MakeNamedMaterial "b" "string type" "conductor" "float roughness" [0.2] "texture displacement" "wd"
MakeNamedMaterial "ab" "string type" "mix" "string materials" ["a" "b"] "texture amount" "amt"
MakeNamedMaterial "abc" "string type" "mix" "string materials" ["ab" "a"] "float amount" [0.3]
NamedMaterial "abc""#,
    );
}

#[test]
fn checkerboard_shows_both_colours() {
    let world = r#"Texture "r" "spectrum" "checkerboard" "float uscale" [2] "float vscale" [2] "rgb tex1" [0 0 0] "rgb tex2" [1 1 1]
Material "diffuse" "texture reflectance" "r""#;
    let img = render_str(&scene(world, 24), &ov(16));
    // Pixels 9 and 14 lie ±0.26 from the centre, one in each of the quad's
    // four cells; the cells alternate black and white (rendered ≈ 0 and ≈ 1
    // under the unit sky), so diagonal cells match and neighbours differ.
    let lum = |x: usize, y: usize| img.get(x, y).iter().sum::<f32>() / 3.0;
    let (a, b, c, d) = (lum(9, 9), lum(14, 9), lum(14, 14), lum(9, 14));
    let (dark, bright) = (a.min(b), a.max(b));
    assert!(dark < 0.05, "dark cell renders {dark}");
    assert!(bright > 0.8, "bright cell renders {bright}");
    assert!(
        (a - c).abs() < 0.3 && (b - d).abs() < 0.3,
        "diagonals {a} {c}, {b} {d}"
    );
}

#[test]
fn mix_material_averages_to_its_amount() {
    // Black (first) and white (second) Lambertian materials on a flat quad
    // that sees only the unit sky: a white hit renders 1, a black one 0, and
    // the second material is chosen with probability `amount` = 0.25.
    let world = r#"MakeNamedMaterial "black" "string type" "diffuse" "rgb reflectance" [0 0 0]
MakeNamedMaterial "white" "string type" "diffuse" "rgb reflectance" [1 1 1]
Material "mix" "string materials" ["black" "white"] "float amount" [0.25]"#;
    let img = render_str(&scene(world, 32), &ov(16));
    // The quad spans pixels ~6..26 at 45° fov from 3 units; stay inside it.
    assert_region(&img, (9, 23, 9, 23), 0.25, 3e-3, "mix of black and white");
}

/// Builds scene text and returns the error message.
fn build_error(text: &str) -> String {
    let desc = candela_scene::parse_str(text, Path::new("test.pbrt")).expect("scene parses");
    match build(&desc, &Overrides::default()) {
        Ok(_) => panic!("scene built but should not have:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// "test.pbrt:line:col" of the first occurrence of `needle` in `text`.
fn loc_of(text: &str, needle: &str) -> String {
    for (i, line) in text.lines().enumerate() {
        if let Some(c) = line.find(needle) {
            return format!("test.pbrt:{}:{}", i + 1, c + 1);
        }
    }
    panic!("{needle} not in the scene");
}

#[test]
fn unknown_texture_names_are_errors_at_the_parameter() {
    let text = scene(
        r#"Texture "a" "float" "scale" "texture tex" "nope"
Material "conductor" "texture roughness" "a""#,
        8,
    );
    let e = build_error(&text);
    let at = loc_of(&text, "\"texture tex\"");
    assert!(e.starts_with(&at), "{e} (expected at {at})");
    assert!(e.contains("unknown float texture \"nope\""), "{e}");
    // From a material, and with the wrong kind.
    let text = scene(
        r#"Texture "f" "float" "constant"
Material "diffuse" "texture reflectance" "f""#,
        8,
    );
    let e = build_error(&text);
    assert!(
        e.starts_with(&loc_of(&text, "\"texture reflectance\"")),
        "{e}"
    );
    assert!(e.contains("is a float texture"), "{e}");
}

#[test]
fn textures_may_only_use_earlier_textures() {
    let text = scene(
        r#"Texture "a" "float" "mix" "texture amount" "b"
Texture "b" "float" "constant"
Material "conductor" "texture roughness" "a""#,
        8,
    );
    let e = build_error(&text);
    assert!(e.starts_with(&loc_of(&text, "\"texture amount\"")), "{e}");
    assert!(e.contains("before its declaration"), "{e}");
}

#[test]
fn missing_image_files_are_reported_at_the_filename() {
    let text = scene(
        r#"Texture "img" "spectrum" "imagemap" "string filename" "wood.png"
Material "diffuse" "texture reflectance" "img""#,
        8,
    );
    let e = build_error(&text);
    assert!(e.starts_with(&loc_of(&text, "\"string filename\"")), "{e}");
    assert!(e.contains("wood.png\" not found"), "{e}");
    // Unreferenced, it is only a warning.
    let text = scene(
        r#"Texture "img" "spectrum" "imagemap" "string filename" "wood.png""#,
        8,
    );
    let desc = candela_scene::parse_str(&text, Path::new("test.pbrt")).expect("parses");
    let setup = build(&desc, &Overrides::default()).expect("builds");
    assert!(
        setup
            .warnings
            .iter()
            .any(|w| w.contains("\"img\" is not used")),
        "{:?}",
        setup.warnings
    );
}

#[test]
fn mix_material_cycles_and_unknown_names_are_errors() {
    let text = scene(
        r#"MakeNamedMaterial "a" "string type" "mix" "string materials" ["b" "b"]
MakeNamedMaterial "b" "string type" "mix" "string materials" ["a" "a"]
NamedMaterial "a""#,
        8,
    );
    assert!(build_error(&text).contains("cycle"));
    let text = scene(r#"Material "mix" "string materials" ["x" "y"]"#, 8);
    let e = build_error(&text);
    assert!(e.starts_with(&loc_of(&text, "\"string materials\"")), "{e}");
    assert!(e.contains("\"x\" is not defined"), "{e}");
}
