//! Python exceptions for candela's errors. A scene that cannot be read or
//! built raises [`SceneError`], whose message is `file:line:col: what` and
//! whose `file`, `line` and `col` attributes hold the place (`None`, `0`, `0`
//! when there is none); a render state that cannot be read or merged raises
//! [`StateError`]. Both derive from [`CandelaError`]. They pickle with their
//! attributes, so a Dask worker's error reaches the client whole.

use candela_core::build::BuildError;
use candela_core::render::{RenderError, StateError as CoreStateError};
use candela_scene::{Loc, SceneError as CoreSceneError};
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(
    candela,
    CandelaError,
    PyException,
    "Base class of candela's errors."
);
pyo3::create_exception!(
    candela,
    SceneError,
    CandelaError,
    "A scene that cannot be read or built; the message starts with file:line:col."
);
pyo3::create_exception!(
    candela,
    StateError,
    CandelaError,
    "A render state (bytes of a partial render) that cannot be read or merged."
);

/// A `SceneError` with `message` and the place `loc` as attributes.
pub fn scene_error(message: String, loc: Option<&Loc>) -> PyErr {
    Python::attach(|py| {
        let err = SceneError::new_err(message);
        let value = err.value(py);
        let (file, line, col) = match loc {
            Some(l) => (Some(l.file.display().to_string()), l.line, l.col),
            None => (None, 0, 0),
        };
        // Setting attributes on a fresh exception instance cannot fail.
        let _ = value.setattr("file", file);
        let _ = value.setattr("line", line);
        let _ = value.setattr("col", col);
        err
    })
}

/// The Python error for a scene that does not parse.
pub fn from_scene(e: &CoreSceneError) -> PyErr {
    scene_error(e.to_string(), Some(e.loc()))
}

/// The Python error for a scene that does not build.
pub fn from_build(e: &BuildError) -> PyErr {
    let loc = match e {
        BuildError::At { loc, .. } => Some(loc),
        BuildError::Scene(s) => Some(s.loc()),
        BuildError::Other(_) => None,
    };
    scene_error(e.to_string(), loc)
}

/// The Python error for a state that cannot be read or merged.
pub fn from_state(e: &CoreStateError) -> PyErr {
    StateError::new_err(e.to_string())
}

/// The Python error for a render that cannot run with these options.
pub fn from_render(e: &RenderError) -> PyErr {
    match e {
        RenderError::Options(m) => PyValueError::new_err(m.clone()),
        RenderError::State(s) => from_state(s),
    }
}
