//! Live view: the image being rendered, shown in the [tev] viewer while the
//! render runs, as pbrt-v4 does with `--display-server HOST:PORT`
//! [pbrt-v4 `src/pbrt/util/display.cpp`].
//!
//! Two layers:
//! - [`tev`]: tev's TCP protocol. Encoding functions build packets (pure, unit
//!   tested) and [`TevClient`] sends them over a `TcpStream`: create an image,
//!   update a rectangle of some channels in tiles of at most
//!   [`tev::TILE_SIZE`]² pixels, close an image.
//! - [`LiveView`]: a client on its own thread behind a one-frame mailbox. The
//!   render loop calls [`LiveView::send`] after each pass; `send` never
//!   waits for the network. A frame not yet picked up is replaced by the
//!   next one (latest wins), so a slow viewer sees fewer frames and the
//!   render never slows down. A viewer that is absent or goes away costs one
//!   warning; the view then reconnects now and then (see
//!   [`LiveViewOptions::retry_interval`]) and recreates the image, so tev can
//!   be started after the render.
//!
//! A [`Frame`] is `width × height` pixels of `channels.len()` interleaved
//! `f32` values, row-major, top row first:
//! `data[(y·width + x)·channels.len() + c]`. Channel names follow the EXR
//! layer convention (`R`, `G`, `B`, `albedo.R`, `depth.Y`), which tev shows
//! as layers.
//!
//! [tev]: https://github.com/Tom94/tev

pub mod decode;
mod frame;
mod live;
pub mod tev;

#[cfg(test)]
mod tests;

pub use frame::Frame;
pub use live::{LiveView, LiveViewOptions, LiveViewStats};
pub use tev::TevClient;

use thiserror::Error;

/// Failure of the live view.
#[derive(Debug, Error)]
pub enum DisplayError {
    /// The viewer address could not be resolved.
    #[error("display server {address}: {msg}")]
    Address {
        /// The address as given.
        address: String,
        /// What is wrong.
        msg: String,
    },
    /// No connection to the viewer.
    #[error("display server {address}: cannot connect: {source}")]
    Connect {
        /// The address as given.
        address: String,
        /// Cause (of the last address tried).
        source: std::io::Error,
    },
    /// Sending to the viewer failed.
    #[error("display server {address}: {source}")]
    Send {
        /// The viewer's address.
        address: String,
        /// Cause.
        source: std::io::Error,
    },
    /// A frame, name or rectangle the protocol cannot carry.
    #[error("live view: {0}")]
    Invalid(String),
}
