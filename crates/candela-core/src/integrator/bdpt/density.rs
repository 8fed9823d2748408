//! The densities BDPT's MIS weights are built from that no walk stored:
//! those next to a connection, and the emission densities of light
//! endpoints [Veach 1997, §10.2; pbrt-v3 `Vertex::Pdf`, `PdfLight`,
//! `PdfLightOrigin`]. Conventions (area measure, vertices at infinity) are
//! those of [`crate::integrator::subpath::Vertex`].

use crate::bsdf::{Bsdf, SampleFlags, TransportMode};
use crate::camera::Camera;
use crate::integrator::subpath::{adjoint_cos, dir, to_area, Vertex, VertexKind};
use crate::light::LightType;
use crate::math::{Ray, Vec3};
use crate::scene::Scene;
use crate::spectrum::SampledSpectrum;

/// Area density of `cur` generating `next`, having been reached from
/// `prev` (`None` when `cur` is an endpoint). `mode` names the kind of
/// walker that would do it: importance for light subpaths.
pub(crate) fn pdf(
    scene: &Scene,
    camera: &Camera,
    cur: &Vertex,
    prev: Option<&Vertex>,
    next: &Vertex,
    mode: TransportMode,
) -> f32 {
    match (cur.kind, prev) {
        (VertexKind::Camera, _) => pdf_camera(camera, cur, next),
        (VertexKind::Light(_), _) | (VertexKind::Surface, None) => pdf_emission(scene, cur, next),
        (VertexKind::Surface, Some(prev)) => pdf_scatter(cur, prev, next, mode),
    }
}

/// BSDF density at surface vertex `cur` of scattering from `prev` to `next`.
fn pdf_scatter(cur: &Vertex, prev: &Vertex, next: &Vertex, mode: TransportMode) -> f32 {
    let Some(bsdf) = &cur.bsdf else { return 0.0 };
    let (wo, wi) = (dir(cur, prev), dir(cur, next));
    to_area(bsdf.pdf(wo, wi, mode, SampleFlags::ALL), cur, next).0
}

/// Both densities of surface vertex `cur` between `prev` and `next` from one
/// frame change per direction: (`pdf(cur, Some(prev), next, mode)`,
/// `pdf(cur, Some(next), prev, mode.adjoint())`), bit for bit what the two
/// calls give ([`crate::bsdf::Bsdf::pdfs_pair`]): what the MIS weights
/// need at each end of a connection.
pub(crate) fn pdf_scatter_pair(
    cur: &Vertex,
    prev: &Vertex,
    next: &Vertex,
    mode: TransportMode,
) -> (f32, f32) {
    debug_assert!(cur.kind == VertexKind::Surface);
    let Some(bsdf) = &cur.bsdf else {
        return (0.0, 0.0);
    };
    let pair = bsdf.local_pair(dir(cur, prev), dir(cur, next));
    let (fwd, rev) = bsdf.pdfs_pair(&pair, mode);
    (to_area(fwd, cur, next).0, to_area(rev, cur, prev).0)
}

/// One end of a connection between two surface vertices, evaluated from one
/// frame change: what the contribution and the MIS weight need of it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct JoinEnd {
    /// f·|cos θ| towards the other end: for a light-subpath vertex f̂ with
    /// the adjoint shading-normal correction ([`Vertex::f_adjoint_cos`]),
    /// for a camera-subpath vertex f·|ωi·ns|.
    pub f_cos: SampledSpectrum,
    /// Area density at the other end of scattering towards it, having come
    /// from the vertex's own predecessor.
    pub pdf_fwd: f32,
    /// Area density at the predecessor of scattering towards it, having
    /// come from the other end (the adjoint mode).
    pub pdf_rev: f32,
}

