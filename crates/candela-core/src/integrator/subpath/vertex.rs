//! The vertex of a camera or light subpath [Veach 1997, §10.2; pbrt-v3
//! `bdpt.h` `Vertex`].
//!
//! A vertex holds its geometry (position, error bound, geometric and
//! shading normals), `wo` towards the previous vertex of its own subpath,
//! the BSDF, the throughput β of the subpath up to it, and two densities in
//! the area measure: `pdf_fwd`, the density with which its own subpath
//! generated it, and `pdf_rev`, the density with which the *other* subpath
//! would have (known once the next vertex of its own subpath exists).
//! Vertices at infinity (escaped camera rays, infinite and distant lights)
//! are parameterised by direction, so densities *of* them are per unit
//! area of the sphere at infinity, that is per steradian; densities of a
//! vertex generated *from* one are a disk position density times the cosine
//! at the vertex (parallel rays). The walk also records how the vertex was
//! reached ([`Vertex::after_delta`], [`Vertex::caustic`]) for estimators that
//! partition paths by their scattering history.

use crate::bsdf::{Bsdf, TransportMode};
use crate::interaction::{Interaction, LightId, SurfaceInteraction};
use crate::math::Vec3;
use crate::sampling::{PdfArea, PdfSolidAngle};
use crate::scene::Scene;
use crate::spectrum::SampledSpectrum;

/// What a vertex is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VertexKind {
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
pub struct Vertex {
    /// Kind of vertex.
    pub kind: VertexKind,
    /// Position, error bound, geometric normal (zero off surfaces), uv, time.
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
    /// Area density from its own subpath (per steradian at infinity).
    pub pdf_fwd: PdfArea,
    /// Area density from the other subpath.
    pub pdf_rev: PdfArea,
    /// |cos θ| / d² at the previous vertex of its own subpath, seen from
    /// this one: what converts a solid-angle density here towards that
    /// vertex into area there (1 when it is at infinity; 0 when unknown).
    /// Set by BDPT's subpath store; connections read it instead of
    /// recomputing the distance.
    pub g_prev: f32,
    /// The lobe sampled here was a delta: no connection can end here.
    pub delta: bool,
    /// Direction light travels from a light at infinity (zero otherwise).
    pub w_inf: Vec3,
    /// Surface vertices from the subpath's endpoint to this one, this one included.
    pub depth: u32,
    /// Reached straight from the walk's start or by a delta scattering: light
    /// arriving here along `wo` was not sampled by the previous vertex's NEE.
    pub after_delta: bool,
    /// Reached through one or more scatterings, every one of them delta (on
    /// a light subpath: an L S+ path, a caustic).
    pub caustic: bool,
    /// Its emission is a fork's to count, not this walk's: the walk forked
    /// at an earlier vertex, took the reflection there, and scattered along
    /// delta lobes only since (module doc of [`super`], "Splitting").
    pub fork_emission: bool,
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
            pdf_fwd: PdfArea(0.0),
            pdf_rev: PdfArea(0.0),
            g_prev: 0.0,
            delta: false,
            w_inf: Vec3::ZERO,
            depth: 0,
            after_delta: true,
            caustic: false,
            fork_emission: false,
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

    /// f̂ = f·|ωo·ns||ωi·ng|/|ωo·ng|, the importance-mode BSDF of a
    /// light-subpath surface vertex scattering towards `wi` times the
    /// geometric cosine there, with the adjoint shading-normal correction
    /// [Veach 1997, eq. 5.19]; zero off surfaces.
    pub fn f_adjoint_cos(&self, wi: Vec3) -> SampledSpectrum {
        let Some(bsdf) = &self.bsdf else {
            return SampledSpectrum::zero();
        };
        match adjoint_cos(&self.it, self.ns, self.wo, wi) {
            Some(k) => bsdf.f(self.wo, wi, TransportMode::Importance) * k,
            None => SampledSpectrum::zero(),
        }
    }
}

/// |ωo·ns||ωi·ng|/|ωo·ng|, the factor that makes the importance-mode f into
/// [`Vertex::f_adjoint_cos`]; `None` when |ωo·ng| = 0.
#[inline]
pub fn adjoint_cos(it: &Interaction, ns: Vec3, wo: Vec3, wi: Vec3) -> Option<f32> {
    let den = wo.dot(it.n).abs();
    (den != 0.0).then(|| wo.dot(ns).abs() * wi.dot(it.n).abs() / den)
}

/// Unit direction from `from` towards `to` (handles vertices at infinity).
pub fn dir(from: &Vertex, to: &Vertex) -> Vec3 {
    if to.at_infinity() {
        -to.w_inf
    } else if from.at_infinity() {
        from.w_inf
    } else {
        (to.p() - from.p()).normalize_or_zero()
    }
}

/// Converts a solid-angle density at `from` into an area density at `to`
/// [Veach 1997, eq. 8.10]: p_A = p_ω |cos θ_to| / d² (unchanged at infinity).
#[inline]
pub fn to_area(pdf: PdfSolidAngle, from: &Vertex, to: &Vertex) -> PdfArea {
    to_area_at(pdf, from.p(), &EndPoint::of(to))
}

/// What converting a density to area at a vertex reads of it: position,
/// geometric normal (zero off surfaces) and whether it is at infinity. A
/// walk keeps this of its previous vertex instead of a copy of the vertex.
#[derive(Clone, Copy, Debug)]
pub struct EndPoint {
    /// Position.
    pub p: Vec3,
    /// Geometric normal (zero off surfaces).
    pub n: Vec3,
    /// A vertex at infinity.
    pub at_infinity: bool,
}

impl EndPoint {
    /// The end point of vertex `v`.
    #[inline]
    pub fn of(v: &Vertex) -> Self {
        Self {
            p: v.p(),
            n: v.it.n,
            at_infinity: v.at_infinity(),
        }
    }
}

/// [`to_area`] from position `from` to end point `to`.
#[inline]
pub fn to_area_at(pdf: PdfSolidAngle, from: Vec3, to: &EndPoint) -> PdfArea {
    if to.at_infinity {
        return PdfArea(pdf.0);
    }
    let d = to.p - from;
    let d2 = d.length_squared();
    if d2 == 0.0 {
        return PdfArea(0.0);
    }
    let cos = if to.n != Vec3::ZERO {
        to.n.dot(d).abs() / d2.sqrt()
    } else {
        1.0
    };
    PdfArea(pdf.0 * cos / d2)
}
