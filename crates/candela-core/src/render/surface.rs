//! The first-hit pass: what the camera sees first, for the film's surface
//! layers (`--aov`, `Film "gbuffer"`), whatever the integrator.
//!
//! After each integrator pass the render loop runs this pass when the film
//! records first-hit values. For every pixel it draws pass i's camera sample
//! with its own copy of the sampler, in the order of the integrators'
//! camera samples (wavelengths, film offset, time, lens), so for the path
//! tracer and BDPT the values belong to the very ray whose radiance the
//! integrator estimated (as pbrt-v4's `VisibleSurface`), and the
//! integrator's own sample values cannot change: they are pure functions of
//! (pixel, pass, dimension). The ray is followed through interface
//! materials to the first surface with a BSDF, and the values are added
//! with the sample's filter weight (`FilmTile::add_surface`); a ray that
//! escapes adds zeros with its weight (pbrt-v4's `GBufferFilm` divides by
//! every sample's weight too).
//!
//! What is recorded [pbrt-v4 `VisibleSurface`, `GBufferFilm::AddSample`]:
//! - albedo: ρ(wo) = ∫ f |cos θ| dωi, estimated with 16 fixed stratified
//!   samples (a 4×4 grid of cell centres for the direction, the bit-reversed
//!   index for the lobe choice), times the output colour space's
//!   illuminant, in output RGB through the sampled wavelengths;
//! - P, N and Ns in world or camera space; N and Ns face the ray;
//! - depth: the distance from the ray's origin on the lens to the hit;
//! - (u, v) of the surface;
//! - ∂z/∂x, ∂z/∂y: the change of camera-space z from one pixel to the next,
//!   from the rays one pixel right and one pixel down (same lens point)
//!   meeting the hit's tangent plane (pbrt-v4's ray differentials; pbrt-v4
//!   further scales them by max(1/8, 1/√spp), candela does not: the values
//!   are per pixel).
//!
//! **Illuminance** (photometric films, `--units photometric`): at the same
//! first surface, one sample per pass of E_v \[lx\] arriving from the side
//! the camera sees (the geometric normal turned towards the ray), by the
//! very estimator of `candela measure` ([`crate::measure`]: delta lights
//! by shadow rays plus a cosine-weighted path-traced direction, at the
//! camera sample's wavelengths, drawing its other dimensions after the
//! camera sample's). Each pass's value is an independent unbiased estimate
//! of E_v at the pixel's visible surface (Radiance's `rpict -i`), so the
//! per-pass spread gives its standard error; a ray that escapes adds its
//! weight and E_v = 0. Its paths follow at most
//! [`crate::film::Film::illuminance_depth`] scattering events: one fewer
//! than the camera paths, whose first is at that surface, so a Lambertian
//! surface of albedo ρ has luminance ρE_v/π in the same render.

use crate::bsdf::{Bsdf, TransportMode};
use crate::camera::CameraSample;
use crate::film::{PassBlock, SurfaceSample, SurfaceSpace};
use crate::integrator::driver::{camera_sample, for_each_tile};
use crate::integrator::{PassOutcome, PathIntegrator, RenderContext};
use crate::interaction::SurfaceInteraction;
use crate::math::{face_forward, Ray, Transform, UVec2, Vec2, Vec3};
use crate::measure;
use crate::sampler::Sampler;
use crate::spectrum::SampledWavelengths;

/// Interfaces a first-hit ray passes through before it gives up.
const MAX_INTERFACES: usize = 64;

/// Samples of the albedo estimate.
const RHO_SAMPLES: usize = 16;

/// The lobe-choice and direction samples of the albedo estimate.
fn rho_samples() -> ([f32; RHO_SAMPLES], [Vec2; RHO_SAMPLES]) {
    let uc = std::array::from_fn(|i| ((i as u32).reverse_bits() >> 28) as f32 / 16.0 + 1.0 / 32.0);
    let u = std::array::from_fn(|i| {
        Vec2::new(((i % 4) as f32 + 0.5) / 4.0, ((i / 4) as f32 + 0.5) / 4.0)
    });
    (uc, u)
}

/// Adds pass `pass`'s first-hit values of every pixel to `block`.
pub fn render_surface_pass(
    ctx: &RenderContext<'_>,
    pass: u64,
    block: &mut PassBlock,
) -> PassOutcome {
    let camera_from_world = ctx.camera.world_from_camera().inverse();
    let meter = measure::meter_path(ctx.film.illuminance_depth());
    let tiles = for_each_tile(ctx, |lo, hi| {
        let mut tile = ctx.film.tile(lo, hi);
        let mut sampler = ctx.sampler.clone();
        let mut cx = PixelContext {
            ctx,
            camera_from_world: &camera_from_world,
            meter: &meter,
            sampler: &mut sampler,
        };
        for y in lo.y..hi.y {
            for x in lo.x..hi.x {
                let pixel = UVec2::new(x, y);
                if let Some((s, e, w)) = cx.pixel_sample(pixel, pass) {
                    tile.add_surface(pixel, &s, w);
                    tile.add_illuminance(pixel, e, w);
                }
            }
        }
        tile
    });
    let Some(tiles) = tiles else {
        return PassOutcome::Cancelled;
    };
    for tile in &tiles {
        block.add_tile(tile);
    }
    PassOutcome::Done
}

/// What the first-hit pass needs at every pixel of a tile.
struct PixelContext<'a, 'c> {
    ctx: &'a RenderContext<'c>,
    camera_from_world: &'a Transform,
    meter: &'a PathIntegrator,
    sampler: &'a mut Sampler,
}

