//! The virtual illuminance meter behind `candela measure`.
//!
//! At a point x with unit normal n the illuminance is
//! E_v = K_m ∫ V(λ) ∫_{H²(n)} L(x, ω, λ) cos θ dω dλ [CIE S 017/E:2011,
//! 17-21-060]. One sample estimates it with three parts: the first finds
//! light paths the others cannot, and the last two, which can find the same
//! emission, share it by multiple importance sampling, so the sum is
//! unbiased:
//!
//! - **delta lights** (point, spot, goniometric, projection, distant),
//!   which no ray can hit: each one's I·cos θ/d² (or E·cos θ) with a
//!   shadow ray, every sample;
//! - **everything a ray can find** (area and infinite lights, directly and
//!   after any number of bounces, including delta lights seen through
//!   diffuse reflection): one cosine-weighted direction ω, p(ω) = cos θ/π,
//!   and the path tracer's radiance estimate L̂(ω), which contributes π·L̂
//!   [pbrt-v4 §13.4]. Its depth limit is [`MeasureSettings::max_depth`];
//! - **light sampling at the sensor** for the area and infinite lights
//!   the cosine ray could hit directly: one light chosen by the scene's
//!   light sampler for next-event estimation, given the sensor's point and
//!   normal (pmf P), a direction on it (density p_l), contributing
//!   L·cos θ/(P·p_l) weighted by the power heuristic against the cosine
//!   density, while the emission the cosine ray finds at its first hit
//!   takes the complementary weight [Veach 1997, eq. 9.13]
//!   (`PathIntegrator::li_sampled`); lights no ray can hit (an area
//!   light of `alpha` 0) take full weight. Small luminaires are then found
//!   by their samples, not by chance.
//!
//! Wavelengths are sampled as for the camera (`sample_visible`) and V(λ)
//! weighs each: Ŷ = (1/N) Σ_k ȳ(λ_k)·Ê(λ_k)/p(λ_k), E_v = K_m·Ŷ. The
//! standard error is √(s²/n) from the sample variance s² of the n samples.
//! Each sample's sampler stream is fixed by (point index, sample index,
//! seed), so a run is reproducible; the caller should pass an independent
//! sampler (i.i.d. samples), for which the sample variance is meaningful. The ray leaves x offset by a small
//! distance along n (10⁻⁵ of the scene's size), so a point on a surface
//! measures what arrives there from the side n faces.

use crate::integrator::{PathIntegrator, PathSettings, RenderContext};
use crate::interaction::Interaction;
use crate::light::{LightChooser, LightSampleContext};
use crate::math::{Frame, Ray, Vec3, PI};
use crate::sampling::{power_heuristic, sample_cosine_hemisphere};
pub(crate) use crate::spectrum::luminous;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use glam::UVec2;

/// Settings of a measurement.
#[derive(Clone, Copy, Debug)]
pub struct MeasureSettings {
    /// Samples per point.
    pub samples: u32,
    /// Path tracer depth (scattering events after the sensor).
    pub max_depth: u32,
}

/// One measured point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measurement {
    /// Estimated illuminance \[lx\].
    pub illuminance: f64,
    /// Its standard error \[lx\].
    pub stderr: f64,
}

/// Illuminance at `p` on a sensor facing unit `n` (see the module doc).
pub fn measure_point(
    ctx: &RenderContext<'_>,
    settings: MeasureSettings,
    index: u32,
    p: Vec3,
    n: Vec3,
) -> Measurement {
    let path = meter_path(settings.max_depth);
    let origin = sensor_origin(ctx.scene, p, n);
    let mut sampler = ctx.sampler.clone();
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for s in 0..settings.samples {
        sampler.start_pixel_sample(UVec2::new(index, 0), s, 0);
        let lambda = SampledWavelengths::sample_visible(sampler.get_1d());
        let y = illuminance_sample(ctx, &path, origin, n, lambda, &mut sampler);
        sum += y;
        sum2 += y * y;
    }
    let n = settings.samples.max(1) as f64;
    let mean = sum / n;
    let var = if n > 1.0 {
        ((sum2 - n * mean * mean) / (n - 1.0)).max(0.0)
    } else {
        0.0
    };
    Measurement {
        illuminance: mean,
        stderr: (var / n).sqrt(),
    }
}

/// The path tracer of the "everything a ray can find" part, without
/// regularisation, following at most `max_depth` scattering events.
pub(crate) fn meter_path(max_depth: u32) -> PathIntegrator {
    PathIntegrator {
        settings: PathSettings {
            max_depth,
            regularize: false,
            split_specular: true,
        },
    }
}

