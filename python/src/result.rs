//! `candela.Render`: the exact state of some passes of a render, with the
//! setup that develops it. Its layers are numpy arrays; two renders of
//! disjoint passes merge exactly (fixed-point sums); its bytes are the
//! `.cndl` state the command line reads and writes, and its EXR the bytes
//! `candela render` writes for the same passes.

use crate::errors;
use crate::scene::Scene;
use candela_core::build::RenderSetup;
use candela_core::film::Developed;
use candela_core::render::{self, RenderState};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyByteArray, PyBytes, PyDict};
use std::path::Path;
use std::sync::{Arc, OnceLock};

/// Dict key of the EXR's root layer (R, G, B and any root channels).
const MAIN: &str = "main";

/// Some passes of a render: `Scene.render(...)`, `a.merge(b)` or `Render.from_bytes`.
#[pyclass(module = "candela", frozen)]
pub struct Render {
    setup: Arc<RenderSetup>,
    state: RenderState,
    developed: OnceLock<Developed>,
}

/// A state's bytes as a `RenderState` (named `what` in errors).
fn parse_state(data: &[u8], what: &str) -> PyResult<RenderState> {
    RenderState::from_bytes(data, Path::new(what)).map_err(|e| errors::from_state(&e))
}

/// The passes held by `state` as `(a, b)` ranges.
fn ranges(state: &RenderState) -> Vec<(u64, u64)> {
    state.film.passes().ranges().to_vec()
}

impl Render {
    /// Wraps `state`, rendered with `setup`.
    pub fn new(setup: Arc<RenderSetup>, state: RenderState) -> Self {
        Render {
            setup,
            state,
            developed: OnceLock::new(),
        }
    }

    /// The developed film (developed once, on first use).
    fn developed(&self, py: Python<'_>) -> &Developed {
        self.developed
            .get_or_init(|| py.detach(|| render::develop_state(&self.setup, &self.state)))
    }

    /// The developed channels grouped by layer, in first-seen order.
    fn groups(&self, py: Python<'_>) -> Vec<(String, Vec<(String, usize)>)> {
        let mut out: Vec<(String, Vec<(String, usize)>)> = Vec::new();
        for (i, ch) in self.developed(py).channels.iter().enumerate() {
            let (layer, name) = match ch.name.rsplit_once('.') {
                Some((l, n)) => (l.to_string(), n.to_string()),
                None => (MAIN.to_string(), ch.name.clone()),
            };
            match out.iter_mut().find(|(l, _)| *l == layer) {
                Some((_, chans)) => chans.push((name, i)),
                None => out.push((layer, vec![(name, i)])),
            }
        }
        out
    }
}

#[pymethods]
impl Render {
    /// Reads a render from its bytes (`to_bytes`, or a `.cndl` file of
    /// `candela render --pass-range`), checked against `scene`.
    #[staticmethod]
    fn from_bytes(py: Python<'_>, scene: &Scene, data: &[u8]) -> PyResult<Render> {
        let state = py.detach(|| parse_state(data, "<render state>"))?;
        let ov = render::overrides_from_settings(&state.settings)
            .map_err(|e| errors::StateError::new_err(format!("<render state>: {e}")))?;
        let setup = scene.setup(py, &ov)?;
        if scene.fingerprint(&ov, &setup)? != state.fingerprint {
            return Err(errors::StateError::new_err(format!(
                "the render state is not of {} as it is now (another scene, a changed file, or other settings)",
                scene.path_text()
            )));
        }
        Ok(Render::new(setup, state))
    }

