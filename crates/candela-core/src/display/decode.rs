//! A decoder of tev's packets, written from the protocol description in
//! [`super::tev`] independently of its encoder: what a test viewer (or a
//! tool recording a live view) uses to check and read a stream.
//!
//! Only the packets candela sends are understood: create image (type 4),
//! update image with per-channel offsets and strides (type 6) and close
//! image (type 2). [`paint`] replays the updates into per-channel planes and
//! checks tile sizes against [`TILE_SIZE`] and [`MAX_PACKET_FLOATS`].

use super::tev::{MAX_PACKET_FLOATS, TILE_SIZE};

/// A decoded packet.
#[derive(Clone, Debug, PartialEq)]
pub enum Packet {
    /// Type 4: create an image.
    Create {
        /// Whether tev should focus it.
        grab: bool,
        /// Image name.
        name: String,
        /// Width.
        width: i32,
        /// Height.
        height: i32,
        /// Channel names.
        channels: Vec<String>,
    },
    /// Type 6; `data[c][p]` is channel c of pixel p of the rectangle.
    Update {
        /// Image name.
        name: String,
        /// Channel names.
        channels: Vec<String>,
        /// x, y, width, height.
        rect: [i32; 4],
        /// Samples per channel, row-major over the rectangle.
        data: Vec<Vec<f32>>,
        /// Floats the packet carried.
        floats: usize,
    },
    /// Type 2: close an image.
    Close {
        /// Image name.
        name: String,
    },
}

/// A stream or packet that is not what candela sends.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("tev stream: {0}")]
pub struct DecodeError(String);

fn bad<T>(m: impl Into<String>) -> Result<T, DecodeError> {
    Err(DecodeError(m.into()))
}

/// A cursor over one packet.
struct Cursor<'a>(&'a [u8], usize);

impl Cursor<'_> {
    /// The next `n` bytes.
    fn take(&mut self, n: usize) -> Result<&[u8], DecodeError> {
        if self.1 + n > self.0.len() {
            return bad("packet ends early");
        }
        self.1 += n;
        Ok(&self.0[self.1 - n..self.1])
    }
    /// A byte 0 or 1.
    fn bool(&mut self) -> Result<bool, DecodeError> {
        match self.take(1)?[0] {
            0 => Ok(false),
            1 => Ok(true),
            b => bad(format!("bool byte {b}")),
        }
    }
    /// A little-endian i32.
    fn i32(&mut self) -> Result<i32, DecodeError> {
        let b = self.take(4)?;
        Ok(i32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }
    /// A little-endian i64.
    fn i64(&mut self) -> Result<i64, DecodeError> {
        let b = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(i64::from_le_bytes(a))
    }
    /// A NUL-terminated UTF-8 string.
    fn str(&mut self) -> Result<String, DecodeError> {
        let rest = &self.0[self.1..];
        let Some(n) = rest.iter().position(|&b| b == 0) else {
            return bad("string without NUL");
        };
        let s = String::from_utf8(rest[..n].to_vec())
            .map_err(|_| DecodeError("string not UTF-8".into()))?;
        self.1 += n + 1;
        Ok(s)
    }
    /// `n` strings.
    fn strs(&mut self, n: i32) -> Result<Vec<String>, DecodeError> {
        (0..n).map(|_| self.str()).collect()
    }
}

/// Decodes one packet, checking its length field and that no byte is left.
pub fn decode_packet(p: &[u8]) -> Result<Packet, DecodeError> {
    let mut c = Cursor(p, 0);
    if c.take(4)? != (p.len() as u32).to_le_bytes() {
        return bad("length prefix");
    }
    let d = match c.take(1)?[0] {
        4 => {
            let (grab, name, width, height) = (c.bool()?, c.str()?, c.i32()?, c.i32()?);
            let n = c.i32()?;
            Packet::Create {
                grab,
                name,
                width,
                height,
                channels: c.strs(n)?,
            }
        }
        6 => update(&mut c)?,
        2 => Packet::Close { name: c.str()? },
        t => return bad(format!("unexpected packet type {t}")),
    };
    if c.1 != p.len() {
        return bad("trailing bytes in packet");
    }
    Ok(d)
}

