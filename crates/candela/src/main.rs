//! The `candela` command-line renderer: a thin layer over `candela-scene`
//! (parsing) and `candela-core` (building and rendering).

mod progress;

use anyhow::{bail, Context, Result};
use candela_core::image::{compare, non_finite, RgbImage};
use candela_core::integrator::sppm::PpmPartial;
use candela_core::integrator::RenderContext;
use candela_core::scene::build::{build, summarize, Overrides};
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
    Render(RenderArgs),
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
    /// Average partial PPM renders (`--pass-range`) of one scene exactly.
    Merge {
        /// The scene the parts were rendered from (for the film settings).
        scene: PathBuf,
        /// Partial results (.ppmpart files) with disjoint pass ranges.
        #[arg(required = true)]
        parts: Vec<PathBuf>,
        /// Output EXR path (a PNG is written beside it).
        #[arg(long, short)]
        outfile: PathBuf,
    },
}

/// Parses "A..B" (A < B).
fn parse_range(s: &str) -> Result<(u64, u64), String> {
    let (a, b) = s.split_once("..").ok_or("expected A..B")?;
    let a: u64 = a.trim().parse().map_err(|e| format!("{a:?}: {e}"))?;
    let b: u64 = b.trim().parse().map_err(|e| format!("{b:?}: {e}"))?;
    if a >= b {
        return Err(format!("empty pass range {a}..{b}"));
    }
    Ok((a, b))
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

#[derive(clap::Args)]
struct RenderArgs {
    /// Scene file (.pbrt, optionally .gz).
    scene: PathBuf,
    /// Samples per pixel (overrides the Sampler's "pixelsamples"; SPPM/PPM: iterations).
    #[arg(long)]
    spp: Option<u32>,
    /// PPM only: render passes A ≤ i < B and also write their sums to
    /// OUTFILE.ppmpart, for `candela merge`.
    #[arg(long, value_parser = parse_range)]
    pass_range: Option<(u64, u64)>,
    /// Integrator name (overrides the Integrator directive).
    #[arg(long)]
    integrator: Option<String>,
    /// Output EXR path (a PNG is written beside it).
    #[arg(long)]
    outfile: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    nthreads: Option<usize>,
    /// Sampler seed (overrides the Sampler's "seed").
    #[arg(long)]
    seed: Option<u64>,
    /// No progress bar or statistics.
    #[arg(long)]
    quiet: bool,
    /// Parse and build the scene, print what `candela info` prints, and stop.
    #[arg(long)]
    check_only: bool,
    /// Render only the part x0 ≤ x < x1, y0 ≤ y < y1 of the image, in [0, 1]
    /// fractions of the film ("x0,x1,y0,y1", pbrt-v4's `--cropwindow`);
    /// overrides the Film's "cropwindow" and "pixelbounds".
    #[arg(long, value_parser = parse_cropwindow)]
    cropwindow: Option<[f32; 4]>,
}

/// Parses "x0,x1,y0,y1" with 0 ≤ x0 < x1 ≤ 1 and 0 ≤ y0 < y1 ≤ 1.
fn parse_cropwindow(s: &str) -> Result<[f32; 4], String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|t| t.trim().parse::<f32>().map_err(|e| format!("{t:?}: {e}")))
        .collect::<Result<_, _>>()?;
    let unit = |a: f32, b: f32| (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b) && a < b;
    match v[..] {
        [x0, x1, y0, y1] if unit(x0, x1) && unit(y0, y1) => Ok([x0, x1, y0, y1]),
        _ => Err("expected x0,x1,y0,y1 in [0, 1] with x0 < x1 and y0 < y1".into()),
    }
}

/// Replaces the Film's "cropwindow" and "pixelbounds" by `--cropwindow`.
fn apply_cropwindow(desc: &mut candela_scene::SceneDescription, cw: Option<[f32; 4]>) {
    use candela_scene::{Entity, Loc, Param, ParamSet, ParamType, ParamValue};
    let Some(cw) = cw else { return };
    let film = desc.film.get_or_insert_with(|| Entity {
        name: "rgb".into(),
        params: ParamSet::default(),
        color_space: "srgb".into(),
        loc: Loc::file_only(Path::new("--cropwindow")),
    });
    let params = &mut film.params.params;
    params.retain(|p| p.name != "cropwindow" && p.name != "pixelbounds");
    params.push(Param {
        name: "cropwindow".into(),
        ty: ParamType::Float,
        value: ParamValue::Floats(cw.to_vec()),
        loc: Loc::file_only(Path::new("--cropwindow")),
        used: Default::default(),
        may_be_unused: false,
    });
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.cmd {
        Cmd::Render(args) if args.check_only => {
            info(&args.scene, &overrides(&args), args.cropwindow)
        }
        Cmd::Render(args) => render(args),
        Cmd::Info { scene } => info(&scene, &Overrides::default(), None),
        Cmd::Diff { a, b, region } => diff(&a, &b, region),
        Cmd::Merge {
            scene,
            parts,
            outfile,
        } => merge(&scene, &parts, &outfile),
    };
    if let Err(e) = result {
        eprintln!("candela: error: {e:#}");
        std::process::exit(1);
    }
}