/// Where the rays of a sensor at `p` facing unit `n` start: `p` moved along
/// `n` by 10⁻⁵ of the scene's size (see the module doc).
pub(crate) fn sensor_origin(scene: &crate::scene::Scene, p: Vec3, n: Vec3) -> Vec3 {
    let b = scene.bounds();
    let size = if b.min.x <= b.max.x {
        (b.max - b.min).length()
    } else {
        1.0
    };
    p + n * (1e-5 * size.max(1e-3))
}

/// One sample of E_v \[lx\] at `origin` on a sensor facing unit `n`, at the
/// wavelengths `lambda`, drawing the rest from `sampler` (already started
/// at its sample): the delta-light part and the cosine-weighted path
/// estimate of the module doc. `candela measure` averages these per point;
/// the photometric film takes one per pass at each pixel's first hit
/// ([`crate::render::surface`]).
pub(crate) fn illuminance_sample(
    ctx: &RenderContext<'_>,
    path: &PathIntegrator,
    origin: Vec3,
    n: Vec3,
    mut lambda: SampledWavelengths,
    sampler: &mut crate::sampler::Sampler,
) -> f64 {
    let mut e = delta_irradiance(ctx, origin, n, &lambda, sampler.get_2d());
    let (u_light, u) = (sampler.get_1d(), sampler.get_2d());
    e += light_irradiance(ctx, origin, n, &lambda, u_light, u);
    let wi = Frame::from_z(n).from_local(sample_cosine_hemisphere(sampler.get_2d()));
    let pdf = wi.dot(n).max(0.0) / PI;
    let sensor = sensor_context(origin, n);
    e += path.li_sampled(ctx, Ray::new(origin, wi), pdf, sensor, &mut lambda, sampler) * PI;
    luminous(&e, &lambda)
}

/// The light-sampling context of a sensor at `origin` facing `n`: the light
/// sampler sees the sensor's normal (its cosine enters the BVH sampler's
/// importance); no error bound, so the light's shapes spawn no offset.
fn sensor_context(origin: Vec3, n: Vec3) -> LightSampleContext {
    LightSampleContext {
        p: origin,
        p_error: Vec3::ZERO,
        n,
        ns: n,
    }
}

/// One MIS-weighted light sample of the hittable (non-delta) lights'
/// L·cos θ at `origin` facing `n` (see the module doc).
fn light_irradiance(
    ctx: &RenderContext<'_>,
    origin: Vec3,
    n: Vec3,
    lambda: &SampledWavelengths,
    u_light: f32,
    u: crate::math::Vec2,
) -> SampledSpectrum {
    let scene = ctx.scene;
    let lsc = sensor_context(origin, n);
    let Some((id, pmf)) = scene.nee_light_sampler().choose(&lsc, u_light) else {
        return SampledSpectrum::zero();
    };
    let light = scene.light(id);
    if light.light_type().is_delta() {
        // Counted, every sample, by `delta_irradiance`.
        return SampledSpectrum::zero();
    }
    let Some(ls) = light.sample_li(&lsc, u, lambda) else {
        return SampledSpectrum::zero();
    };
    let cos = ls.wi.dot(n);
    let p_l = pmf * ls.pdf.0;
    if cos <= 0.0 || ls.l.is_black() || p_l <= 0.0 {
        return SampledSpectrum::zero();
    }
    if !scene.unoccluded(&Interaction::at_point(origin), &ls.p_light) {
        return SampledSpectrum::zero();
    }
    let w = if light.is_hittable() {
        power_heuristic(1.0, p_l, 1.0, cos / PI)
    } else {
        1.0
    };
    ls.l * (cos * w / p_l)
}

/// Σ over delta lights of their unoccluded Li·cos θ at `origin` facing `n`.
fn delta_irradiance(
    ctx: &RenderContext<'_>,
    origin: Vec3,
    n: Vec3,
    lambda: &SampledWavelengths,
    u: crate::math::Vec2,
) -> SampledSpectrum {
    let scene = ctx.scene;
    let here = Interaction::at_point(origin);
    let lsc = LightSampleContext::at_point(origin);
    let mut e = SampledSpectrum::zero();
    for light in scene.lights() {
        if !light.light_type().is_delta() {
            continue;
        }
        let Some(ls) = light.sample_li(&lsc, u, lambda) else {
            continue;
        };
        let cos = ls.wi.dot(n);
        if cos > 0.0 && scene.unoccluded(&here, &ls.p_light) {
            e += ls.l * (cos / ls.pdf.0);
        }
    }
    e
}
