//! `imagemap` textures end to end: PNG files written at test time, resolved
//! relative to the scene file, on a diffuse quad that fills an orthographic
//! view under a uniform white sky. With nothing else in the scene, a diffuse
//! surface under a uniform sky of radiance 1 reflects exactly its albedo
//! (validation.md T4(d)), so each pixel reads the texel's RGB (direct
//! lighting only: `maxdepth` 1). Tolerance: 5σ of the region mean plus
//! b = 0.01 for the spectral round trip of the RGB (table fit, 4-wavelength
//! film).

mod common;

use candela_core::build::Overrides;
use common::{assert_region, render_at};
use std::path::{Path, PathBuf};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-imgtex-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Linear value of an 8-bit sRGB code.
fn srgb(b: u8) -> f64 {
    let v = b as f64 / 255.0;
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

fn quad_scene(world: &str) -> String {
    format!(
        r#"LookAt 0 0 -3  0 0 0  0 1 0
Camera "orthographic"
Film "rgb" "integer xresolution" [16] "integer yresolution" [16]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [1]
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
{world}
Shape "trianglemesh" "point3 P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]
    "point2 uv" [0 0  1 0  1 1  0 1] "integer indices" [0 1 2  0 2 3]
"#
    )
}

fn render(dir: &Path, world: &str, spp: u32) -> (candela_core::image::RgbImage, Vec<String>) {
    let ov = Overrides {
        spp: Some(spp),
        seed: Some(7),
        ..Default::default()
    };
    render_at(&quad_scene(world), &dir.join("scene.pbrt"), &ov)
}

/// The inner 6×6 pixels of each 8×8 quadrant: top-left, top-right, bottom-left, bottom-right.
const QUADRANTS: [(usize, usize, usize, usize); 4] =
    [(1, 7, 1, 7), (9, 15, 1, 7), (1, 7, 9, 15), (9, 15, 9, 15)];

#[test]
fn rgb_image_appears_upright_with_its_texel_colours() {
    let dir = temp_dir("rgb");
    let texels: [[u8; 3]; 4] = [[200, 60, 40], [40, 190, 70], [50, 60, 210], [128, 128, 128]];
    let raw: Vec<u8> = texels.iter().flatten().copied().collect();
    image::RgbImage::from_raw(2, 2, raw)
        .unwrap()
        .save(dir.join("tex.png"))
        .unwrap();
    let (img, _) = render(
        &dir,
        r#"Texture "t" "spectrum" "imagemap" "string filename" "tex.png" "string filter" "point"
Material "diffuse" "texture reflectance" "t""#,
        64,
    );
    for (q, t) in QUADRANTS.iter().zip(texels) {
        for (c, &code) in t.iter().enumerate() {
            let (m, se) = common::region_mean(&img, c, q.0, q.1, q.2, q.3);
            let want = srgb(code);
            eprintln!("quadrant {q:?} channel {c}: {m:.4} ± {se:.4}, texel {want:.4}");
            assert!(
                (m - want).abs() <= 5.0 * se + 0.01,
                "{q:?} c{c}: {m} vs {want}"
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn float_image_scales_inverts_and_reads_the_first_channel() {
    let dir = temp_dir("float");
    // Red channel 0 on the left column, 204 on the right; green and blue are ignored.
    let raw = vec![0, 255, 255, 204, 0, 0, 0, 255, 255, 204, 0, 0];
    image::RgbImage::from_raw(2, 2, raw)
        .unwrap()
        .save(dir.join("f.png"))
        .unwrap();
    let (img, warnings) = render(
        &dir,
        r#"Texture "f" "float" "imagemap" "string filename" "f.png" "string filter" "ewa"
    "string encoding" "linear" "float scale" [0.5] "bool invert" true "string wrap" "clamp"
Texture "r" "spectrum" "scale" "rgb tex" [1 1 1] "texture scale" "f"
Material "diffuse" "texture reflectance" "r""#,
        64,
    );
    // 1 − 0.5·v: 1 on the left, 1 − 0.5·0.8 = 0.6 on the right, outside the
    // bilinear ramp between the texel centres s = 1/4 and s = 3/4.
    assert_region(&img, (0, 4, 0, 16), 1.0, 0.01, "left");
    assert_region(&img, (12, 16, 0, 16), 0.6, 0.01, "right");
    let (mid, _) = common::region_mean(&img, 1, 7, 9, 0, 16);
    assert!((mid - 0.8).abs() < 0.05, "ramp midpoint {mid}");
    // EWA is implemented now: no substitution warning.
    assert!(
        !warnings.iter().any(|w| w.contains("\"ewa\"")),
        "{warnings:?}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn non_power_of_two_images_and_unbounded_spectra_render() {
    let dir = temp_dir("npot");
    image::RgbImage::from_pixel(3, 5, image::Rgb([90, 150, 210]))
        .save(dir.join("c.png"))
        .unwrap();
    let (img, _) = render(
        &dir,
        r#"Texture "c" "spectrum" "imagemap" "string filename" "c.png"
Material "diffuse" "texture reflectance" "c""#,
        32,
    );
    for (c, b) in [90u8, 150, 210].into_iter().enumerate() {
        let (m, se) = common::region_mean(&img, c, 1, 15, 1, 15);
        assert!(
            (m - srgb(b)).abs() <= 5.0 * se + 0.01,
            "c{c}: {m} vs {}",
            srgb(b)
        );
    }
    // The same file as η and k of a conductor (unbounded RGB): finite.
    let (img, _) = render(
        &dir,
        r#"Texture "c" "spectrum" "imagemap" "string filename" "c.png" "float scale" [3]
Material "conductor" "texture eta" "c" "texture k" "c" "float roughness" [0.3]"#,
        4,
    );
    assert!(img.pixels.iter().flatten().all(|v| v.is_finite()));
    std::fs::remove_dir_all(&dir).ok();
}

/// A 64×64 checkerboard of texels 0 and 1 repeated 8 times over the quad:
/// 512 texels across 16 pixels, 32 per pixel. With 16 spp the orthographic
/// footprint is ∂s/∂x = 8 · (2/16)/2 · ¼ = 1/8, so every filter reads levels
/// ≥ 4 as pbrt-v4's `MIPMap::Filter` picks them (`point` and `bilinear` at
/// ⌊ℓ⌋, `trilinear` between ⌊ℓ⌋ and ⌊ℓ⌋ + 1, `ewa` by its minor axis), where
/// every texel is the mean 0.5: each pixel is 0.5 up to the light transport
/// noise. A filter reading level 0 instead aliases: the per-lookup variance
/// of a bilinear checkerboard (1/18) adds ≈ 0.0035 to each pixel's variance
/// over 16 samples, on top of the transport noise all filters share
/// (measured with level-0 bilinear: pixel variance 0.0029 against 0.00094
/// for trilinear). Over 256 pixels a variance is known to ±9% (√(2/255)), so
/// without aliasing a ratio of variances is 1 ± 0.13; staying below 1.8 is a
/// 6σ margin, and level-0 lookups (ratio ≈ 3) fail it.
/// The mean and standard deviation over the pixels of `world` rendered
/// over the 64×64 checkerboard of [`minified_checkerboard_is_averaged_by_every_filter`].
fn checkerboard_spread(dir: &Path, world: &str) -> (f64, f64) {
    let n = 64u32;
    let img = image::GrayImage::from_fn(n, n, |x, y| {
        image::Luma([if (x + y) % 2 == 0 { 255 } else { 0 }])
    });
    img.save(dir.join("checks.png")).unwrap();
    let (img, warnings) = render(dir, world, 16);
    assert!(warnings.is_empty(), "{warnings:?}");
    let v: Vec<f64> = img.pixels.iter().map(|p| p[1] as f64).collect();
    assert!(v.iter().all(|x| x.is_finite()));
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64).sqrt();
    (mean, sd)
}

/// The checkerboard texture with MIP filter `filter`.
fn checks(filter: &str) -> String {
    format!(
        r#"Texture "c" "spectrum" "imagemap" "string filename" "checks.png" "string filter" "{filter}"
    "string encoding" "linear" "float uscale" [8] "float vscale" [8]
"#
    )
}

#[test]
fn minified_checkerboard_is_averaged_by_every_filter() {
    let dir = temp_dir("mip");
    let spread = |filter: &str| {
        let world = checks(filter) + r#"Material "diffuse" "texture reflectance" "c""#;
        checkerboard_spread(&dir, &world)
    };
    let (_, tri_sd) = spread("trilinear");
    for filter in ["trilinear", "ewa", "bilinear", "point"] {
        let (m, sd) = spread(filter);
        eprintln!("{filter}: {m} ± {sd}");
        // Mean 0.5 within b = 0.01 for the spectral round trip plus 5σ of
        // the mean of 256 pixels.
        assert!(
            (m - 0.5).abs() < 0.01 + 5.0 * sd / 16.0,
            "{filter} mean {m}"
        );
        let ratio = (sd / tri_sd).powi(2);
        assert!(
            ratio < 1.8,
            "{filter} aliases: variance ratio {ratio} ({sd} vs trilinear {tri_sd})"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A mix material whose own parameters name no texture (a constant amount
/// of 0 picks its first material) gives its hits the footprint that its
/// textured material filters with: the checkerboard seen through the mix
/// is as smooth as seen directly (the variance ratio bound of
/// [`minified_checkerboard_is_averaged_by_every_filter`]; without the
/// footprint the lookups read level 0 and alias, ratio ≈ 3).
#[test]
fn a_mix_passes_the_footprint_to_its_textured_material() {
    let dir = temp_dir("mipmix");
    let direct = checks("trilinear") + r#"Material "diffuse" "texture reflectance" "c""#;
    let mixed = checks("trilinear")
        + r#"MakeNamedMaterial "textured" "string type" "diffuse" "texture reflectance" "c"
MakeNamedMaterial "plain" "string type" "diffuse" "rgb reflectance" [0.5 0.5 0.5]
MakeNamedMaterial "both" "string type" "mix" "string materials" ["textured" "plain"] "float amount" [0]
NamedMaterial "both""#;
    let (_, direct_sd) = checkerboard_spread(&dir, &direct);
    let (_, mixed_sd) = checkerboard_spread(&dir, &mixed);
    let ratio = (mixed_sd / direct_sd).powi(2);
    assert!(ratio < 1.8, "the mix aliases: variance ratio {ratio}");
    std::fs::remove_dir_all(&dir).ok();
}
