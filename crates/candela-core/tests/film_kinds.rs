//! pbrt-v4's three films: `rgb`; `gbuffer` and `spectral`, which write the
//! same RGB image plus extra channels. candela renders the latter two as
//! `rgb` (identical pixels for the same seed) with a warning naming what is
//! not written; any other film is a located error.

mod common;

use candela_core::build::{build, Overrides};
use common::render_at;
use std::path::Path;

fn scene(film: &str) -> String {
    format!(
        r#"LookAt 0 0 -3  0 0 0  0 1 0
Camera "perspective"
Film "{film}" "integer xresolution" [8] "integer yresolution" [8]
Sampler "independent"
WorldBegin
LightSource "infinite" "rgb L" [0.4 0.5 0.6]
Material "diffuse"
Shape "sphere"
"#
    )
}

#[test]
fn gbuffer_and_spectral_films_render_the_rgb_image_with_a_warning() {
    let ov = Overrides {
        spp: Some(4),
        seed: Some(1),
        ..Default::default()
    };
    let path = Path::new("f.pbrt");
    let (rgb, _) = render_at(&scene("rgb"), path, &ov);
    for film in ["gbuffer", "spectral"] {
        let (img, warnings) = render_at(&scene(film), path, &ov);
        assert_eq!(img, rgb, "{film}");
        assert!(
            warnings.iter().any(|w| w.contains("f.pbrt:3:1")
                && w.contains(&format!("\"{film}\" is written as \"rgb\""))),
            "{film}: {warnings:?}"
        );
    }
    let desc = candela_scene::parse_str(&scene("hdr"), path).expect("parses");
    let e = build(&desc, &ov)
        .err()
        .expect("unknown film fails")
        .to_string();
    assert!(e.contains("f.pbrt:3:1") && e.contains("\"hdr\""), "{e}");
}
