//! tev's IPC protocol over TCP [tev `include/tev/Ipc.h`, `src/Ipc.cpp`;
//! pbrt-v4 `src/pbrt/util/display.cpp`].
//!
//! A connection carries a stream of packets and nothing comes back. Every
//! packet starts with its total length in bytes, *including* these four, as
//! a little-endian `u32`, then one byte of packet type. Integers are
//! little-endian, booleans one byte (0 or 1), strings UTF-8 ended by a NUL.
//! The packets used here:
//!
//! | type | body after the type byte |
//! |---|---|
//! | 4 `CreateImage` | grab focus: bool, name: str, width: i32, height: i32, n: i32, n × channel name: str |
//! | 6 `UpdateImageV3` | grab focus: bool, name: str, n: i32, n × channel name: str, x, y, width, height: i32, n × offset: i64, n × stride: i64, floats: f32… |
//! | 2 `CloseImage` | name: str |
//!
//! In `UpdateImageV3`, sample c of pixel p of the `width × height` rectangle
//! at (x, y) is float number `offset[c] + p·stride[c]`, p counting the
//! rectangle's pixels row-major; the packet holds exactly
//! `max_c(offset[c] + (width·height − 1)·stride[c]) + 1` floats. We send the
//! rectangle's channels interleaved (offset c, stride n), as tev's own
//! Python client does. pbrt-v4 sends the older `UpdateImage` (type 3: one
//! channel per packet, planar); V3 carries several channels per packet
//! and is what current tev writes itself.
//!
//! Updates go out in tiles of at most [`TILE_SIZE`]² pixels (pbrt-v4's and
//! tev's Python client's 128) and at most [`MAX_PACKET_FLOATS`] samples, so
//! one packet stays under ~256 KiB whatever the image and channel count:
//! tev buffers a whole packet before it decodes it.

use super::{DisplayError, Frame};
use std::io::Write;
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::time::Duration;

/// tev's default port.
pub const DEFAULT_PORT: u16 = 14158;
/// Largest tile side of an update, in pixels.
pub const TILE_SIZE: usize = 128;
/// Most samples in one update packet (a full tile of 4 channels).
pub const MAX_PACKET_FLOATS: usize = TILE_SIZE * TILE_SIZE * 4;
/// How long a send may stall before the viewer counts as gone.
pub const DEFAULT_WRITE_TIMEOUT: Duration = Duration::from_secs(5);

/// tev's packet types [tev `IpcPacket::EType`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum PacketType {
    /// Open a file on the viewer's machine (path and channel selector in one string).
    OpenImage = 0,
    /// Reload an image from its file.
    ReloadImage = 1,
    /// Close an image.
    CloseImage = 2,
    /// Update one channel of a rectangle, planar.
    UpdateImage = 3,
    /// Create an empty image with named channels.
    CreateImage = 4,
    /// Update several channels of a rectangle, planar.
    UpdateImageV2 = 5,
    /// Update several channels of a rectangle with per-channel offsets and strides.
    UpdateImageV3 = 6,
    /// Open a file (path and channel selector apart).
    OpenImageV2 = 7,
    /// Draw vector graphics over an image.
    VectorGraphics = 8,
}

/// A pixel rectangle: `width × height` pixels with top-left corner (x, y).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rect {
    /// Left column.
    pub x: usize,
    /// Top row.
    pub y: usize,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
}

impl Rect {
    /// The whole of `frame`.
    pub fn of(frame: &Frame) -> Self {
        Self {
            x: 0,
            y: 0,
            width: frame.width(),
            height: frame.height(),
        }
    }
}

/// A packet being built: the length placeholder, then the type.
struct Packet(Vec<u8>);

impl Packet {
    /// An empty packet of type `t`.
    fn new(t: PacketType, capacity: usize) -> Self {
        let mut v = Vec::with_capacity(capacity + 5);
        v.extend_from_slice(&[0; 4]);
        v.push(t as u8);
        Packet(v)
    }

    /// Appends a boolean byte.
    fn bool(&mut self, b: bool) {
        self.0.push(u8::from(b));
    }

    /// Appends a NUL-terminated string; NULs inside are refused.
    fn str(&mut self, s: &str) -> Result<(), DisplayError> {
        if s.contains('\0') {
            return Err(DisplayError::Invalid(format!("name {s:?} holds a NUL")));
        }
        self.0.extend_from_slice(s.as_bytes());
        self.0.push(0);
        Ok(())
    }

    /// Appends an `i32`; values beyond its range are refused.
    fn i32(&mut self, v: usize) -> Result<(), DisplayError> {
        let v = i32::try_from(v).map_err(|_| DisplayError::Invalid(format!("{v} exceeds i32")))?;
        self.0.extend_from_slice(&v.to_le_bytes());
        Ok(())
    }

