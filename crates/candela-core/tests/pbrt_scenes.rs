//! Real pbrt-v4 scenes bundled in `scenes/` against pbrt-v4's own renders
//! beside them (issues #3 and #4):
//! - killeroo-simple (loopsubdiv, coateddiffuse, sphere area light), path
//!   tracer: image mean within 3 %.
//! - caustic-glass (spot light, uniform sky, dielectric and coateddiffuse
//!   PLY meshes; the reference is pbrt-v4's BDPT): the path tracer within
//!   3 % in two regions it converges (the lit back floor and the spot's
//!   pool; it cannot render the caustic), BDPT within 2 % over the whole
//!   image and within 5 % in the caustic below the glass; SPPM, PPM and
//!   the photon map within 5 % in the caustic (rendered through a crop
//!   window over it), and VCM there too.
//!
//! Each bound is the stated relative tolerance plus 5σ of the rendered
//! mean. Every scene is rendered twice with different seeds; the estimate
//! is the average of the two and its noise variance per pixel is
//! (a − b)²/4, so σ² of the region mean is Σ(a − b)²/(4n²): noise only,
//! without the image's own spatial variation.

mod common;

use candela_core::build::Overrides;
use candela_core::image::RgbImage;
use common::render_at;
use std::path::{Path, PathBuf};

fn scene_dir(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(name)
}

fn render(file: &Path, integrator: &str, spp: u32, seed: u64) -> RgbImage {
    let text = std::fs::read_to_string(file).expect("scene file");
    let ov = Overrides {
        spp: Some(spp),
        seed: Some(seed),
        integrator: Some(integrator.into()),
        ..Default::default()
    };
    render_at(&text, file, &ov).0
}

/// Two renders with independent seeds.
struct Pair(RgbImage, RgbImage);

fn render_pair(file: &Path, integrator: &str, spp: u32) -> Pair {
    Pair(
        render(file, integrator, spp, 17),
        render(file, integrator, spp, 18),
    )
}

fn pixels(r: [usize; 4]) -> impl Iterator<Item = (usize, usize)> {
    (r[1]..r[3]).flat_map(move |y| (r[0]..r[2]).map(move |x| (x, y)))
}

fn luma(img: &RgbImage, x: usize, y: usize) -> f64 {
    img.get(x, y).iter().map(|&c| c as f64).sum()
}

/// Mean of the channel sum of the pair's average over a region, and its noise σ.
fn region_stats(p: &Pair, r: [usize; 4]) -> (f64, f64) {
    let n = pixels(r).count() as f64;
    let (mut sum, mut d2) = (0.0, 0.0);
    for (x, y) in pixels(r) {
        let (a, b) = (luma(&p.0, x, y), luma(&p.1, x, y));
        sum += 0.5 * (a + b);
        d2 += (a - b) * (a - b) / 4.0;
    }
    (sum / n, d2.sqrt() / n)
}

fn assert_close(img: &Pair, reference: &RgbImage, r: [usize; 4], tol: f64, what: &str) {
    let (m, se) = region_stats(img, r);
    let mr = pixels(r).map(|(x, y)| luma(reference, x, y)).sum::<f64>() / pixels(r).count() as f64;
    eprintln!(
        "{what}: {m:.5} ± {se:.5} vs pbrt-v4 {mr:.5} (ratio {:.4})",
        m / mr
    );
    assert!(
        (m - mr).abs() <= tol * mr + 5.0 * se,
        "{what}: {m} ± {se} vs {mr}"
    );
}

#[test]
fn killeroo_simple_path_tracer_matches_pbrt_v4() {
    let dir = scene_dir("killeroo-simple");
    let img = render_pair(&dir.join("killeroo-simple.pbrt"), "path", 4);
    let reference = RgbImage::read_exr(&dir.join("reference-pbrt-v4-256spp.exr")).expect("ref");
    assert_close(&img, &reference, [0, 0, 700, 700], 0.03, "killeroo image");
}

#[test]
fn caustic_glass_path_tracer_matches_pbrt_v4_away_from_the_caustic() {
    let dir = scene_dir("caustic-glass");
    let img = render_pair(&dir.join("scene.pbrt"), "path", 8);
    let reference =
        RgbImage::read_exr(&dir.join("reference-pbrt-v4-bdpt-1024spp.exr")).expect("ref");
    assert_close(
        &img,
        &reference,
        [0, 0, 350, 150],
        0.03,
        "back floor and glass top",
    );
    assert_close(
        &img,
        &reference,
        [250, 100, 350, 200],
        0.03,
        "spot light pool",
    );
}

