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
//! a pixel's camera path carries its group's wavelengths and photon `i`
//! those of group `i mod G`. A visible point whose camera-path throughput
//! does not depend on wavelength (the first hit of the camera ray, or a
//! point seen only through dielectrics, whose Fresnel terms take one scalar
//! η: [`crate::bsdf::Bxdf::is_wavelength_independent`]) gathers the
//! photons of *every* group: at the camera pass its BSDF is also built
//! at the other groups' wavelengths, a photon of group h is weighed with
//! the BSDF of group h, and each group's sum is converted to RGB with its
//! own wavelengths. That is the average of G unbiased estimates, one per
//! group (each photon's power scaled by N/(G·N_h)), so the point rests on
//! all N photons of the pass while its colour noise stays its own instead
//! of tinting the whole pass. A visible point reached through any other
//! scattering (a coloured mirror, a glossy metal, dispersive glass) gathers
//! only its own group's photons, with power scaled by N/N_g, as its
//! throughput is known at its own wavelengths only.
//! The photon sums stay spectral, per group, until the pixel update
//! converts them.
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
use crate::interaction::SurfaceInteraction;
use crate::math::{UVec2, Vec3};
use crate::sampler::Sampler;
use crate::scene::Scene;
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
    /// It gathers every group's photons (module doc); its BSDFs at the
    /// other groups' wavelengths are in [`Visits::group_bsdfs`].
    pub all_groups: bool,
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
/// the visits are 42 MB for a 350×500 film, above glibc's largest mmap
/// threshold (32 MB), so fresh vectors each pass came from fresh mappings
/// and paid ~10 000 page faults (and their zeroing) per pass.
#[derive(Debug, Default)]
pub struct Visits {
    /// One visit per pixel, in [`pixel_list`] order.
    pub visits: Vec<PixelVisit>,
    /// With G > 1 groups, G slots per pixel: slot `j·G + h` holds the BSDF
    /// of pixel `j`'s visible point at group h's wavelengths when it gathers
    /// every group ([`VisiblePoint::all_groups`]; its own group's slot stays
    /// empty, that BSDF is [`VisiblePoint::bsdf`]). Empty when G = 1.
    pub group_bsdfs: Vec<Option<Bsdf>>,
    /// The photon pass's visible-point grids, kept between passes so that
    /// their entry arrays (tens of MB at a few hundred thousand pixels) are
    /// reused rather than allocated and faulted in anew every iteration.
    pub grids: Vec<SphereGrid>,
}

impl Visits {
    /// The BSDF with which visible point `j` (of group `own`) weighs a
    /// photon of group `h`.
    fn bsdf_for<'a>(
        &'a self,
        j: usize,
        vp: &'a VisiblePoint,
        own: usize,
        h: usize,
        g: usize,
    ) -> Option<&'a Bsdf> {
        if h == own {
            Some(&vp.bsdf)
        } else {
            self.group_bsdfs.get(j * g + h)?.as_ref()
        }
    }
}

/// The [`Visits`] of an integrator, kept between passes.
#[derive(Debug, Default)]
pub struct VisitBuffer(std::sync::Mutex<Visits>);

