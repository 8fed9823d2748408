//! The exact state of a render after some passes: the film's fixed-point
//! sums, the integrator's own state (SPPM) and the render's fingerprint.
//! Checkpoints and partial renders (`--pass-range`) are this state on disk.
//!
//! File layout (little endian): the magic `CNDLST01`, the fingerprint (u64),
//! the integrator name, the planned number of passes (u64), the length of
//! the body, then the body deflate-compressed, then a 64-bit hash of
//! everything before it. A truncated or altered file fails the hash or the
//! decoding and is refused; nothing of it is used.

use crate::film::{Buckets, FilmLayout, FilmState, MergeError, PassSet, SurfaceAov};
use crate::integrator::sppm::PixelStats;
use crate::integrator::{IntegratorState, SppmState};
use crate::sampling::murmur_hash64a;
use std::io::{Read, Write};
use std::path::Path;
use thiserror::Error;

const MAGIC: &[u8; 8] = b"CNDLST01";

/// A render's state that cannot be read, written or combined.
#[derive(Debug, Error)]
pub enum StateError {
    /// The file could not be read or written.
    #[error("{path}: {error}")]
    Io {
        /// File.
        path: String,
        /// Cause (not a `source`: the message already holds it).
        error: std::io::Error,
    },
    /// Not a candela state file, or damaged.
    #[error("{path}: {what}")]
    Corrupt {
        /// File.
        path: String,
        /// What is wrong.
        what: String,
    },
    /// States of different renders.
    #[error("{0}")]
    Mismatch(String),
    /// The film sums cannot be merged.
    #[error(transparent)]
    Merge(#[from] MergeError),
}

/// The state of a render.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderState {
    /// [`super::fingerprint`] of the scene and settings.
    pub fingerprint: u64,
    /// Name of the integrator.
    pub integrator: String,
    /// Passes the render was planned with (`--spp`).
    pub total_passes: u64,
    /// The command-line settings the render was made with, as `key=value`
    /// lines (so `merge` and `--resume` can rebuild the same render).
    pub settings: String,
    /// The accumulated film.
    pub film: FilmState,
    /// The integrator's state.
    pub integrator_state: IntegratorState,
}

impl RenderState {
    /// Adds `other`, a state of the same render over disjoint passes.
    pub fn merge(&mut self, other: &RenderState) -> Result<(), StateError> {
        if other.fingerprint != self.fingerprint || other.integrator != self.integrator {
            return Err(StateError::Mismatch(
                "the partial results come from different scenes or settings".into(),
            ));
        }
        if other.total_passes != self.total_passes {
            return Err(StateError::Mismatch(format!(
                "the partial results were planned with different pass counts ({} and {})",
                self.total_passes, other.total_passes
            )));
        }
        if self.integrator_state != IntegratorState::Stateless
            || other.integrator_state != IntegratorState::Stateless
        {
            return Err(StateError::Mismatch(format!(
                "{} passes depend on each other: its partial results cannot be merged",
                self.integrator
            )));
        }
        self.film.merge(&other.film)?;
        Ok(())
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut body = Vec::new();
        write_film(&mut body, &self.film);
        write_integrator(&mut body, &self.integrator_state);
        let mut z = flate2::write::DeflateEncoder::new(Vec::new(), flate2::Compression::fast());
        // Writing to a Vec cannot fail.
        let _ = z.write_all(&body);
        let packed = z.finish().unwrap_or_default();
        let mut out = Vec::with_capacity(packed.len() + 64);
        out.extend_from_slice(MAGIC);
        put_u64(&mut out, self.fingerprint);
        put_u64(&mut out, self.integrator.len() as u64);
        out.extend_from_slice(self.integrator.as_bytes());
        put_u64(&mut out, self.total_passes);
        put_u64(&mut out, self.settings.len() as u64);
        out.extend_from_slice(self.settings.as_bytes());
        put_u64(&mut out, body.len() as u64);
        out.extend_from_slice(&packed);
        let h = murmur_hash64a(&out, 0x5747_4154);
        put_u64(&mut out, h);
        out
    }

    /// Reads a state from `bytes` (`path` names it in errors).
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Self, StateError> {
        let corrupt = |what: &str| StateError::Corrupt {
            path: path.display().to_string(),
            what: what.to_string(),
        };
        if bytes.len() < 48 || &bytes[..8] != MAGIC {
            return Err(corrupt(
                "not a candela render state (checkpoint or partial render)",
            ));
        }
        let (data, tail) = bytes.split_at(bytes.len() - 8);
        let stored = u64::from_le_bytes(tail.try_into().map_err(|_| corrupt("truncated"))?);
        if murmur_hash64a(data, 0x5747_4154) != stored {
            return Err(corrupt(
                "the file is truncated or damaged (checksum mismatch)",
            ));
        }
        let mut r = Reader { b: data, at: 8 };
        let fingerprint = r.u64()?;
        let name_len = r.len(64)?;
        let integrator = String::from_utf8(r.bytes(name_len)?.to_vec())
            .map_err(|_| corrupt("bad integrator name"))?;
        let total_passes = r.u64()?;
        let settings_len = r.len(1 << 20)?;
        let settings = String::from_utf8(r.bytes(settings_len)?.to_vec())
            .map_err(|_| corrupt("bad settings"))?;
        let body_len = r.len(1 << 40)?;
        let mut body = Vec::new();
        flate2::read::DeflateDecoder::new(&data[r.at..])
            .take(body_len as u64 + 1)
            .read_to_end(&mut body)
            .map_err(|_| corrupt("the compressed body does not decode"))?;
        if body.len() != body_len {
            return Err(corrupt("the body has the wrong length"));
        }
        let mut r = Reader { b: &body, at: 0 };
        let film = read_film(&mut r).map_err(|_| corrupt("the film sums do not decode"))?;
        let integrator_state =
            read_integrator(&mut r).map_err(|_| corrupt("the integrator state does not decode"))?;
        if r.at != body.len() {
            return Err(corrupt("trailing bytes in the body"));
        }
        Ok(Self {
            fingerprint,
            integrator,
            total_passes,
            settings,
            film,
            integrator_state,
        })
    }

