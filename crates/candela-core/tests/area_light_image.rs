//! Diffuse area lights with an image (`filename`) and with `alpha`, end to
//! end (pbrt-v4 `DiffuseAreaLight`).
//!
//! - A two-sided quad emitter (uv = the unit square) fills an orthographic
//!   view: each pixel reads the image's RGB at (u, 1 − v), bilinear with
//!   edges clamped, so outside the ramp between texel centres a pixel is the
//!   texel itself and the middle columns (or rows) are the texels' mean.
//! - A checkerboard alpha (0/1) on an emitter: the camera sees black where
//!   α = 0, and a diffuse floor below receives the irradiance of the
//!   unmasked checks only, compared with a quadrature of
//!   E(x) = L∫ cos θ cos θ'/r² dA over them (half the unmasked emitter's in
//!   the far field). Constant α = 0 is pbrt-v4's invisible light: the
//!   camera sees through it, and the floor receives the unmasked irradiance
//!   in the path tracer and BDPT.
//! - Path tracer, light tracer and BDPT agree (per-block Welch tests, see
//!   `common/stats.rs`) on a scene lit only by an image emitter with an
//!   alpha checkerboard.
//! - Build errors name file:line:col.
//!
//! Tolerances: 5σ of the region mean (σ from the pixel spread, pixels being
//! independent estimates) plus b for the spectral round trip of RGB through
//! an illuminant spectrum and the 4-wavelength film: b = 0.01 as in
//! `image_textures.rs`, relative 2 % where a reflectance round trip is added.

mod common;

use candela_core::build::{build, Overrides};
use candela_core::image::RgbImage;
use common::{region_mean, render_at, stats};
use std::path::{Path, PathBuf};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-arealight-{name}-{}", std::process::id()));
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

fn write_png(dir: &Path, name: &str, w: u32, h: u32, texels: &[[u8; 3]]) {
    let raw: Vec<u8> = texels.iter().flatten().copied().collect();
    image::RgbImage::from_raw(w, h, raw)
        .unwrap()
        .save(dir.join(name))
        .unwrap();
}

fn ov(spp: u32, seed: u64, integrator: Option<&str>) -> Overrides {
    Overrides {
        spp: Some(spp),
        seed: Some(seed),
        integrator: integrator.map(Into::into),
        ..Default::default()
    }
}

/// An orthographic 16×16 view of the quad [−1, 1]² at z = 0 (uv = unit
/// square), which emits `light` (an `AreaLightSource` line) with `shape_extra`.
fn emitter_view(light: &str, shape_extra: &str, textures: &str) -> String {
    format!(
        r#"LookAt 0 0 -3  0 0 0  0 1 0
Camera "orthographic"
Film "rgb" "integer xresolution" [16] "integer yresolution" [16]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [1]
WorldBegin
{textures}
AttributeBegin
{light}
Shape "trianglemesh" "point3 P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0]
    "point2 uv" [0 0  1 0  1 1  0 1] "integer indices" [0 1 2  0 2 3] {shape_extra}
AttributeEnd
"#
    )
}

const A: [u8; 3] = [200, 60, 40];
const B: [u8; 3] = [40, 190, 70];

/// Asserts the region's channels equal `want` (linear) within 5σ + 0.01.
fn assert_rgb(img: &RgbImage, r: (usize, usize, usize, usize), want: [f64; 3], what: &str) {
    for (c, w) in want.into_iter().enumerate() {
        let (m, se) = region_mean(img, c, r.0, r.1, r.2, r.3);
        eprintln!("{what} c{c}: {m:.4} ± {se:.4}, want {w:.4}");
        assert!((m - w).abs() <= 5.0 * se + 0.01, "{what} c{c}: {m} vs {w}");
    }
}

