//! `candela render` and `candela merge`: flags → render loop → outputs.

use crate::live::Live;
use crate::output;
use crate::progress;
use anyhow::{bail, Context, Result};
use candela_core::build::{build, Overrides, RenderSetup};
use candela_core::film::develop::develop;
use candela_core::film::Aov;
use candela_core::image::falsecolor::FalseColorScale;
use candela_core::integrator::{IntegratorKind, Visualize};
use candela_core::render::{self, RenderOptions, RenderState, StopReason};
use candela_scene::SceneDescription;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Exit code of a render stopped by a signal (after writing its outputs).
const EXIT_INTERRUPTED: i32 = 130;

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

/// Parses a positive, finite number of seconds.
fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!(
            "expected a positive number of seconds, found {s:?}"
        )),
    }
}

/// Parses a relative error in (0, 1).
fn parse_error(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
        _ => Err(format!(
            "expected a relative error between 0 and 1, found {s:?}"
        )),
    }
}

/// Parses a sample count ≥ 1.
fn parse_spp(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(v) if v >= 1 => Ok(v),
        _ => Err(format!(
            "expected a whole number of at least 1, found {s:?}"
        )),
    }
}

/// `candela render` flags.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// Scene file (.pbrt, optionally .gz).
    pub scene: PathBuf,
    /// Passes: samples per pixel for path, lightpath and bdpt; iterations for
    /// the photon integrators (overrides the Sampler's "pixelsamples").
    #[arg(long, value_parser = parse_spp)]
    pub spp: Option<u32>,
    /// Render only passes A ≤ i < B of the --spp passes and write their exact
    /// state beside the image (OUTFILE.passes-A-B.cndl, or --checkpoint) for
    /// `candela merge`. Not for sppm, whose passes depend on each other.
    #[arg(long, value_parser = parse_range)]
    pub pass_range: Option<(u64, u64)>,
    /// Integrator name (overrides the Integrator directive).
    #[arg(long)]
    pub integrator: Option<String>,
    /// Output EXR path (a PNG is written beside it).
    #[arg(long)]
    pub outfile: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub nthreads: Option<usize>,
    /// Sampler seed (overrides the Sampler's "seed").
    #[arg(long)]
    pub seed: Option<u64>,
    /// No progress display or statistics.
    #[arg(long)]
    pub quiet: bool,
    /// Parse and build the scene, print what `candela info` prints, and stop.
    #[arg(long)]
    pub check_only: bool,
    /// Where the render's state is written when it stops early, every
    /// --checkpoint-every seconds, and at the end (default on a stop:
    /// OUTFILE.cndl).
    #[arg(long)]
    pub checkpoint: Option<PathBuf>,
    /// Write a checkpoint this often (seconds).
    #[arg(long, value_parser = parse_seconds)]
    pub checkpoint_every: Option<f64>,
    /// Continue the render whose state is in this checkpoint (same scene and flags).
    #[arg(long)]
    pub resume: Option<PathBuf>,
    /// Render whole passes until this many seconds are spent.
    #[arg(long, value_parser = parse_seconds)]
    pub time_limit: Option<f64>,
    /// Render only the part x0 ≤ x < x1, y0 ≤ y < y1 of the image, in [0, 1]
    /// fractions of the film ("x0,x1,y0,y1", pbrt-v4's `--cropwindow`);
    /// overrides the Film's "cropwindow" and "pixelbounds".
    #[arg(long, value_parser = render::parse_cropwindow)]
    pub cropwindow: Option<[f32; 4]>,
    /// Stop once the relative standard error of the image mean (every
    /// channel, from the spread of the per-pass means) is below this.
    #[arg(long, value_parser = parse_error)]
    pub target_error: Option<f64>,
    /// Extra EXR layers, comma-separated. First-hit values (of each pass's
    /// camera ray, followed through interface materials to the first
    /// surface with a BSDF; filter-weighted averages, rays that escape
    /// count as 0): `albedo` (albedo.R/G/B: directional reflectance ρ(wo)
    /// times the colour space's illuminant, output RGB), `position`
    /// (position.X/Y/Z, world space), `normal` and `shading_normal`
    /// (normal.X/Y/Z, shading_normal.X/Y/Z: unit, world space, facing the
    /// camera), `depth` (depth.Z: distance from the lens point), `uv`
    /// (uv.U/V: surface coordinates), `dzdxy` (dzdx, dzdy: |change of
    /// camera-space z| per pixel). `variance` (variance.R/G/B): variance of
    /// each pixel's value, from the spread of the independent passes
    /// (s²/n; needs 2 passes).
    #[arg(long, value_parser = parse_aovs)]
    pub aov: Option<AovList>,
    /// `sensor` (default): the film's sensor RGB. `photometric`: instead
    /// of RGB, the EXR holds `luminance.Y` [cd/m²] (683 lm/W × ∫L V dλ,
    /// CIE 1931 V = ȳ), `illuminance.Y` \[lx\] (arriving at the first visible
    /// surface of each pixel, from the side the camera sees; 0 where the
    /// ray escapes; Radiance's `rpict -i`) and their standard errors
    /// `luminance_stderr.Y`, `illuminance_stderr.Y` (√(s²/n) over the
    /// passes; needs 2), with the units in the header (`<layer>.units`);
    /// false-colour PNGs OUTFILE.luminance.png and OUTFILE.illuminance.png
    /// with a legend replace the tone-mapped PNG. Every integrator but sppm.
    #[arg(long, value_parser = parse_units, default_value = "sensor")]
    pub units: Units,
    /// Scale of the false-colour PNGs (`--units photometric`): `log`
    /// (default; 3 decades below the maximum) or `linear` (0 to the maximum).
    #[arg(long, default_value = "log")]
    pub falsecolor_scale: FalseColorScale,
    /// Top of the false-colour scale in cd/m² and lx (default: per
    /// picture, the smallest 1, 2 or 5 × 10^k above the 99th percentile).
    #[arg(long, value_parser = parse_positive)]
    pub falsecolor_max: Option<f64>,
    /// Show the image in the tev viewer listening at HOST:PORT while it
    /// renders (tev's default is 127.0.0.1:14158): every channel of the
    /// EXR, at most 4 frames a second, never blocking the render; the
    /// final image is always sent.
    #[arg(long, value_name = "HOST:PORT")]
    pub display_server: Option<String>,
    /// Refuse to start a render whose film, photon and other large
    /// structures are estimated above this size ("4G", "512MiB", "50%";
    /// default: 75% of physical memory).
    #[arg(long, value_parser = candela_core::build::parse_memory)]
    pub memory_limit: Option<u64>,
}