    /// Writes the state to `path` atomically (temporary file, then rename).
    pub fn save(&self, path: &Path) -> Result<(), StateError> {
        crate::image::write_atomic_bytes(path, &self.to_bytes()).map_err(|error| StateError::Io {
            path: path.display().to_string(),
            error,
        })
    }

    /// Reads the state file at `path`.
    pub fn load(path: &Path) -> Result<Self, StateError> {
        let bytes = std::fs::read(path).map_err(|error| StateError::Io {
            path: path.display().to_string(),
            error,
        })?;
        Self::from_bytes(&bytes, path)
    }
}

#[cfg(test)]
mod tests {
    use super::{put_varint, Reader};

    #[test]
    fn varints_round_trip_at_the_extremes() {
        for v in [
            0,
            1,
            -1,
            63,
            -64,
            64,
            1 << 70,
            -(1 << 100),
            i128::MAX,
            i128::MIN,
        ] {
            let mut b = Vec::new();
            put_varint(&mut b, v);
            assert!(b.len() <= 19);
            let mut r = Reader { b: &b, at: 0 };
            assert_eq!(r.varint().ok(), Some(v), "{v}");
            assert_eq!(r.at, b.len());
        }
        let mut r = Reader {
            b: &[0xff; 30],
            at: 0,
        };
        assert!(r.varint().is_err(), "an unterminated varint is refused");
    }
}

fn put_u64(out: &mut Vec<u8>, v: u64) {
    out.extend_from_slice(&v.to_le_bytes());
}
fn put_f64(out: &mut Vec<u8>, v: f64) {
    out.extend_from_slice(&v.to_le_bytes());
}

/// A cursor over bytes whose reads fail instead of panicking.
struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

/// A decoding failure (the caller names the file and the part).
#[derive(Debug)]
struct Short;

impl From<Short> for StateError {
    fn from(_: Short) -> Self {
        StateError::Mismatch("truncated render state".into())
    }
}

impl<'a> Reader<'a> {
    fn bytes(&mut self, n: usize) -> Result<&'a [u8], Short> {
        let end = self.at.checked_add(n).ok_or(Short)?;
        let s = self.b.get(self.at..end).ok_or(Short)?;
        self.at = end;
        Ok(s)
    }
    fn u64(&mut self) -> Result<u64, Short> {
        Ok(u64::from_le_bytes(
            self.bytes(8)?.try_into().map_err(|_| Short)?,
        ))
    }
    fn f64(&mut self) -> Result<f64, Short> {
        Ok(f64::from_bits(self.u64()?))
    }
    /// A varint written by [`put_varint`] (at most 19 bytes).
    fn varint(&mut self) -> Result<i128, Short> {
        let mut z: u128 = 0;
        for shift in (0..133).step_by(7) {
            let b = *self.bytes(1)?.first().ok_or(Short)?;
            z |= u128::from(b & 0x7f).checked_shl(shift).ok_or(Short)?;
            if b & 0x80 == 0 {
                return Ok((z >> 1) as i128 ^ -((z & 1) as i128));
            }
        }
        Err(Short)
    }
    /// A count, refused above `max` or above what the remaining bytes can hold.
    fn len(&mut self, max: u64) -> Result<usize, Short> {
        let n = self.u64()?;
        if n > max {
            return Err(Short);
        }
        usize::try_from(n).map_err(|_| Short)
    }
}

const AOVS: [SurfaceAov; 7] = [
    SurfaceAov::Albedo,
    SurfaceAov::Position,
    SurfaceAov::Normal,
    SurfaceAov::ShadingNormal,
    SurfaceAov::Depth,
    SurfaceAov::Uv,
    SurfaceAov::DepthGradient,
];

