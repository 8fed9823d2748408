//! Render progress on stderr: a bar with rate and ETA on a terminal
//! (indicatif), plain lines every ten seconds otherwise (CI logs, pipes),
//! nothing with `--quiet`.

use candela_core::render::{Progress, Snapshot};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// How progress is shown.
pub enum Display {
    /// A bar on a terminal.
    Bar(ProgressBar),
    /// A line every `every`.
    Lines {
        /// When the last line was printed.
        last: Mutex<Option<Instant>>,
        /// Period.
        every: Duration,
    },
    /// Nothing.
    Quiet,
}

/// Picks the display for stderr.
pub fn display(quiet: bool) -> Display {
    if quiet {
        Display::Quiet
    } else if std::io::stderr().is_terminal() {
        let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
        let style = ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {percent:>3}% ETA {eta} {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar());
        bar.set_style(style);
        Display::Bar(bar)
    } else {
        Display::Lines {
            last: Mutex::new(None),
            every: Duration::from_secs(10),
        }
    }
}

/// "pass 12/64, 1.25 M samples/s[, 0.6 M light paths/s], status".
fn describe(s: &Snapshot) -> String {
    let passes_this_run = s.passes_done - s.passes_at_start;
    let work = passes_this_run * s.work_per_pass + s.work_in_pass;
    let secs = s.elapsed.as_secs_f64();
    let per_sec = |n: f64| if secs > 0.0 { n / secs } else { 0.0 };
    let mut msg = format!(
        "pass {}/{}, {:.3} M {}/s",
        s.passes_done,
        s.passes_goal,
        per_sec(work as f64) / 1e6,
        s.unit
    );
    if s.light_paths_per_pass > 0 && s.work_per_pass > 0 {
        // Light paths of finished passes, and the pass under way's share of them.
        let frac = s.work_in_pass as f64 / s.work_per_pass as f64;
        let light = (passes_this_run as f64 + frac.min(1.0)) * s.light_paths_per_pass as f64;
        msg.push_str(&format!(", {:.3} M light paths/s", per_sec(light) / 1e6));
    }
    if let Some(st) = &s.status {
        msg.push_str(", ");
        msg.push_str(st);
    }
    msg
}

/// Work units done and planned in this run.
fn position(s: &Snapshot) -> (u64, u64) {
    let run = s.passes_goal - s.passes_at_start;
    let done = (s.passes_done - s.passes_at_start) * s.work_per_pass + s.work_in_pass;
    let total = run * s.work_per_pass;
    (done.min(total), total)
}

impl Progress for Display {
    fn update(&self, s: &Snapshot) {
        match self {
            Display::Bar(bar) => {
                let (pos, len) = position(s);
                bar.set_length(len.max(1));
                bar.set_position(pos);
                bar.set_message(describe(s));
            }
            Display::Lines { last, every } => {
                let Ok(mut last) = last.lock() else { return };
                if last.is_some_and(|t| t.elapsed() < *every) {
                    return;
                }
                *last = Some(Instant::now());
                let (pos, len) = position(s);
                let pct = if len > 0 {
                    100.0 * pos as f64 / len as f64
                } else {
                    100.0
                };
                let eta = if pos > 0 {
                    let secs = s.elapsed.as_secs_f64() * (len - pos) as f64 / pos as f64;
                    format!("{secs:.0} s")
                } else {
                    "?".to_string()
                };
                eprintln!(
                    "candela: {:.0} s, {pct:.0}%, ETA {eta}: {}",
                    s.elapsed.as_secs_f64(),
                    describe(s)
                );
            }
            Display::Quiet => {}
        }
    }

    fn finish(&self, _s: &Snapshot) {
        if let Display::Bar(bar) = self {
            bar.finish_and_clear();
        }
    }
}
