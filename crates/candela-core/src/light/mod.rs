//! Light sources: emission, sampling from both ends, and power.
//!
//! Every light answers two families of queries [pbrt-v4 §12.1]:
//!
//! - **Incident** (camera paths, next-event estimation): [`Light::sample_li`]
//!   draws a point or direction on the light as seen from a receiving point
//!   and returns the incident radiance `Li`, the direction `wi` and its
//!   density per unit solid angle at the receiver; [`Light::pdf_li`] evaluates
//!   that density for MIS.
//! - **Emitted** (light paths, photons): [`Light::sample_le`] draws a ray
//!   leaving the light with a position density `pdf_pos` (per unit area) and a
//!   direction density `pdf_dir` (per unit solid angle) [Veach 1997, §8.2,
//!   eq. 8.9: emitted radiance factors as `Le = Le⁽⁰⁾(x)·Le⁽¹⁾(x, ω)`, sampled
//!   one factor at a time]. [`Light::pdf_le`] / [`Light::pdf_le_area`]
//!   evaluate both densities for a given ray.
//!
//! Light subpaths carry **power**. A subpath starts with
//! `β₀ = Le·|cos θ| / (p_light·p_pos·p_dir)` (the seed notes, §3.2; pbrt-v3
//! `GenerateLightSubpath`), whose expectation is the light's share of power
//! [`Light::phi`]: Φ = 4πI for a point light (seed eq. 二.5) and Φ = πAL for a
//! one-sided diffuse emitter (seed eq. 二.7; 2πAL when two-sided). Every
//! light here samples proportionally to its emission, so `β₀/Φ` is constant
//! per subpath: with power-proportional light selection ([`LightSampler`])
//! each subpath starts with exactly `β₀ = Φ_total`.
//!
//! Delta lights (point, spot, goniometric and projection: a delta in
//! position; distant: a delta in
//! direction) are flagged by [`Light::light_type`], never by huge densities:
//! their delta component is reported with density 1 and must not enter MIS
//! against techniques that cannot sample it.
//!
//! Distant and infinite lights need the scene's bounding sphere
//! ([`Light::preprocess`]) before `phi`, `sample_li` (for the far point) and
//! `sample_le` (which aims rays from a disk of the scene's radius) are valid.

mod bounds;
mod bvh;
mod create;
mod diffuse_area;
mod distant;
mod emission;
mod flux;
mod goniometric;
mod ies_web;
mod image_infinite;
mod infinite;
mod point;
mod projection;
mod sampler;
mod spot;

#[cfg(test)]
mod tests;

pub use bounds::LightBounds;
pub use bvh::BvhLightSampler;
pub use create::{
    diffuse_area_image_light, diffuse_area_light, distant_light, goniometric_light, ies_light,
    image_infinite_light, point_light, projection_light, spot_light, uniform_infinite_light,
};
pub use diffuse_area::DiffuseAreaLight;
pub use distant::DistantLight;
pub use emission::{spectrum_photometric, LightSpectrum};
pub use flux::Flux;
pub use goniometric::GoniometricLight;
pub use ies_web::{IesSample, IesWeb, IesWebError};
pub use image_infinite::ImageInfiniteLight;
pub use infinite::UniformInfiniteLight;
pub use point::PointLight;
pub use projection::ProjectionLight;
pub use sampler::{LightChooser, LightSampler, LightSelection, NeeLightSampler};
pub use spot::SpotLight;

use crate::interaction::{Interaction, SurfaceInteraction};
use crate::math::{Bounds3, Ray, Vec2, Vec3};
use crate::sampling::{PdfArea, PdfSolidAngle};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// What kind of singularity a light's emission has [pbrt-v4 §12.1].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightType {
    /// Emits from a single point (point, spot): delta in position.
    DeltaPosition,
    /// Emits along a single direction (distant): delta in direction.
    DeltaDirection,
    /// Emits from the surface of a shape.
    Area,
    /// Surrounds the scene at infinity; rays that escape see it.
    Infinite,
}

impl LightType {
    /// True for lights that cannot be hit by a ray (delta position or direction).
    #[inline]
    pub fn is_delta(self) -> bool {
        matches!(self, LightType::DeltaPosition | LightType::DeltaDirection)
    }
}

/// The receiving point of an incident-light query; same fields as the
/// shapes' sampling context (position, its error bound, geometric and
/// shading normals; normals zero in free space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSampleContext {
    /// Receiving position.
    pub p: Vec3,
    /// Absolute error bound of `p`.
    pub p_error: Vec3,
    /// Geometric normal (zero for points in media).
    pub n: Vec3,
    /// Shading normal (zero for points in media).
    pub ns: Vec3,
}