impl VisitBuffer {
    /// The buffer (passes run one at a time; a poisoned lock only means an
    /// earlier pass panicked, and the camera pass refills the buffer anyway).
    pub fn lock(&self) -> std::sync::MutexGuard<'_, Visits> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// Pixels per parallel work item of the camera pass.
const PIXEL_CHUNK: usize = 64;

/// The camera pass of iteration `iter` into `out` (one visit per pixel),
/// each pixel at its group's wavelengths in `pw` (`None` if the render was
/// cancelled meanwhile). The sampler is reset at every pixel, so the
/// visits do not depend on how the work is split between threads.
/// `cw` is a [`visible_point_walk`].
pub fn camera_pass(
    ctx: &RenderContext<'_>,
    pixels: &[UVec2],
    iter: u32,
    pw: &PassWavelengths,
    cw: &CameraWalk,
    out: &mut Visits,
) -> Option<()> {
    let g = pw.len();
    let blank = PixelVisit::none(pw.group(0), 0);
    out.visits.clear();
    out.visits.resize(pixels.len(), blank);
    out.group_bsdfs.clear();
    if g > 1 {
        out.group_bsdfs.resize(pixels.len() * g, None);
    }
    let mut extra: Vec<&mut [Option<Bsdf>]> = if g > 1 {
        out.group_bsdfs.chunks_mut(PIXEL_CHUNK * g).collect()
    } else {
        Vec::new()
    };
    extra.resize_with(pixels.len().div_ceil(PIXEL_CHUNK), Default::default);
    out.visits
        .par_chunks_mut(PIXEL_CHUNK)
        .zip(extra)
        .enumerate()
        .for_each_init(
            || ctx.sampler.clone(),
            |sampler, (c, (visits, extra))| {
                for (k, v) in visits.iter_mut().enumerate() {
                    let i = c * PIXEL_CHUNK + k;
                    let group = pw.pixel_group(i as u64);
                    if ctx.cancelled() {
                        *v = PixelVisit::none(pw.group(group), group);
                        continue;
                    }
                    let slots = extra.get_mut(k * g..(k + 1) * g).unwrap_or_default();
                    sampler.start_pixel_sample(pixels[i], iter, 0);
                    *v = visit_pixel(ctx, pixels[i], pw, group, cw, sampler, slots);
                }
            },
        );
    (!ctx.cancelled()).then_some(())
}

/// The camera walk of SPPM's and PPM's visible points: to `max_depth`,
/// direct light by MIS, pbrt-v4's depth rule (module doc of
/// [`crate::integrator::camera_walk`]).
pub fn visible_point_walk(max_depth: u32, split_specular: bool) -> CameraWalk {
    CameraWalk {
        max_depth,
        emission_beyond: false,
        mis_direct: true,
        split_specular,
    }
}

/// The camera walk of one pixel of group `group`: direct light on the way
/// and the visible point at the first diffuse vertex (or a glossy one at
/// `max_depth`); a visible point whose throughput holds at every
/// wavelength (module doc) also gets its BSDFs at the other groups'
/// wavelengths in `slots` (G of them, or none when G = 1).
fn visit_pixel(
    ctx: &RenderContext<'_>,
    pixel: UVec2,
    pw: &PassWavelengths,
    group: usize,
    cw: &CameraWalk,
    sampler: &mut Sampler,
    slots: &mut [Option<Bsdf>],
) -> PixelVisit {
    let mut visit = PixelVisit::none(pw.group(group), group);
    let Some(cs) = camera_sample(ctx, pixel, sampler) else {
        return visit;
    };
    let beta = SampledSpectrum::splat(cs.ray_weight);
    let mut vp = None;
    // Every scattering before the visible point was by a BSDF that is the
    // same at all wavelengths, so β is too and the point can weigh every
    // group's photons with it.
    let mut flat = true;
    visit.ld = camera_walk(
        ctx.scene,
        cs.ray,
        beta,
        &mut visit.lambda,
        sampler,
        cw,
        |v, si, bsdf, lam, _| {
            let flags = bsdf.flags();
            let glossy_last = flags.contains(BxdfFlags::GLOSSY) && v.depth == cw.max_depth;
            if !flags.contains(BxdfFlags::DIFFUSE) && !glossy_last {
                flat &= bsdf.bxdf.is_wavelength_independent();
                return Flow::Continue;
            }
            let terminated = lam.secondary_terminated();
            let all_groups = !slots.is_empty()
                && flat
                && !terminated
                && other_group_bsdfs(ctx.scene, si, pw, group, slots);
            vp = Some(VisiblePoint {
                p: v.p(),
                wo: v.wo,
                n: v.it.n,
                bsdf: *bsdf,
                beta: v.beta,
                terminated,
                all_groups,
            });
            Flow::Stop
        },
    );
    visit.vp = vp;
    visit
}

/// Builds the BSDF at hit `si` (prepared by the walk) at every other
/// group's wavelengths into `slots` (G slots, own group's left empty); false
/// (and the slots cleared) when a material there is dispersive.
fn other_group_bsdfs(
    scene: &Scene,
    si: &SurfaceInteraction,
    pw: &PassWavelengths,
    group: usize,
    slots: &mut [Option<Bsdf>],
) -> bool {
    for (h, slot) in slots.iter_mut().enumerate() {
        if h == group {
            continue;
        }
        let mut lambda = *pw.group(h);
        *slot = scene.bsdf_prepared(si, &mut lambda);
        if slot.is_none() || lambda.secondary_terminated() {
            slots.fill(None);
            return false;
        }
    }
    true
}

/// A visible point's sphere for the grid (negative radius: none).
#[derive(Clone, Copy)]
struct Sphere(Vec3, f32);

impl HasSphere for Sphere {
    fn center(&self) -> Vec3 {
        self.0
    }
    fn radius(&self) -> f32 {
        self.1
    }
}

/// The photons the visible points gathered in one pass.
#[derive(Clone, Debug)]
pub struct Gathered {
    /// Groups per pass (G).
    groups: usize,
    /// Σ β_p·f(x, ωp → ωo) per visible point and group, slot `j·G + h`
    /// (W, spectral at group h's wavelengths, power scales applied).
    phi: Vec<SampledSpectrum>,
    /// Photons inside each visible point's sphere (M).
    m: Vec<u64>,
}

impl Gathered {
    /// Number of photons visible point `j` gathered (M).
    pub fn m(&self, j: usize) -> u64 {
        self.m[j]
    }

