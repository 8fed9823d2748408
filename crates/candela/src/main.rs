//! The `candela` command-line renderer: a thin layer over `candela-scene`
//! (parsing) and `candela-core` (building, the render loop, the film).

mod info;
mod live;
mod measure_cmd;
mod output;
mod progress;
mod render_cmd;

use anyhow::{bail, Context, Result};
use candela_core::build::{build, summarize, Overrides};
use candela_core::image::{compare, non_finite, RgbImage};
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// candela: a spectral, physically based renderer for pbrt-v4 scenes.
#[derive(Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Render a pbrt-v4 scene to EXR (linear, float) and PNG (tone-mapped sRGB).
    Render(Box<render_cmd::RenderArgs>),
    /// Parse and build a scene without rendering: print what it contains
    /// (shapes, triangles, lights, materials, textures, camera, film, sampler,
    /// integrator) and every warning.
    Info {
        /// Scene file (.pbrt, optionally .gz).
        scene: PathBuf,
    },
    /// Compare two EXR images: per-channel mean ratio, relMSE, MAE, worst 32×32 block.
    Diff {
        /// The image to check.
        a: PathBuf,
        /// The reference.
        b: PathBuf,
        /// Compare only pixels x0 ≤ x < x1, y0 ≤ y < y1 ("x0,y0,x1,y1").
        #[arg(long, value_parser = parse_region)]
        region: Option<[usize; 4]>,
    },
    /// Merge partial renders (`render --pass-range`) of one scene exactly:
    /// the image equals one render of all their passes, bit for bit.
    Merge(render_cmd::MergeArgs),
    /// Virtual illuminance meter: illuminance \[lx\] and its standard error at
    /// each point of `--points` (`x y z nx ny nz` per line), as CSV.
    Measure(measure_cmd::MeasureArgs),
}

/// Parses "x0,y0,x1,y1".
fn parse_region(s: &str) -> Result<[usize; 4], String> {
    let v: Vec<usize> = s
        .split(',')
        .map(|t| t.trim().parse::<usize>().map_err(|e| format!("{t:?}: {e}")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x0, y0, x1, y1] if x0 < x1 && y0 < y1 => Ok([x0, y0, x1, y1]),
        _ => Err("expected x0,y0,x1,y1 with x0 < x1 and y0 < y1".into()),
    }
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.cmd {
        Cmd::Render(args) if args.check_only => info(&args.scene, &args.overrides()),
        Cmd::Render(args) => render_cmd::render(*args),
        Cmd::Info { scene } => info(&scene, &Overrides::default()),
        Cmd::Diff { a, b, region } => diff(&a, &b, region).map(|()| 0),
        Cmd::Merge(args) => render_cmd::merge(args).map(|()| 0),
        Cmd::Measure(args) => measure_cmd::measure(args).map(|()| 0),
    };
    match result {
        Ok(0) => {}
        Ok(code) => std::process::exit(code),
        Err(e) => {
            eprintln!("candela: error: {e:#}");
            std::process::exit(1);
        }
    }
}

/// Parses and builds `scene`, then prints its summary and load times.
fn info(scene: &Path, ov: &Overrides) -> Result<i32> {
    let t0 = Instant::now();
    let desc = candela_scene::parse_file(scene)?;
    let parsed = t0.elapsed();
    let setup = build(&desc, ov)?;
    let total = t0.elapsed();
    println!("scene       {}", scene.display());
    print!("{}", info::format_summary(&summarize(&desc, &setup)));
    println!(
        "load        {:.3} s (parse {:.3} s, build {:.3} s)",
        total.as_secs_f64(),
        parsed.as_secs_f64(),
        (total - parsed).as_secs_f64()
    );
    Ok(0)
}

fn diff(a: &Path, b: &Path, region: Option<[usize; 4]>) -> Result<()> {
    let (mut ia, mut ib) = (RgbImage::read_exr(a)?, RgbImage::read_exr(b)?);
    if let Some(r) = region {
        ia = ia
            .crop(r)
            .with_context(|| format!("region outside {}", a.display()))?;
        ib = ib
            .crop(r)
            .with_context(|| format!("region outside {}", b.display()))?;
    }
    // Positions are reported in the full image, not in the region.
    let (x0, y0) = region.map_or((0, 0), |r| (r[0], r[1]));
    let mut bad = Vec::new();
    for (img, path) in [(&ia, a), (&ib, b)] {
        if let Some(nf) = non_finite(img) {
            bad.push(format!(
                "{}: {} non-finite (NaN or infinite) pixels, the first at ({}, {})",
                path.display(),
                nf.count,
                x0 + nf.first.0,
                y0 + nf.first.1
            ));
        }
    }
    if !bad.is_empty() {
        bail!("{}", bad.join("; "));
    }
    let c = compare(&ia, &ib)?;
    let (ma, mb) = (ia.channel_means(), ib.channel_means());
    println!(
        "{:<10} {:>12} {:>12} {:>10}",
        "channel", "mean A", "mean B", "A/B"
    );
    for (i, ch) in ["R", "G", "B"].iter().enumerate() {
        // 0/0 (two black channels) has no ratio.
        let r = c.mean_ratio[i];
        let ratio = if r.is_finite() {
            format!("{r:.5}")
        } else {
            "n/a".to_string()
        };
        println!("{:<10} {:>12.6} {:>12.6} {:>10}", ch, ma[i], mb[i], ratio);
    }
    println!("relMSE (eps 0.01)  {:.6}", c.rel_mse);
    println!(
        "relMSE without the worst {} % of pixels  {:.6}",
        candela_core::image::TRIM * 100.0,
        c.rel_mse_trimmed
    );
    println!("MAE                {:.6}", c.mae);
    let (r, bx, by) = c.worst_block;
    println!(
        "worst 32x32 block  {:.5} at block ({bx}, {by}) = pixels ({}, {})",
        r,
        bx * 32,
        by * 32
    );
    Ok(())
}