fn write_film(out: &mut Vec<u8>, f: &FilmState) {
    let l = &f.layout;
    match l.spectral {
        Some(b) => {
            put_u64(out, b.n as u64);
            put_f64(out, b.lambda_min as f64);
            put_f64(out, b.lambda_max as f64);
        }
        None => {
            put_u64(out, 0);
            put_f64(out, 0.0);
            put_f64(out, 0.0);
        }
    }
    put_u64(out, l.surface.len() as u64);
    for a in &l.surface {
        put_u64(out, AOVS.iter().position(|x| x == a).unwrap_or(0) as u64);
    }
    // Bit 0: the variance layer; bit 1: the photometric layers (files
    // written before the photometric layers existed hold 0 or 1).
    put_u64(out, l.variance as u64 | (l.photometric as u64) << 1);
    put_u64(out, l.strategies as u64);
    put_u64(out, f.pixels as u64);
    put_u64(out, f.passes.ranges().len() as u64);
    for (a, b) in f.passes.ranges() {
        put_u64(out, *a);
        put_u64(out, *b);
    }
    put_u64(out, f.pass_means.len() as u64);
    for (p, m) in &f.pass_means {
        put_u64(out, *p);
        m.iter().for_each(|v| put_f64(out, *v));
    }
    put_u64(out, f.dropped);
    put_u64(out, f.saturated);
    put_u64(out, f.sums.len() as u64);
    for s in &f.sums {
        put_varint(out, *s);
    }
}

/// A zigzag LEB128 varint: most sums are small multiples of 2⁻⁶⁴ units next
/// to the i128 range, so this is 4–10 bytes instead of 16, before deflate.
fn put_varint(out: &mut Vec<u8>, v: i128) {
    let mut z = ((v << 1) ^ (v >> 127)) as u128;
    loop {
        let byte = (z & 0x7f) as u8;
        z >>= 7;
        if z == 0 {
            out.push(byte);
            return;
        }
        out.push(byte | 0x80);
    }
}

fn read_film(r: &mut Reader<'_>) -> Result<FilmState, Short> {
    let nb = r.len(1 << 16)?;
    let (lmin, lmax) = (r.f64()? as f32, r.f64()? as f32);
    let spectral = (nb > 0).then_some(Buckets {
        n: nb,
        lambda_min: lmin,
        lambda_max: lmax,
    });
    let ns = r.len(AOVS.len() as u64)?;
    let surface = (0..ns)
        .map(|_| AOVS.get(r.len(AOVS.len() as u64)?).copied().ok_or(Short))
        .collect::<Result<Vec<_>, _>>()?;
    let flags = r.u64()?;
    if flags > 3 {
        return Err(Short);
    }
    let strategies = r.len(1 << 16)?;
    let layout = FilmLayout {
        spectral,
        surface,
        variance: flags & 1 != 0,
        strategies,
        photometric: flags & 2 != 0,
    };
    let pixels = r.len(1 << 40)?;
    let n_ranges = r.len(1 << 32)?;
    let mut passes = PassSet::default();
    for _ in 0..n_ranges {
        let (a, b) = (r.u64()?, r.u64()?);
        if a >= b {
            return Err(Short);
        }
        passes.union(&PassSet::range(a, b));
    }
    let n_means = r.len(1 << 40)?;
    let mut pass_means = Vec::with_capacity(n_means.min(1 << 20));
    for _ in 0..n_means {
        pass_means.push((r.u64()?, [r.f64()?, r.f64()?, r.f64()?]));
    }
    let (dropped, saturated) = (r.u64()?, r.u64()?);
    let n_sums = r.len(1 << 40)?;
    if n_sums != pixels.checked_mul(layout.state_stride()).ok_or(Short)? {
        return Err(Short);
    }
    if r.b.len() - r.at < n_sums {
        return Err(Short);
    }
    let sums = (0..n_sums)
        .map(|_| r.varint())
        .collect::<Result<Vec<_>, _>>()?;
    Ok(FilmState {
        layout,
        pixels,
        sums,
        passes,
        pass_means,
        dropped,
        saturated,
    })
}

fn write_integrator(out: &mut Vec<u8>, s: &IntegratorState) {
    match s {
        IntegratorState::Stateless => put_u64(out, 0),
        IntegratorState::Sppm(st) => {
            put_u64(out, 1);
            put_u64(out, st.photons_per_iteration);
            put_u64(out, st.stats.len() as u64);
            for p in &st.stats {
                for v in [
                    p.n, p.r2, p.tau[0], p.tau[1], p.tau[2], p.ld[0], p.ld[1], p.ld[2],
                ] {
                    put_f64(out, v);
                }
            }
        }
    }
}

fn read_integrator(r: &mut Reader<'_>) -> Result<IntegratorState, Short> {
    match r.u64()? {
        0 => Ok(IntegratorState::Stateless),
        1 => {
            let photons_per_iteration = r.u64()?;
            let n = r.len(1 << 40)?;
            if r.b.len() - r.at < n * 64 {
                return Err(Short);
            }
            let mut stats = Vec::with_capacity(n);
            for _ in 0..n {
                let v: [f64; 8] = [(); 8].map(|_| r.f64().unwrap_or(f64::NAN));
                stats.push(PixelStats {
                    n: v[0],
                    r2: v[1],
                    tau: [v[2], v[3], v[4]],
                    ld: [v[5], v[6], v[7]],
                });
            }
            Ok(IntegratorState::Sppm(SppmState {
                photons_per_iteration,
                stats,
            }))
        }
        _ => Err(Short),
    }
}