/// Parses a positive finite number.
fn parse_positive(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("expected a positive number, found {s:?}")),
    }
}

/// What the film records (`--units`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Units {
    /// Sensor RGB.
    Sensor,
    /// Luminance and illuminance with standard errors.
    Photometric,
}

/// Parses `--units`.
fn parse_units(s: &str) -> Result<Units, String> {
    match s {
        "sensor" => Ok(Units::Sensor),
        "photometric" => Ok(Units::Photometric),
        _ => Err(format!("expected sensor or photometric, found {s:?}")),
    }
}

/// The layers of `--aov` (one value to clap, not a list of values).
#[derive(Clone, Debug)]
pub struct AovList(Vec<Aov>);

/// Parses an `--aov` list.
fn parse_aovs(s: &str) -> Result<AovList, String> {
    Aov::parse_list(s).map(AovList)
}

impl RenderArgs {
    /// The command-line values that override the scene file.
    pub fn overrides(&self) -> Overrides {
        Overrides {
            spp: self.spp,
            integrator: self.integrator.clone(),
            outfile: self.outfile.clone(),
            seed: self.seed,
            cropwindow: self.cropwindow,
            aovs: self.aov.clone().map(|a| a.0).unwrap_or_default(),
            memory_limit: self.memory_limit,
            photometric: self.units == Units::Photometric,
        }
    }
}