/// [`JoinEnd`] of surface vertex `v` (BSDF `bsdf`, reached in `v.mode`)
/// joined along unit direction `w` to a vertex with geometric normal
/// `other_n` (zero off surfaces) at squared distance `d2`. It reads the
/// vertex's stored `wo` and [`Vertex::g_prev`] where [`pdf_scatter_pair`]
/// recomputes both from positions: the same densities up to rounding.
pub(crate) fn join_end(v: &Vertex, bsdf: &Bsdf, w: Vec3, other_n: Vec3, d2: f32) -> JoinEnd {
    let pair = bsdf.local_pair(v.wo, w);
    let f_cos = match v.mode {
        TransportMode::Importance => match adjoint_cos(&v.it, v.ns, v.wo, w) {
            Some(k) => bsdf.f_pair(&pair, v.mode) * k,
            None => SampledSpectrum::zero(),
        },
        TransportMode::Radiance => bsdf.f_pair(&pair, v.mode) * w.dot(v.ns).abs(),
    };
    let (fwd, rev) = bsdf.pdfs_pair(&pair, v.mode);
    // [Veach 1997, eq. 8.10], as `to_area` with |d| = 1 for the unit `w`.
    let cos = if other_n != Vec3::ZERO {
        other_n.dot(w).abs()
    } else {
        1.0
    };
    JoinEnd {
        f_cos,
        pdf_fwd: fwd.0 * cos / d2,
        pdf_rev: rev.0 * v.g_prev,
    }
}

/// Density of the camera's ray from lens point `cur` through `next`.
fn pdf_camera(camera: &Camera, cur: &Vertex, next: &Vertex) -> f32 {
    let ray = Ray::new(cur.p(), dir(cur, next));
    to_area(camera.pdf_we(&ray).1, cur, next).0
}

/// Density of the light at `cur` emitting towards `next` (the direction
/// part of `sample_le`; for lights at infinity, the disk position part).
pub(crate) fn pdf_emission(scene: &Scene, cur: &Vertex, next: &Vertex) -> f32 {
    let Some(id) = cur.light_id() else { return 0.0 };
    let light = scene.light(id);
    if cur.at_infinity() {
        let (pdf_pos, _) = light.pdf_le(&Ray::new(cur.p(), cur.w_inf));
        let cos = if next.it.is_surface() {
            next.it.n.dot(cur.w_inf).abs()
        } else {
            1.0
        };
        return pdf_pos.0 * cos;
    }
    let w = dir(cur, next);
    let pdf_dir = if light.light_type() == LightType::Area {
        light.pdf_le_area(&cur.it, w).1
    } else {
        light.pdf_le(&Ray::new(cur.p(), w)).1
    };
    to_area(pdf_dir, cur, next).0
}

/// Density of choosing `cur` as the origin of a light subpath: p_light
/// times the position density (for lights at infinity, the direction
/// density; zero for delta directions).
pub(crate) fn pdf_light_origin(scene: &Scene, cur: &Vertex, next: &Vertex) -> f32 {
    let Some(id) = cur.light_id() else { return 0.0 };
    let light = scene.light(id);
    let p_light = scene.light_sampler().pmf(id);
    let w = dir(cur, next);
    match light.light_type() {
        LightType::Area => p_light * light.pdf_le_area(&cur.it, w).0 .0,
        LightType::DeltaPosition => p_light * light.pdf_le(&Ray::new(cur.p(), w)).0 .0,
        LightType::Infinite => p_light * light.pdf_le(&Ray::new(cur.p(), cur.w_inf)).1 .0,
        LightType::DeltaDirection => 0.0,
    }
}

/// Emitted radiance from light vertex `v` towards `w` (area lights on the
/// surface, infinite lights along the escaped direction).
pub(crate) fn emitted(
    scene: &Scene,
    v: &Vertex,
    w: Vec3,
    lambda: &crate::spectrum::SampledWavelengths,
) -> SampledSpectrum {
    let Some(id) = v.light_id() else {
        return SampledSpectrum::zero();
    };
    let light = scene.light(id);
    if v.at_infinity() {
        light.le(&Ray::new(Vec3::ZERO, -v.w_inf), lambda)
    } else {
        light.l(v.p(), v.it.n, v.it.uv, w, lambda)
    }
}
