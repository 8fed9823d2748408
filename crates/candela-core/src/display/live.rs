//! A live view on its own thread: the render loop hands over frames and never
//! waits for the network.
//!
//! The hand-over is a mailbox of one frame (a bounded channel whose `send`
//! replaces an unread frame instead of blocking): `send` takes a lock held
//! only for a pointer swap, and the worker thread sends what it finds there.
//! While the worker is busy writing a frame to a slow viewer, every newer
//! frame but the last is dropped, so the viewer always gets the newest image
//! once it catches up.
//!
//! Connection: the worker connects when started. On failure, or when the
//! viewer goes away mid-frame, it reports one warning and drops frames; it
//! tries again with the next frame once [`LiveViewOptions::retry_interval`]
//! has passed since the last attempt (never, if `None`), and a last time
//! when finishing with a frame undelivered. After a (re)connection it
//! creates the image before the first update. The warning callback is called
//! once per outage, not once per attempt.

use super::tev::{TevClient, DEFAULT_WRITE_TIMEOUT};
use super::{DisplayError, Frame};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Where and how the live view connects.
#[derive(Clone, Debug)]
pub struct LiveViewOptions {
    /// Viewer address, `host:port` (tev listens on 127.0.0.1:14158).
    pub address: String,
    /// The image's name in the viewer (tev's tab title).
    pub image_name: String,
    /// Longest wait for a connection, per resolved address.
    pub connect_timeout: Duration,
    /// Longest stall of one send before the viewer counts as gone.
    pub write_timeout: Duration,
    /// Least time between connection attempts after a failure; `None`: do
    /// not try again.
    pub retry_interval: Option<Duration>,
}

impl LiveViewOptions {
    /// Defaults: 1 s to connect, 5 s per stalled send, a retry every 2 s.
    pub fn new(address: impl Into<String>, image_name: impl Into<String>) -> Self {
        Self {
            address: address.into(),
            image_name: image_name.into(),
            connect_timeout: Duration::from_secs(1),
            write_timeout: DEFAULT_WRITE_TIMEOUT,
            retry_interval: Some(Duration::from_secs(2)),
        }
    }
}

/// Counts of what happened to the frames handed to [`LiveView::send`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LiveViewStats {
    /// Frames handed to `send`.
    pub submitted: u64,
    /// Frames replaced by a newer one before the worker took them.
    pub superseded: u64,
    /// Frames the worker took.
    pub taken: u64,
    /// Frames sent whole to the viewer.
    pub delivered: u64,
}

/// What the render thread and the worker share.
struct Shared {
    /// The mailbox.
    slot: Mutex<Slot>,
    /// Signalled when a frame arrives or on shutdown.
    wake: Condvar,
    /// `LiveViewStats` fields, in order.
    counts: [AtomicU64; 4],
}

/// The mailbox content.
#[derive(Default)]
struct Slot {
    /// The newest frame not yet taken.
    pending: Option<Frame>,
    /// Set by `finish`: send what is pending, then stop.
    shutdown: bool,
}

impl Shared {
    /// The mailbox, even if a thread panicked while holding it (the slot is
    /// always in a valid state).
    fn lock(&self) -> MutexGuard<'_, Slot> {
        self.slot.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Adds one to count `i`.
    fn count(&self, i: usize) {
        self.counts[i].fetch_add(1, Ordering::Relaxed);
    }
}

/// A tev live view fed from the render loop; see the module doc.
pub struct LiveView {
    /// Mailbox and counters.
    shared: Arc<Shared>,
    /// The worker; `None` once joined.
    worker: Option<JoinHandle<()>>,
}

impl LiveView {
    /// Starts the worker, which connects in the background; returns at once.
    /// `on_warning` gets one message per outage (on the worker thread).
    pub fn start(
        options: LiveViewOptions,
        on_warning: impl Fn(&str) + Send + 'static,
    ) -> Result<Self, DisplayError> {
        let shared = Arc::new(Shared {
            slot: Mutex::new(Slot::default()),
            wake: Condvar::new(),
            counts: Default::default(),
        });
        let worker = Worker {
            shared: Arc::clone(&shared),
            options,
            warn: Box::new(on_warning),
            client: None,
            layout: None,
            last_attempt: None,
            warned: false,
        };
        let handle = std::thread::Builder::new()
            .name("candela-live-view".into())
            .spawn(move || worker.run())
            .map_err(|e| {
                DisplayError::Invalid(format!("cannot start the live-view thread: {e}"))
            })?;
        Ok(Self {
            shared,
            worker: Some(handle),
        })
    }

    /// Hands `frame` to the viewer thread without waiting; a frame it has not
    /// taken yet is replaced.
    pub fn send(&self, frame: Frame) {
        self.shared.count(0);
        let old = self.shared.lock().pending.replace(frame);
        self.shared.wake.notify_one();
        if old.is_some() {
            self.shared.count(1);
        }
        // `old` is freed here, outside the lock.
    }

