//! Size and write/read time of a checkpoint of a 1920×1080 film after one
//! path-traced pass of the Cornell box:
//! `cargo run --release -p candela-core --example checkpoint_size`.

use candela_core::build::{build, Overrides};
use candela_core::render;
use std::path::Path;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/cornell-box/scene.pbrt");
    let text = std::fs::read_to_string(&root)?
        .replace(
            "\"integer xresolution\" [256]",
            "\"integer xresolution\" [1920]",
        )
        .replace(
            "\"integer yresolution\" [256]",
            "\"integer yresolution\" [1080]",
        );
    let desc = candela_scene::parse_str(&text, &root)?;
    let setup = build(
        &desc,
        &Overrides {
            spp: Some(1),
            ..Default::default()
        },
    )?;
    let (_, state) = render::render_all(&setup);
    let dir = std::env::temp_dir().join(format!("candela-ckpt-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("c.cndl");
    let t = Instant::now();
    state.save(&path)?;
    let write = t.elapsed();
    let t = Instant::now();
    let back = render::RenderState::load(&path)?;
    let read = t.elapsed();
    assert!(back == state);
    let size = std::fs::metadata(&path)?.len();
    let (w, h) = (setup.film.resolution().x, setup.film.resolution().y);
    println!(
        "{w}x{h}: checkpoint {:.1} MB ({:.1} B/pixel), write {:.0} ms, read {:.0} ms, in-memory state {:.1} MB",
        size as f64 / 1e6,
        size as f64 / (w * h) as f64,
        write.as_secs_f64() * 1e3,
        read.as_secs_f64() * 1e3,
        setup.film.memory_estimate().1 as f64 / 1e6
    );
    std::fs::remove_dir_all(&dir).ok();
    Ok(())
}
