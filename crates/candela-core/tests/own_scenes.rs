//! candela's own scenes in `scenes/` (textures, a PLY killeroo in coated
//! materials, metals under a uniform sky, mix materials, bump mapping, the
//! less common shapes, pbrt-v3 syntax): each builds without warnings (the
//! pbrt-v3 one with one per converted directive), renders without a single
//! non-finite sample, and two sets of renders with independent seeds agree
//! block by block (Welch's t-test on 8×8 block means, Šidák-corrected; see
//! `common/stats.rs`). A seed-dependent bias, a NaN or a sample that is
//! sometimes huge fails here.

mod common;

use candela_core::build::{build, Overrides, RenderSetup};
use candela_core::image::RgbImage;
use common::stats;
use std::path::PathBuf;

/// Renders per set of seeds.
const K: usize = 8;
/// Samples per pixel of each render.
const SPP: u32 = 2;

fn scene_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../scenes/{name}/scene.pbrt"))
}

fn setup(name: &str) -> RenderSetup {
    let path = scene_path(name);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    setup_text(name, &text)
}

/// Builds scene `text` as if it were scene `name`'s file.
fn setup_text(name: &str, text: &str) -> RenderSetup {
    let desc =
        candela_scene::parse_str(text, &scene_path(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    let ov = Overrides {
        spp: Some(SPP),
        ..Default::default()
    };
    build(&desc, &ov).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// One render with `seed`; checks no sample was dropped and every pixel is finite.
fn render(s: &mut RenderSetup, seed: u64, name: &str) -> RgbImage {
    s.sampler = s.sampler.clone_with_seed(seed);
    let (dev, state) = candela_core::render::render_all(s);
    assert_eq!(
        state.film.dropped(),
        0,
        "{name}, seed {seed}: non-finite samples"
    );
    let img = dev.rgb();
    assert!(
        img.pixels.iter().flatten().all(|v| v.is_finite()),
        "{name}, seed {seed}: non-finite pixel"
    );
    img
}

/// Block means of K renders with seeds `first..first + K`, `[block][render]`.
fn blocks(s: &mut RenderSetup, first: u64, name: &str) -> Vec<Vec<f64>> {
    let renders: Vec<Vec<f64>> = (first..first + K as u64)
        .map(|seed| stats::block_means(&render(s, seed, name)))
        .collect();
    stats::by_block(&renders)
}

/// Builds `name` (checking its size and that it is warning-free), renders
/// two independent sets of seeds and compares them.
fn check(name: &str) -> RenderSetup {
    let mut s = setup(name);
    let res = s.film.resolution();
    assert!(res.x <= 128 && res.y <= 128, "{name}: {res} is not small");
    if name != "pbrt-v3-materials" {
        assert!(s.warnings.is_empty(), "{name}: {:#?}", s.warnings);
    }
    let (a, b) = (blocks(&mut s, 1, name), blocks(&mut s, 1001, name));
    assert_eq!(a.len(), (res.x as usize / 8) * (res.y as usize / 8));
    stats::assert_blocks_agree(&a, &b, name);
    s
}

#[test]
fn textured_floor() {
    check("textured-floor");
}

#[test]
fn coated_killeroo_on_a_ply_mesh() {
    let s = check("coated-killeroo");
    // Two killeroos of 8316 triangles, a floor of two, and the light.
    assert_eq!(s.scene.primitive_count(), 2 * 8316 + 2 + 1);
}

#[test]
fn metals_under_a_uniform_sky() {
    check("env-metals");
}

#[test]
fn mix_materials() {
    check("mix-material");
}

#[test]
fn bump_mapped_plane() {
    check("bump-plane");
}

#[test]
fn cylinder_bilinear_patch_loop_subdivision_and_partial_quadrics() {
    check("shapes-zoo");
}

#[test]
fn pbrt_v3_materials_are_upgraded() {
    let s = check("pbrt-v3-materials");
    // Film, Sampler, AreaLightSource, the "color" texture, the scale
    // texture, the floor mesh's uv and ten materials.
    assert_eq!(s.warnings.len(), 16, "{:#?}", s.warnings);
    for w in &s.warnings {
        assert!(w.contains("pbrt-v3 syntax"), "{w}");
        assert!(w.contains("scene.pbrt:"), "{w}");
    }
}

#[test]
fn the_comparison_sees_a_four_per_cent_brighter_sky() {
    let name = "env-metals";
    let text = std::fs::read_to_string(scene_path(name)).expect("scene");
    let brighter = text.replace("\"rgb L\" [0.9 0.95 1.0]", "\"rgb L\" [0.936 0.988 1.04]");
    assert_ne!(text, brighter);
    let (mut a, mut b) = (setup(name), setup_text(name, &brighter));
    let d = stats::disagreement(&blocks(&mut a, 1, name), &blocks(&mut b, 1001, name));
    assert!(d.is_some(), "a 4% brighter sky went unnoticed");
}
