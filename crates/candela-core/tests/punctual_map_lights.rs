//! `LightSource "projection"` and `"goniometric"` end to end: images written
//! as EXR beside the scene at test time, rendered by the path tracer, the
//! light tracer and BDPT, and the build's errors and warnings.
//!
//! **Closed form.** A projector at the origin looking along +z with a
//! constant white image, `fov` 90° and intensity I lights a Lambertian plane
//! (ρ) at z = d inside the square |x|, |y| ≤ d: E = I·cos θ/r² = I·d/r³, so
//! L = ρ·I·d/(π·r³), and zero outside. The camera sits at the light with a
//! 120° field of view, so the view holds the lit square and dark margins.
//! Each pixel's expected value averages L over its footprint (16×16
//! points, a quadrature error below 10⁻⁴). Each integrator renders K = 4
//! seeds; per pixel their mean and the variance of that mean (from the
//! seeds' spread) are kept. Per region and channel the mean residual
//! (pixel − expected) must satisfy |r̄| ≤ 5σ + b, σ = √(Σ var)/n from the
//! per-pixel variances (not from the residuals' spread, which would absorb
//! a wrong pattern inside the region) and b = 2·10⁻³·mean expected for the
//! RGB ↔ spectrum round trip (as in `closed_forms.rs`); dark regions must
//! be exactly 0.
//!
//! **Agreement.** A goniometric light with a non-constant map over two
//! planes has no closed form: the path tracer, the light tracer and BDPT
//! render it K times and every 8×8 block must pass Welch's t-test at the
//! Šidák-corrected level (`common::stats`).

mod common;

use candela_core::build::{build, Overrides};
use candela_core::image::RgbImage;
use common::{render_at, stats};
use std::path::{Path, PathBuf};

fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-punctual-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes a w×h EXR from `f(u, v)` at texel centres.
fn write_image(path: &Path, w: usize, h: usize, f: impl Fn(f32, f32) -> [f32; 3]) {
    let mut im = RgbImage::new(w, h);
    for y in 0..h {
        for x in 0..w {
            im.pixels[y * w + x] = f((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
        }
    }
    im.write_exr(path).unwrap();
}

fn ov(spp: u32, seed: u64, integrator: &str) -> Overrides {
    Overrides {
        spp: Some(spp),
        seed: Some(seed),
        integrator: Some(integrator.into()),
        ..Default::default()
    }
}

/// Camera at the origin looking along +z (fov `cam_fov`), `light` at the
/// origin, a diffuse plane (ρ = 0.5) at z = 1, and an optional floor.
fn plane_scene(light: &str, cam_fov: f32, floor: bool) -> String {
    let floor = if floor {
        r#"Material "diffuse" "rgb reflectance" [0.7 0.6 0.5]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point3 P" [-3 -0.6 -1  3 -0.6 -1  3 -0.6 1  -3 -0.6 1]"#
    } else {
        ""
    };
    format!(
        r#"LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [{cam_fov}]
Film "rgb" "integer xresolution" [32] "integer yresolution" [32]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [5]
WorldBegin
AttributeBegin
{light}
AttributeEnd
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point3 P" [-4 -4 1  4 -4 1  4 4 1  -4 4 1]
{floor}
"#
    )
}

/// L = ρ·I·d/(π r³) (zero outside |x|, |y| ≤ d) averaged over pixel
/// (px, py)'s footprint; the camera's screen spans ±tan(cam_fov/2) on z = 1.
fn expected_pixel(px: usize, py: usize, cam_fov: f64, rho: f64, i: f64) -> f64 {
    let t = (cam_fov.to_radians() / 2.0).tan();
    let k = 16;
    let mut s = 0.0;
    for j in 0..k {
        for q in 0..k {
            let x = -t + 2.0 * t * (px as f64 + (q as f64 + 0.5) / k as f64) / 32.0;
            let y = -t + 2.0 * t * (py as f64 + (j as f64 + 0.5) / k as f64) / 32.0;
            if x.abs() <= 1.0 && y.abs() <= 1.0 {
                s += rho * i / (std::f64::consts::PI * (1.0 + x * x + y * y).powf(1.5));
            }
        }
    }
    s / (k * k) as f64
}

/// Per-pixel mean over `K_SEEDS` renders and the variance of that mean,
/// estimated from the renders' spread (so that structured errors inside a
/// region cannot hide in the noise estimate).
struct Estimate {
    mean: Vec<[f64; 3]>,
    var: Vec<[f64; 3]>,
}

/// Independent renders per integrator for [`Estimate`].
const K_SEEDS: u64 = 4;

fn estimate(scene: &str, dir: &Path, integrator: &str, spp: u32) -> Estimate {
    let imgs: Vec<RgbImage> = (0..K_SEEDS)
        .map(|k| render_at(scene, &dir.join("scene.pbrt"), &ov(spp, 3 + k, integrator)).0)
        .collect();
    let n = imgs[0].pixels.len();
    let k = K_SEEDS as f64;
    let mut mean = vec![[0.0; 3]; n];
    let mut var = vec![[0.0; 3]; n];
    for i in 0..n {
        for c in 0..3 {
            let v: Vec<f64> = imgs.iter().map(|im| im.pixels[i][c] as f64).collect();
            let (m, s2) = stats::mean_var(&v);
            mean[i][c] = m;
            var[i][c] = s2 / k;
        }
    }
    Estimate { mean, var }
}

/// Asserts region `r` = (x0, x1, y0, y1) matches the closed form: its mean
/// residual lies within 5σ + b (see the module doc).
fn assert_residuals(est: &Estimate, r: (usize, usize, usize, usize), what: &str) {
    let pixels: Vec<usize> = (r.2..r.3)
        .flat_map(|y| (r.0..r.1).map(move |x| y * 32 + x))
        .collect();
    let exp: Vec<f64> = pixels
        .iter()
        .map(|&i| expected_pixel(i % 32, i / 32, 120.0, 0.5, std::f64::consts::PI))
        .collect();
    let n = pixels.len() as f64;
    let mean_exp = exp.iter().sum::<f64>() / n;
    for c in 0..3 {
        let m = pixels
            .iter()
            .zip(&exp)
            .map(|(&i, e)| est.mean[i][c] - e)
            .sum::<f64>()
            / n;
        let se = pixels.iter().map(|&i| est.var[i][c]).sum::<f64>().sqrt() / n;
        eprintln!("{what} c{c}: residual {m:+.6} ± {se:.6} on {mean_exp:.5}");
        assert!(
            m.abs() <= 5.0 * se + 2e-3 * mean_exp,
            "{what} c{c}: residual {m} (σ {se}) on {mean_exp}"
        );
    }
}

#[test]
fn white_projector_on_a_plane_matches_the_closed_form_in_every_integrator() {
    // I = π (scale π on a white texel: one nit per unit RGB), so L = 0.5/r³.
    let dir = temp_dir("closed");
    write_image(&dir.join("white.exr"), 4, 4, |_, _| [1.0; 3]);
    let light = r#"LightSource "projection" "string filename" "white.exr" "float fov" [90] "float scale" [3.14159265]"#;
    let scene = plane_scene(light, 120.0, false);
    // The lit square spans pixels 6.76 … 25.24 (|screen| ≤ 1/tan 60°); a
    // texel of the 4×4 image covers ~4.6 pixels, so 4×4-pixel tiles resolve
    // errors in the light's distribution inside a texel.
    let mut regions = vec![
        ("lit square".to_string(), (7, 25, 7, 25)),
        ("dark corner".to_string(), (0, 6, 0, 6)),
        ("dark edge".to_string(), (26, 32, 12, 20)),
    ];
    for ty in (8..24).step_by(4) {
        for tx in (8..24).step_by(4) {
            regions.push((format!("tile {tx},{ty}"), (tx, tx + 4, ty, ty + 4)));
        }
    }
    for (integrator, spp) in [("path", 16), ("lightpath", 64), ("bdpt", 16)] {
        let est = estimate(&scene, &dir, integrator, spp);
        for (name, r) in &regions {
            assert_residuals(&est, *r, &format!("projector {integrator}, {name}"));
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Block means of K renders of `scene` by `integrator`, `[block][render]`.
fn block_means(scene: &str, dir: &Path, integrator: &str, spp: u32) -> Vec<Vec<f64>> {
    let renders: Vec<Vec<f64>> = (0..8)
        .map(|k| {
            let o = ov(spp, 200 + k, integrator);
            stats::block_means(&render_at(scene, &dir.join("scene.pbrt"), &o).0)
        })
        .collect();
    stats::by_block(&renders)
}

#[test]
fn goniometric_light_path_light_and_bidirectional_tracers_agree() {
    // A warm spot and a blue gradient over a dim map, turned so that the
    // map's centre (the user's +y before the turn) faces the plane; the
    // floor adds indirect light.
    let dir = temp_dir("gonio");
    write_image(&dir.join("gonio.exr"), 32, 32, |u, v| {
        let d2 = (u - 0.45).powi(2) + (v - 0.55).powi(2);
        let spot = 40.0 * (-d2 / 0.004).exp();
        [0.2 + spot, 0.1 + 0.5 * spot + u, 0.3 + v]
    });
    let light = r#"Translate 0.2 0.1 0.3
Rotate 70 1 0 0
LightSource "goniometric" "string filename" "gonio.exr" "rgb I" [2 2 2]"#;
    let scene = plane_scene(light, 90.0, true);
    let pt = block_means(&scene, &dir, "path", 64);
    let lt = block_means(&scene, &dir, "lightpath", 128);
    let bd = block_means(&scene, &dir, "bdpt", 32);
    stats::assert_blocks_agree(&pt, &lt, "goniometric PT vs LT");
    stats::assert_blocks_agree(&pt, &bd, "goniometric PT vs BDPT");
    let lit = pt.iter().filter(|b| stats::mean_var(b).0 > 1e-3).count();
    assert!(lit > 8, "only {lit} of 16 blocks lit");
    std::fs::remove_dir_all(&dir).ok();
}

/// The build error for `light` in a scene read from `dir`.
fn build_error(dir: &Path, light: &str) -> String {
    let text = plane_scene(light, 90.0, false);
    let desc = candela_scene::parse_str(&text, &dir.join("scene.pbrt")).expect("parses");
    match build(&desc, &Overrides::default()) {
        Ok(_) => panic!("built, but should not have: {light}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_images_and_parameters_are_errors_with_locations() {
    let dir = temp_dir("errors");
    write_image(&dir.join("wide.exr"), 4, 2, |_, _| [1.0; 3]);
    std::fs::write(dir.join("junk.exr"), b"not an image").unwrap();
    // The light is on line 9: errors point at the directive, or at the
    // offending parameter.
    let cases = [
        (
            r#"LightSource "projection" "float fov" [45]"#,
            "scene.pbrt:9:1",
            "must provide \"filename\"",
        ),
        (
            r#"LightSource "projection" "string filename" "nope.exr""#,
            "scene.pbrt:9:26",
            "not found",
        ),
        (
            r#"LightSource "projection" "string filename" "junk.exr""#,
            "scene.pbrt:9:26",
            "junk.exr",
        ),
        (
            r#"LightSource "projection" "string filename" "wide.exr" "float fov" [180]"#,
            "scene.pbrt:9:55",
            "(0, 180)",
        ),
        (
            r#"LightSource "goniometric" "string filename" "wide.exr""#,
            "scene.pbrt:9:27",
            "non-square",
        ),
        (
            r#"LightSource "goniometric" "string filename" "nope.exr""#,
            "scene.pbrt:9:27",
            "not found",
        ),
    ];
    for (light, loc, msg) in cases {
        let e = build_error(&dir, light);
        assert!(e.contains(loc) && e.contains(msg), "{light}: {e}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn goniometric_light_without_a_map_warns_and_is_isotropic() {
    // pbrt-v4 only warns; candela then emits like the point light of the
    // same I, so both render the same image (same seed, same paths).
    let dir = temp_dir("nomap");
    let o = ov(4, 5, "path");
    let (gonio, warnings) = render_at(
        &plane_scene(r#"LightSource "goniometric" "rgb I" [2 2 2]"#, 90.0, true),
        &dir.join("scene.pbrt"),
        &o,
    );
    assert!(
        warnings.iter().any(|w| w.contains("no \"filename\"")),
        "{warnings:?}"
    );
    let (point, _) = render_at(
        &plane_scene(r#"LightSource "point" "rgb I" [2 2 2]"#, 90.0, true),
        &dir.join("scene.pbrt"),
        &o,
    );
    for (a, b) in gonio.pixels.iter().zip(&point.pixels) {
        for c in 0..3 {
            assert!(
                (a[c] - b[c]).abs() <= 1e-5 * b[c].max(1e-3),
                "{a:?} vs {b:?}"
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
