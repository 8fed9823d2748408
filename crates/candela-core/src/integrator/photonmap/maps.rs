//! The two photon maps of one pass and the radiance estimate.
//!
//! **Contents.** Photons are shot with [`trace_photon`]; each wavelength
//! group of the pass ([`crate::integrator::wavelengths`]) has its own pair
//! of maps, holding the hits of the paths `i` with `i mod G` = g. A hit of
//! photon path `i` at its `d`-th surface is stored with power ΔΦ = β/N_g,
//! N_g the number of paths of its group shot for that map [Jensen 2001, §5.1, eq. 5.1 for one
//! light and a power-proportional choice among several]. The caustic map
//! keeps the L S+ D hits of `causticphotons` paths. What the global map
//! keeps depends on how it is read (see the module doc of `photonmap`):
//! every non-specular hit when final gathering reads it one bounce away,
//! only the indirect non-caustic hits (d ≥ 2, not L S+ D) when the camera
//! reads it directly.
//!
//! **Radiance estimate.** L_r(x, ωo) ≈ Σ_p f(x, ωo, ωp)·ΔΦ_p·w(d_p/r) /
//! (c_w·πr²) [Jensen 2001, §7.2, eq. 7.6; filters §7.2.1], where r is the
//! distance to the k-th nearest photon (or `maxradius` when fewer than k lie
//! within it), w a radial kernel and c_w its mean over the unit disk. When
//! k photons were found the k-th one, which only defines r, is left out of
//! the sum: with N uniform photons on a surface whose area within r is πr²,
//! πr_k²/A is Beta(k, N − k + 1) distributed, so E[(k − 1)/(πr_k²)] = N/A
//! exactly, and given r_k the k − 1 nearer photons are uniform in the disk,
//! so any kernel normalised by c_w keeps the estimate unbiased. Summing all
//! k photons overestimates by k/(k − 1) [García et al., "Description and
//! Solution of an Unreported Intrinsic Bias in Photon Mapping Density
//! Estimation with Constant Kernel", CGF 2012; for the cone and other
//! kernels, García et al., TVCG 2014]. With fewer than k photons the radius
//! is fixed and every photon found counts. Kernel bias from a curved or
//! varying density remains, ≈ (r²/8)∇²E for the disk kernel.
//!
//! The kernels: `disk` w = 1, c = 1; Jensen's `cone` w = 1 − t/κ (κ ≥ 1),
//! c = 1 − 2/(3κ) [Jensen 2001, eqs. 7.7–7.8]; `epanechnikov` w = 1 − t²,
//! c = 1/2 (t = d/r).
//!
//! **Photons from a curved neighbourhood or across an edge.** Which of the
//! k photons count, with which direction and kernel distance, is the rule
//! shared with `sppm` and `vcm` ([`crate::integrator::gather`]): on smooth
//! surfaces ωp is carried into x's frame by the rotation taking the
//! photon's normal to x's (exact on a sphere under a uniform field at any
//! radius, where Jensen's world-space ωp loses 2.5 % in T4(b) at
//! r ≈ 0.45 R); across a crease the neighbouring face is unfolded onto x's
//! plane, so a room's wall photons stand for exactly the part of the disk
//! its edge cuts off.
//!
//! Shading normals: a photon's density is flux per geometric area, dΦ =
//! L_i|ωp·n_g| dω dA, while the reflected radiance integrates L_i|ωp·n_s|,
//! so each photon is weighted by |ωp·n_s|/|ωp·n_g| (1 without shading
//! normals) [Veach 1997, §5.3].

use super::PhotonMapSettings;
use crate::bsdf::{Bsdf, TransportMode};
use crate::integrator::gather::{gather, Surfel};
use crate::integrator::photon::{trace_photon, PhotonHit, ShootSettings};
use crate::integrator::wavelengths::PassWavelengths;
use crate::math::Vec3;
use crate::sampling::hash_u64s;
use crate::scene::Scene;
use crate::spatial::{HasPosition, Neighbor, PointKdTree};
use crate::spectrum::SampledSpectrum;
use rayon::prelude::*;