    /// Appends an `i64`.
    fn i64(&mut self, v: usize) -> Result<(), DisplayError> {
        let v = i64::try_from(v).map_err(|_| DisplayError::Invalid(format!("{v} exceeds i64")))?;
        self.0.extend_from_slice(&v.to_le_bytes());
        Ok(())
    }

    /// Writes the total length into the first four bytes.
    fn finish(mut self) -> Result<Vec<u8>, DisplayError> {
        let n = u32::try_from(self.0.len())
            .map_err(|_| DisplayError::Invalid("packet longer than 4 GiB".into()))?;
        self.0[..4].copy_from_slice(&n.to_le_bytes());
        Ok(self.0)
    }
}

/// The `CreateImage` packet: an image `name` of `width × height` pixels and
/// the given channels, all zero.
pub fn encode_create_image(
    name: &str,
    grab_focus: bool,
    width: usize,
    height: usize,
    channels: &[String],
) -> Result<Vec<u8>, DisplayError> {
    let names: usize = channels.iter().map(|c| c.len() + 1).sum();
    let mut p = Packet::new(PacketType::CreateImage, name.len() + names + 14);
    p.bool(grab_focus);
    p.str(name)?;
    p.i32(width)?;
    p.i32(height)?;
    p.i32(channels.len())?;
    for c in channels {
        p.str(c)?;
    }
    p.finish()
}

/// The `UpdateImageV3` packet carrying channels `channels` (indices into
/// `frame.channels()`) of rectangle `rect` of `frame`; it holds all of
/// `rect` however large (see [`update_packets`] for bounded packets).
pub fn encode_update_image(
    name: &str,
    frame: &Frame,
    channels: &[usize],
    rect: Rect,
) -> Result<Vec<u8>, DisplayError> {
    let inside = rect
        .x
        .checked_add(rect.width)
        .is_some_and(|r| r <= frame.width())
        && rect
            .y
            .checked_add(rect.height)
            .is_some_and(|b| b <= frame.height());
    if !inside || rect.width == 0 || rect.height == 0 {
        return Err(DisplayError::Invalid(format!(
            "rectangle {rect:?} is empty or outside the {}x{} frame",
            frame.width(),
            frame.height()
        )));
    }
    let all = frame.channels();
    if channels.is_empty() || channels.iter().any(|&c| c >= all.len()) {
        return Err(DisplayError::Invalid(format!(
            "channels {channels:?} of a frame with {}",
            all.len()
        )));
    }
    let k = channels.len();
    let floats = rect.width * rect.height * k;
    let names: usize = channels.iter().map(|&c| all[c].len() + 1).sum();
    let mut p = Packet::new(
        PacketType::UpdateImageV3,
        name.len() + names + 22 + 16 * k + 4 * floats,
    );
    p.bool(false);
    p.str(name)?;
    p.i32(k)?;
    for &c in channels {
        p.str(&all[c])?;
    }
    for v in [rect.x, rect.y, rect.width, rect.height] {
        p.i32(v)?;
    }
    for c in 0..k {
        p.i64(c)?; // offset: interleaved samples
    }
    for _ in 0..k {
        p.i64(k)?; // stride
    }
    for y in rect.y..rect.y + rect.height {
        for x in rect.x..rect.x + rect.width {
            let px = frame.pixel(x, y);
            for &c in channels {
                p.0.extend_from_slice(&px[c].to_le_bytes());
            }
        }
    }
    p.finish()
}

/// The `CloseImage` packet for image `name`.
pub fn encode_close_image(name: &str) -> Result<Vec<u8>, DisplayError> {
    let mut p = Packet::new(PacketType::CloseImage, name.len() + 1);
    p.str(name)?;
    p.finish()
}

/// The tiles of `rect`: row-major, at most `tile × tile` pixels each,
/// covering every pixel once.
pub fn tiles(rect: Rect, tile: usize) -> impl Iterator<Item = Rect> {
    let tile = tile.max(1);
    let ys = (rect.y..rect.y + rect.height).step_by(tile);
    ys.flat_map(move |y| {
        (rect.x..rect.x + rect.width)
            .step_by(tile)
            .map(move |x| Rect {
                x,
                y,
                width: tile.min(rect.x + rect.width - x),
                height: tile.min(rect.y + rect.height - y),
            })
    })
}

