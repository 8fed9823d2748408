//! Film layers against closed forms: the first-hit pass (`--aov`), pbrt-v4's
//! `gbuffer` film, and the RGB channels, which layers must leave alone.

mod common;

use candela_core::build::{build, Overrides};
use candela_core::film::{Aov, Developed};
use candela_core::render::render_all;
use std::path::Path;

const W: usize = 32;
const H: usize = 24;

fn ov(aovs: &str, spp: u32) -> Overrides {
    Overrides {
        spp: Some(spp),
        seed: Some(3),
        aovs: if aovs.is_empty() {
            Vec::new()
        } else {
            Aov::parse_list(aovs).expect("known layers")
        },
        ..Overrides::default()
    }
}

fn developed(text: &str, ov: &Overrides) -> Developed {
    let desc = candela_scene::parse_str(text, Path::new("layers.pbrt")).expect("parses");
    let setup = build(&desc, ov).expect("builds");
    let (dev, state) = render_all(&setup);
    assert_eq!(state.film.dropped(), 0);
    dev
}

fn channel<'a>(dev: &'a Developed, name: &str) -> &'a [f32] {
    let names: Vec<&str> = dev.channels.iter().map(|c| c.name.as_str()).collect();
    &dev.channels
        .iter()
        .find(|c| c.name == name)
        .unwrap_or_else(|| panic!("no channel {name} in {names:?}"))
        .data
}

/// A camera at `eye` looking down +z at a diffuse ρ = 0.5 plane through
/// (0, 0, 2) with normal ∝ (−slope, 0, 1), uv = (x + 100, y + 100)/200.
fn plane_scene(camera: &str, film: &str, slope: f32) -> String {
    let z = |x: f32| 2.0 + slope * x;
    format!(
        r#"LookAt 0 0 0  0 0 1  0 1 0
Camera {camera}
Film {film} "integer xresolution" [{W}] "integer yresolution" [{H}]
PixelFilter "box" "float xradius" [0.5] "float yradius" [0.5]
Sampler "independent"
Integrator "path" "integer maxdepth" [1]
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "point3 P" [-100 -100 {}  100 -100 {}  100 100 {}  -100 100 {}]
  "integer indices" [0 1 2 0 2 3] "point2 uv" [0 0 1 0 1 1 0 1]
"#,
        z(-100.0),
        z(100.0),
        z(100.0),
        z(-100.0)
    )
}

