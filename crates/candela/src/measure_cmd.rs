//! `candela measure`: illuminance at listed points, as CSV on stdout.
//!
//! The points file has one point per line, `x y z nx ny nz` (world space;
//! `#` starts a comment, blank lines are skipped). Each row of the output
//! is `x,y,z,nx,ny,nz,illuminance_lx,stderr_lx`, in input order; the
//! estimator is `candela_core::measure` (path tracing from the point).

use anyhow::{bail, Context, Result};
use candela_core::build::{build, Overrides};
use candela_core::integrator::RenderContext;
use candela_core::math::Vec3;
use candela_core::measure::{measure_point, MeasureSettings};
use candela_core::sampler::{Sampler, SamplerKind};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64};

/// Arguments of `candela measure`.
#[derive(clap::Args)]
pub struct MeasureArgs {
    /// Scene file (.pbrt, optionally .gz).
    pub scene: PathBuf,
    /// Measurement points, one `x y z nx ny nz` per line.
    #[arg(long)]
    pub points: PathBuf,
    /// Samples per point.
    #[arg(long, default_value_t = 4096)]
    pub samples: u32,
    /// Estimator: `path` (the only one so far).
    #[arg(long, default_value = "path")]
    pub integrator: String,
    /// Seed of the sample streams.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Maximum number of scattering events after the sensor.
    #[arg(long, default_value_t = 64)]
    pub maxdepth: u32,
}

/// Reads the points file: (position, unit normal) per line.
fn read_points(path: &Path) -> Result<Vec<(Vec3, Vec3)>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut points = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let at = || format!("{}:{}", path.display(), i + 1);
        let v: Vec<f32> = line
            .split_whitespace()
            .map(str::parse::<f32>)
            .collect::<Result<_, _>>()
            .with_context(|| format!("{}: not a number", at()))?;
        if v.len() != 6 || v.iter().any(|x| !x.is_finite()) {
            bail!("{}: expected six finite numbers `x y z nx ny nz`", at());
        }
        let n = Vec3::new(v[3], v[4], v[5]);
        if n.length() == 0.0 {
            bail!("{}: the normal is zero", at());
        }
        points.push((Vec3::new(v[0], v[1], v[2]), n.normalize()));
    }
    Ok(points)
}

/// Runs `candela measure`.
pub fn measure(args: MeasureArgs) -> Result<()> {
    if args.integrator != "path" {
        bail!(
            "--integrator {}: only \"path\" is implemented for measure",
            args.integrator
        );
    }
    if args.samples == 0 {
        bail!("--samples must be at least 1");
    }
    let points = read_points(&args.points)?;
    let desc = candela_scene::parse_file(&args.scene)?;
    let ov = Overrides {
        seed: Some(args.seed),
        integrator: Some("path".into()),
        ..Overrides::default()
    };
    let setup = build(&desc, &ov)?;
    for w in &setup.warnings {
        eprintln!("candela: warning: {w}");
    }
    let (cancel, work) = (AtomicBool::new(false), AtomicU64::new(0));
    // Independent samples, so that the sample variance gives the standard
    // error (a low-discrepancy sequence would make it meaningless).
    let sampler = Sampler::new(SamplerKind::Independent, args.samples, args.seed);
    let ctx = RenderContext {
        scene: &setup.scene,
        camera: &setup.camera,
        sampler: &sampler,
        film: &setup.film,
        cancel: &cancel,
        work: &work,
    };
    let settings = MeasureSettings {
        samples: args.samples,
        max_depth: args.maxdepth,
    };
    println!("x,y,z,nx,ny,nz,illuminance_lx,stderr_lx");
    for (k, (p, n)) in points.iter().enumerate() {
        let m = measure_point(&ctx, settings, k as u32, *p, *n);
        println!(
            "{},{},{},{},{},{},{:.6},{:.6}",
            p.x, p.y, p.z, n.x, n.y, n.z, m.illuminance, m.stderr
        );
    }
    Ok(())
}
