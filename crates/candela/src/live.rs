//! `--display-server HOST:PORT`: the developed image, every channel the EXR
//! gets, streamed to the tev viewer while the render runs
//! ([`candela_core::display::LiveView`]: the network never blocks the
//! render; a frame the viewer has not taken yet is replaced by the next).
//!
//! Developing a film costs time on the render thread, so a frame is built
//! after a pass only when the viewer has taken the previous one and at
//! least [`MIN_INTERVAL`] and ten times the last frame's build time have
//! passed since the last frame: at most 4 frames a second, and never more
//! than about a tenth of the render's time spent on frames. The final
//! image is always sent.

use anyhow::{Context, Result};
use candela_core::build::RenderSetup;
use candela_core::display::{Frame, LiveView, LiveViewOptions};
use candela_core::render::{self, RenderState};
use std::time::{Duration, Instant};

/// Least time between two frames.
pub const MIN_INTERVAL: Duration = Duration::from_millis(250);

/// A live view fed from the render loop.
pub struct Live {
    view: LiveView,
    last: Option<Instant>,
    build_time: Duration,
    frames: u64,
    total_build: Duration,
}

/// What the live view cost.
pub struct LiveReport {
    /// Frames built (the final one included).
    pub frames: u64,
    /// Mean time to develop and pack one frame.
    pub mean_build: Duration,
    /// Frames the viewer received whole.
    pub delivered: u64,
}

impl Live {
    /// Starts the view of image `name` at `address` (connects in the background).
    pub fn start(address: &str, name: &str) -> Result<Self> {
        let view = LiveView::start(LiveViewOptions::new(address, name), |w| {
            eprintln!("candela: warning: {w}")
        })
        .context("--display-server")?;
        Ok(Self {
            view,
            last: None,
            build_time: Duration::ZERO,
            frames: 0,
            total_build: Duration::ZERO,
        })
    }

    /// Called after every pass: sends a frame if the throttle allows.
    pub fn after_pass(&mut self, setup: &RenderSetup, state: &RenderState) {
        let due = self
            .last
            .is_none_or(|t| t.elapsed() >= MIN_INTERVAL.max(self.build_time * 10));
        if due && self.view.wants_frame() {
            self.send(setup, state);
        }
    }

    /// Sends the final image, waits (bounded by the view's timeouts) for it
    /// to go out, and reports the cost.
    pub fn finish(mut self, setup: &RenderSetup, state: &RenderState) -> LiveReport {
        self.send(setup, state);
        let frames = self.frames;
        let mean_build = self.total_build / frames.max(1) as u32;
        let stats = self.view.finish();
        LiveReport {
            frames,
            mean_build,
            delivered: stats.delivered,
        }
    }

    /// Develops `state` into a frame and hands it to the view.
    fn send(&mut self, setup: &RenderSetup, state: &RenderState) {
        let t = Instant::now();
        let dev = render::develop_state(setup, state);
        match Frame::from_exr_layers(
            dev.width,
            dev.height,
            &candela_core::render::exr_layers(&dev),
        ) {
            Ok(f) => self.view.send(f),
            Err(e) => eprintln!("candela: warning: live view: {e}"),
        }
        self.build_time = t.elapsed();
        self.total_build += self.build_time;
        self.frames += 1;
        self.last = Some(Instant::now());
    }
}
