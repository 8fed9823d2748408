//! The default merge radius from the density of the light vertices.
//!
//! A merge's variance is set by how many light vertices fall in its disk
//! and its kernel bias by the disk's radius, so no radius in pixel units
//! suits every scene: on the Cornell box one iteration stores ~2.6 light
//! vertices per pixel footprint² (~1.6 of them beyond the first bounce,
//! the ones that merge there by default), on caustic-glass 0.3 and on
//! the pool 0.14 (on the floor under the water). These figures, and the
//! measurements below those of the `vcm` module doc, are from when every
//! vertex merged (`directmerges always`) and K was 2: the Cornell box was
//! best at 0.7–1 footprint (16 s: relMSE 0.0011–0.0012; 0.0035 at 3),
//! caustic-glass at 3–5 (0.021–0.028; 0.044–0.069 at 1), the pool at 3
//! (0.032; 0.043 at 1, 0.065 at 6). Without the direct merges the Cornell
//! box is best near 2 footprints.
//!
//! (Those references were means of vcm and sppm renders of a few thousand
//! iterations, blurred by their own kernels, which favours large radii; against
//! low-bias references (module doc of [`super`], "α") the pool is best near 2
//! footprints, where this rule gives it 4.2, and caustic-glass still at 6.)
//!
//! So without a written `radius` the first iteration's radius is the one
//! whose disk holds [`TARGET_NEIGHBOURS`] other light vertices around the
//! median stored vertex, counting only vertices that merge (beyond the
//! first bounce unless `directmerges always`) — the k-nearest-neighbour
//! radius of photon mapping [Jensen 2001, §7.2], taken once for the whole
//! image. A pilot light pass
//! (a fixed pass index of its own, so every process of a `--pass-range`
//! render finds the same radius and passes stay independent) stores its
//! vertices; around every `stride`-th of them (at most `QUERIES`) the
//! vertices within a probe radius R are counted, and with the median count
//! m (itself excluded) the radius is R √(K / m), since on surfaces the
//! count grows as r². It is kept within [`MIN_FOOTPRINTS`, `MAX_FOOTPRINTS`]
//! footprints so that a pilot that finds almost nothing, or a caustic that
//! holds almost every vertex, cannot choose an absurd kernel; with no
//! vertex at all the footprint default stays.
//!
//! Checked (with K = 2 and every vertex merging) beyond the three scenes
//! it was fitted on (relMSE against long path-traced references):
//! env-metals (an environment light; the pilot
//! takes the upper bound, 6 footprints; 8 s, one seed) 0.00022 against
//! 0.00024 at one footprint; killeroo-simple at 176² (4.7 footprints; 16 s,
//! two seeds) 0.0015–0.0018 against 0.0014–0.0017, 8 % worse: its light
//! vertices spread over a floor far larger than the view, and the median
//! vertex, not the median visible point, sets the radius.
//!
//! **The lower bound, 2 footprints.** Where light vertices are dense (the
//! Cornell box: K = 3 gives 1.4 footprints, radius 0.026 at half
//! resolution) a kernel of about one pixel leaves the merges noisy early
//! on, and since light tracing no longer takes the direct light
//! ([`super::variance`]) the early error is mostly theirs. Measured there
//! (relMSE against a 1200-s reference, seeds 1 and 2): at 36 iterations
//! 0.00163 and 0.00155 with 2 footprints (radius 0.038) against 0.00196
//! and 0.00194; at 240 iterations 0.000366 and 0.000371 against 0.000347
//! and 0.000342, as the kernel's bias starts to show (on the ceiling next
//! to the light). The equal-time benchmark's early points are the ones
//! that missed its target. The other scenes checked are above 2 footprints
//! already.
//!
//! **The radius field.** With `localradius` (the default) the same pilot,
//! with three more light passes of its own, gives every cell of space its
//! own K-neighbour radius around the global one ([`field_for`], module doc
//! of [`super::field`]).

use super::field::{FactorField, RadiusField, FIELD_PASSES};
use super::light::LightVertex;
use super::mis::DirectMerges;
use super::VcmIntegrator;
use crate::integrator::sppm::passes::pass_wavelengths;
use crate::integrator::RenderContext;
use crate::math::Vec3;
use crate::spatial::{CellMap, HashGrid};
use rayon::prelude::*;
use std::sync::atomic::AtomicU64;

/// Other light vertices the default radius's disk holds around the median
/// stored vertex (module docs).
pub const TARGET_NEIGHBOURS: f32 = 3.0;

