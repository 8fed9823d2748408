//! `candela measure`: illuminance at listed points, as CSV on stdout.
//!
//! The points file has one point per line, `x y z nx ny nz` (world space;
//! `#` starts a comment, blank lines are skipped). Each row of the output
//! is `x,y,z,nx,ny,nz,illuminance_lx,stderr_lx`, in input order; the
//! estimator is `candela_core::measure` (path tracing from the point) or,
//! with `--integrator ppm|sppm`, `candela_core::measure_photons` (photon
//! density estimates).

use anyhow::{bail, Context, Result};
use candela_core::build::{build, Overrides};
use candela_core::integrator::RenderContext;
use candela_core::math::Vec3;
use candela_core::measure::{measure_point, MeasureSettings, Measurement};
use candela_core::measure_photons::{measure_photons, PhotonEstimator, PhotonMeasureSettings};
use candela_core::sampler::{Sampler, SamplerKind};
use candela_core::scene::Scene;
use rayon::prelude::*;
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
    /// Samples per point (`path`).
    #[arg(long, default_value_t = 4096)]
    pub samples: u32,
    /// Estimator: `path` (unbiased), `ppm` or `sppm` (photon density).
    #[arg(long, default_value = "path")]
    pub integrator: String,
    /// Photon passes (`ppm`, `sppm`; at least 2 for a standard error).
    #[arg(long, default_value_t = 16)]
    pub passes: u32,
    /// Photons per pass (`ppm`, `sppm`).
    #[arg(long, default_value_t = 200_000)]
    pub photons: u64,
    /// Initial gather radius (`ppm`, `sppm`; default 1 % of the scene's
    /// bounding-box diagonal).
    #[arg(long)]
    pub radius: Option<f32>,
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
    let estimator = match args.integrator.as_str() {
        "path" => None,
        "ppm" => Some(PhotonEstimator::Ppm),
        "sppm" => Some(PhotonEstimator::Sppm),
        other => bail!("--integrator {other}: measure knows path, ppm and sppm"),
    };
    if args.samples == 0 || args.passes == 0 || args.photons == 0 {
        bail!("--samples, --passes and --photons must be at least 1");
    }
    if args.radius.is_some_and(|r| !(r.is_finite() && r > 0.0)) {
        bail!("--radius must be positive and finite");
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
    let results = match estimator {
        Some(e) => photon_estimates(&setup.scene, &args, e, &points)?,
        None => path_estimates(&setup, &args, &points),
    };
    println!("x,y,z,nx,ny,nz,illuminance_lx,stderr_lx");
    for ((p, n), m) in points.iter().zip(results) {
        println!(
            "{},{},{},{},{},{},{:.6},{:.6}",
            p.x, p.y, p.z, n.x, n.y, n.z, m.illuminance, m.stderr
        );
    }
    Ok(())
}

/// The photon estimates of `--integrator ppm|sppm`.
fn photon_estimates(
    scene: &Scene,
    args: &MeasureArgs,
    estimator: PhotonEstimator,
    points: &[(Vec3, Vec3)],
) -> Result<Vec<Measurement>> {
    let b = scene.bounds();
    let diagonal = if b.min.x <= b.max.x {
        (b.max - b.min).length()
    } else {
        1.0
    };
    let s = PhotonMeasureSettings {
        estimator,
        passes: args.passes,
        photons: args.photons,
        radius: args.radius.unwrap_or(0.01 * diagonal.max(1e-3)),
        max_depth: args.maxdepth,
        seed: args.seed,
    };
    measure_photons(scene, &s, points).context("unusable photon settings")
}

/// The path estimates of the default `--integrator path`.
fn path_estimates(
    setup: &candela_core::build::RenderSetup,
    args: &MeasureArgs,
    points: &[(Vec3, Vec3)],
) -> Vec<Measurement> {
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
    // Points in parallel; each point's samples are fixed by its index.
    points
        .par_iter()
        .enumerate()
        .map(|(k, (p, n))| measure_point(&ctx, settings, k as u32, *p, *n))
        .collect()
}
