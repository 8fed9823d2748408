//! Integrators: estimators of the measurement equation.
//!
//! Every integrator implements [`Integrator`]. Camera-driven ones implement
//! [`PixelEstimator`] and share the tiled driver in [`driver`], which owns
//! threads, tiles, progress and deterministic accumulation (Tungsten's split
//! of driver / per-path tracer / settings). Photon mapping renders pass by
//! pass, each pass with its own photon maps, and has its own loop.

mod bdpt;
mod direct;
pub mod driver;
mod light_tracer;
mod path;
pub mod photon;
pub mod photonmap;
pub mod sppm;

pub use bdpt::{BdptIntegrator, BdptSettings, MisHeuristic, Visualize};
pub use light_tracer::LightTracer;
pub use path::{PathIntegrator, PathSettings};
pub use photonmap::{PhotonMapIntegrator, PhotonMapSettings};
pub use sppm::{PpmIntegrator, PpmSettings, SppmIntegrator, SppmSettings};

use crate::camera::Camera;
use crate::film::{RgbFilm, SplatBuffer};
use crate::math::Ray;
use crate::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Progress reporting from the render loop (thread-safe).
pub trait Progress: Sync {
    /// Called with the total amount of work before rendering starts.
    fn start(&self, total: u64, unit: &str);
    /// Called as work completes.
    fn advance(&self, done: u64);
    /// Called once at the end.
    fn finish(&self);
    /// Status shown beside the bar (photon rates, radius).
    fn message(&self, _msg: &str) {}
}

/// A progress sink that ignores everything.
pub struct NoProgress;

impl Progress for NoProgress {
    fn start(&self, _total: u64, _unit: &str) {}
    fn advance(&self, _done: u64) {}
    fn finish(&self) {}
}

/// What every render needs besides the integrator.
pub struct RenderContext<'a> {
    /// The traceable scene.
    pub scene: &'a Scene,
    /// The camera.
    pub camera: &'a Camera,
    /// The prototype sampler (cloned per tile; fixes spp and seed).
    pub sampler: &'a Sampler,
    /// Progress sink.
    pub progress: &'a dyn Progress,
}

/// A light transport algorithm.
pub trait Integrator: Send + Sync {
    /// Renders the scene onto `film`.
    fn render(&self, ctx: &RenderContext<'_>, film: &mut RgbFilm);
}

/// A camera-driven estimator: the radiance arriving along one camera ray.
pub trait PixelEstimator: Send + Sync {
    /// Estimates the incident radiance along `ray` for the wavelengths
    /// `lambda`; estimators that connect to the camera add those
    /// contributions to `splats` (scaled by 1/spp on output).
    fn li(
        &self,
        ctx: &RenderContext<'_>,
        ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        splats: &mut SplatBuffer,
    ) -> SampledSpectrum;

    /// True when [`PixelEstimator::li`] splats (the driver then allocates splat buffers).
    fn splats(&self) -> bool {
        false
    }
}
