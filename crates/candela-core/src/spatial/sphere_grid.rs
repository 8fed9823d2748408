//! Hashed grid over spheres, queried with points: SPPM's visible-point grid.
//!
//! In stochastic progressive photon mapping every pixel owns a visible point
//! with its own, shrinking, gather radius, and each photon hit must find the
//! visible points whose sphere contains it. pbrt-v3 (`SPPMIntegrator::Render`,
//! "Create grid of all SPPM visible points"; PBR 3rd ed. §16.2.3) enters each
//! visible point in every grid cell its bounding box overlaps, so that a
//! photon reads the single cell it falls in. This is that grid, with the
//! cells hashed and filled by counting sort like [`super::HashGrid`] instead
//! of pbrt-v3's per-cell linked lists: one pass counts the entries per
//! bucket, a prefix sum places the runs, a second pass scatters (centre, r²,
//! index) records into them.
//!
//! **Cell size.** pbrt-v3 makes cells as wide as the largest radius, so a
//! sphere spans up to 3×3×3 cells. The default here is twice that, so a sphere
//! spans at most 2×2×2 cells, as a query does in [`super::HashGrid`]. On 1M
//! spheres of equal radius r centred on uniform points (each query point inside
//! 50 of them on average), cells of r took 1.4 s to build single-threaded and
//! 27M entries (540 MB); cells of 2r took 0.4–0.5 s and 8M entries (160 MB),
//! for queries 35% slower (3.0 µs against 2.2 µs). Use
//! [`SphereGrid::with_cell_size`] with r where queries far outnumber spheres.
//!
//! **Repeats.** When two cells of one sphere hash to the same bucket the sphere
//! enters it twice, but in a row (each sphere's entries are scattered before
//! the next one's), so a query skips repeats by comparing with the previous
//! entry and reports every containing sphere exactly once. That is cheaper than
//! de-duplicating the buckets of every sphere at build: with cells of r, the
//! build above took 2.4–3.7 s that way.

use super::hash_grid::{prefix_starts, CellHash};
use super::HasSphere;
use crate::math::Bounds3;
use glam::Vec3;

/// A stored sphere: centre and squared radius.
#[derive(Clone, Copy, Debug)]
struct GridSphere {
    center: Vec3,
    r2: f32,
}

/// A hashed grid of spheres answering "which spheres contain this point?".
#[derive(Clone, Debug)]
pub struct SphereGrid {
    cells: CellHash,
    /// Bucket b owns entries `cell_starts[b]..cell_starts[b + 1]`.
    cell_starts: Vec<u32>,
    /// Spheres ordered by bucket; a sphere appears in each bucket it touches.
    spheres: Vec<GridSphere>,
    /// The caller's index of each entry of `spheres`.
    indices: Vec<u32>,
}

/// True for an item that takes part: radius ≥ 0 (not negative, not NaN).
#[inline]
fn is_sphere<T: HasSphere>(it: &T) -> bool {
    it.radius() >= 0.0
}

impl SphereGrid {
    /// Builds the grid with cells twice as wide as the largest finite radius
    /// (1 when there is none). Items with a negative or NaN radius are left
    /// out.
    ///
    /// # Panics
    /// If there are 2³² items or more, or 2³² grid entries or more.
    pub fn build<T: HasSphere>(items: &[T]) -> Self {
        let max_radius = items
            .iter()
            .map(|it| it.radius())
            .filter(|r| r.is_finite())
            .fold(0.0f32, f32::max);
        let cell_size = if max_radius > 0.0 && (2.0 * max_radius).is_finite() {
            2.0 * max_radius
        } else {
            1.0
        };
        Self::with_cell_size(items, cell_size)
    }

    /// Builds the grid with cells of side `cell_size`.
    ///
    /// # Panics
    /// If `cell_size` is not positive and finite, or there are 2³² items or
    /// grid entries or more.
    pub fn with_cell_size<T: HasSphere>(items: &[T], cell_size: f32) -> Self {
        assert!(items.len() < u32::MAX as usize, "too many items");
        let spheres = || items.iter().enumerate().filter(|(_, it)| is_sphere(*it));
        let bounds = spheres().fold(Bounds3::EMPTY, |b, (_, it)| b.union_point(it.center()));
        let mut cells = CellHash::new(bounds.min, cell_size, spheres().count());
        // Pass 1: occupied cells and entries per bucket.
        let mut counts = vec![0u32; cells.n_buckets()];
        for (_, it) in spheres() {
            if let Some((lo, hi)) = cells.cells_around(it.center(), it.radius()) {
                cells.mark_occupied(lo, hi);
                cells.for_each_cell_bucket(lo, hi, |b| counts[b] += 1);
            }
        }
        // Pass 2: scatter the entries into their buckets' runs.
        let cell_starts = prefix_starts(&counts);
        let n_entries = *cell_starts.last().unwrap_or(&0) as usize;
        let mut next = cell_starts.clone();
        let mut entries = vec![
            GridSphere {
                center: Vec3::ZERO,
                r2: 0.0
            };
            n_entries
        ];
        let mut indices = vec![0u32; n_entries];
        for (i, it) in spheres() {
            let Some((lo, hi)) = cells.cells_around(it.center(), it.radius()) else {
                continue;
            };
            let s = GridSphere {
                center: it.center(),
                r2: it.radius() * it.radius(),
            };
            cells.for_each_cell_bucket(lo, hi, |b| {
                let slot = next[b] as usize;
                next[b] += 1;
                entries[slot] = s;
                indices[slot] = i as u32;
            });
        }
        Self {
            cells,
            cell_starts,
            spheres: entries,
            indices,
        }
    }

    /// Number of (sphere, bucket) entries: the memory the grid takes, in
    /// units of 20 bytes.
    pub fn entry_count(&self) -> usize {
        self.spheres.len()
    }

    /// Calls `f(index)` once for every sphere that contains `p`
    /// (`|p − centre|² ≤ r²`); `index` is the item's position in the build
    /// slice.
    pub fn for_each_containing(&self, p: Vec3, mut f: impl FnMut(u32)) {
        let c = self.cells.cell(p);
        if self.cells.clip(c, c).is_none() {
            return;
        }
        let b = self.cells.bucket(c);
        let run = self.cell_starts[b] as usize..self.cell_starts[b + 1] as usize;
        // A sphere whose cells share this bucket sits in it several times,
        // in a row: report it once.
        let mut last = None;
        for (s, &i) in self.spheres[run.clone()].iter().zip(&self.indices[run]) {
            if last != Some(i) && (p - s.center).length_squared() <= s.r2 {
                f(i);
                last = Some(i);
            }
        }
    }
}