fn render(args: RenderArgs) -> Result<()> {
    if let Some(n) = args.nthreads {
        if n == 0 {
            bail!("--nthreads must be at least 1");
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("setting up the thread pool")?;
    }
    let t0 = Instant::now();
    let mut desc = candela_scene::parse_file(&args.scene)?;
    apply_cropwindow(&mut desc, args.cropwindow);
    let mut setup = build(&desc, &overrides(&args))?;
    for w in &setup.warnings {
        eprintln!("candela: warning: {w}");
    }
    let load_time = t0.elapsed();
    let bar = progress::Bar::new(args.quiet);
    let ctx = RenderContext {
        scene: &setup.scene,
        camera: &setup.camera,
        sampler: &setup.sampler,
        progress: &bar,
    };
    let t1 = Instant::now();
    setup.integrator.render(&ctx, &mut setup.film);
    let render_time = t1.elapsed();
    let image = setup.film.image();
    let exr = setup.outfile.clone();
    write_outputs(&image, &exr)?;
    if setup.film.dropped_samples() > 0 {
        eprintln!(
            "candela: warning: {} non-finite samples were dropped (a bug: please report)",
            setup.film.dropped_samples()
        );
    }
    if !args.quiet {
        let m = image.channel_means();
        eprintln!(
            "candela: {} with {} spp: load {:.2} s, render {:.2} s; mean RGB {:.5} {:.5} {:.5}; wrote {}",
            setup.integrator_name,
            setup.sampler.samples_per_pixel(),
            load_time.as_secs_f64(),
            render_time.as_secs_f64(),
            m[0],
            m[1],
            m[2],
            exr.display()
        );
    }
    Ok(())
}

/// The command-line values that override the scene file.
fn overrides(args: &RenderArgs) -> Overrides {
    Overrides {
        spp: args.spp,
        integrator: args.integrator.clone(),
        outfile: args.outfile.clone(),
        seed: args.seed,
        pass_range: args.pass_range,
    }
}

/// Parses and builds `scene`, then prints its summary and load times.
fn info(scene: &Path, ov: &Overrides, cropwindow: Option<[f32; 4]>) -> Result<()> {
    let t0 = Instant::now();
    let mut desc = candela_scene::parse_file(scene)?;
    apply_cropwindow(&mut desc, cropwindow);
    let parsed = t0.elapsed();
    let setup = build(&desc, ov)?;
    let total = t0.elapsed();
    println!("scene       {}", scene.display());
    print!("{}", summarize(&desc, &setup));
    println!(
        "load        {:.3} s (parse {:.3} s, build {:.3} s)",
        total.as_secs_f64(),
        parsed.as_secs_f64(),
        (total - parsed).as_secs_f64()
    );
    Ok(())
}

/// Writes the EXR and a PNG beside it (same stem).
fn write_outputs(image: &RgbImage, exr: &Path) -> Result<()> {
    let exr = if exr
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"))
    {
        exr.to_path_buf()
    } else if exr
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
    {
        exr.with_extension("exr")
    } else {
        bail!(
            "output file {} must end in .exr (a .png is written beside it)",
            exr.display()
        );
    };
    if let Some(dir) = exr.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    image.write_exr(&exr)?;
    image.write_png(&exr.with_extension("png"), 0.0)?;
    Ok(())
}

/// Adds partial PPM results and writes their average.
fn merge(scene: &Path, parts: &[PathBuf], outfile: &Path) -> Result<()> {
    let mut loaded = parts
        .iter()
        .map(|p| PpmPartial::load(p).map_err(anyhow::Error::msg))
        .collect::<Result<Vec<_>>>()?;
    loaded.sort_by_key(|p| p.passes.0);
    let mut total = loaded.remove(0);
    for p in &loaded {
        if p.passes.0 != total.passes.1 {
            bail!(
                "pass ranges are not contiguous: {}..{} then {}..{}",
                total.passes.0,
                total.passes.1,
                p.passes.0,
                p.passes.1
            );
        }
        total.merge(p).map_err(anyhow::Error::msg)?;
    }
    let desc = candela_scene::parse_file(scene)?;
    let mut setup = build(&desc, &Overrides::default())?;
    let (lo, hi) = setup.film.pixel_bounds();
    if lo != total.origin || hi - lo != total.size {
        bail!(
            "the partial results do not match the film of {}",
            scene.display()
        );
    }
    total.write_film(&mut setup.film);
    write_outputs(&setup.film.image(), outfile)?;
    eprintln!(
        "candela: merged passes {}..{} into {}",
        total.passes.0,
        total.passes.1,
        outfile.display()
    );
    Ok(())
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
