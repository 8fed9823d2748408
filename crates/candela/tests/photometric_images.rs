//! `candela render --units photometric` end to end: the luminance layer's
//! absolute scale, T5 through the illuminance (and luminance) image, the
//! standard-error layers' calibration, the EXR header's units and the
//! false-colour PNGs.
//!
//! **Tolerances.** The renders use the independent sampler with fixed
//! seeds, so pixels are independent and each pixel's passes are i.i.d.;
//! the mean of N pixels then has the standard error σ = √(Σ se_i²)/N from
//! the `*_stderr` layers, and a mean must lie within 5σ of its closed form
//! (each test also requires σ to be small, so it has power).

use candela_core::image::falsecolor::{self, FalseColorScale};
use candela_core::image::{read_exr_layers, ExrAttribute, ExrImage};
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;

/// A fresh temporary directory for one test.
fn dir(name: &str) -> PathBuf {
    common::dir("photo-images", name)
}

/// Renders `scene` with `--units photometric` and `extra` flags into
/// `d/name.exr` and reads it back.
fn render(d: &Path, name: &str, scene: &str, extra: &[&str]) -> ExrImage {
    let s = d.join(format!("{name}.pbrt"));
    std::fs::write(&s, scene).unwrap();
    let exr = d.join(format!("{name}.exr"));
    let out = Command::new(env!("CARGO_BIN_EXE_candela"))
        .arg("render")
        .arg(&s)
        .args(["--units", "photometric", "--quiet", "--outfile"])
        .arg(&exr)
        .args(extra)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    read_exr_layers(&exr).unwrap()
}

/// The samples of `layer.Y`.
fn layer<'a>(img: &'a ExrImage, layer: &str) -> &'a [f32] {
    img.channel(layer, "Y")
        .unwrap_or_else(|| panic!("no {layer}.Y"))
}

/// Mean of `layer` over the image and its standard error from `layer_stderr`.
fn mean_and_sigma(img: &ExrImage, name: &str) -> (f64, f64) {
    let v = layer(img, name);
    let se = layer(img, &format!("{name}_stderr"));
    let n = v.len() as f64;
    let mean = v.iter().map(|&x| x as f64).sum::<f64>() / n;
    let var: f64 = se.iter().map(|&s| (s as f64).powi(2)).sum();
    (mean, var.sqrt() / n)
}

/// Asserts `got` = `want` within 5σ, and σ < `rel`·want.
fn within_5_sigma(what: &str, (got, sigma): (f64, f64), want: f64, rel: f64) {
    eprintln!("{what}: {got:.4} ± {sigma:.4} (expected {want:.4})");
    assert!(sigma > 0.0 && sigma < rel * want, "{what}: σ = {sigma}");
    assert!(
        (got - want).abs() <= 5.0 * sigma,
        "{what}: {got} ± {sigma}, expected {want}"
    );
}

/// A camera 1 m in front of a 4 m × 4 m diffuse area light with `light`'s
/// parameters (it fills the 20° view), 16 × 16 pixels.
fn emitter(light: &str) -> String {
    format!(
        "LookAt 0 0 1  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [20]\n\
         Film \"rgb\" \"integer xresolution\" [16] \"integer yresolution\" [16]\n\
         Sampler \"independent\" \"integer pixelsamples\" [16]\nWorldBegin\n\
         AreaLightSource \"diffuse\" {light} \"bool twosided\" true\n\
         Shape \"trianglemesh\" \"point3 P\" [-2 -2 0 2 -2 0 2 2 0 -2 2 0] \"integer indices\" [0 1 2 0 2 3]\n"
    )
}

#[test]
fn luminance_of_a_seen_emitter_is_km_times_its_v_weighted_radiance() {
    // pbrt-v4 normalises an area light's L to ∫ȳ·L dλ = scale (ȳ(555) = 1,
    // not divided by ∫ȳ), so its luminance is 683·scale cd/m² whatever
    // the spectrum; `luminance` gives cd/m² directly. A pbrt-style Y
    // (divided by ∫ȳ = 106.857) would miss by that factor, one without
    // K_m by 683. The only noise is the wavelength sampling's. (An "rgb L"
    // is normalised by its illuminant alone, as in pbrt-v4, so it is left
    // out here: with `luminance` it renders Y(rgb)·value.)
    let d = dir("emitter");
    let cases = [
        ("bb", "\"blackbody L\" 3000 \"float scale\" 0.5", 341.5),
        ("flat", "\"spectrum L\" [360 2 830 2]", 683.0),
        ("lum", "\"blackbody L\" 5000 \"float luminance\" 250", 250.0),
    ];
    for (name, light, want) in cases {
        let img = render(&d, name, &emitter(light), &["--seed", "4"]);
        within_5_sigma(name, mean_and_sigma(&img, "luminance"), want, 0.01);
        assert!(img.layer("").is_none(), "{name}: sensor RGB written too");
    }
    std::fs::remove_dir_all(&d).ok();
}

