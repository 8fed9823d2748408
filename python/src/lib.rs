//! `candela._native`: candela as a Python module (PyO3; built by maturin,
//! `pip install ./python`). The pure-Python package `candela` re-exports
//! it and adds the Dask farm (`candela.farm`).
//!
//! - `load(path) -> Scene` parses and builds a scene (errors are
//!   `SceneError` with `file:line:col`), `Scene.info()` summarises it,
//!   `Scene.files()` (or `scene_files(path)`, parsing only) lists every
//!   file it reads;
//! - `Scene.render(...) -> Render` renders a pass range with the GIL
//!   released; Ctrl-C stops it (`run`);
//! - a `Render`'s layers are numpy arrays; renders merge exactly, go to and
//!   from bytes (the command line's `.cndl` state) and save as the EXR the
//!   command line writes;
//! - `merge_states(a, b)` adds two states' bytes without a scene.

mod errors;
mod files;
mod result;
mod run;
mod scene;

use pyo3::prelude::*;
use std::path::PathBuf;

/// Parses and builds the pbrt-v4 scene at `path` (the GIL is released
/// meanwhile) with the render overrides it will be rendered with (building
/// is then not repeated); raises SceneError ("file:line:col: what").
#[pyfunction]
#[pyo3(signature = (path, *, spp=None, integrator=None, seed=None, crop=None))]
fn load(
    py: Python<'_>,
    path: PathBuf,
    spp: Option<u32>,
    integrator: Option<String>,
    seed: Option<u64>,
    crop: Option<(f32, f32, f32, f32)>,
) -> PyResult<scene::Scene> {
    let ov = scene::overrides(spp, integrator, seed, crop)?;
    scene::Scene::load(py, path, &ov)
}

/// Every file the scene at `path` reads (its scene files and every file a
/// string parameter names), from a parse without building: what a cluster
/// client packs for its workers. Raises SceneError.
#[pyfunction]
fn scene_files(py: Python<'_>, path: PathBuf) -> PyResult<Vec<String>> {
    let found = py.detach(|| {
        let desc = candela_scene::parse_file(&path)?;
        files::scene_files(&desc)
    });
    let found = found.map_err(|e| errors::from_scene(&e))?;
    Ok(found.iter().map(|p| p.display().to_string()).collect())
}

/// The module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(scene_files, m)?)?;
    m.add_function(wrap_pyfunction!(result::merge_states, m)?)?;
    m.add_function(wrap_pyfunction!(result::state_info, m)?)?;
    m.add_class::<scene::Scene>()?;
    m.add_class::<result::Render>()?;
    m.add("CandelaError", py.get_type::<errors::CandelaError>())?;
    m.add("SceneError", py.get_type::<errors::SceneError>())?;
    m.add("StateError", py.get_type::<errors::StateError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