/// Bounds of the default radius, in pixel footprints.
pub const MIN_FOOTPRINTS: f32 = 2.0;
/// See [`MIN_FOOTPRINTS`].
pub const MAX_FOOTPRINTS: f32 = 6.0;

/// First probe radius, in footprints.
const PROBE_FOOTPRINTS: f32 = 4.0;

/// The probe radius doubles until the median count reaches this many
/// (so that √(K / m) is not read from a count of one or two) ...
const PROBE_COUNT: f32 = 16.0;
/// ... or this many times.
const PROBE_DOUBLINGS: u32 = 4;

/// Most vertices the median is taken over.
const QUERIES: usize = 8192;

/// Largest radius of the field, in global radii.
const FIELD_GROWTH: f32 = 2.0;

/// A cell's radius differs from the global one when it is off by more
/// than this fraction ...
const FIELD_DIFFERENCE: f32 = 0.2;
/// ... and the field is kept only when this share of the vertices lie in
/// such cells (module doc of [`super::field`]).
const FIELD_MIN_SHARE: f64 = 0.05;

/// Most vertices the radius field counts around.
const FIELD_QUERIES: usize = 65536;

/// The pilot's pass index: no rendered pass has it.
const PILOT_PASS: u64 = u64::MAX;

/// The merge radius of the first iteration for a render whose pixel
/// footprint radius is `footprint` (module docs), and with `localradius`
/// the radius field around it ([`super::field`]); `None` if the render
/// was cancelled.
pub(super) fn density_radius(
    vcm: &VcmIntegrator,
    ctx: &RenderContext<'_>,
    footprint: f32,
) -> Option<(f32, Option<RadiusField>)> {
    let mut points = pilot_points(vcm, ctx, footprint, PILOT_PASS)?;
    let r = radius_for_neighbours(&points, footprint);
    if !vcm.settings.local_radius || points.is_empty() {
        return Some((r, None));
    }
    // One pass's counts already tell a field that would be dropped (module
    // doc of [`super::field`]): their noise moves more cells away from r_g,
    // not fewer, so the other passes are traced only when it is kept.
    if field_for(&points, r, 1, footprint).is_none() {
        return Some((r, None));
    }
    for k in 1..FIELD_PASSES {
        points.extend(pilot_points(vcm, ctx, footprint, PILOT_PASS - k)?);
    }
    Some((r, field_for(&points, r, FIELD_PASSES, footprint)))
}

/// The positions of the merging vertices of the pilot light pass `pass`.
fn pilot_points(
    vcm: &VcmIntegrator,
    ctx: &RenderContext<'_>,
    footprint: f32,
    pass: u64,
) -> Option<Vec<Vec3>> {
    let n_light = vcm.light_paths(ctx) as f32;
    let f = FactorField::uniform(footprint, n_light, false, true, DirectMerges::Always);
    let lambda = *pass_wavelengths(vcm.settings.seed, pass, 1).group(0);
    let time = vcm.time(ctx, pass);
    // Its own work counter: the pass's progress counts rendered paths only.
    let work = AtomicU64::new(0);
    let pilot = RenderContext {
        work: &work,
        ..*ctx
    };
    let light = vcm.light_pass(&pilot, pass, &lambda, time, &f, None)?;
    // The vertices that merge count: those next to the light only if they
    // all do (module doc of `mis`: by default only behind specular ones).
    let all = vcm.direct_merges() == DirectMerges::Always;
    let merges = |v: &&LightVertex| all || v.depth >= 2;
    let points: Vec<Vec3> = light
        .chunks()
        .iter()
        .flat_map(|c| c.iter().filter(merges).map(|v| v.p()))
        .collect();
    light.recycle(&vcm.pools.chunks);
    Some(points)
}