/// The settings of `ov` that decide a render's passes, as `key=value` lines.
fn settings_text(ov: &Overrides) -> String {
    render::settings_text(ov)
}

/// The overrides stored by [`settings_text`].
fn overrides_from(text: &str) -> Result<Overrides> {
    render::overrides_from_settings(text).map_err(|e| anyhow::anyhow!("{e} in the state file"))
}

/// Raises the returned flag on SIGINT, SIGTERM and SIGHUP; a second signal
/// exits at once.
fn stop_flag() -> Result<Arc<AtomicBool>> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let flag = Arc::new(AtomicBool::new(false));
    for sig in [SIGINT, SIGTERM, SIGHUP] {
        signal_hook::flag::register_conditional_shutdown(sig, EXIT_INTERRUPTED, flag.clone())
            .context("installing signal handlers")?;
        signal_hook::flag::register(sig, flag.clone()).context("installing signal handlers")?;
    }
    Ok(flag)
}

/// Strategy image names of a film with `n` strategy layers.
fn strategy_names(setup: &RenderSetup) -> Vec<Option<String>> {
    let n = setup.film.layout().strategies;
    (0..64u32)
        .find(|&d| Visualize::strategy_count(d) == n)
        .map(Visualize::file_names)
        .unwrap_or_default()
}

/// Develops `state` and writes the image files, the false-colour ones with `fc`.
fn write_image(
    setup: &RenderSetup,
    state: &RenderState,
    exr: &Path,
    fc: &output::FalseColor,
) -> Result<()> {
    let overlay = setup
        .integrator
        .develop_overlay(&state.integrator_state, state.film.passes().count());
    let dev = develop(&setup.film, &state.film, overlay.as_deref());
    let attrs = render::exr_attributes(&dev, &state.integrator, state.total_passes);
    output::write(&dev, exr, &attrs, &strategy_names(setup), fc)
}

/// Where the output path came from, to start errors about it: the flag, or
/// the Film's `"filename"` (or its pbrt-v4 default).
fn outfile_origin(args: &RenderArgs, desc: &SceneDescription) -> String {
    if args.outfile.is_some() {
        return "--outfile".into();
    }
    let film = desc.film.as_ref();
    match film.and_then(|f| f.params.param_loc("filename")) {
        Some(loc) => format!("{loc}: Film \"filename\""),
        None => "the default output file (no --outfile, no Film \"filename\")".into(),
    }
}

/// Refuses false-colour flags without photometric layers; prints the
/// build's warnings and one about standard errors of a single pass.
fn check_units(args: &RenderArgs, setup: &RenderSetup) -> Result<()> {
    let photometric = setup.film.layout().photometric;
    if args.falsecolor_max.is_some() && !photometric {
        bail!(
            "--falsecolor-max needs --units photometric (the false-colour PNGs are of its layers)"
        );
    }
    for w in &setup.warnings {
        eprintln!("candela: warning: {w}");
    }
    if photometric && setup.sampler.samples_per_pixel() < 2 {
        eprintln!("candela: warning: --units photometric with 1 pass: the standard-error layers need 2 passes and are 0");
    }
    Ok(())
}

