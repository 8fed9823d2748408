//! Classic two-pass photon mapping (`Integrator "photonmap"`) [Jensen 1996,
//! "Global Illumination using Photon Maps"; Jensen 2001, "Realistic Image
//! Synthesis Using Photon Mapping", ch. 9].
//!
//! **Passes and wavelengths.** A render is `spp` independent passes. Pass i
//! has `wavelengthgroups` groups of four stratified wavelengths
//! ([`crate::integrator::wavelengths`]), with the pass position u jittered
//! by hash(seed, i) inside stratum i of the `spp` strata of [0, 1). It
//! shoots `photons` and `causticphotons` paths, photon j at the wavelengths
//! of group j mod G, builds a global and a caustic kd-tree per group, and
//! then renders one filter-sampled camera sample per pixel at the
//! wavelengths of the pixel's (hashed) group, reading that group's maps, so
//! that f·ΔΦ is formed spectrally at exactly the wavelengths the photons
//! carry (see `photon.rs`) while the colour noise differs between pixels. The film averages the passes. The rendering loop is
//! parallel over 16×16 tiles and merges them in a fixed order, photons come
//! from per-(pass, index) streams, so the image does not depend on the
//! thread count. More passes average out noise, not the kernel bias of one
//! pass's maps: that shrinks only with more photons per pass or a smaller
//! `lookup`.
//!
//! **Partition of the light paths** [Jensen 2001, §9.1: reflected radiance
//! split into direct, specular, caustic and indirect parts]. The camera path follows
//! the specular (delta) lobes from the eye; emission it meets is always
//! counted, since no other estimator produces E S* L paths. At every vertex
//! x with a non-specular lobe the incident light is split by its light
//! subpath:
//! - x ← L, **direct**: next-event estimation, light sampling only (the
//!   camera never continues along a non-specular lobe, so nothing else
//!   finds these paths and no MIS is needed);
//! - x ← S+ ← L, **caustic**: the caustic map at x;
//! - x ← (anything containing a non-specular vertex) ← L, **indirect**:
//!   with `finalgather`, `gatherrays` rays sample the BSDF's non-specular
//!   part, follow delta lobes to the first vertex y with a non-specular
//!   lobe and read there the global map holding *every* photon hit (all the
//!   light reaching y, direct and caustic included, is indirect for x; y's
//!   own emission is not, so gather rays ignore emission). Without it the
//!   global map is read at x itself and must then hold only hits with depth
//!   ≥ 2 that are not L S+ D.
//!
//! The delta part of x's BSDF continues the camera path; a continuation
//! that samples a non-specular lobe is dropped, since the three terms above
//! already cover it. Each path is so counted exactly once.
//!
//! **Depth.** `maxdepth` bounds the scattering events of a whole path as in
//! the path tracer. A photon stored at its d-th hit and read at the camera
//! path's j-th scattering vertex closes a path with j + d − 1 of them, so
//! lookups ignore photons with d > maxdepth − j + 1.
//!
//! Parameters (Mitsuba-style table):
//!
//! | name | type | default | meaning |
//! |---|---|---|---|
//! | `photons` | integer | 100000 | photon paths per pass for the global map |
//! | `causticphotons` | integer | 100000 | photon paths per pass for the caustic map |
//! | `lookup` | integer | 50 | photons per radiance estimate, k (at least 2) |
//! | `maxradius` | float | 0.05·R_scene | cap on the global-map lookup radius; R_scene the scene's bounding-sphere radius (Mitsuba 0.6's relative default) |
//! | `causticmaxradius` | float | `maxradius`/4 | cap on the caustic-map lookup radius (Mitsuba 0.6's ratio, 0.0125 to 0.05) |
//! | `kernel` | string | `cone` | `cone`, `epanechnikov` or `disk` |
//! | `conek` | float | 1.1 | κ of the cone filter w = 1 − d/(κr) |
//! | `finalgather` | bool | true | gather indirect light one bounce away |
//! | `gatherrays` | integer | 16 | final-gather rays per non-specular camera vertex |
//! | `maxdepth` | integer | 5 | scattering events per path |
//! | `wavelengthgroups` | integer | 4 | wavelength groups per pass (1 to 64) |
//!
//! Lights are always chosen in proportion to their power.

mod camera;
mod maps;

pub use maps::{Kernel, Lookup, Photon, PhotonMap};

use super::wavelengths::PassWavelengths;
use super::{
    driver, Integrator, IntegratorKind, IntegratorState, PassOutcome, PassWork, RenderContext,
};
use crate::film::{FilmTile, PassBlock};
use crate::math::UVec2;
use crate::sampling::{hash_u64s, Pcg32};
use camera::CameraSide;
use maps::PassMaps;

/// Default `maxradius` as a fraction of the scene's bounding-sphere radius.
pub const DEFAULT_RELATIVE_RADIUS: f32 = 0.05;

/// Parameters of `Integrator "photonmap"`.
#[derive(Clone, Debug)]
pub struct PhotonMapSettings {
    /// Scattering events per path.
    pub max_depth: u32,
    /// Photon paths per pass for the global map.
    pub photons: u64,
    /// Photon paths per pass for the caustic map.
    pub caustic_photons: u64,
    /// Photons per radiance estimate (k ≥ 2).
    pub lookup: usize,
    /// Largest global-map lookup radius; `None`: [`DEFAULT_RELATIVE_RADIUS`]
    /// of the scene's bounding radius.
    pub max_radius: Option<f32>,
    /// Largest caustic-map lookup radius; `None`: a quarter of the global one.
    pub caustic_max_radius: Option<f32>,
    /// Density-estimation kernel.
    pub kernel: Kernel,
    /// Estimate indirect light by final gathering (else read the global map at the camera vertex).
    pub final_gather: bool,
    /// Final-gather rays per non-specular camera vertex.
    pub gather_rays: u32,
    /// Seed of wavelengths and photons.
    pub seed: u64,
    /// Wavelength groups per pass (`wavelengthgroups`).
    pub wavelength_groups: u32,
    /// Fork the camera walk at a first smooth dielectric (`splitspecular`,
    /// default true; [`crate::integrator::camera_walk`]).
    pub split_specular: bool,
}