    /// Whether a new frame would be taken soon (none is waiting): the render
    /// loop may skip building frames while this is false.
    pub fn wants_frame(&self) -> bool {
        self.shared.lock().pending.is_none()
    }

    /// What happened to the frames so far.
    pub fn stats(&self) -> LiveViewStats {
        let c = |i: usize| self.shared.counts[i].load(Ordering::Relaxed);
        LiveViewStats {
            submitted: c(0),
            superseded: c(1),
            taken: c(2),
            delivered: c(3),
        }
    }

    /// Sends the last pending frame, closes the connection (the image stays
    /// open in tev) and stops the worker. Bounded by the connect and write
    /// timeouts. Dropping the view does the same.
    pub fn finish(mut self) -> LiveViewStats {
        self.stop();
        self.stats()
    }

    /// Signals shutdown and joins the worker.
    fn stop(&mut self) {
        if let Some(handle) = self.worker.take() {
            self.shared.lock().shutdown = true;
            self.shared.wake.notify_one();
            // A panic in the worker has nothing left to report.
            let _ = handle.join();
        }
    }
}

impl Drop for LiveView {
    fn drop(&mut self) {
        self.stop();
    }
}

/// The viewer thread's state.
struct Worker {
    /// Mailbox and counters.
    shared: Arc<Shared>,
    /// Connection settings.
    options: LiveViewOptions,
    /// Warning sink.
    warn: Box<dyn Fn(&str) + Send>,
    /// The connection, when up.
    client: Option<TevClient>,
    /// Size and channels of the image the viewer has, if any.
    layout: Option<(usize, usize, Vec<String>)>,
    /// When the last connection attempt was made.
    last_attempt: Option<Instant>,
    /// A warning was given for the current outage.
    warned: bool,
}

impl Worker {
    /// Connects, then shows frames until shutdown.
    fn run(mut self) {
        self.connect();
        loop {
            let (frame, last) = {
                let mut slot = self.shared.lock();
                while slot.pending.is_none() && !slot.shutdown {
                    slot = self
                        .shared
                        .wake
                        .wait(slot)
                        .unwrap_or_else(PoisonError::into_inner);
                }
                (slot.pending.take(), slot.shutdown)
            };
            let Some(frame) = frame else { break };
            self.shared.count(2);
            if self.client.is_none() && (last || self.may_retry()) {
                self.connect();
            }
            if self.client.is_some() {
                self.show(frame);
            }
            if last {
                break; // no frame can arrive after shutdown
            }
        }
        // Dropping the client closes the socket; tev keeps the image.
    }

    /// Whether the retry interval has passed since the last attempt.
    fn may_retry(&self) -> bool {
        match (self.options.retry_interval, self.last_attempt) {
            (Some(dt), Some(t)) => t.elapsed() >= dt,
            (Some(_), None) => true,
            (None, _) => false,
        }
    }

    /// Tries to connect; warns on the first failure of an outage.
    fn connect(&mut self) {
        self.last_attempt = Some(Instant::now());
        let o = &self.options;
        let client = TevClient::connect(&o.address, o.connect_timeout)
            .and_then(|c| c.set_write_timeout(Some(o.write_timeout)).map(|()| c));
        match client {
            Ok(c) => {
                self.client = Some(c);
                self.layout = None;
                self.warned = false;
            }
            Err(e) => self.fail(&e),
        }
    }

    /// Sends `frame`, creating the image first if the viewer lacks it.
    fn show(&mut self, frame: Frame) {
        let Some(client) = self.client.as_mut() else {
            return;
        };
        let name = &self.options.image_name;
        let (w, h) = (frame.width(), frame.height());
        let fresh = match &self.layout {
            Some((lw, lh, lc)) => (*lw, *lh) != (w, h) || lc.as_slice() != frame.channels(),
            None => true,
        };
        let mut sent = Ok(());
        if fresh {
            self.layout = None;
            sent = client.create_image(name, true, w, h, frame.channels());
        }
        let sent = sent.and_then(|()| client.update_frame(name, &frame));
        match sent {
            Ok(()) => {
                self.shared.count(3);
                if fresh {
                    self.layout = Some((w, h, frame.channels().to_vec()));
                }
            }
            Err(e) => {
                self.client = None;
                self.layout = None;
                self.fail(&e);
            }
        }
    }

    /// Records a failure; the first of an outage is reported.
    fn fail(&mut self, e: &DisplayError) {
        if !self.warned {
            self.warned = true;
            let then = match self.options.retry_interval {
                Some(dt) => format!("retrying every {dt:?}"),
                None => "not retrying".to_string(),
            };
            (self.warn)(&format!("live view: {e}; rendering goes on, {then}"));
        }
    }
}