/// `candela render`; returns the exit code.
pub fn render(args: RenderArgs) -> Result<i32> {
    if let Some(n) = args.nthreads {
        if n == 0 {
            bail!("--nthreads must be at least 1");
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("setting up the thread pool")?;
    }
    let stop = stop_flag()?;
    let t0 = Instant::now();
    let ov = args.overrides();
    let desc = candela_scene::parse_file(&args.scene)?;
    let setup = build(&desc, &ov)?;
    check_units(&args, &setup)?;
    let exr = output::checked_exr(&setup.outfile, &outfile_origin(&args, &desc))?;
    let (mut state, opts, partial) = plan(&args, &desc, &setup, &ov, &exr)?;
    let checkpoint = opts.checkpoint.clone().unwrap_or_default();
    let load_time = t0.elapsed();
    let display = progress::display(args.quiet);
    let name = args
        .scene
        .file_name()
        .map_or("candela".into(), |n| n.to_string_lossy().to_string());
    let mut live = args
        .display_server
        .as_deref()
        .map(|a| Live::start(a, &name))
        .transpose()?;
    let outcome = render::render(&setup, &mut state, &opts, &stop, &display, &mut |st| {
        if let Some(l) = live.as_mut() {
            l.after_pass(&setup, st);
        }
    })?;
    let live_report = live.map(|l| l.finish(&setup, &state));
    let fc = output::FalseColor {
        scale: args.falsecolor_scale,
        max: args.falsecolor_max,
    };
    write_image(&setup, &state, &exr, &fc)?;
    let stopped_early = outcome.reason != StopReason::Finished;
    let write_state = partial.is_some() || args.checkpoint.is_some() || stopped_early;
    if write_state {
        state.save(&checkpoint)?;
    }
    if state.film.dropped() > 0 {
        eprintln!(
            "candela: warning: {} non-finite samples were dropped (a bug: please report)",
            state.film.dropped()
        );
    }
    report(
        &args,
        &setup,
        &state,
        &outcome,
        load_time,
        &exr,
        write_state.then_some(&checkpoint),
    );
    if let (Some(r), false) = (live_report, args.quiet) {
        eprintln!(
            "candela: live view: {} frames ({} delivered), {:.1} ms each to develop",
            r.frames,
            r.delivered,
            r.mean_build.as_secs_f64() * 1e3
        );
    }
    Ok(
        if outcome.reason == StopReason::Interrupted || stop.load(Ordering::Relaxed) {
            EXIT_INTERRUPTED
        } else {
            0
        },
    )
}

/// The state to start from, the loop's options and the partial-state path
/// (with `--pass-range`) of a render.
fn plan(
    args: &RenderArgs,
    desc: &candela_scene::SceneDescription,
    setup: &RenderSetup,
    ov: &Overrides,
    exr: &Path,
) -> Result<(RenderState, RenderOptions, Option<PathBuf>)> {
    let total = setup.sampler.samples_per_pixel() as u64;
    let passes = args.pass_range.unwrap_or((0, total));
    if passes.1 > total {
        bail!(
            "--pass-range {}..{} goes past the {total} passes of the render (set --spp)",
            passes.0,
            passes.1
        );
    }
    let kind = setup.integrator.kind();
    if args.pass_range.is_some() && !kind.independent_passes() {
        bail!("--pass-range: {kind}'s passes depend on each other and cannot be split (use ppm, or --checkpoint and --resume)");
    }
    let fp = render::fingerprint(desc, ov, setup.film.layout());
    let state = match &args.resume {
        Some(path) => resumed(path, fp, total, kind)?,
        None => render::new_state(setup, fp, total, &settings_text(ov)),
    };
    let partial = args.pass_range.map(|(a, b)| {
        args.checkpoint
            .clone()
            .unwrap_or_else(|| exr.with_extension(format!("passes-{a}-{b}.cndl")))
    });
    let checkpoint = partial
        .clone()
        .or_else(|| args.checkpoint.clone())
        .unwrap_or_else(|| exr.with_extension("cndl"));
    let opts = RenderOptions {
        passes,
        time_limit: args.time_limit.map(Duration::from_secs_f64),
        target_error: args.target_error,
        checkpoint: Some(checkpoint),
        checkpoint_every: args.checkpoint_every.map(Duration::from_secs_f64),
    };
    Ok((state, opts, partial))
}

/// The state in checkpoint `path`, checked against this render.
fn resumed(path: &Path, fp: u64, total: u64, kind: IntegratorKind) -> Result<RenderState> {
    let state = RenderState::load(path).with_context(|| "--resume".to_string())?;
    if state.fingerprint != fp || state.integrator != kind.name() {
        bail!(
            "--resume {}: the checkpoint is of another scene or other settings (same scene file, files and flags needed)",
            path.display()
        );
    }
    if state.total_passes != total {
        bail!(
            "--resume {}: the checkpoint was planned with {} passes, this render with {total}",
            path.display(),
            state.total_passes
        );
    }
    Ok(state)
}

/// The closing line on stderr.
fn report(
    args: &RenderArgs,
    setup: &RenderSetup,
    state: &RenderState,
    outcome: &render::Outcome,
    load: Duration,
    exr: &Path,
    checkpoint: Option<&PathBuf>,
) {
    if args.quiet {
        return;
    }
    let why = match outcome.reason {
        StopReason::Finished => String::new(),
        StopReason::Interrupted => " (interrupted)".into(),
        StopReason::TimeLimit => " (time limit)".into(),
        StopReason::TargetError(e) => format!(" (relative error {e:.2e} reached)"),
    };
    let done = state.film.passes().count();
    // The integrator's status at the last pass rendered (its iteration and
    // radius, VCM's stored light vertices).
    let status = setup
        .integrator
        .status(&state.integrator_state, done.saturating_sub(1))
        .map_or(String::new(), |s| format!(" ({s})"));
    eprintln!(
        "candela: {} with {done} of {} passes{why}{status}: load {:.2} s, render {:.2} s; wrote {}{}",
        setup.integrator.kind(),
        state.total_passes,
        load.as_secs_f64(),
        outcome.elapsed.as_secs_f64(),
        exr.display(),
        checkpoint.map_or(String::new(), |c| format!(" and {}", c.display()))
    );
}

/// `candela merge` flags.
#[derive(clap::Args)]
pub struct MergeArgs {
    /// The scene the parts were rendered from.
    pub scene: PathBuf,
    /// Partial renders (.cndl state files) with disjoint pass ranges.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// Output EXR path (a PNG is written beside it).
    #[arg(long, short)]
    pub outfile: PathBuf,
    /// Also write the merged state here (to merge or resume it further).
    #[arg(long)]
    pub checkpoint: Option<PathBuf>,
    /// As for `render` (photometric parts).
    #[arg(long, default_value = "log")]
    pub falsecolor_scale: FalseColorScale,
    /// As for `render` (photometric parts).
    #[arg(long, value_parser = parse_positive)]
    pub falsecolor_max: Option<f64>,
}

/// `candela merge`.
pub fn merge(args: MergeArgs) -> Result<()> {
    let exr = output::checked_exr(&args.outfile, "--outfile")?;
    let mut states = args
        .parts
        .iter()
        .map(|p| RenderState::load(p).map_err(anyhow::Error::from));
    let mut total = states.next().context("no parts to merge")??;
    for (s, path) in states.zip(args.parts.iter().skip(1)) {
        total
            .merge(&s?)
            .with_context(|| format!("merging {}", path.display()))?;
    }
    let ov = overrides_from(&total.settings)?;
    let desc = candela_scene::parse_file(&args.scene)?;
    let setup = build(&desc, &ov)?;
    if render::fingerprint(&desc, &ov, setup.film.layout()) != total.fingerprint {
        bail!(
            "the parts were not rendered from {} as it is now (the scene or a file it uses changed)",
            args.scene.display()
        );
    }
    let fc = output::FalseColor {
        scale: args.falsecolor_scale,
        max: args.falsecolor_max,
    };
    write_image(&setup, &total, &exr, &fc)?;
    if let Some(c) = &args.checkpoint {
        total.save(c)?;
    }
    eprintln!(
        "candela: merged passes {} into {}",
        total.film.passes(),
        exr.display()
    );
    Ok(())
}