impl LightSampleContext {
    /// A context at a bare point (no surface).
    pub fn at_point(p: Vec3) -> Self {
        Self {
            p,
            p_error: Vec3::ZERO,
            n: Vec3::ZERO,
            ns: Vec3::ZERO,
        }
    }
    /// A context at a surface hit.
    pub fn from_surface(si: &SurfaceInteraction) -> Self {
        Self {
            p: si.it.p,
            p_error: si.it.p_error,
            n: si.it.n,
            ns: si.shading.n,
        }
    }
    /// A context at a sampled interaction (geometric normal as shading normal).
    pub fn from_interaction(it: &Interaction) -> Self {
        Self {
            p: it.p,
            p_error: it.p_error,
            n: it.n,
            ns: it.n,
        }
    }
}

/// Result of [`Light::sample_li`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightLiSample {
    /// Incident radiance at the receiver (for point/spot: I/d²; no visibility).
    pub l: SampledSpectrum,
    /// Unit direction from the receiver towards the light.
    pub wi: Vec3,
    /// Density per unit solid angle at the receiver; 1 for delta lights.
    pub pdf: PdfSolidAngle,
    /// The sampled point on (or, for lights at infinity, beyond) the light.
    pub p_light: Interaction,
}

/// Result of [`Light::sample_le`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightLeSample {
    /// Emitted radiance (intensity for point/spot) along the ray.
    pub l: SampledSpectrum,
    /// The emitted ray; its direction is normalised.
    pub ray: Ray,
    /// The point on an area light's surface (`None` for other lights).
    pub intr: Option<Interaction>,
    /// Density of the origin per unit area; 1 for delta-position lights.
    pub pdf_pos: PdfArea,
    /// Density of the direction per unit solid angle; 1 for delta-direction lights.
    pub pdf_dir: PdfSolidAngle,
}

/// `sample_li` of a light at point `p` (a delta in position: point, spot,
/// goniometric, projection) whose intensity towards light-frame direction
/// `wl` is `intensity(wl)` [W/sr]: Li = I(wl)/d² from the receiver, density 1.
/// `None` at the light itself or where it emits nothing.
pub(crate) fn delta_position_li(
    p: Vec3,
    light_from_render: &crate::math::Transform,
    ctx: &LightSampleContext,
    intensity: impl FnOnce(Vec3) -> SampledSpectrum,
) -> Option<LightLiSample> {
    let d2 = p.distance_squared(ctx.p);
    if d2 == 0.0 {
        return None;
    }
    let wi = (p - ctx.p) / d2.sqrt();
    let l = intensity(light_from_render.vector(-wi).normalize()) / d2;
    if l.is_black() {
        return None;
    }
    Some(LightLiSample {
        l,
        wi,
        pdf: PdfSolidAngle(1.0),
        p_light: Interaction::at_point(p),
    })
}

impl LightLeSample {
    /// The same emission at path time `time` (motion blur).
    pub fn at_time(mut self, time: f32) -> Self {
        self.ray.time = time;
        if let Some(it) = &mut self.intr {
            it.time = time;
        }
        self
    }
    /// |cos θ| between the surface normal and the ray (1 without a surface).
    #[inline]
    pub fn abs_cos_theta(&self) -> f32 {
        match &self.intr {
            Some(it) if it.is_surface() => it.n.dot(self.ray.d).abs(),
            _ => 1.0,
        }
    }
    /// Initial light-path throughput `Le·|cos θ|/(p_light·p_pos·p_dir)`: the
    /// power this subpath carries (seed §3.2); zero when a density is zero.
    pub fn beta0(&self, p_light: f32) -> SampledSpectrum {
        let denom = p_light * self.pdf_pos.0 * self.pdf_dir.0;
        if denom == 0.0 {
            return SampledSpectrum::zero();
        }
        self.l * (self.abs_cos_theta() / denom)
    }
}

/// A light source: a closed set of implementations, dispatched by `match`.
#[derive(Clone, Debug)]
pub enum Light {
    /// Isotropic point light.
    Point(PointLight),
    /// Point light with a smooth-step cone falloff.
    Spot(SpotLight),
    /// Point light with an equal-area intensity map.
    Goniometric(GoniometricLight),
    /// Point light projecting an RGB image through a frustum.
    Projection(ProjectionLight),
    /// Parallel light from one direction.
    Distant(DistantLight),
    /// Lambertian emitter on a shape.
    DiffuseArea(DiffuseAreaLight),
    /// Constant radiance from every direction at infinity.
    UniformInfinite(UniformInfiniteLight),
    /// Radiance at infinity from an equal-area environment image.
    ImageInfinite(ImageInfiniteLight),
}

/// Writes the dispatch `match` over every light once.
macro_rules! dispatch {
    ($self:expr, $l:ident => $body:expr) => {
        match $self {
            Light::Point($l) => $body,
            Light::Spot($l) => $body,
            Light::Goniometric($l) => $body,
            Light::Projection($l) => $body,
            Light::Distant($l) => $body,
            Light::DiffuseArea($l) => $body,
            Light::UniformInfinite($l) => $body,
            Light::ImageInfinite($l) => $body,
        }
    };
}

