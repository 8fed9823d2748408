//! Reading input files (scenes, includes, meshes, spectra) defensively.
//!
//! A scene names files, and a hostile or mistaken scene can name anything:
//! `/dev/zero` (endless), a FIFO (blocks forever on open), a directory, or a
//! small gzip file that inflates to terabytes. Every file the parser reads
//! goes through [`read_file`], which
//!
//! 1. refuses anything that is not a regular file (after following
//!    symlinks) *before* opening it, so a FIFO cannot block the open;
//! 2. reads at most `limit` bytes and fails past that, so a file that grows
//!    while being read, or a `/proc` file that reports size 0, is bounded;
//! 3. gunzips names ending in `.gz` with the same bound on the *inflated*
//!    size (a "zip bomb" stops at the limit, not at the disk's size).
//!
//! The limits are far above any real scene (pbrt-v4's largest public scenes
//! have single files of a few GiB only when gzipped), yet small enough that
//! hitting one is a clear error instead of an out-of-memory abort.

use std::io::{self, Read};
use std::path::Path;

use crate::error::{Loc, SceneError};

/// Largest scene text (one file, after gunzipping) the parser reads.
pub const MAX_SCENE_FILE_BYTES: u64 = 4 << 30;

/// Largest PLY file (after gunzipping) the mesh reader reads.
pub const MAX_PLY_FILE_BYTES: u64 = 4 << 30;

/// Largest spectrum (`.spd`) file read.
pub const MAX_SPECTRUM_FILE_BYTES: u64 = 64 << 20;

/// Reads `path` (gunzipping a `.gz` name) into memory, refusing non-regular
/// files and contents over `limit` bytes. Errors are reported at `loc`.
pub(crate) fn read_file(path: &Path, loc: &Loc, limit: u64) -> Result<Vec<u8>, SceneError> {
    let io_err = |e: io::Error| SceneError::io(loc, path, e);
    let meta = std::fs::metadata(path).map_err(io_err)?;
    if !meta.is_file() {
        let what = if meta.is_dir() {
            "it is a directory"
        } else {
            "it is not a regular file (a device, FIFO or socket)"
        };
        return Err(io_err(io::Error::new(io::ErrorKind::InvalidInput, what)));
    }
    let file = std::fs::File::open(path).map_err(io_err)?;
    let gz = path.extension().is_some_and(|e| e == "gz");
    let bytes = if gz {
        read_bounded(flate2::read::MultiGzDecoder::new(file), limit)
    } else {
        read_bounded(file, limit)
    }
    .map_err(io_err)?;
    bytes.ok_or_else(|| {
        let unzipped = if gz { " once decompressed" } else { "" };
        let msg = format!("it is larger than the limit of {limit} bytes{unzipped}");
        io_err(io::Error::new(io::ErrorKind::InvalidData, msg))
    })
}

/// Reads `r` to its end, or returns `None` as soon as it yields more than
/// `limit` bytes.
fn read_bounded(r: impl Read, limit: u64) -> io::Result<Option<Vec<u8>>> {
    let mut out = Vec::new();
    r.take(limit.saturating_add(1)).read_to_end(&mut out)?;
    Ok((out.len() as u64 <= limit).then_some(out))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn tmp(name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("candela-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }

    #[test]
    fn limit_is_inclusive_and_enforced() {
        let p = tmp("ten.txt", b"0123456789");
        let loc = Loc::file_only(&p);
        assert_eq!(read_file(&p, &loc, 10).unwrap().len(), 10);
        let e = read_file(&p, &loc, 9).unwrap_err().to_string();
        assert!(e.contains("larger than the limit of 9 bytes"), "{e}");
    }

    #[test]
    fn gzip_limit_applies_to_the_inflated_size() {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
        enc.write_all(&vec![b' '; 1 << 20]).unwrap();
        let p = tmp("bomb.pbrt.gz", &enc.finish().unwrap());
        assert!(std::fs::metadata(&p).unwrap().len() < 10_000);
        let e = read_file(&p, &Loc::file_only(&p), 1000)
            .unwrap_err()
            .to_string();
        assert!(e.contains("once decompressed"), "{e}");
        assert_eq!(
            read_file(&p, &Loc::file_only(&p), 1 << 20).unwrap().len(),
            1 << 20
        );
    }

    #[test]
    fn devices_and_directories_are_refused() {
        let dir = std::env::temp_dir();
        let e = read_file(&dir, &Loc::file_only(&dir), 100)
            .unwrap_err()
            .to_string();
        assert!(e.contains("is a directory"), "{e}");
        let zero = Path::new("/dev/zero");
        if zero.exists() {
            let e = read_file(zero, &Loc::file_only(zero), 100)
                .unwrap_err()
                .to_string();
            assert!(e.contains("not a regular file"), "{e}");
        }
    }
}
