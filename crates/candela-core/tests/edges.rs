//! Photon density estimation at edges and corners (issue 16), through the
//! gather rule `sppm`, `ppm`, `photonmap` and `vcm` share
//! (`integrator::gather`).
//!
//! - validation.md's T5 cube (side 10, ρ = 2/3 flat, centred I = 75, so the
//!   mean face radiance ρΦ/(πS(1 − ρ)) is 1; maxdepth 1000), back face seen
//!   whole by an orthographic camera: the image mean is within 5σ + b of 1
//!   at radius 1 and 0.3, and the outer 10 % band of the face within 2 % of
//!   the path tracer's. σ comes from K independent seeds (all pixels of a
//!   render share its photons). b = 2e-3 (the RGB ↔ spectrum round trip, as
//!   in closed_forms.rs) + the corner loss of the unfolded kernel: the
//!   quadrant of the disk beyond both walls of a corner, ∫∫A_q = r⁴/8 per
//!   corner, is r²/(200π) of a face's indirect light (2/3 of the total) —
//!   with the old rule (photons on the adjacent wall dropped) the edges lose
//!   (2/3)r³ per unit length, 5.7 % of the indirect light at r = 1.
//! - A T1-style floor meeting a wall at 90°, lit by a point light on their
//!   bisector (so the two faces' indirect irradiance is mirror-symmetric and
//!   continuous across the edge): per-block floor radiance of SPPM vs the
//!   path tracer within 5σ + b, b the disk-kernel bias of a kink of slope g
//!   of the indirect light at the edge, g r²/(8w) for a block of width w
//!   (∫₀^r of the disk average of g|s| minus g·d), with g the path tracer's
//!   indirect slope between the two blocks nearest the edge.
//!
//! The full 256-iteration measurement is `examples/t5_edges.rs`.

mod common;

use candela_core::build::Overrides;
use candela_core::image::RgbImage;
use common::render_str;

/// The T5 cube for `integrator` at gather radius `radius` (see the example).
fn cube(integrator: &str, radius: f32, photons: u64) -> String {
    let params = match integrator {
        "photonmap" => format!(
            "\"float maxradius\" [{radius}] \"string kernel\" \"disk\" \"integer lookup\" [100000] \"integer photons\" [{photons}] \"integer causticphotons\" [0] \"bool finalgather\" false"
        ),
        "path" => String::new(),
        _ => format!("\"float radius\" [{radius}] \"integer photonsperiteration\" [{photons}]"),
    };
    format!(
        r#"LookAt 0 0 0  0 0 1  0 1 0
Camera "orthographic" "float screenwindow" [-5 5 -5 5]
Film "rgb" "integer xresolution" [20] "integer yresolution" [20]
PixelFilter "box"
Sampler "independent"
Integrator "{integrator}" "integer maxdepth" [1000] {params}
WorldBegin
LightSource "point" "point3 from" [0 0 0] "rgb I" [75 75 75]
Material "diffuse" "spectrum reflectance" [300 0.6666667 800 0.6666667]
Shape "trianglemesh" "point3 P" [-5 -5 -5  5 -5 -5  5 5 -5  -5 5 -5  -5 -5 5  5 -5 5  5 5 5  -5 5 5]
  "integer indices" [0 2 1 0 3 2  4 5 6 4 6 7  0 1 5 0 5 4  3 7 6 3 6 2  0 4 7 0 7 3  1 2 6 1 6 5]
"#
    )
}

/// Green-channel mean over the whole image and over its outer 10 % band.
fn face_and_band(img: &RgbImage) -> (f64, f64) {
    let (w, h) = (img.width, img.height);
    let band = w / 10;
    let (mut all, mut edge, mut n_edge) = (0.0, 0.0, 0usize);
    for y in 0..h {
        for x in 0..w {
            let v = img.get(x, y)[1] as f64;
            all += v;
            if x < band || y < band || x >= w - band || y >= h - band {
                edge += v;
                n_edge += 1;
            }
        }
    }
    (all / (w * h) as f64, edge / n_edge as f64)
}

/// Mean and standard error of the mean of `v`.
fn mean_se(v: &[f64]) -> (f64, f64) {
    let (m, var) = common::stats::mean_var(v);
    (m, (var / v.len() as f64).sqrt())
}

/// (face, band) of K seeds of `scene` at `spp` iterations.
fn seeds(scene: &str, spp: u32, k: u64) -> (Vec<f64>, Vec<f64>) {
    (0..k)
        .map(|s| {
            let ov = Overrides {
                spp: Some(spp),
                seed: Some(s + 1),
                ..Default::default()
            };
            face_and_band(&render_str(scene, &ov))
        })
        .unzip()
}

