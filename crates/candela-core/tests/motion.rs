//! Motion blur (pbrt-v4's `ActiveTransform StartTime/EndTime` and the
//! camera's `shutteropen`/`shutterclose`), against closed forms.
//!
//! An orthographic camera looks at a uniform sky (L = 1) through a black
//! square 1 wide that slides along x from −1 to +1 over `TransformTimes`
//! [0, 1]. A film point at x sees the square while its centre c(t) = −1 + 2t
//! is within ½ of x, i.e. for t ∈ [(x − ½ + 1)/2, (x + ½ + 1)/2]. Its value is
//! the exposure (close − open, pbrt-v4's imaging ratio) times the fraction of
//! the shutter interval during which the sky is visible, averaged over the
//! pixel footprint (box filter). Each pixel sample sees either 1 or 0, so a
//! column of n samples has σ ≤ exposure·½/√n; the bound is 5σ.

mod common;

use candela_core::build::{build, Overrides};
use common::render_str;
use std::path::Path;

const W: usize = 32;
const H: usize = 4;
const SPP: u32 = 256;

/// Length of [a, b] ∩ [lo, hi].
fn overlap(a: f64, b: f64, lo: f64, hi: f64) -> f64 {
    (b.min(hi) - a.max(lo)).max(0.0)
}

/// Expected value of pixel column `i` for the shutter [open, close].
fn expected(i: usize, open: f64, close: f64) -> f64 {
    let n = 256;
    let x0 = -2.0 + 4.0 * i as f64 / W as f64;
    let visible: f64 = (0..n)
        .map(|k| {
            let x = x0 + 4.0 / W as f64 * (k as f64 + 0.5) / n as f64;
            let covered = overlap((x + 0.5) / 2.0, (x + 1.5) / 2.0, open, close);
            1.0 - covered / (close - open)
        })
        .sum::<f64>()
        / n as f64;
    (close - open) * visible
}

const QUAD: &str = r#"Shape "trianglemesh" "integer indices" [0 1 2 0 2 3]
    "point3 P" [-0.5 -1 0  0.5 -1 0  0.5 1 0  -0.5 1 0]"#;

fn header(close: f32) -> String {
    format!(
        r#"LookAt 0 0 0  0 0 1  0 1 0
Camera "orthographic" "float screenwindow" [-2 2 -0.25 0.25]
    "float shutteropen" [0] "float shutterclose" [{close}]
Film "rgb" "integer xresolution" [{W}] "integer yresolution" [{H}]
PixelFilter "box"
Sampler "independent"
Integrator "path" "integer maxdepth" [1]
WorldBegin
LightSource "infinite" "rgb L" [1 1 1]
Material "diffuse" "rgb reflectance" [0 0 0]
"#
    )
}

/// The square placed by `ActiveTransform` on the shape itself.
fn moving_shape(close: f32) -> String {
    format!(
        "{}AttributeBegin\n  Translate -1 0 2\n  ActiveTransform EndTime\n  Translate 2 0 0\n  ActiveTransform All\n  {QUAD}\nAttributeEnd\n",
        header(close)
    )
}

/// The same motion carried by an object instance.
fn moving_instance(close: f32) -> String {
    format!(
        "{}ObjectBegin \"square\"\n  {QUAD}\nObjectEnd\nAttributeBegin\n  Translate -1 0 2\n  ActiveTransform EndTime\n  Translate 2 0 0\n  ActiveTransform All\n  ObjectInstance \"square\"\nAttributeEnd\n",
        header(close)
    )
}

fn check_profile(scene: &str, open: f64, close: f64, what: &str) {
    let ov = Overrides {
        spp: Some(SPP),
        seed: Some(7),
        ..Default::default()
    };
    let img = render_str(scene, &ov);
    let n = (H as u32 * SPP) as f64;
    let sigma = (close - open) * 0.5 / n.sqrt();
    for i in 0..W {
        let want = expected(i, open, close);
        for c in 0..3 {
            let got = (0..H).map(|y| img.get(i, y)[c] as f64).sum::<f64>() / H as f64;
            assert!(
                (got - want).abs() <= 5.0 * sigma + 2e-3,
                "{what}: column {i} channel {c}: {got} vs {want} (σ {sigma})"
            );
        }
    }
}

#[test]
fn a_sliding_square_blurs_into_the_closed_form_profile() {
    check_profile(&moving_shape(1.0), 0.0, 1.0, "shape, shutter [0, 1]");
    // A shorter shutter sees half the motion and half the exposure.
    check_profile(&moving_shape(0.5), 0.0, 0.5, "shape, shutter [0, 0.5]");
}

#[test]
fn a_moving_object_instance_blurs_like_a_moving_shape() {
    check_profile(&moving_instance(1.0), 0.0, 1.0, "instance, shutter [0, 1]");
}

#[test]
fn the_profile_test_rejects_an_unblurred_square() {
    // The same square held at its start position gives a different profile:
    // the closed form above can tell a static scene from a moving one.
    let scene = moving_shape(1.0).replace("ActiveTransform EndTime\n  Translate 2 0 0\n", "");
    let result = std::panic::catch_unwind(|| check_profile(&scene, 0.0, 1.0, "static"));
    assert!(
        result.is_err(),
        "a static square passed the motion-blur profile"
    );
}

#[test]
fn moving_area_lights_are_refused_and_moving_cameras_warned_about() {
    let light = moving_shape(1.0).replace(
        "  Shape \"trianglemesh\"",
        "  AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n  Shape \"trianglemesh\"",
    );
    let desc = candela_scene::parse_str(&light, Path::new("m.pbrt")).expect("parses");
    let err = build(&desc, &Overrides::default())
        .err()
        .expect("must fail")
        .to_string();
    assert!(
        err.contains("m.pbrt:") && err.contains("moving shape"),
        "{err}"
    );

    let camera = moving_shape(1.0).replace(
        "LookAt 0 0 0  0 0 1  0 1 0\n",
        "LookAt 0 0 0  0 0 1  0 1 0\nActiveTransform EndTime\nTranslate 0 0 1\nActiveTransform All\n",
    );
    let desc = candela_scene::parse_str(&camera, Path::new("m.pbrt")).expect("parses");
    let setup = build(&desc, &Overrides::default()).expect("builds");
    assert!(
        setup
            .warnings
            .iter()
            .any(|w| w.contains("motion of a camera")),
        "{:?}",
        setup.warnings
    );
}
