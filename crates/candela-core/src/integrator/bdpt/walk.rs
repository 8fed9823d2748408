//! Subpath generation: `generate_camera_subpath`, `generate_light_subpath`
//! and the `random_walk` both share [Veach 1997, §10.2; pbrt-v3 `bdpt.cpp`].
//!
//! The walk stores for every vertex its forward density (converted to area
//! at the new vertex) and, once the next direction is sampled, the reverse
//! density of the *previous* vertex, evaluated with the opposite transport
//! mode. Specular vertices get density 0 and the `delta` flag, which the
//! MIS weights skip over. Unlike pbrt, both subpaths end by Russian
//! roulette on their throughput, so a large `maxdepth` stays cheap; the
//! survival probability divides β, so the estimator stays unbiased.

use super::vertex::{pdf_light_origin, to_area, Vertex};
use crate::bsdf::{SampleFlags, TransportMode};
use crate::camera::Camera;
use crate::interaction::Interaction;
use crate::light::LightType;
use crate::math::{Ray, Vec3};
use crate::sampler::Sampler;
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
    cam.pdf_fwd = pdf_pos.0;
    path.push(cam);
    let beta = SampledSpectrum::one();
    random_walk(
        scene,
        ray,
        lambda,
        sampler,
        beta,
        pdf_dir.0,
        settings,
        TransportMode::Radiance,
        path,
    );
}

/// A light subpath: a light chosen by the scene's light sampler, its
/// emitted ray, then up to `max_vertices` surface vertices. The first
/// vertex's β is Le·|cos θ|/(p_light·p_pos·p_dir), the subpath's share of the
/// emitted power (seed §3.2). `time` is the camera subpath's: both halves
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
    let u_light = sampler.get_1d();
    let (u1, u2) = (sampler.get_2d(), sampler.get_2d());
    let Some((id, p_light)) = scene.light_sampler().sample(u_light) else {
        return;
    };
    let light = scene.light(id);
    let Some(les) = light.sample_le(u1, u2, lambda) else {
        return;
    };
    let les = les.at_time(time);
    if les.pdf_pos.0 == 0.0 || les.pdf_dir.0 == 0.0 || les.l.is_black() {
        return;
    }
    let at_infinity = matches!(
        light.light_type(),
        LightType::Infinite | LightType::DeltaDirection
    );
    let it = les.intr.unwrap_or(Interaction {
        time,
        ..Interaction::at_point(les.ray.o)
    });
    let w_inf = if at_infinity { les.ray.d } else { Vec3::ZERO };
    let mut v0 = Vertex::light(
        id,
        it,
        w_inf,
        SampledSpectrum::splat(1.0 / (p_light * les.pdf_pos.0)),
    );
    v0.pdf_fwd = if at_infinity {
        // Density of the direction: the position is on the disk.
        pdf_light_origin(scene, &v0, &v0)
    } else {
        p_light * les.pdf_pos.0
    };
    path.push(v0);
    let beta = les.beta0(p_light);
    // From a light at infinity the first vertex's density is the disk
    // position density times its cosine (parallel rays), set by the walk.
    let pdf_dir = if at_infinity {
        les.pdf_pos.0
    } else {
        les.pdf_dir.0
    };
    random_walk(
        scene,
        les.ray,
        lambda,
        sampler,
        beta,
        pdf_dir,
        settings,
        TransportMode::Importance,
        path,
    );
}

/// Extends `path` from its last vertex along `ray` by BSDF sampling.
/// `pdf_dir` is the solid-angle density of `ray`'s direction at the last
/// vertex (for a light at infinity: the disk position density).
fn random_walk(
    scene: &Scene,
    mut ray: Ray,
    lambda: &mut SampledWavelengths,
    sampler: &mut Sampler,
    mut beta: SampledSpectrum,
    mut pdf_dir: f32,
    settings: WalkSettings,
    mode: TransportMode,
    path: &mut Vec<Vertex>,
) {
    let start = path.len();
    let mut any_non_specular = false;
    let mut eta_scale = 1.0f32;
    while !beta.is_black() && path.len() - start < settings.max_vertices {
        let prev = *path.last().expect("walk starts from an endpoint");
        let Some(mut si) = scene.intersect(&ray, f32::INFINITY) else {
            if mode == TransportMode::Radiance {
                push_escape(scene, &ray, beta, pdf_dir, path);
            }
            break;
        };
        let Some(mut bsdf) = scene.bsdf(&mut si, lambda) else {
            // An interface without scattering: not a vertex.
            ray = si.spawn_ray(ray.d);
            continue;
        };
        if settings.regularize && any_non_specular {
            bsdf.regularize();
        }
        let mut v = Vertex::surface(&si, bsdf, mode, beta);
        v.pdf_fwd = if prev.at_infinity() {
            pdf_dir * si.n().dot(ray.d.normalize()).abs()
        } else {
            to_area(pdf_dir, &prev, &v)
        };
        path.push(v);
        if path.len() - start >= settings.max_vertices {
            break;
        }
        let wo = si.wo;
        let Some(bs) = bsdf.sample_f(
            wo,
            sampler.get_1d(),
            sampler.get_2d(),
            mode,
            SampleFlags::ALL,
        ) else {
            break;
        };
        let cos = bs.wi.dot(bsdf.ns()).abs();
        let correction = match mode {
            TransportMode::Radiance => 1.0,
            TransportMode::Importance => si.importance_shading_correction(wo, bs.wi),
        };
        beta *= bs.f * (cos * correction / bs.pdf.0);
        pdf_dir = if bs.pdf_is_proportional {
            bsdf.pdf(wo, bs.wi, mode, SampleFlags::ALL).0
        } else {
            bs.pdf.0
        };
        let mut pdf_rev = bsdf.pdf(bs.wi, wo, mode.adjoint(), SampleFlags::ALL).0;
        let n = path.len();
        if bs.is_specular() {
            path[n - 1].delta = true;
            pdf_dir = 0.0;
            pdf_rev = 0.0;
        } else {
            any_non_specular = true;
        }
        if bs.is_transmission() {
            eta_scale *= bs.eta * bs.eta;
        }
        path[n - 2].pdf_rev = to_area(pdf_rev, &path[n - 1], &path[n - 2]);
        ray = si.spawn_ray(bs.wi);
        if !russian_roulette(&mut beta, eta_scale, n - start, sampler) {
            break;
        }
    }
}

/// Ends an escaped camera path in a vertex at infinity on the first infinite light.
fn push_escape(
    scene: &Scene,
    ray: &Ray,
    beta: SampledSpectrum,
    pdf_dir: f32,
    path: &mut Vec<Vertex>,
) {
    let Some(&id) = scene.infinite_lights().first() else {
        return;
    };
    let d = ray.d.normalize();
    let mut v = Vertex::light(id, Interaction::at_point(ray.o + d), -d, beta);
    v.mode = TransportMode::Radiance;
    v.pdf_fwd = pdf_dir;
    path.push(v);
}

/// Russian roulette after the third vertex on the throughput (η²-corrected
/// so refraction does not bias the decision); returns false to stop.
fn russian_roulette(
    beta: &mut SampledSpectrum,
    eta_scale: f32,
    vertices: usize,
    sampler: &mut Sampler,
) -> bool {
    let m = (*beta * eta_scale).max_component();
    if vertices > 3 && m < 1.0 {
        let q = (1.0 - m).max(0.05);
        if sampler.get_1d() < q {
            return false;
        }
        *beta /= 1.0 - q;
    }
    true
}
