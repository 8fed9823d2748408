//! BDPT's two subpaths, traced by the shared walker
//! ([`crate::integrator::subpath`]) with a visitor that stores every vertex
//! [Veach 1997, §10.2; pbrt-v3 `GenerateCameraSubpath`,
//! `GenerateLightSubpath`].
//!
//! The walker gives each vertex its forward density (converted to area at
//! the vertex) and, after the next scattering, the reverse density of the
//! *previous* vertex, evaluated with the opposite transport mode; the store
//! writes both into the path. Specular vertices get density 0 and the
//! `delta` flag, which the MIS weights skip over. Unlike pbrt, both
//! subpaths end by Russian roulette ([`Roulette::Bidirectional`]), so a
//! large `maxdepth` stays cheap; the survival probability divides β, so the
//! estimator stays unbiased.

use crate::bsdf::TransportMode;
use crate::camera::Camera;
use crate::integrator::roulette::Roulette;
use crate::integrator::subpath::{
    start_light_subpath, to_area_at, walk, Dispersion, EndPoint, Escape, Flow, Scatter, Start,
    Vertex, Visitor, Walk,
};
use crate::interaction::Interaction;
use crate::interaction::SurfaceInteraction;
use crate::math::Ray;
use crate::sampler::Sampler;
use crate::sampling::PdfSolidAngle;
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Settings the walks need.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WalkSettings {
    /// Maximum number of vertices after the endpoint.
    pub max_vertices: usize,
    /// Roughen near-specular lobes after the first non-specular bounce.
    pub regularize: bool,
}

impl WalkSettings {
    fn walk(self, mode: TransportMode) -> Walk {
        Walk {
            mode,
            max_depth: self.max_vertices as u32,
            roulette: Some(Roulette::Bidirectional),
            regularize: self.regularize,
            dispersion: Dispersion::Keep,
        }
    }
}

/// The visitor that stores a subpath.
struct Store<'a> {
    scene: &'a Scene,
    path: &'a mut Vec<Vertex>,
    /// A camera subpath (it ends in a vertex at infinity when it escapes).
    camera: bool,
}

impl Visitor<Sampler> for Store<'_> {
    const DENSITIES: bool = true;

    fn vertex(
        &mut self,
        v: &Vertex,
        _: &SurfaceInteraction,
        _: &mut SampledWavelengths,
        _: &mut Sampler,
    ) -> Flow {
        // The previous vertex stored is the walk's previous vertex (the
        // subpath's endpoint for the first): its area factor, for the
        // connections' reverse densities ([`Vertex::g_prev`]).
        let mut v = *v;
        if let Some(prev) = self.path.last() {
            v.g_prev = to_area_at(PdfSolidAngle(1.0), v.p(), &EndPoint::of(prev)).0;
        }
        self.path.push(v);
        Flow::Continue
    }

    fn scattered(&mut self, s: &Scatter) {
        let n = self.path.len();
        self.path[n - 1].delta = s.delta;
        self.path[n - 2].pdf_rev = s.prev_pdf_rev;
    }

    /// An escaped camera path ends in a vertex at infinity on the first infinite light.
    fn escaped(&mut self, e: &Escape, _: &SampledWavelengths) {
        if !self.camera {
            return;
        }
        let Some(&id) = self.scene.infinite_lights().first() else {
            return;
        };
        let d = e.ray.d.normalize();
        let mut v = Vertex::light(id, Interaction::at_point(e.ray.o + d), -d, e.beta);
        v.mode = TransportMode::Radiance;
        v.pdf_fwd = crate::sampling::PdfArea(e.pdf_dir.0);
        self.path.push(v);
    }
}

/// The camera subpath for `ray`: the lens point, then up to `max_vertices`
/// surface vertices; an escaped ray ends in a vertex at infinity on the first
/// infinite light (the connection step evaluates every infinite light).
pub(crate) fn generate_camera_subpath(
    scene: &Scene,
    camera: &Camera,
    ray: Ray,
    lambda: &mut SampledWavelengths,
    sampler: &mut Sampler,
    settings: WalkSettings,
    path: &mut Vec<Vertex>,
) {
    path.clear();
    let lens = Interaction {
        time: ray.time,
        ..Interaction::at_point(ray.o)
    };
    let mut cam = Vertex::camera(lens, SampledSpectrum::one());
    let (pdf_pos, pdf_dir) = camera.pdf_we(&ray);
    cam.pdf_fwd = pdf_pos;
    path.push(cam);
    let start = Start {
        ray,
        beta: SampledSpectrum::one(),
        depth: 0,
        from: Some(cam),
        pdf_dir,
    };
    let w = settings.walk(TransportMode::Radiance);
    let mut store = Store {
        scene,
        path,
        camera: true,
    };
    walk(scene, lambda, sampler, &w, start, &mut store);
}

/// A light subpath: a light chosen by the scene's light sampler, its
/// emitted ray, then up to `max_vertices` surface vertices
/// ([`start_light_subpath`]). `time` is the camera subpath's: both halves
/// of a path see moving geometry at one instant.
pub(crate) fn generate_light_subpath(
    scene: &Scene,
    time: f32,
    lambda: &mut SampledWavelengths,
    sampler: &mut Sampler,
    settings: WalkSettings,
    path: &mut Vec<Vertex>,
) {
    path.clear();
    let Some(ls) = start_light_subpath(scene, lambda, sampler, Some(time)) else {
        return;
    };
    path.push(ls.vertex);
    let w = settings.walk(TransportMode::Importance);
    let mut store = Store {
        scene,
        path,
        camera: false,
    };
    walk(scene, lambda, sampler, &w, ls.start, &mut store);
}
