//! The two passes every progressive photon-mapping iteration makes
//! [Hachisuka, Ogaki & Jensen 2008; Hachisuka & Jensen 2009; pbrt-v3/v4 SPPM]:
//!
//! 1. `camera_pass`: one camera path per pixel (the shared camera walk,
//!    [`crate::integrator::camera_walk`]) follows specular (and, before
//!    the last bounce, glossy) scattering, adds emission seen directly or
//!    through specular chains and direct light at every non-specular vertex
//!    (light and BSDF sampling under MIS, as pbrt-v4's camera pass), and
//!    stops at the first diffuse vertex (or a glossy one at depth maxdepth),
//!    which becomes the pixel's *visible point*.
//! 2. `photon_pass`: photons from [`crate::integrator::photon`] that reach a
//!    surface after at least one bounce (direct light is the camera pass's
//!    job) add β·f(x, ωp → ωo) to every visible point whose sphere contains
//!    them [Hachisuka & Jensen 2009, eq. 7, before the 1/(πr²N) factor].
//!
//! Which photons inside a sphere count, with which direction, is the rule
//! shared with `photonmap` and `vcm` ([`crate::integrator::gather`]): the
//! chord kernel with each photon's direction carried into the visible
//! point's frame on smooth surfaces, the unfolded kernel across creases, so
//! neither a curved surface nor a room's edges lose photons.
//!
//! Wavelengths come in stratified groups ([`crate::integrator::wavelengths`]):
//! a pixel's camera path carries its group's wavelengths, photon `i` those
//! of group `i mod G` with its power scaled by N/N_g, and a visible point
//! gathers only the photons of its group (one sphere grid per group), so
//! the photon sum Φ stays spectral until the pixel update converts it.
//! Photon chunks return their contributions as lists merged in chunk order:
//! deterministic.

use crate::bsdf::{Bsdf, BxdfFlags, TransportMode};
use crate::film::Film;
use crate::integrator::camera_walk::{camera_walk, CameraWalk};
use crate::integrator::driver::camera_sample;
use crate::integrator::gather::{gather, Surfel};
use crate::integrator::photon::{trace_photon, PhotonHit, ShootSettings};
use crate::integrator::subpath::Flow;
use crate::integrator::wavelengths::PassWavelengths;
use crate::integrator::RenderContext;
use crate::math::{UVec2, Vec3};
use crate::sampler::Sampler;
use crate::spatial::{HasSphere, SphereGrid};
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rayon::prelude::*;

/// Where a pixel's camera path ended on a diffuse (or last glossy) surface.
#[derive(Clone, Copy, Debug)]
pub struct VisiblePoint {
    /// Position.
    pub p: Vec3,
    /// Direction back towards the camera.
    pub wo: Vec3,
    /// Geometric normal.
    pub n: Vec3,
    /// Its BSDF at the iteration's wavelengths.
    pub bsdf: Bsdf,
    /// Camera-path throughput up to the point.
    pub beta: SampledSpectrum,
    /// The camera path left only the hero wavelength (dispersion).
    pub terminated: bool,
}

/// What the camera pass found for one pixel.
#[derive(Clone, Copy, Debug)]
pub struct PixelVisit {
    /// Direct light (and emission seen through specular chains).
    pub ld: SampledSpectrum,
    /// The wavelengths of the pixel's path (its group's, possibly with the
    /// secondary ones terminated by dispersion).
    pub lambda: SampledWavelengths,
    /// The pixel's wavelength group in this pass.
    pub group: usize,
    /// The visible point, if the path found one.
    pub vp: Option<VisiblePoint>,
}

impl PixelVisit {
    /// A pixel that saw nothing (yet).
    fn none(lambda: &SampledWavelengths, group: usize) -> Self {
        PixelVisit {
            ld: SampledSpectrum::zero(),
            lambda: *lambda,
            group,
            vp: None,
        }
    }
}

/// Pixels of the film's bounds in scanline order.
pub fn pixel_list(film: &Film) -> Vec<UVec2> {
    let (lo, hi) = film.pixel_bounds();
    (lo.y..hi.y)
        .flat_map(|y| (lo.x..hi.x).map(move |x| UVec2::new(x, y)))
        .collect()
}