/// The radius field ([`super::field`]) of `points`, the merging vertices
/// of `passes` light passes, with cells of side `r_g` (the global default
/// radius) and radii within the footprint bounds.
pub fn field_for(points: &[Vec3], r_g: f32, passes: u64, footprint: f32) -> Option<RadiusField> {
    // At most twice the global radius: where the global rule sits at its
    // lower bound (the Cornell box) a sparse cell would otherwise take 3×,
    // which cost merge lookups there and gained nothing (module doc of
    // [`super::field`]).
    let lo = MIN_FOOTPRINTS * footprint;
    let hi = (FIELD_GROWTH * r_g).min(MAX_FOOTPRINTS * footprint).max(lo);
    let grid = HashGrid::build(points, r_g);
    let stride = points.len().div_ceil(FIELD_QUERIES).max(1);
    let queries: Vec<Vec3> = points.iter().step_by(stride).copied().collect();
    let counts: Vec<u32> = queries
        .par_iter()
        .map(|&p| {
            let mut c = 0u32;
            grid.for_each_within(p, r_g, |_, _| c += 1);
            c.saturating_sub(1)
        })
        .collect();
    // Per cell: the sum of the neighbour counts and the vertices counted.
    let origin = points.iter().fold(Vec3::INFINITY, |m, &p| m.min(p));
    let mut sums = CellMap::new(origin, r_g, queries.len(), (0.0f64, 0u32));
    for (&p, &c) in queries.iter().zip(&counts) {
        let e = sums.entry(p);
        e.0 += f64::from(c);
        e.1 += 1;
    }
    let k = f64::from(TARGET_NEIGHBOURS) * passes as f64;
    let radius_of = |(sum, n): (f64, u32)| {
        let mean = sum / f64::from(n);
        let r = if mean > 0.0 {
            (f64::from(r_g) * (k / mean).sqrt()) as f32
        } else {
            hi
        };
        r.clamp(lo, hi)
    };
    // The share of the vertices whose cell's radius is not the global one.
    let moved: u32 = sums
        .values()
        .filter(|&&v| (radius_of(v) / r_g - 1.0).abs() > FIELD_DIFFERENCE)
        .map(|&(_, n)| n)
        .sum();
    let share = f64::from(moved) / queries.len().max(1) as f64;
    (share >= FIELD_MIN_SHARE).then(|| RadiusField::new(sums.map(hi, radius_of)))
}

/// The radius whose disk holds [`TARGET_NEIGHBOURS`] other points around
/// the median point, within [[`MIN_FOOTPRINTS`], [`MAX_FOOTPRINTS`]]
/// footprints (module docs); `footprint` if there are no points.
pub fn radius_for_neighbours(points: &[Vec3], footprint: f32) -> f32 {
    if points.is_empty() {
        return footprint;
    }
    let (mut probe, mut m) = (PROBE_FOOTPRINTS * footprint, 0.0);
    for _ in 0..PROBE_DOUBLINGS {
        m = median_neighbours(points, probe);
        if m >= PROBE_COUNT {
            break;
        }
        probe *= 2.0;
    }
    let r = if m > 0.0 {
        probe * (TARGET_NEIGHBOURS / m).sqrt()
    } else {
        MAX_FOOTPRINTS * footprint
    };
    r.clamp(MIN_FOOTPRINTS * footprint, MAX_FOOTPRINTS * footprint)
}

