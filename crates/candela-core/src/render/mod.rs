//! The render loop: the one place that owns the pass sequence, threads'
//! work, progress, stopping, budgets and checkpoints (the integrator owns
//! one pass, [`crate::integrator::Integrator::render_pass`]).
//!
//! ```text
//! for pass in passes not yet in the state {
//!     stop requested, time or error budget spent?  → stop
//!     integrator.render_pass(ctx, pass, &mut integrator_state, &mut block)
//!     surface::render_surface_pass(ctx, pass, &mut block)   (first-hit layers and illuminance, if any)
//!     film_state.add_pass(pass, block)            (exact, fixed point)
//!     on_pass(state)                              (live view, …)
//!     checkpoint if due
//! }
//! ```
//!
//! Passes are pure functions of their index and the film adds them in fixed
//! point, so an interrupted render resumed from its state, a render split
//! into pass ranges and merged, and one uninterrupted run give the same bits.
//!
//! **Budgets.** `time_limit` never starts a pass that the mean pass time so
//! far says would end after the limit (the first pass always runs), so a
//! render stops within one pass of it. `target_error` stops once every
//! output channel's relative standard error of the image mean, estimated
//! from the spread of the per-pass image means (s/√n over n ≥ 8 independent
//! passes, [`crate::film::FilmState::relative_error`]), is below the target;
//! SPPM's passes are not independent, so it has no such estimate.

mod exr;
mod fingerprint;
mod settings;
mod state;
pub mod surface;

pub use exr::{encode_exr, exr_attributes, exr_layers};
pub use fingerprint::fingerprint;
pub use settings::{overrides_from_settings, parse_cropwindow, settings_text};
pub use state::{RenderState, StateError};

use crate::build::RenderSetup;
use crate::integrator::{IntegratorKind, PassOutcome, RenderContext};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};
use thiserror::Error;

/// Fewest passes from which the error estimate of `target_error` is trusted.
pub const MIN_PASSES_FOR_ERROR: u64 = 8;

/// How to run a render.
#[derive(Clone, Debug, Default)]
pub struct RenderOptions {
    /// Passes [a, b) to render (those already in the state are skipped).
    pub passes: (u64, u64),
    /// Stop before a pass that would end after this much time.
    pub time_limit: Option<Duration>,
    /// Stop once the relative standard error of the image mean is below this.
    pub target_error: Option<f64>,
    /// Write the state here every `checkpoint_every`.
    pub checkpoint: Option<PathBuf>,
    /// Period of checkpoints.
    pub checkpoint_every: Option<Duration>,
}

/// Why the loop stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StopReason {
    /// Every pass of the range is in the state.
    Finished,
    /// A stop was requested (signal, Ctrl-C); the pass under way was abandoned.
    Interrupted,
    /// The time limit was reached.
    TimeLimit,
    /// The error target was reached, with this estimated relative error.
    TargetError(f64),
}

/// What a render loop did.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Why it stopped.
    pub reason: StopReason,
    /// Passes this run rendered.
    pub passes_rendered: u64,
    /// Time spent in this run.
    pub elapsed: Duration,
}

/// A render that cannot run.
#[derive(Debug, Error)]
pub enum RenderError {
    /// Options that do not fit the integrator or the state.
    #[error("{0}")]
    Options(String),
    /// A checkpoint could not be written.
    #[error(transparent)]
    State(#[from] StateError),
}

/// One look at a running render, for progress displays.
#[derive(Clone, Debug)]
pub struct Snapshot {
    /// Passes in the state (resumed ones included).
    pub passes_done: u64,
    /// Passes the state will hold when this run ends (without budgets).
    pub passes_goal: u64,
    /// Passes already in the state when this run started.
    pub passes_at_start: u64,
    /// Work units done in the pass under way.
    pub work_in_pass: u64,
    /// Work units of one pass.
    pub work_per_pass: u64,
    /// Name of the work units.
    pub unit: &'static str,
    /// Light subpaths per pass when they are not the units (0: none shown).
    pub light_paths_per_pass: u64,
    /// Time since this run started.
    pub elapsed: Duration,
    /// Integrator status (radius, …).
    pub status: Option<String>,
}

/// Receives the render's progress (called from the loop and from a ticker thread).
pub trait Progress: Sync {
    /// Called every few hundred milliseconds and after every pass.
    fn update(&self, snap: &Snapshot);
    /// Called once when the loop ends.
    fn finish(&self, _snap: &Snapshot) {}
}

/// A progress sink that ignores everything.
pub struct NoProgress;

impl Progress for NoProgress {
    fn update(&self, _snap: &Snapshot) {}
}

/// A fresh state for `setup` with the fingerprint `fp`, `total_passes`
/// planned, and the command-line `settings` it was made with.
pub fn new_state(setup: &RenderSetup, fp: u64, total_passes: u64, settings: &str) -> RenderState {
    let work = AtomicU64::new(0);
    let cancel = AtomicBool::new(false);
    let ctx = context(setup, &cancel, &work);
    RenderState {
        fingerprint: fp,
        integrator: setup.integrator.kind().name().to_string(),
        total_passes,
        settings: settings.to_string(),
        film: setup.film.state(),
        integrator_state: setup.integrator.initial_state(&ctx),
    }
}

fn context<'a>(
    setup: &'a RenderSetup,
    cancel: &'a AtomicBool,
    work: &'a AtomicU64,
) -> RenderContext<'a> {
    RenderContext {
        scene: &setup.scene,
        camera: &setup.camera,
        sampler: &setup.sampler,
        film: &setup.film,
        cancel,
        work,
    }
}