/// Mean and standard error of the mean of `v` (pixels are independent).
fn mean_se(v: &[f32]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().map(|&x| x as f64).sum::<f64>() / n;
    let var = v.iter().map(|&x| (x as f64 - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

/// Perspective, 60° over the shorter axis: pixel (x, y) spans screen
/// coordinates s ∈ [−a + 2a·x/W, −a + 2a·(x+1)/W] (a = W/H) and
/// t ∈ [1 − 2y/H, 1 − 2(y+1)/H]; the ray through (s, t) meets the plane
/// z = 2 after 2·√(1 + k²(s² + t²)), k = tan 30°. Every sample of the pixel
/// lies between the nearest and farthest corner, so the pixel's average
/// does too (plus f32 round-off).
#[test]
fn perspective_layers_of_a_plane_facing_the_camera() {
    let text = plane_scene(r#""perspective" "float fov" [60]"#, r#""rgb""#, 0.0);
    let dev = developed(
        &text,
        &ov("albedo,position,normal,shading_normal,depth,uv,dzdxy", 16),
    );
    // Albedo: ρ = 0.5 times sRGB's illuminant, which is RGB (1, 1, 1); the
    // estimate is noisy only through the sampled wavelengths. 5σ, σ from
    // the spread of the (independent) pixels.
    for c in ["R", "G", "B"] {
        let (m, se) = mean_se(channel(&dev, &format!("albedo.{c}")));
        assert!((m - 0.5).abs() <= 5.0 * se + 1e-6, "albedo.{c} {m} ± {se}");
        assert!(se < 0.01, "albedo.{c} noise {se}");
    }
    let (a, k) = (W as f64 / H as f64, (30f64).to_radians().tan());
    let (px, py) = (channel(&dev, "position.X"), channel(&dev, "position.Y"));
    let (pz, depth) = (channel(&dev, "position.Z"), channel(&dev, "depth.Z"));
    let (u, v) = (channel(&dev, "uv.U"), channel(&dev, "uv.V"));
    for y in 0..H {
        for x in 0..W {
            let i = y * W + x;
            let s = [x, x + 1].map(|x| -a + 2.0 * a * x as f64 / W as f64);
            let t = [y, y + 1].map(|y| 1.0 - 2.0 * y as f64 / H as f64);
            let near = |r: [f64; 2]| {
                if r[0] * r[1] <= 0.0 {
                    0.0
                } else {
                    r[0].abs().min(r[1].abs())
                }
            };
            let far = |r: [f64; 2]| r[0].abs().max(r[1].abs());
            let d = |s: f64, t: f64| 2.0 * (1.0 + k * k * (s * s + t * t)).sqrt();
            let (lo, hi) = (d(near(s), near(t)), d(far(s), far(t)));
            let got = depth[i] as f64;
            assert!(
                lo - 1e-5 <= got && got <= hi + 1e-5,
                "depth ({x},{y}) {got} not in [{lo}, {hi}]"
            );
            assert!((pz[i] - 2.0).abs() < 1e-5, "position.Z ({x},{y}) {}", pz[i]);
            // Averages of linear functions: uv follows the position exactly.
            assert!((u[i] - (px[i] + 100.0) / 200.0).abs() < 1e-5);
            assert!((v[i] - (py[i] + 100.0) / 200.0).abs() < 1e-5);
            for n in ["normal", "shading_normal"] {
                let nv = ["X", "Y", "Z"].map(|c| channel(&dev, &format!("{n}.{c}"))[i]);
                assert!(
                    nv[0].abs() < 1e-6 && nv[1].abs() < 1e-6 && (nv[2] + 1.0).abs() < 1e-6,
                    "{n} {nv:?}"
                );
            }
            for c in ["dzdx", "dzdy"] {
                assert!(
                    channel(&dev, c)[i].abs() < 1e-5,
                    "{c} of a plane facing the camera"
                );
            }
        }
    }
}

/// Orthographic camera over the plane z = 2 + x/2: screen coordinates are
/// camera coordinates, one pixel is 2/H wide in x and y, so |∂z/∂x| = 1/H
/// and ∂z/∂y = 0 exactly; depth = z and z = 2 + x/2 are linear, so their
/// pixel averages obey the same relation; the normal facing the camera is
/// (1/2, 0, −1)/√1.25 (world space = camera space here).
#[test]
fn orthographic_layers_of_a_tilted_plane() {
    let text = plane_scene(r#""orthographic""#, r#""rgb""#, 0.5);
    let dev = developed(&text, &ov("position,normal,depth,dzdxy", 4));
    let (px, pz, depth) = (
        channel(&dev, "position.X"),
        channel(&dev, "position.Z"),
        channel(&dev, "depth.Z"),
    );
    let (dzdx, dzdy) = (channel(&dev, "dzdx"), channel(&dev, "dzdy"));
    let n = ["X", "Y", "Z"].map(|c| channel(&dev, &format!("normal.{c}")));
    let want_n = [0.5, 0.0, -1.0].map(|v: f32| v / 1.25f32.sqrt());
    let a = W as f32 / H as f32;
    for y in 0..H {
        for x in 0..W {
            let i = y * W + x;
            assert!(
                (pz[i] - (2.0 + 0.5 * px[i])).abs() < 1e-5,
                "position ({x},{y})"
            );
            assert!(
                (depth[i] - pz[i]).abs() < 1e-5,
                "depth ({x},{y}) {} vs z {}",
                depth[i],
                pz[i]
            );
            let (x0, x1) = (
                -a + 2.0 * a * x as f32 / W as f32,
                -a + 2.0 * a * (x + 1) as f32 / W as f32,
            );
            assert!(
                x0 - 1e-5 <= px[i] && px[i] <= x1 + 1e-5,
                "position.X ({x},{y}) {}",
                px[i]
            );
            assert!((dzdx[i] - 1.0 / H as f32).abs() < 1e-5, "dzdx {}", dzdx[i]);
            assert!(dzdy[i].abs() < 1e-5, "dzdy {}", dzdy[i]);
            for c in 0..3 {
                assert!(
                    (n[c][i] - want_n[c]).abs() < 1e-5,
                    "normal ({x},{y}) {c}: {}",
                    n[c][i]
                );
            }
        }
    }
}

/// pbrt-v4's `GBufferFilm` channels, in its order; `coordinatesystem`
/// moves P and N between camera space (the camera at (0, 0, −3) sees the
/// plane z = 0 at camera z = 3) and world space.
#[test]
fn gbuffer_channels_and_coordinate_systems() {
    let scene = |cs: &str| {
        plane_scene(
            r#""perspective" "float fov" [60]"#,
            &format!(r#""gbuffer" "string coordinatesystem" "{cs}""#),
            0.0,
        )
        .replace("LookAt 0 0 0  0 0 1  0 1 0", "LookAt 0 0 -5  0 0 -4  0 1 0")
    };
    let cam = developed(&scene("camera"), &ov("", 8));
    let names: Vec<&str> = cam.channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "R",
            "G",
            "B",
            "Albedo.R",
            "Albedo.G",
            "Albedo.B",
            "P.X",
            "P.Y",
            "P.Z",
            "dzdx",
            "dzdy",
            "N.X",
            "N.Y",
            "N.Z",
            "Ns.X",
            "Ns.Y",
            "Ns.Z",
            "u",
            "v",
            "Variance.R",
            "Variance.G",
            "Variance.B",
            "RelativeVariance.R",
            "RelativeVariance.G",
            "RelativeVariance.B"
        ]
    );
    let world = developed(&scene("world"), &ov("", 8));
    for i in 0..W * H {
        // The plane sits at world z = 2, camera z = 7.
        assert!((channel(&cam, "P.Z")[i] - 7.0).abs() < 1e-4);
        assert!((channel(&world, "P.Z")[i] - 2.0).abs() < 1e-4);
        assert!((channel(&cam, "N.Z")[i] + 1.0).abs() < 1e-5);
        // Variance, relative variance and the pixel value agree.
        let (r, var, rel) = (
            channel(&cam, "R")[i],
            channel(&cam, "Variance.R")[i],
            channel(&cam, "RelativeVariance.R")[i],
        );
        assert!(
            var >= 0.0 && (rel * r * r - var).abs() <= 1e-4 * var.max(1e-6),
            "{r} {var} {rel}"
        );
    }
    // The RGB image is that of the rgb film.
    let rgb = developed(
        &scene("camera").replace(
            r#""gbuffer" "string coordinatesystem" "camera""#,
            r#""rgb""#,
        ),
        &ov("", 8),
    );
    for c in 0..3 {
        assert!(
            rgb.channels[c] == cam.channels[c],
            "gbuffer channel {c} differs from rgb"
        );
    }
}

/// An unknown `coordinatesystem` is refused with its location and value.
#[test]
fn gbuffer_refuses_an_unknown_coordinate_system() {
    let bad = plane_scene(
        r#""perspective" "float fov" [60]"#,
        r#""gbuffer" "string coordinatesystem" "screen""#,
        0.0,
    );
    let desc = candela_scene::parse_str(&bad, Path::new("layers.pbrt")).expect("parses");
    let e = build(&desc, &ov("", 1))
        .err()
        .expect("unknown coordinate system")
        .to_string();
    assert!(
        e.contains("layers.pbrt:3:") && e.contains("\"screen\""),
        "{e}"
    );
}

/// A box with a light, a glass sphere and an interface surface: every
/// integrator's RGB channels are the same bits with and without layers.
#[test]
fn layers_leave_every_integrators_rgb_alone() {
    let scene = |integrator: &str| {
        format!(
            r#"LookAt 0 1 -3.2  0 1 0  0 1 0
Camera "perspective" "float fov" [45]
Film "rgb" "integer xresolution" [20] "integer yresolution" [17]
Sampler "independent"
Integrator {integrator}
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [8 8 8]
  Translate 0 1.99 0
  Shape "trianglemesh" "point3 P" [-0.3 0 -0.3  0.3 0 -0.3  0.3 0 0.3  -0.3 0 0.3] "integer indices" [0 2 1 0 3 2]
AttributeEnd
Material "diffuse" "rgb reflectance" [0.6 0.5 0.4]
Shape "trianglemesh" "point3 P" [-1 0 -1  1 0 -1  1 0 1  -1 0 1  -1 2 -1  1 2 -1  1 2 1  -1 2 1]
  "integer indices" [0 1 2 0 2 3  4 6 5 4 7 6  0 3 7 0 7 4  1 5 6 1 6 2  3 2 6 3 6 7]
Material "dielectric" "float eta" [1.5]
AttributeBegin
  Translate 0.3 0.4 0.2
  Shape "sphere" "float radius" [0.35]
AttributeEnd
Material "interface"
Shape "sphere" "float radius" [0.2]
"#
        )
    };
    let all = "albedo,position,normal,shading_normal,depth,uv,dzdxy";
    for integrator in [
        r#""path""#,
        r#""lightpath""#,
        r#""bdpt""#,
        r#""ppm" "float radius" [0.1] "integer photonsperiteration" [2000]"#,
        r#""photonmap" "integer photons" [2000] "integer causticphotons" [2000]"#,
        r#""sppm" "float radius" [0.1] "integer photonsperiteration" [2000]"#,
    ] {
        let text = scene(integrator);
        let plain = developed(&text, &ov("", 3));
        let layers = if integrator.contains("sppm") {
            all.to_string()
        } else {
            format!("{all},variance")
        };
        let layered = developed(&text, &ov(&layers, 3));
        for c in 0..3 {
            assert!(
                plain.channels[c] == layered.channels[c],
                "{integrator}: channel {c} changed"
            );
        }
        let albedo = channel(&layered, "albedo.G");
        assert!(
            albedo.iter().any(|&a| a > 0.1),
            "{integrator}: the pass ran"
        );
    }
}

/// The variance layer (s²/n of a pixel's n pass values) against the spread
/// of 24 independent renders of the same pixel: both estimate the variance
/// of the pixel's value without bias (the independent sampler makes the
/// passes i.i.d.). Per pixel, d = (variance across renders) − (mean of the
/// layer over renders); the mean of d over the independent pixels must be
/// within 5σ of 0, σ the standard error from the spread of d; and that σ
/// must be small against the variance itself, or the test could not see
/// a factor-of-n error.
#[test]
fn variance_layer_matches_the_spread_of_independent_renders() {
    let text = r#"LookAt 0 2 -2  0 0 0  0 1 0
Camera "perspective" "float fov" [50]
Film "rgb" "integer xresolution" [16] "integer yresolution" [16]
Sampler "independent"
Integrator "path" "integer maxdepth" [2]
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [20 20 20]
  Translate 0 1.5 0
  Shape "trianglemesh" "point3 P" [-0.2 0 -0.2  0.2 0 -0.2  0.2 0 0.2  -0.2 0 0.2] "integer indices" [0 1 2 0 2 3]
AttributeEnd
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "point3 P" [-4 0 -4  4 0 -4  4 0 4  -4 0 4] "integer indices" [0 1 2 0 2 3]
"#;
    let k = 24;
    let renders: Vec<Developed> = (0..k)
        .map(|seed| {
            let o = Overrides {
                seed: Some(100 + seed),
                ..ov("variance", 8)
            };
            developed(text, &o)
        })
        .collect();
    let n = 16 * 16;
    let (mut d, mut v_mean) = (Vec::with_capacity(n), 0.0);
    for i in 0..n {
        let r: Vec<f64> = renders
            .iter()
            .map(|dev| dev.channels[0].data[i] as f64)
            .collect();
        let m = r.iter().sum::<f64>() / k as f64;
        let spread = r.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (k - 1) as f64;
        let layer = renders
            .iter()
            .map(|dev| channel(dev, "variance.R")[i] as f64)
            .sum::<f64>()
            / k as f64;
        d.push((spread - layer) as f32);
        v_mean += layer / n as f64;
    }
    let (md, sd) = mean_se(&d);
    assert!(
        md.abs() <= 5.0 * sd,
        "spread − layer = {md} ± {sd} (variance {v_mean})"
    );
    assert!(sd < 0.1 * v_mean, "too noisy to test: {sd} vs {v_mean}");
}
