//! The merge side of an iteration: the light vertices as photons, in the
//! order of the hash grid that finds them.
//!
//! A merge reads, for every light vertex within r of a camera vertex, only
//! its position, geometric normal, `wo`, β, depth, dispersion flag and the
//! vertex's partial MIS quantities ([`Partial::merge_weight`]): 72 bytes,
//! against the 232 of a whole [`LightVertex`] with its BSDF. The photons are
//! made from the light pass's chunks and copied once per iteration into the
//! grid's entry order ([`HashGrid::entry_order`]), both in parallel (only
//! the grid's counting sort runs on one thread), so the photons of one bucket are adjacent in
//! memory, and a query reads them front to back, positions included
//! ([`HashGrid::for_each_candidate_run`]): one cache miss per bucket.
//! Reading the stored vertices through the grid's indices instead was a
//! cache miss per point found:
//! on the Cornell box at 128² that load alone was 18 % of a VCM iteration
//! (`perf annotate`, the merge loop was 39 % of it).

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

/// A hash grid over an iteration's light vertices and their photons in the
/// grid's entry order.
pub(super) struct MergeGrid {
    grid: HashGrid,
    photons: Vec<Photon>,
}

impl MergeGrid {
    /// The grid for merge radius `radius` over the stored vertices of `light`.
    /// The grid is built over their positions alone (12 bytes a vertex,
    /// gathered on one thread), and each photon is made once, in parallel,
    /// straight into its entry slot: collecting the photons first through
    /// rayon's `flat_map_iter` and then reordering them cost 2.3 + 1.2 ms
    /// of a 65-ms Cornell box iteration at 128² on 2 threads, against
    /// 0.7 ms for the grid itself.
    pub fn build(light: &LightPaths, radius: f32) -> Self {
        let chunks = light.chunks();
        let positions: Vec<Vec3> = chunks
            .iter()
            .flat_map(|c| c.iter().map(|v| v.it.p))
            .collect();
        let grid = HashGrid::build(&positions, radius);
        // First global index of each chunk, to find an entry's vertex.
        let starts: Vec<usize> = chunks
            .iter()
            .scan(0, |n, c| {
                let s = *n;
                *n += c.len();
                Some(s)
            })
            .collect();
        let vertex = |i: u32| {
            let i = i as usize;
            let c = starts.partition_point(|&s| s <= i) - 1;
            &chunks[c][i - starts[c]]
        };
        let photons = grid
            .entry_order()
            .par_iter()
            .map(|&i| Photon::new(vertex(i)))
            .collect();
        MergeGrid { grid, photons }
    }

    /// Calls `f` with every photon within `radius` of `p` (inclusive).
    #[inline]
    pub fn for_each_within(&self, p: Vec3, radius: f32, mut f: impl FnMut(&Photon)) {
        let r2 = radius * radius;
        self.grid.for_each_candidate_run(p, radius, |run| {
            for ph in &self.photons[run] {
                if (ph.surfel.p - p).length_squared() <= r2 {
                    f(ph);
                }
            }
        });
    }
}
