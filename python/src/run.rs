//! Running a render from Python without holding the GIL, and stopping it on
//! Ctrl-C.
//!
//! The render loop runs in a thread of its own. The calling thread waits
//! for it with the GIL released (other Python threads run meanwhile), and
//! every [`POLL`] it takes the GIL back for a moment to run Python's signal
//! handlers (`Python::check_signals`) and the progress callback. When a
//! handler raises (Ctrl-C raises `KeyboardInterrupt`) or the callback does,
//! the loop's stop flag is raised: the integrator abandons the pass under
//! way within a tile, the loop returns, and only then is the exception
//! passed on, so no render thread outlives the call. Off the main thread
//! (a Dask worker's task thread) Python runs no signal handlers and the
//! check does nothing; the render then ends with its passes.

use crate::errors;
use candela_core::build::RenderSetup;
use candela_core::render::{self, Outcome, Progress, RenderOptions, RenderState, Snapshot};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::sync::atomic::AtomicBool;
use std::sync::atomic::Ordering;
use std::sync::Mutex;
use std::time::Duration;

/// How often the waiting thread looks at signals and progress.
const POLL: Duration = Duration::from_millis(50);

/// The last progress the loop reported: (passes done, passes planned, seconds).
#[derive(Default)]
struct Latest(Mutex<Option<(u64, u64, f64)>>);

impl Progress for Latest {
    fn update(&self, s: &Snapshot) {
        if let Ok(mut l) = self.0.lock() {
            *l = Some((s.passes_done, s.passes_goal, s.elapsed.as_secs_f64()));
        }
    }
}

impl Latest {
    /// Calls `cb(done, total, seconds)` if the pass count changed since `shown`.
    fn report(&self, cb: &Bound<'_, PyAny>, shown: &mut Option<u64>) -> PyResult<()> {
        let latest = self.0.lock().ok().and_then(|l| *l);
        match latest {
            Some((done, goal, secs)) if *shown != Some(done) => {
                *shown = Some(done);
                cb.call1((done, goal, secs)).map(|_| ())
            }
            _ => Ok(()),
        }
    }
}

/// The rayon pool of `threads` workers, or `None` for the global pool.
fn pool(threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    match threads {
        None => Ok(None),
        Some(0) => Err(PyValueError::new_err("threads must be at least 1")),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map(Some)
            .map_err(|e| PyRuntimeError::new_err(format!("starting {n} render threads: {e}"))),
    }
}

/// Renders the passes of `opts` into `state` (see the module doc).
pub fn run(
    py: Python<'_>,
    setup: &RenderSetup,
    state: &mut RenderState,
    opts: &RenderOptions,
    threads: Option<usize>,
    progress: Option<&Bound<'_, PyAny>>,
) -> PyResult<Outcome> {
    let pool = pool(threads)?;
    let stop = AtomicBool::new(false);
    let latest = Latest::default();
    std::thread::scope(|s| {
        let worker = s.spawn(|| {
            let mut go = || render::render(setup, state, opts, &stop, &latest, &mut |_| {});
            match &pool {
                Some(p) => p.install(go),
                None => go(),
            }
        });
        let mut failure: Option<PyErr> = None;
        let mut shown = None;
        while !worker.is_finished() {
            py.detach(|| wait(&worker));
            if failure.is_some() {
                continue;
            }
            let checked = py.check_signals().and_then(|()| match progress {
                Some(cb) => latest.report(cb, &mut shown),
                None => Ok(()),
            });
            if let Err(e) = checked {
                stop.store(true, Ordering::Relaxed);
                failure = Some(e);
            }
        }
        let result = worker.join();
        if let Some(e) = failure {
            return Err(e);
        }
        if let Some(cb) = progress {
            latest.report(cb, &mut shown)?;
        }
        match result {
            Ok(Ok(outcome)) => Ok(outcome),
            Ok(Err(e)) => Err(errors::from_render(&e)),
            Err(_) => Err(PyRuntimeError::new_err("the render thread panicked")),
        }
    })
}

/// Sleeps until `worker` finishes or [`POLL`] has passed.
fn wait<T>(worker: &std::thread::ScopedJoinHandle<'_, T>) {
    let step = Duration::from_millis(2);
    let mut slept = Duration::ZERO;
    while slept < POLL && !worker.is_finished() {
        std::thread::sleep(step);
        slept += step;
    }
}
