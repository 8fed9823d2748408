//! The bundled Cornell box rendered by the path tracer matches pbrt-v4's own
//! 1024-spp render: per-channel mean within 1 % and every 32×32 block within
//! 4 % (issue #2's acceptance bounds). At 256 spp a block mean of ~1000
//! pixel samples × 256 has a relative standard error well under 1 %, so 4 %
//! leaves room only for noise in the reference (~1.5 %) — a bias of a few
//! per cent in any region fails the test.

use candela_core::build::{build, Overrides};
use candela_core::image::{compare, RgbImage};
use std::path::Path;

#[test]
fn cornell_box_matches_pbrt_v4_reference() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box");
    let desc = candela_scene::parse_file(&root.join("scene.pbrt")).expect("scene parses");
    let ov = Overrides {
        spp: Some(256),
        seed: Some(7),
        ..Default::default()
    };
    let setup = build(&desc, &ov).expect("scene builds");
    let (dev, state) = candela_core::render::render_all(&setup);
    assert_eq!(state.film.dropped(), 0, "non-finite samples");
    let img = dev.rgb();
    let reference =
        RgbImage::read_exr(&root.join("reference-pbrt-v4-path-1024spp.exr")).expect("reference");
    let c = compare(&img, &reference).expect("same size");
    eprintln!(
        "cornell: mean ratio {:?}, worst block {:?}, relMSE {}",
        c.mean_ratio, c.worst_block, c.rel_mse
    );
    for r in c.mean_ratio {
        assert!(
            (r - 1.0).abs() < 0.01,
            "channel mean ratio {r} (want within 1 %)"
        );
    }
    assert!(
        (c.worst_block.0 - 1.0).abs() < 0.04,
        "worst 32x32 block ratio {:?}",
        c.worst_block
    );
}
