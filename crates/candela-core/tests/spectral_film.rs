//! pbrt-v4's `Film "spectral"`: each bucket holds the radiance averaged
//! over its wavelengths, from camera samples and from splats alike.

use candela_core::build::{build, Overrides, RenderSetup};
use candela_core::film::Developed;
use candela_core::math::{Ray, Vec3};
use candela_core::render::render_all;
use candela_core::spectrum::SampledWavelengths;
use std::path::Path;

fn setup(text: &str, spp: u32, seed: u64) -> RenderSetup {
    let desc = candela_scene::parse_str(text, Path::new("spectral.pbrt")).expect("parses");
    let ov = Overrides {
        spp: Some(spp),
        seed: Some(seed),
        ..Overrides::default()
    };
    build(&desc, &ov).expect("builds")
}

fn render(setup: &RenderSetup) -> Developed {
    let (dev, state) = render_all(setup);
    assert_eq!(state.film.dropped(), 0);
    dev
}

/// Mean and standard error of the mean of `v` (independent pixels).
fn mean_se(v: &[f32]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().map(|&x| x as f64).sum::<f64>() / n;
    let var = v.iter().map(|&x| (x as f64 - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

/// The spectral channels (`S0.<λ>nm`), in bucket order.
fn buckets(dev: &Developed) -> Vec<(&str, &[f32])> {
    dev.channels
        .iter()
        .filter(|c| c.name.starts_with("S0."))
        .map(|c| (c.name.as_str(), c.data.as_slice()))
        .collect()
}

/// A sky of a two-segment piecewise-linear spectrum fills the view of a
/// camera in empty space: every pixel's bucket b estimates
/// (1/Δ)∫_b L(λ) dλ, computed here by the midpoint rule on the light's own
/// L(λ) (1000 points per bucket: exact to 1e-6 for a piecewise-linear
/// spectrum). Each bucket's image mean must lie within 5σ of it, σ from
/// the spread of the independent pixels (16 buckets: Šidák at α = 0.01
/// would ask for 3.8σ, 5σ is stricter on false alarms).
#[test]
fn buckets_of_a_sky_average_its_spectrum_over_each_bucket() {
    let text = r#"LookAt 0 0 0  0 0 1  0 1 0
Camera "perspective" "float fov" [60]
Film "spectral" "integer xresolution" [16] "integer yresolution" [16]
Sampler "independent"
WorldBegin
LightSource "infinite" "spectrum L" [360 0.2  600 2.0  830 0.5]
"#;
    let s = setup(text, 32, 7);
    let dev = render(&s);
    let b = buckets(&dev);
    assert_eq!(b.len(), 16);
    assert_eq!(b[0].0, "S0.374,688nm");
    let light = &s.scene.lights()[0];
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    let width = (830.0 - 360.0) / 16.0;
    for (k, (name, data)) in b.iter().enumerate() {
        let m = 1000;
        let want = (0..m)
            .map(|j| {
                let l = 360.0 + width * (k as f32 + (j as f32 + 0.5) / m as f32);
                let lambda = SampledWavelengths::from_parts([l; 4], [1.0; 4]);
                light.le(&ray, &lambda).0[0] as f64
            })
            .sum::<f64>()
            / m as f64;
        let (got, se) = mean_se(data);
        assert!(
            (got - want).abs() <= 5.0 * se + 1e-6 * want,
            "{name}: {got} ± {se}, want {want}"
        );
        assert!(se < 0.1 * want, "{name}: too noisy to test ({se})");
    }
}

/// A diffuse floor under a spectral quad light, seen by the path tracer
/// (camera samples) and by the light tracer (splats only): the image
/// means of every bucket agree: the mean over pixels of the per-pixel
/// difference is within 5σ, σ its standard error from the spread of the
/// differences (pixels are independent; the differences cancel the
/// image's own variation).
#[test]
fn light_tracer_and_path_tracer_fill_the_same_buckets() {
    let scene = |integrator: &str| {
        format!(
            r#"LookAt 0 2 -2  0 0 0  0 1 0
Camera "perspective" "float fov" [50]
Film "spectral" "integer xresolution" [16] "integer yresolution" [16] "integer nbuckets" [6]
  "float lambdamin" [400] "float lambdamax" [700]
PixelFilter "box" "float xradius" [0.5] "float yradius" [0.5]
Sampler "independent"
Integrator "{integrator}" "integer maxdepth" [1]
WorldBegin
AttributeBegin
  AreaLightSource "diffuse" "spectrum L" [400 1  550 6  700 2] "float scale" [20]
  Translate 0 1.5 0
  Shape "trianglemesh" "point3 P" [-0.5 0 -0.5  0.5 0 -0.5  0.5 0 0.5  -0.5 0 0.5] "integer indices" [0 1 2 0 2 3]
AttributeEnd
Material "diffuse" "spectrum reflectance" [400 0.8  700 0.2]
Shape "trianglemesh" "point3 P" [-4 0 -4  4 0 -4  4 0 4  -4 0 4] "integer indices" [0 1 2 0 2 3]
"#
        )
    };
    let pt = render(&setup(&scene("path"), 256, 1));
    let lt = render(&setup(&scene("lightpath"), 256, 2));
    let (bp, bl) = (buckets(&pt), buckets(&lt));
    assert_eq!(bp.len(), 6);
    for ((name, a), (_, b)) in bp.iter().zip(&bl) {
        let d: Vec<f32> = a.iter().zip(*b).map(|(x, y)| x - y).collect();
        let ((md, sd), (ma, _)) = (mean_se(&d), mean_se(a));
        assert!(
            md.abs() <= 5.0 * sd,
            "{name}: path − lightpath = {md} ± {sd} (path {ma})"
        );
        assert!(sd < 0.03 * ma, "{name}: too noisy to test ({sd} vs {ma})");
    }
}

/// SPPM accumulates τ in RGB: a spectral film is refused before rendering.
#[test]
fn sppm_refuses_a_spectral_film() {
    let text = r#"Film "spectral" "integer xresolution" [4] "integer yresolution" [4]
Integrator "sppm"
WorldBegin
LightSource "infinite"
"#;
    let s = setup(text, 1, 1);
    let mut state = candela_core::render::new_state(&s, 0, 1, "");
    let opts = candela_core::render::RenderOptions {
        passes: (0, 1),
        ..Default::default()
    };
    let stop = std::sync::atomic::AtomicBool::new(false);
    let e = candela_core::render::render(
        &s,
        &mut state,
        &opts,
        &stop,
        &candela_core::render::NoProgress,
        &mut |_| {},
    )
    .map(|_| ())
    .expect_err("refused")
    .to_string();
    assert!(e.contains("spectral") && e.contains("sppm"), "{e}");
}