#[test]
fn image_emitter_shows_its_texels_upright() {
    let dir = temp_dir("upright");
    write_png(&dir, "h.png", 2, 1, &[A, B]);
    write_png(&dir, "v.png", 1, 2, &[A, B]);
    let light = |f: &str| {
        format!(r#"AreaLightSource "diffuse" "string filename" "{f}" "bool twosided" true"#)
    };
    let (a, b) = (A.map(srgb), B.map(srgb));
    let mid = [0, 1, 2].map(|c| 0.5 * (a[c] + b[c]));
    // 2×1: texel 0 for u < 1/4 (left columns 0–3), texel 1 for u > 3/4.
    let text = emitter_view(&light("h.png"), "", "");
    let (img, _) = render_at(&text, &dir.join("h.pbrt"), &ov(16, 3, None));
    assert_rgb(&img, (0, 4, 0, 16), a, "2×1 left");
    assert_rgb(&img, (12, 16, 0, 16), b, "2×1 right");
    assert_rgb(&img, (7, 9, 0, 16), mid, "2×1 middle");
    // 1×2: row 0 at v = 1, the top of the view.
    let text = emitter_view(&light("v.png"), "", "");
    let (img, _) = render_at(&text, &dir.join("v.pbrt"), &ov(16, 3, None));
    assert_rgb(&img, (0, 16, 0, 4), a, "1×2 top");
    assert_rgb(&img, (0, 16, 12, 16), b, "1×2 bottom");
    assert_rgb(&img, (0, 16, 7, 9), mid, "1×2 middle");
    std::fs::remove_dir_all(&dir).ok();
}

const CHECKER: &str = r#"Texture "checks" "float" "checkerboard" "float uscale" [2] "float vscale" [2]
    "float tex1" [1] "float tex2" [0]"#;

#[test]
fn alpha_checkerboard_cuts_the_emitter_seen_by_the_camera() {
    let text = emitter_view(
        r#"AreaLightSource "diffuse" "rgb L" [1 1 1] "bool twosided" true"#,
        r#""texture alpha" "checks""#,
        CHECKER,
    );
    let (img, _) = render_at(&text, Path::new("a.pbrt"), &ov(16, 5, None));
    // α = 1 where ⌊2u⌋ + ⌊2v⌋ is even: bottom-left and top-right quadrants.
    assert_rgb(&img, (1, 7, 9, 15), [1.0; 3], "bottom-left");
    assert_rgb(&img, (9, 15, 1, 7), [1.0; 3], "top-right");
    for r in [(0, 8, 0, 8), (8, 16, 8, 16)] {
        for c in 0..3 {
            assert_eq!(region_mean(&img, c, r.0, r.1, r.2, r.3).0, 0.0, "{r:?}");
        }
    }
}

/// The floor scene: a unit-square emitter (uv = unit square, `L` = 1,
/// two-sided) at height H above a diffuse floor (ρ = 0.5), viewed from
/// above by an orthographic camera over [−4, 4]², 16×16 pixels, direct
/// lighting only.
const H: f64 = 2.0;
fn floor_scene(shape_extra: &str) -> String {
    format!(
        r#"LookAt 0 0 10  0 0 0  0 1 0
Camera "orthographic" "float screenwindow" [-4 4 -4 4]
Film "rgb" "integer xresolution" [16] "integer yresolution" [16]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [1]
WorldBegin
Texture "checks" "float" "checkerboard" "float uscale" [8] "float vscale" [8]
    "float tex1" [1] "float tex2" [0]
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "point3 P" [-4 -4 0  4 -4 0  4 4 0  -4 4 0] "integer indices" [0 1 2  0 2 3]
AttributeBegin
AreaLightSource "diffuse" "rgb L" [1 1 1] "bool twosided" true
Shape "trianglemesh" "point3 P" [-0.5 -0.5 {H}  0.5 -0.5 {H}  0.5 0.5 {H}  -0.5 0.5 {H}]
    "point2 uv" [0 0  1 0  1 1  0 1] "integer indices" [0 1 2  0 2 3] {shape_extra}
AttributeEnd
"#
    )
}

/// Expected floor radiance ρ/π·E(x, y) for emitter checks `lit(i, j)` of an
/// 8×8 checkerboard on the unit-square emitter, by a 6×6 midpoint rule per
/// check (the integrand varies by < 1 % across a check at r ≥ 2).
fn floor_radiance(x: f64, y: f64, lit: impl Fn(usize, usize) -> bool) -> f64 {
    let (n, m) = (8, 6);
    let d = 1.0 / (n * m) as f64;
    let mut e = 0.0;
    for j in 0..n * m {
        for i in 0..n * m {
            if !lit(i / m, j / m) {
                continue;
            }
            let (px, py) = (-0.5 + (i as f64 + 0.5) * d, -0.5 + (j as f64 + 0.5) * d);
            let r2 = (px - x).powi(2) + (py - y).powi(2) + H * H;
            e += H * H / (r2 * r2) * d * d; // cos θ·cos θ' / r² with both cosines H/r
        }
    }
    0.5 / std::f64::consts::PI * e
}

/// Pixels outside the central 6×6 (which may see the emitter's top).
fn floor_pixels() -> Vec<(usize, usize)> {
    (0..16)
        .flat_map(|y| (0..16).map(move |x| (x, y)))
        .filter(|&(x, y)| !((5..11).contains(&x) && (5..11).contains(&y)))
        .collect()
}

/// Mean residual of the image against `want(pixel)` (green channel) and its
/// standard error; pixel (x, y) covers [−4 + x/2, −3.5 + x/2] × (y flipped).
fn residual(img: &RgbImage, want: &dyn Fn(f64, f64) -> f64) -> (f64, f64, f64) {
    let px = floor_pixels();
    let mut res = Vec::new();
    let mut expected = 0.0;
    for &(x, y) in &px {
        // Expected pixel mean: 3×3 points over the pixel's footprint.
        let mut w = 0.0;
        for k in 0..9 {
            let fx = -4.0 + 0.5 * (x as f64 + ((k % 3) as f64 + 0.5) / 3.0);
            let fy = 4.0 - 0.5 * (y as f64 + ((k / 3) as f64 + 0.5) / 3.0);
            w += want(fx, fy) / 9.0;
        }
        expected += w;
        res.push(img.get(x, y)[1] as f64 - w);
    }
    let (m, var) = stats::mean_var(&res);
    let n = res.len() as f64;
    (m, (var / n).sqrt(), expected / n)
}

#[test]
fn alpha_checkerboard_emitter_lights_the_floor_with_its_unmasked_half() {
    let all = |x: f64, y: f64| floor_radiance(x, y, |_, _| true);
    // Checkerboard: α = 1 where i + j is even.
    let half = |x: f64, y: f64| floor_radiance(x, y, |i, j| (i + j) % 2 == 0);
    let far = half(4.0, 4.0) / all(4.0, 4.0);
    eprintln!("far-field ratio {far:.4}");
    assert!((far - 0.5).abs() < 0.01);
    for (extra, want, what) in [
        ("", &all as &dyn Fn(f64, f64) -> f64, "unmasked"),
        (r#""texture alpha" "checks""#, &half, "checkerboard"),
    ] {
        for integrator in ["path", "bdpt"] {
            let (img, _) = render_at(
                &floor_scene(extra),
                Path::new("f.pbrt"),
                &ov(64, 11, Some(integrator)),
            );
            let (m, se, e) = residual(&img, want);
            eprintln!("{what} {integrator}: residual {m:e} ± {se:e} of mean {e:.5}");
            assert!(
                m.abs() <= 5.0 * se + 0.02 * e,
                "{what} {integrator}: {m} (σ {se}, mean {e})"
            );
        }
    }
    // Constant α = 0: pbrt-v4's invisible light. It still lights the floor
    // fully, through light sampling (PT, BDPT's s = 1) and emission
    // sampling (BDPT's s ≥ 2; the orthographic pinhole has no importance for
    // the light tracer), and is never seen: the central pixels, which would
    // read L = 1 on the emitter, see the floor below it.
    for integrator in ["path", "bdpt"] {
        let (img, _) = render_at(
            &floor_scene(r#""float alpha" [0]"#),
            Path::new("f.pbrt"),
            &ov(64, 11, Some(integrator)),
        );
        let (m, se, e) = residual(&img, &all);
        eprintln!("invisible {integrator}: residual {m:e} ± {se:e} of mean {e:.5}");
        assert!(
            m.abs() <= 5.0 * se + 0.02 * e,
            "invisible {integrator}: {m} (σ {se}, mean {e})"
        );
        let centre = (5..11).flat_map(|y| (5..11).map(move |x| (x, y)));
        let brightest = centre.map(|(x, y)| img.get(x, y)[1]).fold(0.0f32, f32::max);
        assert!(
            brightest < 0.1,
            "invisible {integrator}: emitter seen ({brightest})"
        );
    }
}

/// Image emitter (2×2 texels) with an alpha checkerboard, tilted above a
/// diffuse floor and seen from below its height: only it lights the scene.
fn agreement_scene() -> String {
    r#"LookAt 0 -3.5 0.8  0 0 0.6  0 0 1
Camera "perspective" "float fov" [60]
Film "rgb" "integer xresolution" [32] "integer yresolution" [32]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [5]
WorldBegin
Texture "checks" "float" "checkerboard" "float uscale" [3] "float vscale" [3]
    "float tex1" [1] "float tex2" [0]
Material "diffuse" "rgb reflectance" [0.6 0.6 0.6]
Shape "trianglemesh" "point3 P" [-3 -3 0  3 -3 0  3 3 0  -3 3 0] "integer indices" [0 1 2  0 2 3]
AttributeBegin
Translate 0 0 1.5
Rotate 20 1 0 0
Scale 0.8 0.8 0.8
AreaLightSource "diffuse" "string filename" "e.png" "float scale" [3]
Shape "trianglemesh" "point3 P" [-1 -1 0  -1 1 0  1 1 0  1 -1 0]
    "point2 uv" [0 0  0 1  1 1  1 0] "integer indices" [0 1 2  0 2 3] "texture alpha" "checks"
AttributeEnd
"#
    .to_string()
}

fn block_means(dir: &Path, integrator: &str, spp: u32) -> Vec<Vec<f64>> {
    let renders: Vec<Vec<f64>> = (0..8)
        .map(|k| {
            let (img, _) = render_at(
                &agreement_scene(),
                &dir.join("s.pbrt"),
                &ov(spp, 200 + k, Some(integrator)),
            );
            stats::block_means(&img)
        })
        .collect();
    stats::by_block(&renders)
}

#[test]
fn path_light_and_bidirectional_tracers_agree_on_an_image_emitter_with_alpha() {
    let dir = temp_dir("agree");
    write_png(&dir, "e.png", 2, 2, &[A, B, [50, 60, 210], [230, 230, 230]]);
    let pt = block_means(&dir, "path", 16);
    let lt = block_means(&dir, "lightpath", 16);
    let bd = block_means(&dir, "bdpt", 8);
    let lit = pt.iter().filter(|b| b.iter().sum::<f64>() > 0.0).count();
    assert!(lit >= 12, "only {lit} of 16 blocks are lit");
    stats::assert_blocks_agree(&pt, &lt, "PT vs LT");
    stats::assert_blocks_agree(&pt, &bd, "PT vs BDPT");
    stats::assert_blocks_agree(&lt, &bd, "LT vs BDPT");
    std::fs::remove_dir_all(&dir).ok();
}

/// The build error of `text` (as if read from `dir/e.pbrt`).
fn build_error(dir: &Path, text: &str) -> String {
    let desc = candela_scene::parse_str(text, &dir.join("e.pbrt")).expect("parses");
    match build(&desc, &Overrides::default()) {
        Ok(_) => panic!("scene built"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn l_with_filename_and_missing_images_are_errors_at_their_directive() {
    let dir = temp_dir("errors");
    write_png(&dir, "ok.png", 1, 1, &[A]);
    let both = emitter_view(
        r#"AreaLightSource "diffuse" "rgb L" [1 1 1] "string filename" "ok.png""#,
        "",
        "",
    );
    let e = build_error(&dir, &both);
    assert!(
        e.contains("e.pbrt:10:1") && e.contains("\"L\" and \"filename\""),
        "{e}"
    );
    let missing = emitter_view(
        r#"AreaLightSource "diffuse"   "string filename" "nope.png""#,
        "",
        "",
    );
    let e = build_error(&dir, &missing);
    assert!(e.contains("e.pbrt:10:29") && e.contains("not found"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

/// An invisible (α = 0) emitter close above a floor lights it exactly like
/// the same emitter made visible: a 3×3 two-sided quad 0.25 above the
/// floor, where BSDF sampling would find the visible emitter often, so the
/// path tracer must give light sampling the whole MIS weight when the
/// emitter cannot be hit (with the visible emitter's weights it loses the
/// BSDF share). Compared over the floor pixels outside the emitter's
/// footprint (the visible emitter covers the rest), 8 seeds × 256 spp each, Welch's
/// t-test at α = 0.001.
#[test]
fn an_invisible_emitter_lights_like_a_visible_one() {
    let scene = |extra: &str| {
        format!(
            r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "orthographic" "float screenwindow" [-4 4 -4 4]
Film "rgb" "integer xresolution" [16] "integer yresolution" [16]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [1]
WorldBegin
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "point3 P" [-4 -4 0  4 -4 0  4 4 0  -4 4 0] "integer indices" [0 1 2  0 2 3]
AttributeBegin
AreaLightSource "diffuse" "rgb L" [1 1 1] "bool twosided" true
Shape "trianglemesh" "point3 P" [-1.5 -1.5 0.25  1.5 -1.5 0.25  1.5 1.5 0.25  -1.5 1.5 0.25]
    "integer indices" [0 1 2  0 2 3] {extra}
AttributeEnd
"#
        )
    };
    // Pixels whose footprint lies outside |x|, |y| < 1.5 (pixel = 0.5 wide).
    let ring = |img: &RgbImage| {
        let px: Vec<f64> = (0..16)
            .flat_map(|y| (0..16).map(move |x| (x, y)))
            .filter(|&(x, y)| !((5..11).contains(&x) && (5..11).contains(&y)))
            .map(|(x, y)| img.get(x, y)[1] as f64)
            .collect();
        px.iter().sum::<f64>() / px.len() as f64
    };
    let means = |extra: &str| -> Vec<f64> {
        (0..8)
            .map(|k| {
                let (img, _) =
                    render_at(&scene(extra), Path::new("i.pbrt"), &ov(256, 40 + k, None));
                ring(&img)
            })
            .collect()
    };
    let visible = means("");
    let invisible = means(r#""float alpha" [0]"#);
    let (t, df, p) = stats::welch(&visible, &invisible);
    let (mv, mi) = (stats::mean_var(&visible).0, stats::mean_var(&invisible).0);
    eprintln!("visible {mv:.5}, invisible {mi:.5}: t = {t:.2}, df = {df:.1}, p = {p:.3e}");
    assert!(p > 1e-3, "visible {mv} vs invisible {mi}: t = {t}, p = {p}");
}