/// Checks that `opts` and `state` fit the integrator of `setup`.
pub fn check_options(
    setup: &RenderSetup,
    state: &RenderState,
    opts: &RenderOptions,
) -> Result<(), RenderError> {
    let kind = setup.integrator.kind();
    if state.film.layout != *setup.film.layout() || state.film.pixels != setup.film.pixel_count() {
        return Err(RenderError::Options(
            "the state is of a film with other pixel bounds or layers".into(),
        ));
    }
    if state.integrator != kind.name() {
        return Err(RenderError::Options(format!(
            "the state is of a \"{}\" render, not \"{}\"",
            state.integrator,
            kind.name()
        )));
    }
    if kind == IntegratorKind::Sppm {
        let layout = setup.film.layout();
        if layout.spectral.is_some() {
            return Err(RenderError::Options(
                "Film \"spectral\" cannot be rendered with sppm: its radiance estimate τ is accumulated in RGB (use ppm, whose passes fill the spectral buckets)".into(),
            ));
        }
        if layout.variance {
            return Err(RenderError::Options(
                "the variance layer (--aov variance, Film \"gbuffer\") needs independent passes; SPPM's iterations depend on each other (use ppm)".into(),
            ));
        }
        if opts.target_error.is_some() {
            return Err(RenderError::Options(
                "--target-error needs independent passes; SPPM's iterations depend on each other (use ppm)".into(),
            ));
        }
        let done = state.film.passes();
        let contiguous = done.ranges().is_empty() || done.ranges() == [(0, done.count())];
        if !contiguous || opts.passes.0 > done.count() {
            return Err(RenderError::Options(
                "SPPM's iterations depend on each other: it cannot render a pass range (use ppm, or --checkpoint/--resume)".into(),
            ));
        }
    }
    Ok(())
}

/// Runs the passes of `opts` not yet in `state`, until done, stopped or out of budget.
pub fn render(
    setup: &RenderSetup,
    state: &mut RenderState,
    opts: &RenderOptions,
    stop: &AtomicBool,
    progress: &dyn Progress,
    on_pass: &mut dyn FnMut(&RenderState),
) -> Result<Outcome, RenderError> {
    check_options(setup, state, opts)?;
    let work = AtomicU64::new(0);
    let ctx = context(setup, stop, &work);
    let pw = setup.integrator.pass_work(&ctx);
    let todo: Vec<u64> = state
        .film
        .passes()
        .missing_in(opts.passes.0, opts.passes.1)
        .collect();
    let at_start = state.film.passes().count();
    let t0 = Instant::now();
    let shared = Shared {
        done: AtomicU64::new(at_start),
        // The first pass this process renders: not 0 after --resume or in a
        // --pass-range (the progress line said "iteration 1" there).
        status: std::sync::Mutex::new(
            setup
                .integrator
                .status(&state.integrator_state, todo.first().copied().unwrap_or(0)),
        ),
        finished: AtomicBool::new(false),
    };
    let snap = || Snapshot {
        passes_done: shared.done.load(Ordering::Relaxed),
        passes_goal: at_start + todo.len() as u64,
        passes_at_start: at_start,
        work_in_pass: work.load(Ordering::Relaxed),
        work_per_pass: pw.units,
        unit: pw.unit,
        light_paths_per_pass: pw.light_paths,
        elapsed: t0.elapsed(),
        status: shared.status.lock().map(|s| s.clone()).unwrap_or(None),
    };
    let result = std::thread::scope(|s| {
        let ticker = s.spawn(|| {
            while !shared.finished.load(Ordering::Relaxed) {
                progress.update(&snap());
                std::thread::park_timeout(Duration::from_millis(250));
            }
        });
        let r = run_passes(setup, state, opts, &ctx, &todo, &shared, t0, &mut |st| {
            progress.update(&snap());
            on_pass(st);
        });
        shared.finished.store(true, Ordering::Relaxed);
        ticker.thread().unpark();
        r
    });
    let (reason, passes_rendered) = result?;
    progress.finish(&snap());
    Ok(Outcome {
        reason,
        passes_rendered,
        elapsed: t0.elapsed(),
    })
}