/// The camera pass's output, kept from pass to pass: at 240 bytes a pixel
/// it is 42 MB for a 350×500 film, above glibc's largest mmap threshold
/// (32 MB), so a fresh vector each pass came from a fresh mapping and paid
/// ~10 000 page faults (and their zeroing) per pass.
#[derive(Debug, Default)]
pub struct VisitBuffer(std::sync::Mutex<Vec<PixelVisit>>);

impl VisitBuffer {
    /// The buffer (passes run one at a time; a poisoned lock only means an
    /// earlier pass panicked, and the camera pass refills the buffer anyway).
    pub fn lock(&self) -> std::sync::MutexGuard<'_, Vec<PixelVisit>> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// The camera pass of iteration `iter` into `visits` (one per pixel), each
/// pixel at its group's wavelengths in `pw` (`None` if the render was
/// cancelled meanwhile). The sampler is reset at every pixel, so the
/// visits do not depend on how the work is split between threads.
pub fn camera_pass(
    ctx: &RenderContext<'_>,
    pixels: &[UVec2],
    iter: u32,
    pw: &PassWavelengths,
    max_depth: u32,
    visits: &mut Vec<PixelVisit>,
) -> Option<()> {
    pixels
        .par_iter()
        .enumerate()
        .map_init(
            || ctx.sampler.clone(),
            |sampler, (i, &pixel)| {
                let group = pw.pixel_group(i as u64);
                let lambda = pw.group(group);
                if ctx.cancelled() {
                    return PixelVisit::none(lambda, group);
                }
                sampler.start_pixel_sample(pixel, iter, 0);
                let mut v = visit_pixel(ctx, pixel, lambda, max_depth, sampler);
                v.group = group;
                v
            },
        )
        .collect_into_vec(visits);
    (!ctx.cancelled()).then_some(())
}

/// The camera walk of one pixel: direct light on the way and the visible
/// point at the first diffuse vertex (or a glossy one at `max_depth`).
fn visit_pixel(
    ctx: &RenderContext<'_>,
    pixel: UVec2,
    lambda: &SampledWavelengths,
    max_depth: u32,
    sampler: &mut Sampler,
) -> PixelVisit {
    let mut visit = PixelVisit::none(lambda, 0);
    let Some(cs) = camera_sample(ctx, pixel, sampler) else {
        return visit;
    };
    let cw = CameraWalk {
        max_depth,
        emission_beyond: false,
        mis_direct: true,
    };
    let beta = SampledSpectrum::splat(cs.ray_weight);
    let mut vp = None;
    visit.ld = camera_walk(
        ctx.scene,
        cs.ray,
        beta,
        &mut visit.lambda,
        sampler,
        &cw,
        |v, bsdf, lam, _| {
            let flags = bsdf.flags();
            let glossy_last = flags.contains(BxdfFlags::GLOSSY) && v.depth == max_depth;
            if !flags.contains(BxdfFlags::DIFFUSE) && !glossy_last {
                return Flow::Continue;
            }
            vp = Some(VisiblePoint {
                p: v.p(),
                wo: v.wo,
                n: v.it.n,
                bsdf: *bsdf,
                beta: v.beta,
                terminated: lam.secondary_terminated(),
            });
            Flow::Stop
        },
    );
    visit.vp = vp;
    visit
}

/// A visible point's sphere for the grid (negative radius: none).
struct Sphere(Vec3, f32);

impl HasSphere for Sphere {
    fn center(&self) -> Vec3 {
        self.0
    }
    fn radius(&self) -> f32 {
        self.1
    }
}

/// Photons gathered by one visible point in one pass.
#[derive(Clone, Copy, Debug, Default)]
pub struct Gathered {
    /// Σ β_p·f(x, ωp → ωo) over the photons inside the sphere (W, spectral).
    pub phi: SampledSpectrum,
    /// Number of photons inside (M).
    pub m: u64,
}

/// Photons per parallel chunk.
const CHUNK: u64 = 4096;

/// Shoots `n_photons` photons of pass `pass` and gathers them at the visible
/// points of their wavelength group, each with its own radius `radius[i]`
/// (`None` if cancelled).
pub fn photon_pass(
    ctx: &RenderContext<'_>,
    visits: &[PixelVisit],
    radius: &[f32],
    pw: &PassWavelengths,
    shoot: &ShootSettings,
    pass: u64,
    n_photons: u64,
) -> Option<Vec<Gathered>> {
    let scene = ctx.scene;
    // One grid per wavelength group, built side by side (each build is serial).
    let grids: Vec<SphereGrid> = (0..pw.len())
        .into_par_iter()
        .map(|g| {
            let spheres: Vec<Sphere> = visits
                .iter()
                .zip(radius)
                .map(|(v, &r)| match v.vp {
                    Some(vp) if v.group == g => Sphere(vp.p, r),
                    _ => Sphere(Vec3::ZERO, -1.0),
                })
                .collect();
            SphereGrid::build(&spheres)
        })
        .collect();
    let lists: Vec<Option<Vec<(u32, SampledSpectrum)>>> = (0..n_photons.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            if ctx.cancelled() {
                return None;
            }
            let mut out = Vec::new();
            for i in c * CHUNK..((c + 1) * CHUNK).min(n_photons) {
                let g = pw.photon_group(i);
                let scale = pw.photon_scale(g, n_photons);
                trace_photon(scene, pw.group(g), shoot, pass, i, |h| {
                    if h.v.depth < 2 {
                        return; // direct light: the camera pass's NEE
                    }
                    grids[g].for_each_containing(h.v.p(), |j| {
                        if let Some(vp) = &visits[j as usize].vp {
                            let r = radius[j as usize];
                            if let Some(phi) = photon_contribution(vp, h, r) {
                                out.push((j, phi * scale));
                            }
                        }
                    });
                });
            }
            ctx.advance(CHUNK.min(n_photons - c * CHUNK));
            Some(out)
        })
        .collect();
    let mut gathered = vec![Gathered::default(); visits.len()];
    for list in lists {
        let list = list?;
        for (j, phi) in list {
            let g = &mut gathered[j as usize];
            g.phi += phi;
            g.m += 1;
        }
    }
    Some(gathered)
}