#[test]
fn t5_cube_photon_estimators_keep_the_edges_and_corners() {
    const K: u64 = 4;
    let (_, path_band) = seeds(&cube("path", 1.0, 0), 256, K);
    let (pb, pb_se) = mean_se(&path_band);
    for integrator in ["sppm", "ppm", "photonmap"] {
        for radius in [1.0f32, 0.3] {
            // Fewer photons fall in a smaller disk: 4× the photons at r = 0.3.
            let photons = if radius < 1.0 { 40_000 } else { 10_000 };
            let (face, band) = seeds(&cube(integrator, radius, photons), 8, K);
            let ((m, se), (b, b_se)) = (mean_se(&face), mean_se(&band));
            let r2 = (radius * radius) as f64;
            let bias = 2e-3 + r2 / (200.0 * std::f64::consts::PI) * 2.0 / 3.0;
            eprintln!(
                "{integrator} r={radius}: face {m:.5} ± {se:.5} (1, b {bias:.4}); band {b:.5} ± {b_se:.5} vs path {pb:.5} ± {pb_se:.5}"
            );
            assert!(
                (m - 1.0).abs() <= 5.0 * se + bias,
                "{integrator} r={radius}: face mean {m} ± {se}"
            );
            assert!(
                (b / pb - 1.0).abs() <= 0.02,
                "{integrator} r={radius}: band {b} vs path {pb}"
            );
        }
    }
}

/// A floor (z = 0, x ≤ 1) meeting a wall (x = 1) at 90°, both ρ = 0.5, lit
/// by a point light on their bisector, floor region [0, 1] × [−½, ½] seen
/// from above.
fn corner_room(integrator: &str, max_depth: u32) -> String {
    format!(
        r#"LookAt 0.5 0 5  0.5 0 0  0 1 0
Camera "orthographic" "float screenwindow" [-0.5 0.5 -0.5 0.5]
Film "rgb" "integer xresolution" [32] "integer yresolution" [32]
PixelFilter "box"
Sampler "independent"
Integrator "{integrator}" "integer maxdepth" [{max_depth}] "float radius" [{EDGE_R}] "integer photonsperiteration" [40000]
WorldBegin
LightSource "point" "point3 from" [0 0 1] "rgb I" [2 2 2]
Material "diffuse" "spectrum reflectance" [300 0.5 800 0.5]
Shape "trianglemesh" "point3 P" [-9 -10 0  1 -10 0  1 10 0  -9 10 0  1 -10 10  1 10 10]
  "integer indices" [0 1 2 0 2 3  1 4 5 1 5 2]
"#
    )
}

/// SPPM's initial gather radius in the edge scene.
const EDGE_R: f64 = 0.25;

#[test]
fn floor_radiance_next_to_a_wall_matches_the_path_tracer() {
    const K: u64 = 4;
    let blocks = |integrator: &str, max_depth: u32, spp: u32| -> Vec<Vec<f64>> {
        let renders: Vec<Vec<f64>> = (0..K)
            .map(|s| {
                let ov = Overrides {
                    spp: Some(spp),
                    seed: Some(s + 1),
                    ..Default::default()
                };
                common::stats::block_means(&render_str(&corner_room(integrator, max_depth), &ov))
            })
            .collect();
        common::stats::by_block(&renders)
    };
    let (path, sppm) = (blocks("path", 50, 256), blocks("sppm", 50, 16));
    // The kink is in the indirect light alone (direct light is next-event
    // estimation in both): its slope g, bounded from the path tracer's
    // indirect part (all depths minus depth 1) between the column of
    // blocks at the wall (the image's first: x ∈ [0.75, 1]) and the next,
    // blocks 0.25 wide; then the kink bias g r²/(8w) (module doc).
    let direct = blocks("path", 1, 256);
    let ind: Vec<f64> = path
        .iter()
        .zip(&direct)
        .map(|(a, d)| mean_se(a).0 - mean_se(d).0)
        .collect();
    let w = 0.25;
    let g = (0..4)
        .map(|row| (ind[4 * row] - ind[4 * row + 1]).abs() / w)
        .fold(0.0, f64::max);
    let bias = g * EDGE_R * EDGE_R / (8.0 * w);
    for (i, (p, s)) in path.iter().zip(&sppm).enumerate() {
        let ((mp, sp), (ms, ss)) = (mean_se(p), mean_se(s));
        let sigma = (sp * sp + ss * ss).sqrt();
        eprintln!("block {i}: sppm {ms:.5} ± {ss:.5}, path {mp:.5} ± {sp:.5} (b {bias:.5})");
        assert!(
            (ms - mp).abs() <= 5.0 * sigma + bias,
            "block {i}: sppm {ms} vs path {mp} (σ {sigma}, b {bias})"
        );
    }
}