/// Photon paths per parallel work item (results are concatenated in order).
const PHOTONS_PER_CHUNK: u64 = 4096;

/// A stored photon hit.
#[derive(Clone, Copy, Debug)]
pub struct Photon {
    /// Where it landed.
    pub p: Vec3,
    /// Direction it came from (pointing away from the surface).
    pub wi: Vec3,
    /// Geometric normal of the surface it landed on.
    pub n: Vec3,
    /// Power ΔΦ at the pass wavelengths \[W\], already divided by the paths shot.
    pub power: SampledSpectrum,
    /// Surfaces hit so far, this one included (1: direct illumination).
    pub depth: u32,
}

impl HasPosition for Photon {
    #[inline]
    fn position(&self) -> Vec3 {
        self.p
    }
}

/// Radial density-estimation kernels (t = d/r ∈ [0, 1]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kernel {
    /// Constant weight.
    Disk,
    /// Jensen's cone filter w = 1 − t/κ with κ ≥ 1 [Jensen 2001, eq. 7.7].
    Cone(f32),
    /// w = 1 − t².
    Epanechnikov,
}

impl Kernel {
    /// Weight of a photon at squared normalised distance `t2` = d²/r².
    #[inline]
    fn weight(self, t2: f32) -> f32 {
        match self {
            Kernel::Disk => 1.0,
            Kernel::Cone(k) => 1.0 - t2.sqrt() / k,
            Kernel::Epanechnikov => 1.0 - t2,
        }
    }

    /// Mean of the weight over the unit disk: (1/π)∫ w dA.
    fn mean(self) -> f32 {
        match self {
            Kernel::Disk => 1.0,
            // [Jensen 2001, eq. 7.8]
            Kernel::Cone(k) => 1.0 - 2.0 / (3.0 * k),
            Kernel::Epanechnikov => 0.5,
        }
    }
}

/// How a map is queried.
#[derive(Clone, Copy, Debug)]
pub struct Lookup {
    /// Nearest photons wanted (k ≥ 2).
    pub k: usize,
    /// Largest search radius.
    pub max_radius: f32,
    /// Density-estimation kernel.
    pub kernel: Kernel,
}

/// One photon map: a kd-tree of photons.
#[derive(Default)]
pub struct PhotonMap {
    tree: PointKdTree<Photon>,
}

/// A camera-side point where a map is read.
pub struct Query<'a> {
    /// The surface point.
    pub p: Vec3,
    /// Its geometric normal.
    pub n: Vec3,
    /// Its BSDF.
    pub bsdf: &'a Bsdf,
    /// Direction towards the viewer.
    pub wo: Vec3,
    /// Deepest photon that still fits in `maxdepth` scattering events.
    pub max_photon_depth: u32,
}

impl PhotonMap {
    /// Builds the map from its photons.
    pub fn new(photons: Vec<Photon>) -> Self {
        Self {
            tree: PointKdTree::build(photons),
        }
    }

    /// Number of photons stored.
    pub fn len(&self) -> usize {
        self.tree.len()
    }

    /// True when no photon is stored.
    pub fn is_empty(&self) -> bool {
        self.tree.is_empty()
    }

    /// The photons, in tree order.
    pub fn photons(&self) -> &[Photon] {
        self.tree.items()
    }

