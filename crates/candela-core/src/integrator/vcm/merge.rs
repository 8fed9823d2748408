//! The merge side of an iteration: the light vertices as photons, in the
//! order of the hash grids that find them.
//!
//! A merge reads, for every light vertex within r of a camera vertex, only
//! its position, geometric normal, `wo`, β, depth, dispersion flag and the
//! vertex's partial MIS quantities ([`Partial::merge_weight`]): 72 bytes,
//! against the 232 of a whole [`LightVertex`] with its BSDF. The photons are
//! made from the light pass's chunks and copied once per iteration into the
//! grid's entry order ([`HashGrid::entry_order`]), in parallel (only the
//! grid's counting sort runs on one thread), so the photons of one bucket
//! are adjacent in memory. A query tests the distances on the grid's own
//! packed positions, eight at a time ([`HashGrid::for_each_slot_within`]),
//! and reads a photon only when it is within r: with cells of side 2r a
//! query on the Cornell box tests about six candidates for each photon it
//! finds. Reading the stored vertices through the grid's indices instead
//! was a cache miss per point found: on the Cornell box at 128² that load
//! alone was 18 % of a VCM iteration (`perf annotate`, the merge loop was
//! 39 % of it).
//!
//! **Two grids.** The vertices next to the light (the first of each light
//! subpath) merge only where a merge next to the light is a technique
//! ([`super::mis::Factors::merges_at`]): by default only after a specular
//! camera vertex. They are a third of the stored vertices on the Cornell
//! box and were a quarter of the photons its queries found, each found to
//! be dropped. So they have a grid of their own, queried only where they
//! merge, and built only when they can merge at all (`directmerges` not
//! `never`). Measured (callgrind, Cornell box at 128², 12 iterations, one
//! thread): 9.744 G instructions with one grid, 9.552 G with two, 9.382 G
//! with the packed distance test as well; wall time 3.66–3.67 s against
//! 3.49–3.55 s at 40 iterations (five interleaved runs each).

use super::light::{LightPaths, LightVertex};
use super::mis::Partial;
use crate::integrator::gather::Surfel;
use crate::math::Vec3;
use crate::spatial::{HasPosition, HashGrid};
use crate::spectrum::SampledSpectrum;
use rayon::prelude::*;

/// Bytes a merging iteration adds per stored vertex: its photon, and the
/// grid's position, index and (about one per vertex) bucket start.
pub const MERGE_BYTES: usize =
    std::mem::size_of::<Photon>() + std::mem::size_of::<Vec3>() + 2 * std::mem::size_of::<u32>();

/// What a merge needs of a stored light vertex (module docs).
#[derive(Clone, Copy, Debug)]
pub(super) struct Photon {
    /// Position, geometric normal and `wo` (towards the light).
    pub surfel: Surfel,
    /// The light subpath's throughput (power) at the vertex.
    pub beta: SampledSpectrum,
    /// The vertex's partial MIS quantities.
    pub mis: Partial,
    /// Surface vertices of the light subpath up to this one.
    pub depth: u32,
    /// Its subpath kept only the hero wavelength.
    pub terminated: bool,
}

impl Photon {
    fn new(lv: &LightVertex) -> Self {
        Photon {
            surfel: Surfel {
                p: lv.it.p,
                n: lv.it.n,
                w: lv.wo,
            },
            beta: lv.beta,
            mis: lv.mis,
            depth: lv.depth,
            terminated: lv.terminated,
        }
    }
}

impl HasPosition for Photon {
    fn position(&self) -> Vec3 {
        self.surfel.p
    }
}

/// A hash grid over some of an iteration's light vertices and their photons
/// in the grid's entry order.
struct Part {
    grid: HashGrid,
    photons: Vec<Photon>,
}

impl Part {
    /// The part over `kept` (stored vertices) at `positions` (theirs). The
    /// grid is built over the positions alone (12 bytes a vertex, on one
    /// thread), and each photon is made once, in parallel, straight into
    /// its entry slot: collecting the photons first through rayon's
    /// `flat_map_iter` and then reordering them cost 2.3 + 1.2 ms of a
    /// 65-ms Cornell box iteration at 128² on 2 threads, against 0.7 ms for
    /// the grid itself.
    fn build(kept: &[&LightVertex], positions: &[Vec3], radius: f32) -> Self {
        let grid = HashGrid::build(positions, radius);
        let photons = grid
            .entry_order()
            .par_iter()
            .map(|&i| Photon::new(kept[i as usize]))
            .collect();
        Part { grid, photons }
    }

    /// Calls `f` with every photon of the part within `radius` of `p`.
    #[inline]
    fn for_each_within(&self, p: Vec3, radius: f32, f: &mut impl FnMut(&Photon)) {
        self.grid
            .for_each_slot_within(p, radius, |slot| f(&self.photons[slot]));
    }
}

/// Hash grids over an iteration's light vertices, those next to the light
/// apart from the rest (module doc).
pub(super) struct MergeGrid {
    /// The vertices next to the light, when they can merge anywhere.
    direct: Option<Part>,
    /// The other vertices.
    beyond: Part,
}

impl MergeGrid {
    /// The grids for merge radius `radius` over the stored vertices of
    /// `light`; the vertices next to the light only when `direct` (they can
    /// merge somewhere).
    pub fn build(light: &LightPaths, radius: f32, direct: bool) -> Self {
        // One pass over the stored vertices (256 bytes each) sorts them.
        let mut parts: [(Vec<&LightVertex>, Vec<Vec3>); 2] = Default::default();
        for v in light.chunks().into_iter().flatten() {
            if v.depth != 1 || direct {
                let (kept, positions) = &mut parts[usize::from(v.depth == 1)];
                kept.push(v);
                positions.push(v.it.p);
            }
        }
        let [(beyond, beyond_p), (near, near_p)] = &parts;
        let (direct, beyond) = rayon::join(
            || direct.then(|| Part::build(near, near_p, radius)),
            || Part::build(beyond, beyond_p, radius),
        );
        MergeGrid { direct, beyond }
    }

    /// Calls `f` with every photon within `radius` of `p` (inclusive), those
    /// next to the light only when `direct`.
    #[inline]
    pub fn for_each_within(&self, p: Vec3, radius: f32, direct: bool, mut f: impl FnMut(&Photon)) {
        if let Some(d) = self.direct.as_ref().filter(|_| direct) {
            d.for_each_within(p, radius, &mut f);
        }
        self.beyond.for_each_within(p, radius, &mut f);
    }
}