#[test]
fn caustic_glass_bdpt_matches_pbrt_v4_bdpt() {
    let dir = scene_dir("caustic-glass");
    let img = render_pair(&dir.join("scene.pbrt"), "bdpt", 8);
    let reference =
        RgbImage::read_exr(&dir.join("reference-pbrt-v4-bdpt-1024spp.exr")).expect("ref");
    assert_close(&img, &reference, [0, 0, 350, 500], 0.02, "whole image");
    assert_close(&img, &reference, [120, 200, 260, 330], 0.05, "caustic");
}

/// Mean luma of the caustic region [120, 260) × [200, 330) rendered through
/// a crop window by a photon integrator, over `seeds` seeds; returns the mean
/// and its standard error from the spread over seeds (the pixels of one
/// render share its photons and wavelengths, so they are not independent).
fn caustic_region(integrator: &str, params: &str, seeds: u64, spp: u32) -> (f64, f64) {
    let dir = scene_dir("caustic-glass");
    let text = std::fs::read_to_string(dir.join("scene.pbrt")).expect("scene");
    let text = text
        .replace(
            "Integrator \"bdpt\"",
            &format!("Integrator \"{integrator}\" {params}"),
        )
        .replace(
            "Film \"rgb\"",
            "Film \"rgb\" \"float cropwindow\" [0.342857 0.742857 0.4 0.66]",
        );
    assert!(text.contains(integrator) && text.contains("cropwindow"));
    let means: Vec<f64> = (0..seeds)
        .map(|seed| {
            let ov = Overrides {
                spp: Some(spp),
                seed: Some(seed),
                ..Default::default()
            };
            let img = render_at(&text, &dir.join("scene.pbrt"), &ov).0;
            assert_eq!((img.width, img.height), (140, 130), "crop window");
            let full = [0, 0, img.width, img.height];
            pixels(full).map(|(x, y)| luma(&img, x, y)).sum::<f64>() / (140.0 * 130.0)
        })
        .collect();
    let n = seeds as f64;
    let m = means.iter().sum::<f64>() / n;
    let se = (means.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
    (m, se)
}

fn assert_caustic(integrator: &str, (m, se): (f64, f64)) {
    let dir = scene_dir("caustic-glass");
    let reference =
        RgbImage::read_exr(&dir.join("reference-pbrt-v4-bdpt-1024spp.exr")).expect("ref");
    let region = [120, 200, 260, 330];
    let mr = pixels(region)
        .map(|(x, y)| luma(&reference, x, y))
        .sum::<f64>()
        / pixels(region).count() as f64;
    eprintln!(
        "{integrator} caustic: {m:.5} ± {se:.5} vs pbrt-v4 {mr:.5} (ratio {:.4})",
        m / mr
    );
    assert!(
        (m - mr).abs() <= 0.05 * mr + 5.0 * se,
        "{integrator}: {m} ± {se} vs {mr}"
    );
}

#[test]
fn caustic_glass_photon_integrators_match_pbrt_v4_in_the_caustic() {
    // SPPM and PPM: four seeds of 8 iterations × 200 000 photons; the photon
    // map: four seeds of 16 passes (global 50 000, caustic 150 000 photons).
    let sppm = "\"float radius\" [0.03] \"integer photonsperiteration\" [200000]";
    assert_caustic("sppm", caustic_region("sppm", sppm, 4, 8));
    assert_caustic("ppm", caustic_region("ppm", sppm, 4, 8));
    let pm = "\"integer photons\" [50000] \"integer causticphotons\" [150000]";
    assert_caustic("photonmap", caustic_region("photonmap", pm, 4, 16));
}

#[test]
fn caustic_glass_vcm_matches_pbrt_v4_bdpt_in_the_caustic() {
    // VCM (issue 12): three seeds of 6 iterations, one light path per pixel
    // of the crop and the photon integrators' initial radius. The caustic
    // lands on the coated floor, which candela shades by the layered random
    // walk; pbrt-v4's BDPT reference evaluates its stochastic layered f(),
    // ~7.5 % brighter, hence the 5 % band shared with the estimators above.
    assert_caustic(
        "vcm",
        caustic_region("vcm", "\"float radius\" [0.03]", 3, 6),
    );
}
