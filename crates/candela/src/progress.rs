//! A progress bar with ETA on stderr (indicatif), hidden by `--quiet`.

use candela_core::integrator::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// The render progress bar.
pub struct Bar {
    bar: ProgressBar,
}

impl Bar {
    /// A bar drawing to stderr, or a hidden one.
    pub fn new(quiet: bool) -> Self {
        let bar = ProgressBar::with_draw_target(
            None,
            if quiet {
                ProgressDrawTarget::hidden()
            } else {
                ProgressDrawTarget::stderr()
            },
        );
        Self { bar }
    }
}

impl Progress for Bar {
    fn start(&self, total: u64, unit: &str) {
        self.bar.set_length(total);
        let style = ProgressStyle::with_template(&format!(
            "{{elapsed_precise}} [{{bar:40}}] {{percent:>3}}% {{pos}}/{{len}} {unit} ETA {{eta}} {{msg}}"
        ))
        .unwrap_or_else(|_| ProgressStyle::default_bar());
        self.bar.set_style(style);
    }
    fn advance(&self, done: u64) {
        self.bar.inc(done);
    }
    fn finish(&self) {
        self.bar.finish_and_clear();
    }
    fn message(&self, msg: &str) {
        self.bar.set_message(msg.to_string());
    }
}