/// The update packets for channels `channels` of `rect`: one per tile and
/// group of channels, each at most [`MAX_PACKET_FLOATS`] samples.
pub fn update_packets<'a>(
    name: &'a str,
    frame: &'a Frame,
    channels: &'a [usize],
    rect: Rect,
) -> impl Iterator<Item = Result<Vec<u8>, DisplayError>> + 'a {
    tiles(rect, TILE_SIZE).flat_map(move |t| {
        let per_packet = (MAX_PACKET_FLOATS / (t.width * t.height)).max(1);
        channels
            .chunks(per_packet)
            .map(move |group| encode_update_image(name, frame, group, t))
    })
}

/// A connection to a tev viewer.
#[derive(Debug)]
pub struct TevClient {
    /// The socket.
    stream: TcpStream,
    /// The address as given, for messages.
    address: String,
}

impl TevClient {
    /// Connects to `address` (`host:port`, or a bare host for port
    /// [`DEFAULT_PORT`]), trying each resolved address for at most `timeout`;
    /// sends then time out after [`DEFAULT_WRITE_TIMEOUT`].
    pub fn connect(address: &str, timeout: Duration) -> Result<Self, DisplayError> {
        let addrs = resolve(address)?;
        let mut last = None;
        for a in &addrs {
            match TcpStream::connect_timeout(a, timeout) {
                Ok(stream) => {
                    let send_err = |source| DisplayError::Send {
                        address: address.to_string(),
                        source,
                    };
                    stream.set_nodelay(true).map_err(send_err)?;
                    stream
                        .set_write_timeout(Some(DEFAULT_WRITE_TIMEOUT))
                        .map_err(send_err)?;
                    return Ok(Self {
                        stream,
                        address: address.to_string(),
                    });
                }
                Err(e) => last = Some(e),
            }
        }
        Err(DisplayError::Connect {
            address: address.to_string(),
            source: last.unwrap_or_else(|| std::io::Error::other("no address")),
        })
    }

    /// How long a send may stall (`None`: forever) before it fails.
    pub fn set_write_timeout(&self, timeout: Option<Duration>) -> Result<(), DisplayError> {
        self.stream
            .set_write_timeout(timeout)
            .map_err(|source| self.send_error(source))
    }

    /// Creates (or replaces) image `name` with all-zero channels.
    pub fn create_image(
        &mut self,
        name: &str,
        grab_focus: bool,
        width: usize,
        height: usize,
        channels: &[String],
    ) -> Result<(), DisplayError> {
        let p = encode_create_image(name, grab_focus, width, height, channels)?;
        self.send(&p)
    }

    /// Sends channels `channels` (indices into `frame.channels()`) of
    /// rectangle `rect` of `frame` to image `name`, tile by tile.
    pub fn update_image(
        &mut self,
        name: &str,
        frame: &Frame,
        channels: &[usize],
        rect: Rect,
    ) -> Result<(), DisplayError> {
        for p in update_packets(name, frame, channels, rect) {
            self.send(&p?)?;
        }
        Ok(())
    }

    /// Sends all of `frame` to image `name`.
    pub fn update_frame(&mut self, name: &str, frame: &Frame) -> Result<(), DisplayError> {
        let all: Vec<usize> = (0..frame.channels().len()).collect();
        self.update_image(name, frame, &all, Rect::of(frame))
    }

    /// Closes image `name` in the viewer.
    pub fn close_image(&mut self, name: &str) -> Result<(), DisplayError> {
        let p = encode_close_image(name)?;
        self.send(&p)
    }

    /// Writes one packet.
    fn send(&mut self, packet: &[u8]) -> Result<(), DisplayError> {
        self.stream
            .write_all(packet)
            .map_err(|source| self.send_error(source))
    }

    /// A send error naming the viewer.
    fn send_error(&self, source: std::io::Error) -> DisplayError {
        DisplayError::Send {
            address: self.address.clone(),
            source,
        }
    }
}

/// The socket addresses of `host:port` (or `host`, on [`DEFAULT_PORT`]).
fn resolve(address: &str) -> Result<Vec<SocketAddr>, DisplayError> {
    let err = |msg: String| DisplayError::Address {
        address: address.to_string(),
        msg,
    };
    let found = match address.to_socket_addrs() {
        Ok(it) => it.collect::<Vec<_>>(),
        // No port given (or an IPv6 literal without brackets): tev's default.
        Err(_) if !address.contains(':') || address.parse::<std::net::IpAddr>().is_ok() => {
            let host = address.trim_start_matches('[').trim_end_matches(']');
            (host, DEFAULT_PORT)
                .to_socket_addrs()
                .map_err(|e| err(e.to_string()))?
                .collect()
        }
        Err(e) => return Err(err(format!("expected HOST:PORT ({e})"))),
    };
    if found.is_empty() {
        return Err(err("resolves to no address".into()));
    }
    Ok(found)
}