/// β_p·f(x, ωp → ωo) of a photon hit `h` inside the sphere (radius `r`)
/// of `vp`, or `None` when the shared gather rule does not count it.
fn photon_contribution(vp: &VisiblePoint, h: &PhotonHit<'_>, r: f32) -> Option<SampledSpectrum> {
    let x = Surfel {
        p: vp.p,
        n: vp.n,
        w: vp.wo,
    };
    let ph = Surfel {
        p: h.v.p(),
        n: h.v.it.n,
        w: h.v.wo,
    };
    let c = gather(&x, &ph, r * r)?;
    let f = vp.bsdf.f(vp.wo, c.wi, TransportMode::Radiance);
    let mut phi = h.v.beta * f;
    if vp.terminated {
        phi = hero_only(phi, h.terminated);
    }
    Some(phi)
}

/// A camera path that kept only the hero wavelength sees only the hero part
/// of a photon, scaled ×4 unless the photon was itself terminated (its β
/// already carries that factor).
fn hero_only(phi: SampledSpectrum, photon_terminated: bool) -> SampledSpectrum {
    let n = phi.0.len() as f32;
    SampledSpectrum::from_fn(|i| {
        if i != 0 {
            0.0
        } else if photon_terminated {
            phi.0[0]
        } else {
            phi.0[0] * n
        }
    })
}

/// The wavelength groups of pass `pass`: the pass position u follows a
/// golden-ratio sequence offset by the seed, so successive passes
/// stratify the visible range.
pub fn pass_wavelengths(seed: u64, pass: u64, groups: u32) -> PassWavelengths {
    let offset =
        (crate::sampling::hash_u64s(&[seed, 0x5350_504d]) >> 11) as f64 / (1u64 << 53) as f64;
    let u = (offset + pass as f64 * 0.618_033_988_749_895).fract();
    PassWavelengths::new(seed, pass, u, groups)
}