/// Median over (at most [`QUERIES`]) of `points` of the other points
/// within `radius`.
fn median_neighbours(points: &[Vec3], radius: f32) -> f32 {
    let grid = HashGrid::build(points, radius);
    let stride = points.len().div_ceil(QUERIES).max(1);
    let mut counts: Vec<u32> = points
        .iter()
        .step_by(stride)
        .map(|&p| {
            let mut c = 0u32;
            grid.for_each_within(p, radius, |_, _| c += 1);
            c.saturating_sub(1)
        })
        .collect();
    let mid = counts.len() / 2;
    let (_, m, _) = counts.select_nth_unstable(mid);
    *m as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    /// n points uniform on the unit square of the plane z = 0.
    fn plane(n: usize, seed: u64) -> Vec<Vec3> {
        let mut rng = Pcg32::new(seed, 0);
        (0..n)
            .map(|_| {
                let x = rng.uniform_f32();
                Vec3::new(x, rng.uniform_f32(), 0.0)
            })
            .collect()
    }

    /// Uniform points of density ρ: the disk of radius r around a point
    /// holds Poisson(ρπr²) others, so the K-neighbour radius is
    /// √(K / (ρπ)). At ρ = 10⁶ on the unit square, with footprints of ½
    /// and ¼ of that radius (inside the bounds, 2–6 footprints), the
    /// pilot's probes (4 footprints, doubled while the median count is
    /// below 16) end at 4 times that radius and hold λ = 16K = 48 others on
    /// average. The median of Poisson(λ)
    /// for an integer λ is λ (P(X ≤ λ−1) < ½ ≤ P(X ≤ λ)); the empirical
    /// median over 8192 queries moves the CDF by ~0.0055 (1σ, about a
    /// tenth of a count here), and the points within a probe radius of the
    /// square's edge (2–3 % of them) see fewer: the median is λ or λ − 1,
    /// so r is within 1/(2λ) ≈ 1 % of the truth and in fact nearer. Bound:
    /// 1 %; a count that includes the query point itself is off by +1 on
    /// every query.
    #[test]
    fn uniform_points_give_the_k_neighbour_radius() {
        let n = 1_000_000;
        let rho = n as f32;
        let truth = (TARGET_NEIGHBOURS / (rho * std::f32::consts::PI)).sqrt();
        for footprint in [0.5 * truth, 0.25 * truth] {
            let r = radius_for_neighbours(&plane(n, 7), footprint);
            assert!(
                (r / truth - 1.0).abs() < 0.01,
                "footprint {footprint}: r = {r}, truth {truth}"
            );
        }
    }

    /// Density one quarter → radius twice: the radius follows the density.
    /// Both sets are probed at λ ≈ 29 neighbours (the dense one after one
    /// doubling of the probe, the sparse one after two), so their medians
    /// are at most one count apart (the argument of the test above): ≤ 2 %
    /// in the ratio. Bound: 3 %. Both radii (1.5 and 3.1 mm) are inside the
    /// bounds, 2–6 footprints of 0.6 mm.
    #[test]
    fn a_quarter_of_the_points_doubles_the_radius() {
        let fp = 6e-4;
        let dense = radius_for_neighbours(&plane(400_000, 1), fp);
        let sparse = radius_for_neighbours(&plane(100_000, 2), fp);
        assert!(
            (sparse / dense / 2.0 - 1.0).abs() < 0.03,
            "{dense} {sparse}"
        );
    }

    #[test]
    fn the_radius_stays_within_its_footprint_bounds() {
        // Ten points on 1 m²: m = 0 at every probe: the upper bound.
        assert_eq!(radius_for_neighbours(&plane(10, 3), 1e-3), 6e-3);
        // A thousand points at one spot: the lower bound.
        let spot = vec![Vec3::ONE; 1000];
        assert_eq!(radius_for_neighbours(&spot, 1e-3), 2e-3);
        assert_eq!(radius_for_neighbours(&[], 1e-3), 1e-3);
    }

    /// The field follows the density: four "passes" of a uniform unit square
    /// at ρ = 40 000 (so the disk of radius r_bg = √(KP / πρ) ≈ 0.0098 holds
    /// KP = 12 others) with a strip x ∈ [0.5, 0.6] sixteen times as dense,
    /// at a footprint of r_bg / 4: the strip's K-neighbour radius, r_bg / 4,
    /// is below the lower bound (2 footprints), so its inner cells have the
    /// bound; the background's cells have r_bg within the counting noise
    /// (cells of side r_bg hold ~4 queries of Poisson(12) counts: 7 % on
    /// the radius, 1σ; the median of 100 cells within 5 %).
    #[test]
    fn the_field_is_small_where_vertices_are_dense() {
        let r_bg = (3.0f32 * 4.0 / (std::f32::consts::PI * 40_000.0)).sqrt();
        let fp = r_bg / 4.0;
        let mut points = plane(40_000, 11);
        let strip = plane(64_000, 12);
        points.extend(strip.iter().map(|p| Vec3::new(0.5 + 0.1 * p.x, p.y, 0.0)));
        let field = field_for(&points, r_bg, 4, fp).expect("the field differs from r_g");
        for y in [0.2f32, 0.5, 0.8] {
            assert_eq!(
                field.at(Vec3::new(0.55, y, 0.0)),
                2.0 * fp,
                "strip at y = {y}"
            );
        }
        let mut bg: Vec<f32> = (0..100)
            .map(|i| field.at(Vec3::new(0.05 + 0.003 * i as f32, 0.3, 0.0)) / r_bg)
            .collect();
        bg.sort_by(f32::total_cmp);
        assert!((bg[50] - 1.0).abs() < 0.05, "background median {}", bg[50]);
    }

    /// Where every cell's radius would be the global one (vertices dense
    /// enough that the K-neighbour radius is below the lower bound, which
    /// r_g then sits at, as on the Cornell box) there is no field.
    #[test]
    fn a_field_equal_to_the_global_radius_is_dropped() {
        let r_bg = (3.0f32 * 4.0 / (std::f32::consts::PI * 40_000.0)).sqrt();
        let fp = r_bg;
        assert!(field_for(&plane(40_000, 13), 2.0 * fp, 4, fp).is_none());
    }
}
