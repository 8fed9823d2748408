//! Path vertices and the densities BDPT's MIS weights are built from.
//!
//! Every vertex stores two densities in the area measure [Veach 1997, §10.2]:
//! `pdf_fwd`, the density with which its own subpath generated it, and
//! `pdf_rev`, the density with which the *other* subpath would have
//! generated it (known once the next vertex of its own subpath exists).
//! Vertices at infinity (escaped camera rays, infinite and distant lights)
//! are parameterised by direction, so densities *of* them stay per unit
//! solid angle; densities of a vertex generated *from* one are a disk
//! position density times the cosine at the vertex (parallel rays).

use crate::bsdf::{Bsdf, SampleFlags, TransportMode};
use crate::camera::Camera;
use crate::interaction::{Interaction, LightId, SurfaceInteraction};
use crate::light::LightType;
use crate::math::{Ray, Vec3};
use crate::scene::Scene;
use crate::spectrum::SampledSpectrum;

/// What a vertex is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum VertexKind {
    /// The camera endpoint (a lens point).
    Camera,
    /// A light endpoint: a point on an area light, a point light's position,
    /// or a direction at infinity.
    Light(LightId),
    /// A scattering point on a surface.
    Surface,
}

/// One vertex of a camera or light subpath.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Vertex {
    /// Kind of vertex.
    pub kind: VertexKind,
    /// Position, error bound, geometric normal (zero off surfaces), uv.
    pub it: Interaction,
    /// Shading normal (zero off surfaces).
    pub ns: Vec3,
    /// Unit direction towards the previous vertex of its own subpath.
    pub wo: Vec3,
    /// Scattering function (surface vertices).
    pub bsdf: Option<Bsdf>,
    /// The area light on the surface, if it emits.
    pub area_light: Option<LightId>,
    /// Transport mode of the subpath that made the vertex.
    pub mode: TransportMode,
    /// Throughput of the subpath up to and including this vertex's density.
    pub beta: SampledSpectrum,
    /// Area density from its own subpath (solid angle for vertices at infinity).
    pub pdf_fwd: f32,
    /// Area density from the other subpath.
    pub pdf_rev: f32,
    /// Sampled from a delta lobe: no connection can end here.
    pub delta: bool,
    /// Direction light travels from a light at infinity (zero otherwise).
    pub w_inf: Vec3,
}

impl Vertex {
    fn blank(
        kind: VertexKind,
        it: Interaction,
        mode: TransportMode,
        beta: SampledSpectrum,
    ) -> Self {
        Self {
            kind,
            it,
            ns: it.n,
            wo: Vec3::ZERO,
            bsdf: None,
            area_light: None,
            mode,
            beta,
            pdf_fwd: 0.0,
            pdf_rev: 0.0,
            delta: false,
            w_inf: Vec3::ZERO,
        }
    }

    /// The camera endpoint at lens point `it`.
    pub fn camera(it: Interaction, beta: SampledSpectrum) -> Self {
        Self::blank(VertexKind::Camera, it, TransportMode::Radiance, beta)
    }

    /// A light endpoint at `it` (for lights at infinity `w_inf` is the
    /// direction light travels and `it` a point on the scene's disk).
    pub fn light(id: LightId, it: Interaction, w_inf: Vec3, beta: SampledSpectrum) -> Self {
        let mut v = Self::blank(VertexKind::Light(id), it, TransportMode::Importance, beta);
        v.w_inf = w_inf;
        v
    }

    /// A surface vertex at hit `si`.
    pub fn surface(
        si: &SurfaceInteraction,
        bsdf: Bsdf,
        mode: TransportMode,
        beta: SampledSpectrum,
    ) -> Self {
        let mut v = Self::blank(VertexKind::Surface, si.it, mode, beta);
        v.ns = si.shading.n;
        v.wo = si.wo;
        v.bsdf = Some(bsdf);
        v.area_light = si.area_light;
        v
    }

    /// Position.
    #[inline]
    pub fn p(&self) -> Vec3 {
        self.it.p
    }

    /// True for light endpoints at infinity.
    #[inline]
    pub fn at_infinity(&self) -> bool {
        self.w_inf != Vec3::ZERO
    }

    /// The light this vertex emits from: a light endpoint or an emitting surface.
    pub fn light_id(&self) -> Option<LightId> {
        match self.kind {
            VertexKind::Light(id) => Some(id),
            VertexKind::Surface => self.area_light,
            VertexKind::Camera => None,
        }
    }

    /// True when the vertex could be found by a path hitting it: an area or
    /// infinite light (not a delta light, not an invisible area light).
    pub fn is_hittable_light(&self, scene: &Scene) -> bool {
        self.light_id()
            .is_some_and(|id| scene.light(id).is_hittable())
    }
}

/// Unit direction from `from` towards `to` (handles vertices at infinity).
pub(crate) fn dir(from: &Vertex, to: &Vertex) -> Vec3 {
    if to.at_infinity() {
        -to.w_inf
    } else if from.at_infinity() {
        from.w_inf
    } else {
        (to.p() - from.p()).normalize_or_zero()
    }
}

/// Converts a solid-angle density at `from` into an area density at `to`
/// [Veach 1997, eq. 8.10]: p_A = p_ω |cos θ_to| / d².
pub(crate) fn to_area(pdf_sa: f32, from: &Vertex, to: &Vertex) -> f32 {
    if to.at_infinity() {
        return pdf_sa;
    }
    let d = to.p() - from.p();
    let d2 = d.length_squared();
    if d2 == 0.0 {
        return 0.0;
    }
    let cos = if to.it.is_surface() {
        to.it.n.dot(d).abs() / d2.sqrt()
    } else {
        1.0
    };
    pdf_sa * cos / d2
}

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
    to_area(bsdf.pdf(wo, wi, mode, SampleFlags::ALL).0, cur, next)
}

/// Density of the camera's ray from lens point `cur` through `next`.
fn pdf_camera(camera: &Camera, cur: &Vertex, next: &Vertex) -> f32 {
    let ray = Ray::new(cur.p(), dir(cur, next));
    to_area(camera.pdf_we(&ray).1 .0, cur, next)
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
    to_area(pdf_dir.0, cur, next)
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