impl Default for PhotonMapSettings {
    fn default() -> Self {
        Self {
            max_depth: 5,
            photons: 100_000,
            caustic_photons: 100_000,
            lookup: 50,
            max_radius: None,
            caustic_max_radius: None,
            kernel: Kernel::Cone(1.1),
            final_gather: true,
            gather_rays: 16,
            seed: 0,
            wavelength_groups: super::wavelengths::DEFAULT_GROUPS,
            split_specular: true,
        }
    }
}

/// The photon-mapping integrator.
pub struct PhotonMapIntegrator {
    /// Settings.
    pub settings: PhotonMapSettings,
}

impl Integrator for PhotonMapIntegrator {
    fn kind(&self) -> IntegratorKind {
        IntegratorKind::PhotonMap
    }

    fn pass_work(&self, _ctx: &RenderContext<'_>) -> PassWork {
        PassWork {
            units: self.settings.photons + self.settings.caustic_photons,
            unit: "photons",
            light_paths: 0,
        }
    }

    fn render_pass(
        &self,
        ctx: &RenderContext<'_>,
        pass: u64,
        _state: &mut IntegratorState,
        block: &mut PassBlock,
    ) -> PassOutcome {
        let passes = ctx.sampler.samples_per_pixel();
        let (global_lookup, caustic_lookup) = self.lookups(ctx);
        let s = &self.settings;
        let pw = pass_wavelengths(s.seed, pass as u32, passes, s.wavelength_groups);
        let maps = PassMaps::shoot(ctx.scene, &pw, s, pass);
        ctx.advance(s.photons + s.caustic_photons);
        let walks: Vec<CameraSide<'_>> = maps
            .iter()
            .map(|maps| CameraSide {
                scene: ctx.scene,
                maps,
                settings: s,
                global_lookup,
                caustic_lookup,
            })
            .collect();
        let Some(tiles) = render_pass(&walks, ctx, pass as u32, &pw) else {
            return PassOutcome::Cancelled;
        };
        for tile in &tiles {
            block.add_tile(tile);
        }
        PassOutcome::Done
    }
}

impl PhotonMapIntegrator {
    /// The global and caustic lookup parameters, default radii resolved against the scene.
    fn lookups(&self, ctx: &RenderContext<'_>) -> (Lookup, Lookup) {
        let s = &self.settings;
        let global = s
            .max_radius
            .unwrap_or_else(|| DEFAULT_RELATIVE_RADIUS * ctx.scene.bounds().bounding_sphere().1);
        let lookup = |max_radius| Lookup {
            k: s.lookup.max(2),
            max_radius,
            kernel: s.kernel,
        };
        (
            lookup(global),
            lookup(s.caustic_max_radius.unwrap_or(global / 4.0)),
        )
    }
}

/// The wavelength groups of pass `pass` of `passes`: the pass position u
/// is jittered in stratum `pass` of [0, 1).
pub fn pass_wavelengths(seed: u64, pass: u32, passes: u32, groups: u32) -> PassWavelengths {
    let mut rng = Pcg32::new(hash_u64s(&[seed, u64::from(pass), 0x1A3B_DA00]), 0);
    let u = (f64::from(pass) + f64::from(rng.uniform_f32())) / f64::from(passes.max(1));
    PassWavelengths::new(seed, u64::from(pass), u.min(1.0), groups)
}

/// Renders one camera sample per pixel for `pass`, tile by tile in parallel,
/// each pixel with the camera side `walks[g]` of its wavelength group g;
/// the tiles come back in scanline order (`None` if cancelled).
fn render_pass(
    walks: &[CameraSide<'_>],
    ctx: &RenderContext<'_>,
    pass: u32,
    pw: &PassWavelengths,
) -> Option<Vec<FilmTile>> {
    let (lo_film, hi_film) = ctx.film.pixel_bounds();
    let width = u64::from(hi_film.x - lo_film.x);
    driver::for_each_tile(ctx, |lo, hi| {
        let mut tile = ctx.film.tile(lo, hi);
        let mut sampler = ctx.sampler.clone();
        let mut scratch = Vec::new();
        for y in lo.y..hi.y {
            for x in lo.x..hi.x {
                let pixel = UVec2::new(x, y);
                let index = u64::from(y - lo_film.y) * width + u64::from(x - lo_film.x);
                let g = pw.pixel_group(index);
                sampler.start_pixel_sample(pixel, pass, 0);
                // The driver's camera sample, with the group's wavelengths
                // replacing the ones it draws (that draw keeps the sampler
                // dimensions aligned with the other integrators').
                let Some(mut cs) = driver::camera_sample(ctx, pixel, &mut sampler) else {
                    continue;
                };
                cs.lambda = *pw.group(g);
                let l = walks[g].li(cs.ray, &mut cs.lambda, &mut sampler, &mut scratch);
                tile.add_sample(pixel, l * cs.ray_weight, &cs.lambda, cs.filter_weight);
            }
        }
        tile
    })
}