/// The body of an update packet (type 6).
fn update(c: &mut Cursor<'_>) -> Result<Packet, DecodeError> {
    let _grab = c.bool()?;
    let name = c.str()?;
    let n = c.i32()?;
    if !(1..=1 << 16).contains(&n) {
        return bad(format!("{n} channels"));
    }
    let channels = c.strs(n)?;
    let rect = [c.i32()?, c.i32()?, c.i32()?, c.i32()?];
    let offsets: Vec<i64> = (0..n).map(|_| c.i64()).collect::<Result<_, _>>()?;
    let strides: Vec<i64> = (0..n).map(|_| c.i64()).collect::<Result<_, _>>()?;
    let pixels = rect[2] as i64 * rect[3] as i64;
    if rect.iter().any(|&v| v < 0) || pixels == 0 {
        return bad(format!("rectangle {rect:?}"));
    }
    let end = |k: usize| offsets[k] + (pixels - 1) * strides[k] + 1;
    if (0..n as usize).any(|k| offsets[k] < 0 || strides[k] < 1) {
        return bad("negative offset or stride");
    }
    let floats = (0..n as usize).map(end).max().unwrap_or(0) as usize;
    let raw: Vec<f32> = c
        .take(4 * floats)?
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let data = (0..n as usize)
        .map(|k| {
            (0..pixels)
                .map(|p| raw[(offsets[k] + p * strides[k]) as usize])
                .collect()
        })
        .collect();
    Ok(Packet::Update {
        name,
        channels,
        rect,
        data,
        floats,
    })
}

/// Splits a received stream into packets by their length prefixes.
pub fn decode_stream(stream: &[u8]) -> Result<Vec<Packet>, DecodeError> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < stream.len() {
        if i + 5 > stream.len() {
            return bad("stream ends inside a length prefix");
        }
        let b = &stream[i..i + 4];
        let n = u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize;
        if n < 5 || i + n > stream.len() {
            return bad(format!("bad packet length {n}"));
        }
        out.push(decode_packet(&stream[i..i + n])?);
        i += n;
    }
    Ok(out)
}

/// Per-channel planes (`names` order; NaN where never written) painted by
/// the update packets, with the number of writes per sample
/// (`writes[(y·w + x)·names.len() + c]`).
pub fn paint(
    packets: &[Packet],
    w: usize,
    h: usize,
    names: &[String],
) -> Result<(Vec<Vec<f32>>, Vec<u32>), DecodeError> {
    let mut img = vec![vec![f32::NAN; w * h]; names.len()];
    let mut writes = vec![0u32; w * h * names.len()];
    for p in packets {
        let Packet::Update {
            channels,
            rect: [x0, y0, tw, th],
            data,
            floats,
            ..
        } = p
        else {
            continue;
        };
        let (x0, y0, tw, th) = (*x0 as usize, *y0 as usize, *tw as usize, *th as usize);
        if tw > TILE_SIZE || th > TILE_SIZE {
            return bad(format!("tile {tw}x{th}"));
        }
        if *floats > MAX_PACKET_FLOATS {
            return bad(format!("{floats} floats in one packet"));
        }
        if x0 + tw > w || y0 + th > h {
            return bad(format!("tile at ({x0}, {y0}) outside the {w}x{h} image"));
        }
        for (ch, plane) in channels.iter().zip(data) {
            let Some(c) = names.iter().position(|n| n == ch) else {
                return bad(format!("unknown channel {ch:?}"));
            };
            for (p, &v) in plane.iter().enumerate() {
                let (x, y) = (x0 + p % tw, y0 + p / tw);
                img[c][y * w + x] = v;
                writes[(y * w + x) * names.len() + c] += 1;
            }
        }
    }
    Ok((img, writes))
}