impl PixelContext<'_, '_> {
    /// The first-hit values of sample `pass` of `pixel`, the illuminance
    /// at its first surface (photometric films; `None` when the ray
    /// escapes) and its filter weight (`None` when the camera makes no ray
    /// there).
    fn pixel_sample(
        &mut self,
        pixel: UVec2,
        pass: u64,
    ) -> Option<(SurfaceSample, Option<f64>, f32)> {
        let (ctx, sampler) = (self.ctx, &mut *self.sampler);
        sampler.start_pixel_sample(pixel, pass as u32, 0);
        // The same draws as the integrators' camera samples.
        let cs = camera_sample(ctx, pixel, sampler)?;
        let (ray, lambda, fs_weight) = (cs.ray, cs.lambda, cs.filter_weight);
        let CameraSample { p_film, p_lens } = cs.camera_sample;
        let layout = ctx.film.layout();
        let Some((si, bsdf, lam)) = first_surface(ctx, &ray, lambda) else {
            return Some((SurfaceSample::default(), None, fs_weight));
        };
        let s = if layout.surface.is_empty() {
            SurfaceSample::default()
        } else {
            let dz = depth_gradient(ctx, self.camera_from_world, &si, p_film, p_lens, ray.time);
            record(ctx, self.camera_from_world, &si, &bsdf, &lam, &ray, dz)
        };
        let e = layout.photometric.then(|| {
            let n = face_forward(si.n(), si.wo).normalize_or_zero();
            let origin = measure::sensor_origin(ctx.scene, si.p(), n);
            measure::illuminance_sample(ctx, self.meter, origin, n, lambda, sampler)
        });
        Some((s, e, fs_weight))
    }
}

/// Follows `ray` through interfaces to the first surface with a BSDF: the
/// hit, its BSDF and the wavelengths after it (dispersion may end some).
fn first_surface(
    ctx: &RenderContext<'_>,
    ray: &Ray,
    lambda: SampledWavelengths,
) -> Option<(SurfaceInteraction, Bsdf, SampledWavelengths)> {
    let mut r = *ray;
    for _ in 0..MAX_INTERFACES {
        let mut si = ctx.scene.intersect(&r, f32::INFINITY)?;
        let mut lam = lambda;
        let Some(bsdf) = ctx.scene.bsdf(&mut si, &mut lam) else {
            r = si.spawn_ray(r.d);
            continue;
        };
        return Some((si, bsdf, lam));
    }
    None
}

/// The first-hit values of the surface `si` with BSDF `bsdf`, met by `ray`.
fn record(
    ctx: &RenderContext<'_>,
    camera_from_world: &Transform,
    si: &SurfaceInteraction,
    bsdf: &Bsdf,
    lam: &SampledWavelengths,
    ray: &Ray,
    dz: [f32; 2],
) -> SurfaceSample {
    let (uc, u) = rho_samples();
    let rho = bsdf.rho(si.wo, &uc, &u, TransportMode::Radiance);
    let cs = ctx.film.color_space();
    let xyz = (rho * cs.illuminant.sample(lam)).to_xyz(lam);
    let rgb = cs.rgb_from_xyz * Vec3::new(xyz.x, xyz.y, xyz.z);
    let to_out = match ctx.film.surface_space() {
        SurfaceSpace::World => Transform::IDENTITY,
        SurfaceSpace::Camera => *camera_from_world,
    };
    let wo = to_out.vector(si.wo);
    let facing = |n: Vec3| face_forward(to_out.normal(n).normalize_or_zero(), wo).to_array();
    SurfaceSample {
        albedo: rgb.to_array(),
        p: to_out.point(si.p()).to_array(),
        n: facing(si.n()),
        ns: facing(si.shading.n),
        depth: (si.p() - ray.o).length(),
        uv: [si.it.uv.x, si.it.uv.y],
        dz,
    }
}

/// |∂z/∂x|, |∂z/∂y| of camera-space z at the hit: where the rays one pixel
/// right and one pixel down meet the hit's tangent plane (0 where they
/// miss it or the camera makes no ray).
fn depth_gradient(
    ctx: &RenderContext<'_>,
    camera_from_world: &Transform,
    si: &SurfaceInteraction,
    p_film: Vec2,
    p_lens: Vec2,
    time: f32,
) -> [f32; 2] {
    let (p, n) = (si.p(), si.n());
    let z = camera_from_world.point(p).z;
    [Vec2::X, Vec2::Y].map(|step| {
        let Some(cr) = ctx.camera.generate_ray(CameraSample {
            p_film: p_film + step,
            p_lens,
        }) else {
            return 0.0;
        };
        let r = cr.ray.at_time(time);
        let t = n.dot(p - r.o) / n.dot(r.d);
        if !t.is_finite() || t <= 0.0 {
            return 0.0;
        }
        let dz = (camera_from_world.point(r.o + r.d * t).z - z).abs();
        if dz.is_finite() {
            dz
        } else {
            0.0
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rho_samples_are_stratified() {
        let (uc, u) = rho_samples();
        let mut c: Vec<u32> = uc.iter().map(|v| (v * 16.0) as u32).collect();
        c.sort_unstable();
        assert_eq!(c, (0..16).collect::<Vec<_>>());
        let mut cells: Vec<(u32, u32)> = u
            .iter()
            .map(|v| ((v.x * 4.0) as u32, (v.y * 4.0) as u32))
            .collect();
        cells.sort_unstable();
        cells.dedup();
        assert_eq!(cells.len(), 16);
    }
}