    /// The non-zero photon sums of visible point `j` of `visit`, each with
    /// the wavelengths it is spectral at (the pixel's own for its group).
    pub fn sums<'a>(
        &'a self,
        j: usize,
        visit: &'a PixelVisit,
        pw: &'a PassWavelengths,
    ) -> impl Iterator<Item = (SampledSpectrum, &'a SampledWavelengths)> + 'a {
        let g = self.groups;
        self.phi[j * g..(j + 1) * g]
            .iter()
            .enumerate()
            .filter(|(_, phi)| !phi.is_black())
            .map(move |(h, phi)| {
                let lambda = if h == visit.group {
                    &visit.lambda
                } else {
                    pw.group(h)
                };
                (*phi, lambda)
            })
    }
}

/// Photons per parallel chunk.
const CHUNK: u64 = 4096;

/// The spheres of the G + 1 grids of a photon pass, each as long as
/// `visits` (a negative radius where the grid has no point; empty when it
/// has none), so a grid's indices are visit indices: list k < G holds group
/// k's points that gather only their own group's photons, list G those that
/// gather every group's.
fn grid_spheres(visits: &[PixelVisit], radius: &[f32], g: usize) -> Vec<Vec<Sphere>> {
    let none = Sphere(Vec3::ZERO, -1.0);
    // A list is allocated when its first point comes: usually one group
    // (all points gather every group unless a dispersive surface is seen),
    // and an empty list builds an empty grid at no cost.
    let mut lists: Vec<Vec<Sphere>> = vec![Vec::new(); g + 1];
    for (j, (v, &r)) in visits.iter().zip(radius).enumerate() {
        if let Some(vp) = &v.vp {
            let k = if vp.all_groups { g } else { v.group };
            if lists[k].is_empty() {
                lists[k] = vec![none; visits.len()];
            }
            lists[k][j] = Sphere(vp.p, r);
        }
    }
    lists
}

/// Shoots `n_photons` photons of pass `pass` and gathers them at the visible
/// points (every group's at those that take all, module doc), each with its
/// own radius `radius[i]` (`None` if cancelled).
pub fn photon_pass(
    ctx: &RenderContext<'_>,
    out: &Visits,
    grids: &mut Vec<SphereGrid>,
    radius: &[f32],
    pw: &PassWavelengths,
    shoot: &ShootSettings,
    pass: u64,
    n_photons: u64,
) -> Option<Gathered> {
    let scene = ctx.scene;
    let visits = &out.visits;
    let g = pw.len();
    // One grid per group for the points that gather only their own group's
    // photons, one (the last) for those that gather all; their spheres are
    // sorted out in one pass over the visits (240 bytes each: a pass per
    // grid read them G + 1 times), then the grids are built side by side
    // (each in parallel parts itself) in `grids`' storage.
    let lists = grid_spheres(visits, radius, g);
    grids.resize_with(lists.len(), SphereGrid::default);
    grids
        .par_iter_mut()
        .zip(lists.into_par_iter())
        .for_each(|(grid, spheres)| grid.rebuild(&spheres));
    let grids: &[SphereGrid] = grids;
    let lists: Vec<Option<Vec<(u32, u32, SampledSpectrum)>>> = (0..n_photons.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            if ctx.cancelled() {
                return None;
            }
            let mut list = Vec::new();
            for i in c * CHUNK..((c + 1) * CHUNK).min(n_photons) {
                let h = pw.photon_group(i);
                let own_scale = pw.photon_scale(h, n_photons);
                let all_scale = own_scale / g as f32;
                trace_photon(scene, pw.group(h), shoot, pass, i, |hit| {
                    if hit.v.depth < 2 {
                        return; // direct light: the camera pass's NEE
                    }
                    for (grid, scale) in [(&grids[h], own_scale), (&grids[g], all_scale)] {
                        grid.for_each_containing(hit.v.p(), |j| {
                            let v = &visits[j as usize];
                            let Some(vp) = &v.vp else { return };
                            let Some(bsdf) = out.bsdf_for(j as usize, vp, v.group, h, g) else {
                                return;
                            };
                            let r = radius[j as usize];
                            if let Some(phi) = photon_contribution(vp, bsdf, hit, r) {
                                list.push((j, h as u32, phi * scale));
                            }
                        });
                    }
                });
            }
            ctx.advance(CHUNK.min(n_photons - c * CHUNK));
            Some(list)
        })
        .collect();
    let mut gathered = Gathered {
        groups: g,
        phi: vec![SampledSpectrum::zero(); visits.len() * g],
        m: vec![0; visits.len()],
    };
    for list in lists {
        for (j, h, phi) in list? {
            gathered.phi[j as usize * g + h as usize] += phi;
            gathered.m[j as usize] += 1;
        }
    }
    Some(gathered)
}

/// β_p·f(x, ωp → ωo) of a photon hit `h` inside the sphere (radius `r`)
/// of `vp`, with `bsdf` the point's BSDF at the photon's wavelengths, or
/// `None` when the shared gather rule does not count it.
fn photon_contribution(
    vp: &VisiblePoint,
    bsdf: &Bsdf,
    h: &PhotonHit<'_>,
    r: f32,
) -> Option<SampledSpectrum> {
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
    let f = bsdf.f(vp.wo, c.wi, TransportMode::Radiance);
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
