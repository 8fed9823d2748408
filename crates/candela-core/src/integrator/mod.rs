//! Integrators: estimators of the measurement equation, each rendering in
//! passes.
//!
//! Every integrator implements [`Integrator`]: it renders pass `i` into a
//! [`PassBlock`] and owns nothing else of the render: the render loop
//! ([`crate::render`]) owns threads, the pass sequence, progress, stopping,
//! checkpoints and output (Tungsten's driver / tracer / settings split;
//! SmallVCM's loop that owns iterations while the estimator owns one).
//!
//! What a pass is:
//! - `path`, `bdpt`: sample index i of every pixel;
//! - `lightpath`: light paths i·N … (i + 1)·N − 1, N the film's pixel count;
//! - `ppm`, `photonmap`: one independent photon pass;
//! - `sppm`: one iteration, which updates per-pixel statistics carried in
//!   [`IntegratorState`] (the only integrator whose passes depend on each
//!   other);
//! - `vcm`: one iteration (light subpaths, then camera subpaths), its
//!   radius fixed by the pass index.
//!
//! Camera-driven estimators implement [`PixelEstimator`] and share the
//! parallel pixel loop of [`driver`].

mod bdpt;
pub mod camera_walk;
pub mod driver;
pub mod gather;
mod light_tracer;
pub mod lt_weights;
pub mod nee;
mod path;
pub mod photon;
pub mod photonmap;
pub mod roulette;
pub mod sppm;
pub mod subpath;
pub mod vcm;
pub mod wavelengths;

pub use bdpt::{BdptIntegrator, BdptSettings, MisHeuristic, Visualize};
pub use light_tracer::{LightTracer, LightTracerSettings};
pub use path::{PathIntegrator, PathSettings};
pub use photonmap::{PhotonMapIntegrator, PhotonMapSettings};
pub use sppm::{PpmIntegrator, PpmSettings, SppmIntegrator, SppmSettings, SppmState};
pub use vcm::mis::DirectMerges;
pub use vcm::{Connections, VcmIntegrator, VcmMode, VcmSettings};

use crate::camera::Camera;
use crate::film::{Film, PassBlock, SplatBuffer};
use crate::math::{Ray, UVec2};
use crate::sampler::Sampler;
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// The estimators candela has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IntegratorKind {
    /// Unidirectional path tracing.
    Path,
    /// Light tracing.
    LightPath,
    /// Bidirectional path tracing.
    Bdpt,
    /// Stochastic progressive photon mapping.
    Sppm,
    /// Probabilistic progressive photon mapping.
    Ppm,
    /// Jensen's two-pass photon mapping.
    PhotonMap,
    /// Vertex connection and merging.
    Vcm,
}

impl IntegratorKind {
    /// Its `Integrator` directive name.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Path => "path",
            IntegratorKind::LightPath => "lightpath",
            IntegratorKind::Bdpt => "bdpt",
            IntegratorKind::Sppm => "sppm",
            IntegratorKind::Ppm => "ppm",
            IntegratorKind::PhotonMap => "photonmap",
            IntegratorKind::Vcm => "vcm",
        }
    }

    /// True when its passes are independent estimates (they can be split
    /// into ranges and merged); false for SPPM.
    pub fn independent_passes(self) -> bool {
        self != IntegratorKind::Sppm
    }
}

impl std::fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What every pass needs besides the integrator.
pub struct RenderContext<'a> {
    /// The traceable scene.
    pub scene: &'a Scene,
    /// The camera.
    pub camera: &'a Camera,
    /// The prototype sampler (fixes the sample count and seed).
    pub sampler: &'a Sampler,
    /// The film (resolution, filter, sensor, layers).
    pub film: &'a Film,
    /// Raised to abandon the pass under way (checked between tiles and chunks).
    pub cancel: &'a AtomicBool,
    /// Work units done in the current pass (see [`Integrator::pass_work`]).
    pub work: &'a AtomicU64,
}

impl RenderContext<'_> {
    /// True once the render has been asked to stop.
    #[inline]
    pub fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
    /// Records `n` more work units done.
    #[inline]
    pub fn advance(&self, n: u64) {
        self.work.fetch_add(n, Ordering::Relaxed);
    }
}

/// How much work one pass is, for progress and rates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PassWork {
    /// Units per pass.
    pub units: u64,
    /// Their name, plural ("samples", "light paths", "photons").
    pub unit: &'static str,
    /// Light subpaths traced per pass when they are not the units (VCM,
    /// BDPT), so that progress can show their rate; 0 otherwise.
    pub light_paths: u64,
}

/// A pass either completes or is abandoned (its block is then discarded).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PassOutcome {
    /// The block holds the whole pass.
    Done,
    /// The render was cancelled during the pass.
    Cancelled,
}

/// What an integrator carries from one pass to the next.
#[derive(Clone, Debug, PartialEq)]
pub enum IntegratorState {
    /// Nothing: passes are independent.
    Stateless,
    /// SPPM's per-pixel photon statistics.
    Sppm(SppmState),
}

/// A light transport algorithm that renders in passes.
pub trait Integrator: Send + Sync {
    /// Which estimator this is.
    fn kind(&self) -> IntegratorKind;

    /// Work units of one pass.
    fn pass_work(&self, ctx: &RenderContext<'_>) -> PassWork;

    /// The state before the first pass.
    fn initial_state(&self, _ctx: &RenderContext<'_>) -> IntegratorState {
        IntegratorState::Stateless
    }

    /// Renders pass `pass` into `block` (empty on entry). `state` may only
    /// change when the pass is [`PassOutcome::Done`].
    fn render_pass(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        state: &mut IntegratorState,
        block: &mut PassBlock,
    ) -> PassOutcome;

    /// The main layer's sensor RGB per pixel when it is not the sum of the
    /// passes (SPPM), after `passes` passes; `None` for every other integrator.
    fn develop_overlay(&self, _state: &IntegratorState, _passes: u64) -> Option<Vec<[f64; 3]>> {
        None
    }

    /// A short status for the progress line (e.g. the current radius).
    fn status(&self, _state: &IntegratorState, _next_pass: u64) -> Option<String> {
        None
    }
}

/// A camera-driven estimator: the radiance arriving along one camera ray.
pub trait PixelEstimator: Send + Sync {
    /// Estimates the incident radiance along `ray` for the wavelengths
    /// `lambda`; estimators that connect to the camera add those
    /// contributions to `splats`.
    fn li(
        &self,
        ctx: &RenderContext<'_>,
        ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        splats: &mut SplatBuffer,
    ) -> SampledSpectrum;

    /// [`PixelEstimator::li`] for a sample of `pixel`: what the driver
    /// calls, for estimators that keep something per pixel.
    fn li_pixel(
        &self,
        ctx: &RenderContext<'_>,
        _pixel: UVec2,
        ray: Ray,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        splats: &mut SplatBuffer,
    ) -> SampledSpectrum {
        self.li(ctx, ray, lambda, sampler, splats)
    }

    /// True when [`PixelEstimator::li`] splats: the driver then sums the splats
    /// it records per tile into splat buffers (module doc of [`driver`]).
    fn splats(&self) -> bool {
        false
    }
}
