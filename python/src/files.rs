//! Every file a scene reads, for shipping it to machines without the
//! scene's filesystem (the Dask farm packs these into one archive).
//!
//! The scene files themselves (the main file, `Include`s and `Import`s) are
//! the description's sources. The others (PLY meshes, images, IES files,
//! `.spd` spectra, which the parser reads into numbers and does not name
//! afterwards) are named by string parameters, so each scene file's text is
//! scanned for quoted strings, skipping `#` comments, and every string that
//! names a regular file relative to the scene's directory is kept. A string
//! that is no file ("diffuse", a built-in spectrum name) is not. An
//! absolute path to a file is an error at its file:line:col: the receiving
//! machine would look for it on its own disk, not in the archive.

use candela_scene::{Loc, SceneDescription, SceneError, MAX_SCENE_FILE_BYTES};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Longest string taken for a file name.
const MAX_NAME: usize = 4096;

/// A quoted string of a scene file and where it starts.
struct Quoted {
    text: String,
    line: u32,
    col: u32,
}

/// Every file `desc` reads: its scene files and every file a quoted string
/// names, sorted and without repeats.
pub fn scene_files(desc: &SceneDescription) -> Result<Vec<PathBuf>, SceneError> {
    let mut out: Vec<PathBuf> = Vec::new();
    for src in &desc.sources {
        out.push(src.path.clone());
        let text = read_text(&src.path)?;
        let file: Arc<Path> = Arc::from(src.path.as_path());
        for q in quoted_strings(&text) {
            let name = Path::new(&q.text);
            let path = if name.is_absolute() {
                name.to_path_buf()
            } else {
                desc.base_dir.join(name)
            };
            if !path.is_file() {
                continue;
            }
            if name.is_absolute() {
                let loc = Loc {
                    file: file.clone(),
                    line: q.line,
                    col: q.col,
                };
                return Err(SceneError::unsupported(
                    &loc,
                    format!(
                        "absolute path \"{}\": a scene sent to other machines must name its files relative to its directory",
                        q.text
                    ),
                ));
            }
            out.push(path);
        }
    }
    out.sort();
    out.dedup();
    Ok(out)
}

/// The (gunzipped) bytes of scene file `path`.
fn read_text(path: &Path) -> Result<Vec<u8>, SceneError> {
    let loc = Loc::file_only(path);
    let io = |e: std::io::Error| SceneError::io(&loc, path, e);
    let file = std::fs::File::open(path).map_err(io)?;
    let mut out = Vec::new();
    let limited = MAX_SCENE_FILE_BYTES + 1;
    if path.extension().is_some_and(|e| e == "gz") {
        flate2::read::MultiGzDecoder::new(file)
            .take(limited)
            .read_to_end(&mut out)
    } else {
        file.take(limited).read_to_end(&mut out)
    }
    .map_err(io)?;
    Ok(out)
}

/// The quoted strings of scene text `b` outside `#` comments (a backslash
/// escapes the next byte, as in pbrt-v4's tokenizer); names too long to be
/// file names, or not UTF-8, are skipped.
fn quoted_strings(b: &[u8]) -> Vec<Quoted> {
    let mut out = Vec::new();
    let (mut i, mut line, mut line_start) = (0usize, 1u32, 0usize);
    while i < b.len() {
        match b[i] {
            b'\n' => {
                line += 1;
                line_start = i + 1;
                i += 1;
            }
            b'#' => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'"' => {
                let col = u32::try_from(i - line_start + 1).unwrap_or(u32::MAX);
                let start = i + 1;
                let mut j = start;
                while j < b.len() && b[j] != b'"' && b[j] != b'\n' {
                    j += if b[j] == b'\\' { 2 } else { 1 };
                }
                let end = j.min(b.len());
                if end - start <= MAX_NAME {
                    if let Ok(s) = std::str::from_utf8(&b[start..end]) {
                        out.push(Quoted {
                            text: s.to_string(),
                            line,
                            col,
                        });
                    }
                }
                i = end + 1;
            }
            _ => i += 1,
        }
    }
    out
}
