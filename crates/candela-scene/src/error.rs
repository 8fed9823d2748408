//! Source locations, errors and warnings.
//!
//! Every problem found while reading a scene is reported against a [`Loc`]:
//! the file it was found in plus a 1-based line and column. Errors stop the
//! parse ([`SceneError`]); warnings ([`Warning`]) are collected in the scene
//! description and left to the caller to print.

use std::fmt;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A position in a scene (or mesh) file.
///
/// `line` and `col` are 1-based. A `line` of 0 means "no line information"
/// (for example an I/O error on the file as a whole, or a problem inside the
/// binary body of a PLY file); `Display` then prints only the file name.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Loc {
    /// The file the position refers to.
    pub file: Arc<Path>,
    /// 1-based line number, or 0 when unknown.
    pub line: u32,
    /// 1-based column (in bytes), or 0 when unknown.
    pub col: u32,
}

impl Loc {
    /// A location that names only a file.
    pub fn file_only(file: &Path) -> Loc {
        Loc {
            file: Arc::from(file),
            line: 0,
            col: 0,
        }
    }
}

impl fmt::Display for Loc {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}", self.file.display())
        } else {
            write!(f, "{}:{}:{}", self.file.display(), self.line, self.col)
        }
    }
}

/// An error that stops reading a scene. `Display` is `file:line:col: message`.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// Malformed input: bad syntax, wrong parameter types, bad nesting...
    #[error("{loc}: {message}")]
    Syntax {
        /// Where the problem is.
        loc: Loc,
        /// What was expected or what is wrong.
        message: String,
    },
    /// Valid input that candela does not handle (e.g. participating media).
    #[error("{loc}: {message}")]
    Unsupported {
        /// Where the unsupported feature is used.
        loc: Loc,
        /// What is not supported.
        message: String,
    },
    /// A file (scene, Include, spectrum, mesh) could not be read.
    ///
    /// The message already ends with the I/O error, so it is not also
    /// chained as a `source()` (error reporters would print it twice), and
    /// the location is left out when it is just the file itself.
    #[error("{}cannot read '{}': {error}", io_prefix(loc, path), path.display())]
    Io {
        /// The directive or parameter that asked for the file, or the file itself.
        loc: Loc,
        /// The path that failed.
        path: PathBuf,
        /// The underlying error.
        error: io::Error,
    },
}

impl SceneError {
    /// A syntax error at `loc`.
    pub fn at(loc: &Loc, message: impl Into<String>) -> SceneError {
        SceneError::Syntax {
            loc: loc.clone(),
            message: message.into(),
        }
    }

    /// An "unsupported feature" error at `loc`.
    pub fn unsupported(loc: &Loc, message: impl Into<String>) -> SceneError {
        SceneError::Unsupported {
            loc: loc.clone(),
            message: message.into(),
        }
    }

    /// An I/O error on `path`, requested at `loc`.
    pub fn io(loc: &Loc, path: &Path, error: io::Error) -> SceneError {
        SceneError::Io {
            loc: loc.clone(),
            path: path.to_path_buf(),
            error,
        }
    }

    /// The location the error refers to.
    pub fn loc(&self) -> &Loc {
        match self {
            SceneError::Syntax { loc, .. }
            | SceneError::Unsupported { loc, .. }
            | SceneError::Io { loc, .. } => loc,
        }
    }
}

/// `"loc: "` before an I/O error, or nothing when `loc` only names `path`
/// (which the message names anyway).
fn io_prefix(loc: &Loc, path: &Path) -> String {
    if loc.line == 0 && *loc.file == *path {
        String::new()
    } else {
        format!("{loc}: ")
    }
}

/// A non-fatal problem found while parsing.
#[derive(Debug, Clone, PartialEq)]
pub struct Warning {
    /// Where the problem is.
    pub loc: Loc,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: warning: {}", self.loc, self.message)
    }
}