    /// Reflected radiance at `q` from the photons near it (module doc).
    pub fn radiance(
        &self,
        q: &Query<'_>,
        lookup: &Lookup,
        scratch: &mut Vec<Neighbor>,
    ) -> SampledSpectrum {
        if self.is_empty() || q.max_photon_depth == 0 {
            return SampledSpectrum::zero();
        }
        let r2 = self
            .tree
            .k_nearest(q.p, lookup.k, lookup.max_radius, scratch);
        if scratch.is_empty() || r2.is_nan() || r2 <= 0.0 {
            return SampledSpectrum::zero();
        }
        // With k found, the farthest only sets r (exact for a uniform density).
        let skip = (scratch.len() >= lookup.k)
            .then(|| scratch.iter().max().map(|n| n.index))
            .flatten();
        let (ns, ng) = (q.bsdf.ns(), q.n);
        let xs = Surfel {
            p: q.p,
            n: ng,
            w: q.wo,
        };
        let mut sum = SampledSpectrum::zero();
        for n in scratch.iter().filter(|n| Some(n.index) != skip) {
            let ph = &self.tree.items()[n.index as usize];
            if ph.depth > q.max_photon_depth {
                continue;
            }
            let ps = Surfel {
                p: ph.p,
                n: ph.n,
                w: ph.wi,
            };
            let Some(c) = gather(&xs, &ps, r2) else {
                continue;
            };
            let wi = c.wi;
            let cos_g = wi.dot(ng).abs();
            if cos_g == 0.0 {
                continue;
            }
            let f = q.bsdf.f(q.wo, wi, TransportMode::Radiance);
            let w = lookup.kernel.weight(c.dist2 / r2) * wi.dot(ns).abs() / cos_g;
            sum += f * ph.power * w;
        }
        sum / (lookup.kernel.mean() * std::f32::consts::PI * r2)
    }
}

/// Which photon hits a map keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Keep {
    /// Every non-specular hit (read one gather bounce away from the camera).
    All,
    /// Indirect hits that are not caustics: depth ≥ 2 and not L S+ D.
    Indirect,
    /// Caustic hits: L S+ D.
    Caustic,
}

impl Keep {
    fn keeps(self, h: &PhotonHit<'_>) -> bool {
        match self {
            Keep::All => true,
            Keep::Indirect => h.v.depth >= 2 && !h.v.caustic,
            Keep::Caustic => h.v.caustic,
        }
    }
}

/// The global and caustic maps of one pass.
#[derive(Default)]
pub struct PassMaps {
    /// Global map (contents depend on `finalgather`).
    pub global: PhotonMap,
    /// Caustic map.
    pub caustic: PhotonMap,
}

impl PassMaps {
    /// Shoots and builds both maps of every wavelength group of `pass`
    /// (index g: the maps of group g).
    pub fn shoot(
        scene: &Scene,
        pw: &PassWavelengths,
        s: &PhotonMapSettings,
        pass: u64,
    ) -> Vec<Self> {
        let global_keep = if s.final_gather {
            Keep::All
        } else {
            Keep::Indirect
        };
        let global = ShootSettings {
            max_depth: s.max_depth,
            seed: s.seed,
            caustic_only: false,
        };
        // An independent photon stream for the caustic map.
        let caustic = ShootSettings {
            max_depth: s.max_depth,
            seed: hash_u64s(&[s.seed, 0xCA05_71C5]),
            caustic_only: true,
        };
        let globals = shoot_map(scene, pw, &global, pass, s.photons, global_keep);
        let caustics = shoot_map(scene, pw, &caustic, pass, s.caustic_photons, Keep::Caustic);
        globals
            .into_iter()
            .zip(caustics)
            .map(|(global, caustic)| Self { global, caustic })
            .collect()
    }
}