/// What the loop shares with the progress ticker.
struct Shared {
    done: AtomicU64,
    status: std::sync::Mutex<Option<String>>,
    finished: AtomicBool,
}

/// The pass loop of [`render`]; returns why it stopped and the passes rendered.
fn run_passes(
    setup: &RenderSetup,
    state: &mut RenderState,
    opts: &RenderOptions,
    ctx: &RenderContext<'_>,
    todo: &[u64],
    shared: &Shared,
    t0: Instant,
    after_pass: &mut dyn FnMut(&RenderState),
) -> Result<(StopReason, u64), RenderError> {
    let mut block = setup.film.block();
    let mut last_checkpoint = Instant::now();
    let mut rendered = 0u64;
    for &pass in todo {
        if let Some(r) = budget_spent(opts, state, t0.elapsed(), rendered, ctx.cancel) {
            return Ok((r, rendered));
        }
        block.clear();
        ctx.work.store(0, Ordering::Relaxed);
        let outcome =
            setup
                .integrator
                .render_pass(ctx, pass, &mut state.integrator_state, &mut block);
        if outcome == PassOutcome::Cancelled {
            return Ok((StopReason::Interrupted, rendered));
        }
        if setup.film.layout().needs_first_hit()
            && surface::render_surface_pass(ctx, pass, &mut block) == PassOutcome::Cancelled
        {
            return Ok((StopReason::Interrupted, rendered));
        }
        state.film.add_pass(&setup.film, pass, &block);
        rendered += 1;
        shared
            .done
            .store(state.film.passes().count(), Ordering::Relaxed);
        if let Ok(mut st) = shared.status.lock() {
            *st = setup.integrator.status(&state.integrator_state, pass + 1);
        }
        after_pass(state);
        if let (Some(path), Some(every)) = (&opts.checkpoint, opts.checkpoint_every) {
            if last_checkpoint.elapsed() >= every {
                state.save(path)?;
                last_checkpoint = Instant::now();
            }
        }
    }
    Ok((StopReason::Finished, rendered))
}

/// Whether to stop before the next pass, having rendered `rendered` passes in `elapsed`.
fn budget_spent(
    opts: &RenderOptions,
    state: &RenderState,
    elapsed: Duration,
    rendered: u64,
    stop: &AtomicBool,
) -> Option<StopReason> {
    if stop.load(Ordering::Relaxed) {
        return Some(StopReason::Interrupted);
    }
    if let Some(target) = opts.target_error {
        if state.film.passes().count() >= MIN_PASSES_FOR_ERROR {
            if let Some(e) = state.film.relative_error() {
                let worst = e.iter().copied().fold(0.0f64, f64::max);
                if worst < target {
                    return Some(StopReason::TargetError(worst));
                }
            }
        }
    }
    if let (Some(limit), true) = (opts.time_limit, rendered > 0) {
        let mean = elapsed / rendered as u32;
        if elapsed + mean > limit {
            return Some(StopReason::TimeLimit);
        }
    }
    None
}

/// Renders every pass of `setup` in this thread pool with no progress,
/// budget or checkpoint, and develops the film (for tests, benchmarks and
/// library users that just want the image).
pub fn render_all(setup: &RenderSetup) -> (crate::film::Developed, RenderState) {
    let total = setup.sampler.samples_per_pixel() as u64;
    let mut state = new_state(setup, 0, total, "");
    let opts = RenderOptions {
        passes: (0, total),
        ..RenderOptions::default()
    };
    let stop = AtomicBool::new(false);
    // Without a checkpoint path the loop cannot fail.
    let _ = render(setup, &mut state, &opts, &stop, &NoProgress, &mut |_| {});
    (develop_state(setup, &state), state)
}

/// Develops `state` with the integrator's overlay (SPPM).
pub fn develop_state(setup: &RenderSetup, state: &RenderState) -> crate::film::Developed {
    let overlay = setup
        .integrator
        .develop_overlay(&state.integrator_state, state.film.passes().count());
    crate::film::develop::develop(&setup.film, &state.film, overlay.as_deref())
}
