//! `candela.Scene`: a parsed scene, the render setups built from it (one
//! per set of overrides, kept for the next render), its summary and the
//! renders themselves.

use crate::errors;
use crate::files;
use crate::result::Render;
use crate::run;
use candela_core::build::{build, summarize, Overrides, RenderSetup};
use candela_core::render::{self, RenderOptions};
use candela_scene::SceneDescription;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyRange, PyRangeMethods};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// Render setups kept per scene (the last ones used).
const KEPT_SETUPS: usize = 4;

/// A pbrt-v4 scene, parsed and built: `candela.load(path)`.
#[pyclass(module = "candela", frozen)]
pub struct Scene {
    path: PathBuf,
    /// The parsed scene, never built: its parameters mark their use in
    /// cells, so each build takes a copy (and reports its own unused ones).
    desc: Mutex<SceneDescription>,
    /// Built setups by settings text, most recent last.
    setups: Mutex<Vec<(String, Arc<RenderSetup>)>>,
}

/// The overrides of a render from its keyword arguments.
pub fn overrides(
    spp: Option<u32>,
    integrator: Option<String>,
    seed: Option<u64>,
    crop: Option<(f32, f32, f32, f32)>,
) -> PyResult<Overrides> {
    if spp == Some(0) {
        return Err(PyValueError::new_err("spp must be at least 1"));
    }
    let cropwindow = match crop {
        None => None,
        Some((x0, x1, y0, y1)) => {
            let unit =
                |a: f32, b: f32| (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b) && a < b;
            if !(unit(x0, x1) && unit(y0, y1)) {
                return Err(PyValueError::new_err(
                    "crop must be (x0, x1, y0, y1) in [0, 1] with x0 < x1 and y0 < y1",
                ));
            }
            Some([x0, x1, y0, y1])
        }
    };
    Ok(Overrides {
        spp,
        integrator,
        seed,
        cropwindow,
        outfile: None,
        ..Overrides::default()
    })
}

/// The pass range `[a, b)` of `passes` (a `range` with step 1, or a pair).
fn pass_range(passes: &Bound<'_, PyAny>) -> PyResult<(u64, u64)> {
    let (a, b) = if let Ok(r) = passes.cast::<PyRange>() {
        if r.step()? != 1 {
            return Err(PyValueError::new_err("passes: a range with step 1"));
        }
        (r.start()?, r.stop()?)
    } else {
        passes.extract::<(isize, isize)>().map_err(|_| {
            PyValueError::new_err("passes must be a range (range(a, b)) or a pair (a, b)")
        })?
    };
    if a < 0 || a >= b {
        return Err(PyValueError::new_err(format!(
            "passes: empty or negative range {a}..{b}"
        )));
    }
    Ok((a as u64, b as u64))
}

impl Scene {
    /// Parses the scene at `path` and builds it with `ov` (without the GIL).
    pub fn load(py: Python<'_>, path: PathBuf, ov: &Overrides) -> PyResult<Self> {
        let desc = py
            .detach(|| candela_scene::parse_file(&path))
            .map_err(|e| errors::from_scene(&e))?;
        let scene = Scene {
            path,
            desc: Mutex::new(desc),
            setups: Mutex::new(Vec::new()),
        };
        scene.setup(py, ov)?;
        Ok(scene)
    }

    /// The setup for `ov`, built now unless kept from before.
    pub fn setup(&self, py: Python<'_>, ov: &Overrides) -> PyResult<Arc<RenderSetup>> {
        let key = render::settings_text(ov);
        if let Some(s) = self.kept(&key) {
            return Ok(s);
        }
        let built =
            py.detach(|| build(&self.description()?, ov).map_err(|e| errors::from_build(&e)))?;
        let setup = Arc::new(built);
        if let Ok(mut kept) = self.setups.lock() {
            kept.retain(|(k, _)| *k != key);
            kept.push((key, setup.clone()));
            let extra = kept.len().saturating_sub(KEPT_SETUPS);
            kept.drain(..extra);
        }
        Ok(setup)
    }

    /// A copy of the parsed scene.
    fn description(&self) -> PyResult<SceneDescription> {
        self.desc
            .lock()
            .map(|d| d.clone())
            .map_err(|_| PyRuntimeError::new_err("a render of this scene panicked"))
    }

    /// The kept setup of settings `key`, if any.
    fn kept(&self, key: &str) -> Option<Arc<RenderSetup>> {
        let kept = self.setups.lock().ok()?;
        kept.iter().find(|(k, _)| k == key).map(|(_, s)| s.clone())
    }

    /// The scene file's path as text.
    pub fn path_text(&self) -> String {
        self.path.display().to_string()
    }