impl Light {
    /// The light's singularity class.
    pub fn light_type(&self) -> LightType {
        match self {
            Light::Point(_) | Light::Spot(_) | Light::Goniometric(_) | Light::Projection(_) => {
                LightType::DeltaPosition
            }
            Light::Distant(_) => LightType::DeltaDirection,
            Light::DiffuseArea(_) => LightType::Area,
            Light::UniformInfinite(_) | Light::ImageInfinite(_) => LightType::Infinite,
        }
    }

    /// Samples incident illumination at `ctx` (no visibility test).
    pub fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLiSample> {
        dispatch!(self, l => l.sample_li(ctx, u, lambda))
    }

    /// Solid-angle density with which `sample_li` would pick `wi` at `ctx`
    /// (0 for delta lights: they cannot be found by other techniques).
    pub fn pdf_li(&self, ctx: &LightSampleContext, wi: Vec3) -> PdfSolidAngle {
        match self {
            Light::DiffuseArea(l) => l.pdf_li(ctx, wi),
            Light::UniformInfinite(l) => l.pdf_li(ctx, wi),
            Light::ImageInfinite(l) => l.pdf_li(ctx, wi),
            _ => PdfSolidAngle(0.0),
        }
    }

    /// Radiance emitted by an area light at a surface point towards `w`
    /// (zero for other lights).
    pub fn l(
        &self,
        p: Vec3,
        n: Vec3,
        uv: Vec2,
        w: Vec3,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        match self {
            Light::DiffuseArea(l) => l.l(p, n, uv, w, lambda),
            _ => SampledSpectrum::zero(),
        }
    }

    /// Radiance arriving along an escaped ray from an infinite light
    /// (zero for other lights).
    pub fn le(&self, ray: &Ray, lambda: &SampledWavelengths) -> SampledSpectrum {
        match self {
            Light::UniformInfinite(l) => l.le(ray, lambda),
            Light::ImageInfinite(l) => l.le(ray, lambda),
            _ => SampledSpectrum::zero(),
        }
    }

    /// Samples a ray leaving the light: `u1` picks the position (direction for
    /// infinite lights), `u2` the rest.
    pub fn sample_le(
        &self,
        u1: Vec2,
        u2: Vec2,
        lambda: &SampledWavelengths,
    ) -> Option<LightLeSample> {
        dispatch!(self, l => l.sample_le(u1, u2, lambda))
    }

    /// Position and direction densities of `sample_le` producing `ray`, for
    /// lights without a surface (area lights: use [`Light::pdf_le_area`]).
    pub fn pdf_le(&self, ray: &Ray) -> (PdfArea, PdfSolidAngle) {
        match self {
            Light::Point(l) => l.pdf_le(ray),
            Light::Spot(l) => l.pdf_le(ray),
            Light::Goniometric(l) => l.pdf_le(ray),
            Light::Projection(l) => l.pdf_le(ray),
            Light::Distant(l) => l.pdf_le(ray),
            Light::UniformInfinite(l) => l.pdf_le(ray),
            Light::ImageInfinite(l) => l.pdf_le(ray),
            Light::DiffuseArea(_) => {
                debug_assert!(false, "pdf_le on an area light: use pdf_le_area");
                (PdfArea(0.0), PdfSolidAngle(0.0))
            }
        }
    }

    /// Densities of `sample_le` leaving surface point `intr` in direction `w`
    /// (area lights; zero for others).
    pub fn pdf_le_area(&self, intr: &Interaction, w: Vec3) -> (PdfArea, PdfSolidAngle) {
        match self {
            Light::DiffuseArea(l) => l.pdf_le_area(intr, w),
            _ => (PdfArea(0.0), PdfSolidAngle(0.0)),
        }
    }

    /// True when a ray can hit the light's emission (area and infinite
    /// lights), so that BSDF sampling competes with light sampling in MIS;
    /// false for delta lights and for invisible area lights.
    pub fn is_hittable(&self) -> bool {
        match self {
            Light::DiffuseArea(l) => !l.is_invisible(),
            other => !other.light_type().is_delta(),
        }
    }

    /// False only for an area light whose [`sample_li`](Self::sample_li)
    /// does not pick its point with the uniform-area density of its emission
    /// sampling (a sphere, whose visible cone is sampled): there next-event
    /// estimation's density of a point depends on the receiver. True for
    /// every other light, so callers need not check the light's type.
    pub fn samples_li_by_area(&self) -> bool {
        match self {
            Light::DiffuseArea(l) => l.samples_li_by_area(),
            _ => true,
        }
    }

    /// Total emitted power Φ (W) at the given wavelengths.
    pub fn phi(&self, lambda: &SampledWavelengths) -> SampledSpectrum {
        dispatch!(self, l => l.phi(lambda))
    }

    /// Records the scene's bounding sphere (distant and infinite lights).
    pub fn preprocess(&mut self, scene_bounds: &Bounds3) {
        match self {
            Light::Distant(l) => l.preprocess(scene_bounds),
            Light::UniformInfinite(l) => l.preprocess(scene_bounds),
            Light::ImageInfinite(l) => l.preprocess(scene_bounds),
            _ => {}
        }
    }
}