/// T5's cube seen from inside by an orthographic camera 1.5 m above the
/// centre looking straight down, its window exactly the floor [−2, 2]²,
/// with a box filter: every pixel covers an equal square of the floor and
/// its samples are uniform in it, so the image mean is the floor's area
/// mean (no perspective weighting, no samples beyond the floor's edge).
fn t5_floor(rho: f64, res: u32, spp: u32) -> String {
    format!(
        "LookAt 0 0 1.5  0 0 -2  0 1 0\n\
         Camera \"orthographic\" \"float screenwindow\" [-2 2 -2 2]\n\
         Film \"rgb\" \"integer xresolution\" [{res}] \"integer yresolution\" [{res}]\n\
         PixelFilter \"box\" \"float xradius\" 0.5 \"float yradius\" 0.5\n\
         Sampler \"independent\" \"integer pixelsamples\" [{spp}]\n\
         Integrator \"path\" \"integer maxdepth\" [100]\n{}",
        common::t5_cube_world(rho)
    )
}

#[test]
fn t5_cube_through_the_illuminance_and_luminance_images() {
    // Floor of the 4 m cube: ⟨E⟩ = Φ/(S(1 − ρ)) (validation.md T5), and, the
    // floor being Lambertian, ⟨L⟩ = ρ⟨E⟩/π. Three rooms × two layers at 5σ:
    // family-wise false alarm < 4·10⁻⁶.
    let d = dir("t5");
    for (rho, want) in [(0.2, 130.21), (0.5, 208.33), (0.8, 520.83)] {
        assert!((common::t5(rho) - want).abs() < 0.01);
        let img = render(&d, "t5", &t5_floor(rho, 16, 16), &["--seed", "9"]);
        let e = mean_and_sigma(&img, "illuminance");
        within_5_sigma(&format!("E rho {rho}"), e, common::t5(rho), 0.02);
        let l = mean_and_sigma(&img, "luminance");
        let l_want = rho * common::t5(rho) / std::f64::consts::PI;
        within_5_sigma(&format!("L rho {rho}"), l, l_want, 0.02);
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn stderr_layers_predict_the_spread_between_independent_seeds() {
    // z_i = (a_i − b_i)/√(se_a² + se_b²) over the pixels of two seeds has
    // unit variance if the stderr layers are right (a layer of √s² instead
    // of √(s²/n) would give 1/16). Over N pixels the sample variance of z
    // has standard deviation ≈ √(2/N) (more with 16-pass stderr estimates'
    // heavier tails), so ±5√(2/N) = ±0.22 at N = 1024. (With s² from 16
    // passes z is t-like rather than normal, E[z²] ≈ ν/(ν − 2) ≈ 1.07 for
    // ν ≈ 30: inside the tolerance; measured 1.13 and 1.03.)
    let d = dir("z");
    let scene = t5_floor(0.5, 32, 16);
    let a = render(&d, "a", &scene, &["--seed", "1"]);
    let b = render(&d, "b", &scene, &["--seed", "2"]);
    for name in ["luminance", "illuminance"] {
        let se = format!("{name}_stderr");
        let z: Vec<f64> = (0..layer(&a, name).len())
            .map(|i| {
                let (x, y) = (layer(&a, name)[i] as f64, layer(&b, name)[i] as f64);
                let (sx, sy) = (layer(&a, &se)[i] as f64, layer(&b, &se)[i] as f64);
                (x - y) / (sx * sx + sy * sy).sqrt()
            })
            .collect();
        let n = z.len() as f64;
        let m = z.iter().sum::<f64>() / n;
        let var = z.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0);
        eprintln!("{name}: var(z) = {var:.3} over {n} pixels");
        assert!(
            (var - 1.0).abs() < 5.0 * (2.0 / n).sqrt(),
            "{name}: var(z) = {var}"
        );
    }
    std::fs::remove_dir_all(&d).ok();
}

/// Rec. 709 luma of an sRGB pixel.
fn luma(p: &image::Rgb<u8>) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

/// Checks the false-colour PNG of `layer`: its size, a drawn legend, and
/// colours whose luma rises with the value.
fn check_png(
    d: &Path,
    img: &ExrImage,
    name: &str,
    layer_name: &str,
    unit: &str,
) -> image::RgbImage {
    let png = image::open(d.join(format!("{name}.{layer_name}.png")))
        .unwrap()
        .to_rgb8();
    let values = layer(img, layer_name);
    let max = falsecolor::auto_max(values);
    let lw = falsecolor::legend_width(unit, FalseColorScale::Log, max);
    assert_eq!(png.width() as usize, img.width + lw, "{layer_name}");
    assert_eq!(png.height() as usize, img.height.max(150), "{layer_name}");
    let mut legend: Vec<[u8; 3]> = (0..png.height())
        .flat_map(|y| (img.width as u32..png.width()).map(move |x| (x, y)))
        .map(|(x, y)| png.get_pixel(x, y).0)
        .collect();
    legend.sort_unstable();
    legend.dedup();
    assert!(
        legend.len() > 20,
        "{layer_name}: legend of {} colours",
        legend.len()
    );
    let mut px: Vec<(f32, f64)> = (0..img.height)
        .flat_map(|y| (0..img.width).map(move |x| (x, y)))
        .map(|(x, y)| {
            let v = values[y * img.width + x];
            (v, luma(png.get_pixel(x as u32, y as u32)))
        })
        .collect();
    px.sort_by(|a, b| a.0.total_cmp(&b.0));
    for w in px.windows(2) {
        // Up to 8-bit rounding of the colour channels.
        assert!(w[1].1 >= w[0].1 - 1.0, "{layer_name}: luma falls {w:?}");
    }
    assert!(
        px[px.len() - 1].1 > px[0].1 + 10.0,
        "{layer_name}: flat picture"
    );
    png
}

#[test]
fn exr_header_carries_units_and_false_colour_pngs_have_legends() {
    let d = dir("png");
    let img = render(&d, "room", &t5_floor(0.5, 24, 4), &["--seed", "3"]);
    let text = |k: &str| match img.attributes.get(k) {
        Some(ExrAttribute::Text(t)) => t.clone(),
        other => panic!("{k}: {other:?}"),
    };
    assert_eq!(text("candela.units"), "photometric");
    assert_eq!(text("luminance.units"), "cd/m^2");
    assert_eq!(text("luminance_stderr.units"), "cd/m^2");
    assert_eq!(text("illuminance.units"), "lx");
    assert_eq!(text("illuminance_stderr.units"), "lx");
    let names: Vec<&str> = img.layers.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "illuminance",
            "illuminance_stderr",
            "luminance",
            "luminance_stderr"
        ]
    );
    check_png(&d, &img, "room", "luminance", "cd/m²");
    check_png(&d, &img, "room", "illuminance", "lx");
    assert!(!d.join("room.png").exists(), "tone-mapped PNG of no RGB");
    // A linear scale topped at 100 lx: every brighter pixel is the top colour.
    let lin = render(
        &d,
        "lin",
        &t5_floor(0.5, 24, 4),
        &[
            "--seed",
            "3",
            "--falsecolor-scale",
            "linear",
            "--falsecolor-max",
            "100",
        ],
    );
    let png = image::open(d.join("lin.illuminance.png"))
        .unwrap()
        .to_rgb8();
    let e = layer(&lin, "illuminance");
    let top = falsecolor::colour(1.0);
    let (w, h) = (lin.width, lin.height);
    assert!(e.iter().any(|&v| v > 100.0) && e.iter().any(|&v| v < 100.0));
    for (i, &v) in e.iter().enumerate() {
        let p = png.get_pixel((i % w) as u32, (i / w) as u32).0;
        assert_eq!(p == top, v >= 100.0, "pixel {i} of {w}x{h}: {v} lx → {p:?}");
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn sppm_and_unknown_units_are_refused_with_a_message() {
    let d = dir("refuse");
    let s = d.join("s.pbrt");
    std::fs::write(&s, t5_floor(0.5, 8, 2)).unwrap();
    for (args, word) in [
        (
            &["--units", "photometric", "--integrator", "sppm"][..],
            "photometric",
        ),
        (&["--units", "lumens"][..], "sensor or photometric"),
        (
            &["--units", "photometric", "--falsecolor-scale", "cubic"][..],
            "log or linear",
        ),
        (
            &["--units", "photometric", "--falsecolor-max", "0"][..],
            "positive",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_candela"))
            .arg("render")
            .arg(&s)
            .args(args)
            .args(["--quiet", "--outfile"])
            .arg(d.join("x.exr"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(word),
            "{args:?}: {err}"
        );
        assert!(!d.join("x.exr").exists());
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn a_photometric_render_stopped_early_resumes_to_the_bytes_of_one_run() {
    // --time-limit stops after the first pass (it always runs one) and
    // writes the state; --resume adds the other passes in fixed point.
    let d = dir("resume");
    let s = d.join("s.pbrt");
    std::fs::write(&s, t5_floor(0.5, 12, 6)).unwrap();
    let run = |out: &str, extra: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_candela"))
            .arg("render")
            .arg(&s)
            .args([
                "--units",
                "photometric",
                "--quiet",
                "--seed",
                "5",
                "--outfile",
            ])
            .arg(d.join(out))
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    run("whole.exr", &[]);
    run("stopped.exr", &["--time-limit", "0.000001"]);
    let stopped = read_exr_layers(&d.join("stopped.exr")).unwrap();
    assert_eq!(
        stopped.attributes.get("candela.passes"),
        Some(&ExrAttribute::Int(1))
    );
    let ckpt = d.join("stopped.cndl");
    run("resumed.exr", &["--resume", ckpt.to_str().unwrap()]);
    let bytes = |n: &str| std::fs::read(d.join(n)).unwrap();
    assert!(bytes("resumed.exr") == bytes("whole.exr"), "EXR differs");
    for png in ["luminance.png", "illuminance.png"] {
        assert!(
            bytes(&format!("resumed.{png}")) == bytes(&format!("whole.{png}")),
            "{png} differs"
        );
    }
    std::fs::remove_dir_all(&d).ok();
}
