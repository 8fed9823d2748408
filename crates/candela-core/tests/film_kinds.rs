//! pbrt-v4's three films: `rgb`; `gbuffer` and `spectral`, which write the
//! same RGB image plus extra channels (identical RGB pixels for the same
//! seed); any other film is a located error.

mod common;

use candela_core::build::{build, Overrides};
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
fn gbuffer_and_spectral_films_render_the_rgb_image_and_more() {
    let ov = Overrides {
        spp: Some(4),
        seed: Some(1),
        ..Default::default()
    };
    let rgb = common::render_developed(&scene("rgb"), &ov);
    for film in ["gbuffer", "spectral"] {
        let dev = common::render_developed(&scene(film), &ov);
        assert_eq!(dev.rgb(), rgb.rgb(), "{film}");
        assert!(dev.channels.len() > 3, "{film}: no extra channels");
    }
    let desc = candela_scene::parse_str(&scene("hdr"), Path::new("f.pbrt")).expect("parses");
    let e = build(&desc, &ov)
        .err()
        .expect("unknown film fails")
        .to_string();
    assert!(e.contains("f.pbrt:3:1") && e.contains("\"hdr\""), "{e}");
}