    /// The state's bytes (a `.cndl` file: `candela merge` reads it).
    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        let bytes = py.detach(|| self.state.to_bytes());
        PyBytes::new(py, &bytes)
    }

    /// This render and `other` (disjoint passes of the same render) merged
    /// exactly: the result equals one render of both sets of passes.
    fn merge(&self, py: Python<'_>, other: &Render) -> PyResult<Render> {
        let mut state = self.state.clone();
        py.detach(|| state.merge(&other.state))
            .map_err(|e| errors::from_state(&e))?;
        Ok(Render::new(self.setup.clone(), state))
    }

    /// The EXR file's bytes (the same as `candela render` writes).
    fn exr_bytes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyBytes>> {
        let bytes = py
            .detach(|| render::encode_exr(&self.setup, &self.state))
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        Ok(PyBytes::new(py, &bytes))
    }

    /// Writes the EXR to `path` atomically (temporary file, then rename).
    fn save(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        py.detach(|| {
            let bytes = render::encode_exr(&self.setup, &self.state)
                .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
            candela_core::image::write_atomic_bytes(&path, &bytes).map_err(|e| {
                pyo3::exceptions::PyOSError::new_err(format!("{}: {e}", path.display()))
            })
        })
    }

    /// Layers by name (`main` for the EXR's root layer): float32 numpy
    /// arrays of shape (height, width, channels), top row first.
    #[getter]
    fn layers<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let np = py.import("numpy")?;
        let dev = self.developed(py);
        let d = PyDict::new(py);
        for (layer, chans) in self.groups(py) {
            let n = dev.width * dev.height;
            let mut bytes = Vec::with_capacity(n * chans.len() * 4);
            for i in 0..n {
                for (_, c) in &chans {
                    bytes.extend_from_slice(&dev.channels[*c].data[i].to_ne_bytes());
                }
            }
            let arr = np
                .call_method1("frombuffer", (PyByteArray::new(py, &bytes), "float32"))?
                .call_method1("reshape", ((dev.height, dev.width, chans.len()),))?;
            d.set_item(layer, arr)?;
        }
        Ok(d)
    }

    /// Channel names of each layer, in the order of the arrays' last axis.
    #[getter]
    fn channels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (layer, chans) in self.groups(py) {
            let names: Vec<String> = chans.into_iter().map(|(n, _)| n).collect();
            d.set_item(layer, pyo3::types::PyTuple::new(py, names)?)?;
        }
        Ok(d)
    }

    /// (width, height) of the image.
    #[getter]
    fn size(&self, py: Python<'_>) -> (usize, usize) {
        let dev = self.developed(py);
        (dev.width, dev.height)
    }

    /// The passes held, as (a, b) ranges of a ≤ pass < b.
    #[getter]
    fn passes(&self) -> Vec<(u64, u64)> {
        ranges(&self.state)
    }

    /// How many passes are held.
    #[getter]
    fn pass_count(&self) -> u64 {
        self.state.film.passes().count()
    }

    /// The passes the render was planned with (spp).
    #[getter]
    fn total_passes(&self) -> u64 {
        self.state.total_passes
    }

    /// The integrator's name.
    #[getter]
    fn integrator(&self) -> String {
        self.state.integrator.clone()
    }

    /// The render's fingerprint (scene files and settings).
    #[getter]
    fn fingerprint(&self) -> u64 {
        self.state.fingerprint
    }

    /// The settings stored with the state, as `key=value` lines.
    #[getter]
    fn settings(&self) -> String {
        self.state.settings.clone()
    }

    fn __repr__(&self) -> String {
        format!(
            "<candela.Render {} passes {} of {}>",
            self.state.integrator,
            self.state.film.passes(),
            self.state.total_passes
        )
    }
}

/// Merges two render states given as bytes (disjoint passes of one render)
/// into the bytes of their merged state; needs no scene (for cluster
/// workers that only add partial renders).
#[pyfunction]
pub fn merge_states<'py>(py: Python<'py>, a: &[u8], b: &[u8]) -> PyResult<Bound<'py, PyBytes>> {
    let merged = py.detach(|| -> PyResult<Vec<u8>> {
        let mut sa = parse_state(a, "<first state>")?;
        let sb = parse_state(b, "<second state>")?;
        sa.merge(&sb).map_err(|e| errors::from_state(&e))?;
        Ok(sa.to_bytes())
    })?;
    Ok(PyBytes::new(py, &merged))
}

/// What a render state's bytes hold, as a dict: fingerprint, integrator,
/// total_passes, passes (ranges), pass_count and settings.
#[pyfunction]
pub fn state_info<'py>(py: Python<'py>, data: &[u8]) -> PyResult<Bound<'py, PyDict>> {
    let s = py.detach(|| parse_state(data, "<render state>"))?;
    let d = PyDict::new(py);
    d.set_item("fingerprint", s.fingerprint)?;
    d.set_item("integrator", &s.integrator)?;
    d.set_item("total_passes", s.total_passes)?;
    d.set_item("passes", ranges(&s))?;
    d.set_item("pass_count", s.film.passes().count())?;
    d.set_item("settings", &s.settings)?;
    Ok(d)
}
