//! Atomic file replacement: a write either completes or leaves the previous
//! file untouched.
//!
//! The bytes go to a new temporary file in the target's own directory (so the
//! final step is a rename within one file system, never a copy). The
//! temporary is flushed and `fsync`ed, then renamed over the target; POSIX
//! `rename` replaces the directory entry in one step, so a reader, a crash or
//! a `kill -9` at any moment sees either the whole old file or the whole new
//! one. Last, the directory is `fsync`ed so the rename itself survives a power
//! loss (best effort: not every platform can open a directory).
//!
//! On any error, and on a panic inside the writer, the temporary is removed.
//! A crash can still leave a temporary behind; its name starts with `.` and
//! ends in `.tmp`, beside the target.
//!
//! Renaming replaces a symbolic link at `path` by a regular file, and the new
//! file gets default permissions, not the old file's.

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `path` through `write`, atomically: on success the file holds
/// exactly what `write` wrote; on error (from `write` or from the file
/// system) the previous file, if any, is untouched and no temporary remains.
pub fn write_atomic<T, E>(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<T, E>,
) -> Result<T, E>
where
    E: From<io::Error>,
{
    let (file, temp) = create_temp(path)?;
    let mut guard = TempGuard {
        path: temp,
        armed: true,
    };
    let mut out = BufWriter::new(file);
    let value = write(&mut out)?;
    let file = out.into_inner().map_err(io::IntoInnerError::into_error)?;
    file.sync_all()?;
    drop(file);
    std::fs::rename(&guard.path, path)?;
    guard.armed = false;
    sync_dir(path);
    Ok(value)
}

/// Replaces `path` by `bytes` atomically (see [`write_atomic`]).
pub fn write_atomic_bytes(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic(path, |w| w.write_all(bytes))
}

/// Removes the temporary file when dropped while armed (error or panic).
struct TempGuard {
    /// The temporary file.
    path: PathBuf,
    /// False once the temporary has been renamed onto the target.
    armed: bool,
}

impl Drop for TempGuard {
    fn drop(&mut self) {
        if self.armed {
            // Nothing more to do if removal fails: the error being returned
            // is the one that matters.
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Creates a new, empty temporary file beside `path`: `.NAME.PID.N.tmp`.
fn create_temp(path: &Path) -> io::Result<(File, PathBuf)> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path.file_name().ok_or_else(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{}: not a file name", path.display()),
        )
    })?;
    let dir = parent_dir(path);
    let mut last_err = None;
    // `create_new` refuses an existing file, so a stale temporary of a
    // crashed run with the same pid is never reused; try a few numbers.
    for _ in 0..16 {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let mut temp_name = std::ffi::OsString::from(".");
        temp_name.push(name);
        temp_name.push(format!(".{}.{n}.tmp", std::process::id()));
        let temp = dir.join(temp_name);
        match OpenOptions::new().write(true).create_new(true).open(&temp) {
            Ok(f) => return Ok((f, temp)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => last_err = Some(e),
            Err(e) => return Err(e),
        }
    }
    Err(last_err.unwrap_or_else(|| io::Error::other("no temporary file name free")))
}

/// The directory holding `path` (`.` for a bare file name).
fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    }
}

/// Flushes the directory entry of a completed rename to disk (best effort).
fn sync_dir(path: &Path) {
    #[cfg(unix)]
    if let Ok(d) = File::open(parent_dir(path)) {
        // The new file is already in place; a failing directory sync only
        // weakens durability across a power loss, so it is not an error.
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = path;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh empty directory for one test.
    fn test_dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("candela-atomic-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// Names of the files in `dir`, sorted.
    fn listing(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn replaces_the_file_and_leaves_no_temporary() {
        let d = test_dir("ok");
        let p = d.join("out.bin");
        write_atomic_bytes(&p, b"first").unwrap();
        write_atomic_bytes(&p, b"second, longer").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second, longer");
        assert_eq!(listing(&d), ["out.bin"]);
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn a_failing_writer_keeps_the_old_file() {
        let d = test_dir("fail");
        let p = d.join("out.bin");
        write_atomic_bytes(&p, b"old").unwrap();
        let r: io::Result<()> = write_atomic(&p, |w| {
            w.write_all(&[7u8; 100_000])?; // past BufWriter's buffer: bytes reach the temporary
            Err(io::Error::other("encoder failed midway"))
        });
        assert_eq!(r.unwrap_err().to_string(), "encoder failed midway");
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(listing(&d), ["out.bin"]);
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn a_panicking_writer_keeps_the_old_file() {
        let d = test_dir("panic");
        let p = d.join("out.bin");
        write_atomic_bytes(&p, b"old").unwrap();
        let r = std::panic::catch_unwind(|| {
            let _: io::Result<()> = write_atomic(&p, |w| {
                w.write_all(b"partial")?;
                panic!("writer panicked");
            });
        });
        assert!(r.is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"old");
        assert_eq!(listing(&d), ["out.bin"]);
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn a_failing_rename_removes_the_temporary() {
        let d = test_dir("rename");
        // A non-empty directory at the target: rename(file, dir) fails.
        let p = d.join("target");
        std::fs::create_dir_all(p.join("inside")).unwrap();
        assert!(write_atomic_bytes(&p, b"data").is_err());
        assert_eq!(listing(&d), ["target"]);
        assert!(p.join("inside").is_dir());
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn a_missing_directory_is_an_error() {
        let d = test_dir("missing");
        let p = d.join("no/such/dir/out.bin");
        assert!(write_atomic_bytes(&p, b"data").is_err());
        assert!(listing(&d).is_empty());
        std::fs::remove_dir_all(&d).ok();
    }
}