    /// The fingerprint of a render of this scene with `ov`.
    pub fn fingerprint(&self, ov: &Overrides, setup: &RenderSetup) -> PyResult<u64> {
        let desc = self
            .desc
            .lock()
            .map_err(|_| PyRuntimeError::new_err("a render of this scene panicked"))?;
        Ok(render::fingerprint(&desc, ov, setup.film.layout()))
    }
}

#[pymethods]
impl Scene {
    /// The scene file's path, as given to `load`.
    #[getter]
    fn path(&self) -> String {
        self.path_text()
    }

    /// Every file the scene reads: its scene files (includes too) and every
    /// file a string parameter names (PLY meshes, images, IES files,
    /// spectra), sorted. Raises SceneError for an absolute path to a file.
    fn files(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        let desc = self.description()?;
        let found = py
            .detach(move || files::scene_files(&desc))
            .map_err(|e| errors::from_scene(&e))?;
        Ok(found.iter().map(|p| p.display().to_string()).collect())
    }

    /// What the scene holds with these overrides, as a dict: camera, film,
    /// sampler, integrator (descriptions), shapes, primitives, lights,
    /// materials, textures (counts by type), triangles, instances, bounds,
    /// resolution (width, height of the rendered pixels), passes (planned),
    /// integrator_name, independent_passes, fingerprint and warnings.
    #[pyo3(signature = (*, spp=None, integrator=None, seed=None, crop=None))]
    fn info<'py>(
        &self,
        py: Python<'py>,
        spp: Option<u32>,
        integrator: Option<String>,
        seed: Option<u64>,
        crop: Option<(f32, f32, f32, f32)>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let ov = overrides(spp, integrator, seed, crop)?;
        let setup = self.setup(py, &ov)?;
        let s = summarize(&self.description()?, &setup);
        let d = PyDict::new(py);
        d.set_item("camera", s.camera)?;
        d.set_item("film", s.film)?;
        d.set_item("sampler", s.sampler)?;
        d.set_item("integrator", s.integrator)?;
        d.set_item("shapes", s.shapes)?;
        d.set_item("instances", s.instances)?;
        d.set_item("primitives", s.primitives)?;
        d.set_item("triangles", s.triangles)?;
        d.set_item("lights", s.lights)?;
        d.set_item("materials", s.materials)?;
        d.set_item("textures", s.textures)?;
        d.set_item("bounds", s.bounds)?;
        d.set_item("warnings", s.warnings)?;
        let (lo, hi) = setup.film.pixel_bounds();
        d.set_item("resolution", (hi.x - lo.x, hi.y - lo.y))?;
        d.set_item("passes", setup.sampler.samples_per_pixel())?;
        let kind = setup.integrator.kind();
        d.set_item("integrator_name", kind.name())?;
        d.set_item("independent_passes", kind.independent_passes())?;
        d.set_item("fingerprint", self.fingerprint(&ov, &setup)?)?;
        Ok(d)
    }

    /// Renders passes `passes` (a range; default all of them) of the render
    /// with these overrides (`spp`: passes planned, `integrator`, `seed`,
    /// `crop`: (x0, x1, y0, y1) fractions of the film) on `threads` threads
    /// (default: all cores; the bytes do not depend on it), with the GIL
    /// released. `progress(done, total, seconds)` is called after passes.
    /// Ctrl-C stops the render and raises KeyboardInterrupt.
    #[pyo3(signature = (*, spp=None, integrator=None, seed=None, crop=None, passes=None, threads=None, progress=None))]
    fn render(
        &self,
        py: Python<'_>,
        spp: Option<u32>,
        integrator: Option<String>,
        seed: Option<u64>,
        crop: Option<(f32, f32, f32, f32)>,
        passes: Option<&Bound<'_, PyAny>>,
        threads: Option<usize>,
        progress: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Render> {
        let ov = overrides(spp, integrator, seed, crop)?;
        let setup = self.setup(py, &ov)?;
        let total = setup.sampler.samples_per_pixel() as u64;
        let range = match passes {
            Some(p) => pass_range(p)?,
            None => (0, total),
        };
        if range.1 > total {
            return Err(PyValueError::new_err(format!(
                "passes {}..{} go past the {total} passes of the render (set spp)",
                range.0, range.1
            )));
        }
        let kind = setup.integrator.kind();
        if range != (0, total) && !kind.independent_passes() {
            return Err(PyValueError::new_err(format!(
                "{kind}'s passes depend on each other: it renders all of them in one call"
            )));
        }
        let fp = self.fingerprint(&ov, &setup)?;
        let mut state = render::new_state(&setup, fp, total, &render::settings_text(&ov));
        let opts = RenderOptions {
            passes: range,
            ..RenderOptions::default()
        };
        run::run(py, &setup, &mut state, &opts, threads, progress)?;
        Ok(Render::new(setup, state))
    }

    fn __repr__(&self) -> String {
        format!("candela.load({:?})", self.path.display().to_string())
    }
}