/// Traces `n` photon paths of `pass` and builds, for each wavelength group
/// of `pw`, a map of its photons' hits that `keep` accepts; photon `i`
/// carries group `i mod G`'s wavelengths and power β/N_g.
pub fn shoot_map(
    scene: &Scene,
    pw: &PassWavelengths,
    settings: &ShootSettings,
    pass: u64,
    n: u64,
    keep: Keep,
) -> Vec<PhotonMap> {
    if n == 0 || scene.lights().is_empty() {
        return (0..pw.len()).map(|_| PhotonMap::default()).collect();
    }
    let inv_n = 1.0 / n as f32;
    let chunks: Vec<Vec<Vec<Photon>>> = (0..n.div_ceil(PHOTONS_PER_CHUNK))
        .into_par_iter()
        .map(|c| {
            let mut out = vec![Vec::new(); pw.len()];
            for i in c * PHOTONS_PER_CHUNK..((c + 1) * PHOTONS_PER_CHUNK).min(n) {
                let g = pw.photon_group(i);
                let w = inv_n * pw.photon_scale(g, n);
                trace_photon(scene, pw.group(g), settings, pass, i, |h| {
                    if keep.keeps(h) {
                        out[g].push(Photon {
                            p: h.v.p(),
                            wi: h.v.wo,
                            n: h.v.it.n,
                            power: h.v.beta * w,
                            depth: h.v.depth,
                        });
                    }
                });
            }
            out
        })
        .collect();
    (0..pw.len())
        .map(|g| PhotonMap::new(chunks.iter().flat_map(|c| c[g].iter().copied()).collect()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::{Bxdf, DiffuseBxdf};
    use crate::interaction::SurfaceInteraction;
    use crate::math::Frame;
    use crate::math::{Vec2, Vec3};
    use crate::sampling::{sample_cosine_hemisphere, sample_uniform_sphere, Pcg32};

    /// Inward-facing Lambertian query at a uniform point of the unit sphere.
    fn sphere_query_radiance(
        map: &PhotonMap,
        q: Vec3,
        lookup: &Lookup,
        scratch: &mut Vec<Neighbor>,
    ) -> f32 {
        let n = -q;
        let frame = Frame::from_z(n);
        let si = SurfaceInteraction::new(
            q,
            Vec3::ZERO,
            Vec2::ZERO,
            n,
            frame.x,
            frame.y,
            Vec3::ZERO,
            Vec3::ZERO,
            false,
        );
        let si = if si.n().dot(n) < 0.0 {
            SurfaceInteraction::new(
                q,
                Vec3::ZERO,
                Vec2::ZERO,
                n,
                frame.x,
                frame.y,
                Vec3::ZERO,
                Vec3::ZERO,
                true,
            )
        } else {
            si
        };
        let bsdf = Bsdf::new(
            si.n(),
            frame.x,
            Bxdf::Diffuse(DiffuseBxdf::new(SampledSpectrum::splat(1.0))),
        );
        let query = Query {
            p: si.p(),
            n: si.n(),
            bsdf: &bsdf,
            wo: n,
            max_photon_depth: 1,
        };
        map.radiance(&query, lookup, scratch)[0]
    }

    #[test]
    fn radiance_estimate_is_exact_on_a_sphere_at_any_radius() {
        // N photons uniform on the inside of the unit sphere, directions
        // cosine-distributed about their own normal, power 1/N each: the
        // irradiance is 1/(4π) and L = E·ρ/π with ρ = 1. One query per
        // independent map; 5σ with σ measured over the queries.
        let (n, trials) = (500usize, 4000usize);
        let truth = 1.0 / (4.0 * std::f64::consts::PI * std::f64::consts::PI);
        let mut rng = Pcg32::new(11, 0);
        let mut u2 = || Vec2::new(rng.uniform_f32(), rng.uniform_f32());
        for lookup in [
            Lookup {
                k: 50,
                max_radius: 2.0,
                kernel: Kernel::Disk,
            },
            Lookup {
                k: 50,
                max_radius: 2.0,
                kernel: Kernel::Cone(1.1),
            },
            Lookup {
                k: 500,
                max_radius: 0.7,
                kernel: Kernel::Epanechnikov,
            },
        ] {
            let mut scratch = Vec::new();
            let est: Vec<f64> = (0..trials)
                .map(|_| {
                    let photons = (0..n)
                        .map(|_| {
                            let p = sample_uniform_sphere(u2());
                            let wi = Frame::from_z(-p).from_local(sample_cosine_hemisphere(u2()));
                            Photon {
                                p,
                                wi,
                                n: -p,
                                power: SampledSpectrum::splat(1.0 / n as f32),
                                depth: 1,
                            }
                        })
                        .collect();
                    let map = PhotonMap::new(photons);
                    sphere_query_radiance(&map, sample_uniform_sphere(u2()), &lookup, &mut scratch)
                        as f64
                })
                .collect();
            let m = est.iter().sum::<f64>() / trials as f64;
            let var = est.iter().map(|e| (e - m).powi(2)).sum::<f64>() / (trials as f64 - 1.0);
            let se = (var / trials as f64).sqrt();
            assert!(
                (m - truth).abs() <= 5.0 * se,
                "{lookup:?}: {} vs 1 ± {}",
                m / truth,
                se / truth
            );
        }
    }
}
