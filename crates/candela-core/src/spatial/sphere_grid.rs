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
//!
//! **Parallel build.** SPPM rebuilds its grid every iteration, serially it
//! was ~10 % of an iteration at two threads (caustic-glass, 166 000 visible
//! points, 1.3 M entries). Items above [`PARALLEL_ITEMS`] are counted in
//! chunks, one per thread, whose counts are summed; the scatter is split by
//! ranges of buckets, each part owning its buckets' contiguous runs of the
//! entry arrays (so safe code writes them in parallel) and scanning every
//! sphere for the entries that fall in them. Every bucket still receives its
//! spheres in item order, so the grid is the same for any number of parts
//! (tested), and [`SphereGrid::rebuild`] reuses a grid's arrays.

use super::hash_grid::{prefix_starts, CellHash};
use super::HasSphere;
use crate::math::Bounds3;
use glam::Vec3;
use rayon::prelude::*;

/// A stored sphere: centre and squared radius.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
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

impl Default for SphereGrid {
    /// The grid of no spheres.
    fn default() -> Self {
        Self {
            cells: CellHash::new(Vec3::ZERO, 1.0, 1),
            cell_starts: vec![0, 0],
            spheres: Vec::new(),
            indices: Vec::new(),
        }
    }
}

/// Items below which a grid builds on one thread.
const PARALLEL_ITEMS: usize = 16 * 1024;

/// Parts a build of `n` items is split into.
fn parts_for(n: usize) -> usize {
    if n < PARALLEL_ITEMS {
        1
    } else {
        rayon::current_num_threads().clamp(1, 8)
    }
}

/// Pass 1: the entries per bucket, and the occupied cells marked in
/// `cells`; the items in `parts` parallel chunks, their counts summed.
fn count_entries<T: HasSphere + Sync>(items: &[T], cells: &mut CellHash, parts: usize) -> Vec<u32> {
    let chunk = items.len().div_ceil(parts).max(1);
    let empty: &CellHash = cells;
    let partial: Vec<(Vec<u32>, CellHash)> = items
        .par_chunks(chunk)
        .map(|part| {
            let mut c = empty.clone();
            let mut counts = vec![0u32; c.n_buckets()];
            for it in part.iter().filter(|it| is_sphere(*it)) {
                if let Some((lo, hi)) = c.cells_around(it.center(), it.radius()) {
                    c.mark_occupied(lo, hi);
                    c.for_each_cell_bucket(lo, hi, |b| counts[b] += 1);
                }
            }
            (counts, c)
        })
        .collect();
    let mut total = vec![0u32; cells.n_buckets()];
    for (counts, c) in &partial {
        cells.merge_occupied(c);
        for (t, n) in total.iter_mut().zip(counts) {
            *t = t.checked_add(*n).expect("more than 2³² grid entries");
        }
    }
    total
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
    pub fn build<T: HasSphere + Sync>(items: &[T]) -> Self {
        let mut grid = Self::default();
        grid.rebuild(items);
        grid
    }

    /// [`Self::build`] into this grid's storage: the same grid, without
    /// allocating its entry arrays anew when they are already large enough
    /// (SPPM rebuilds its grid every iteration).
    ///
    /// # Panics
    /// As [`Self::build`].
    pub fn rebuild<T: HasSphere + Sync>(&mut self, items: &[T]) {
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
        self.fill(items, cell_size, parts_for(items.len()));
    }

    /// Builds the grid with cells of side `cell_size`.
    ///
    /// # Panics
    /// If `cell_size` is not positive and finite, or there are 2³² items or
    /// grid entries or more.
    pub fn with_cell_size<T: HasSphere + Sync>(items: &[T], cell_size: f32) -> Self {
        let mut grid = Self::default();
        grid.fill(items, cell_size, parts_for(items.len()));
        grid
    }

    /// Fills the grid with `items` in cells of side `cell_size`, reusing its
    /// arrays, in `parts` parallel parts (module doc; the same grid for any
    /// number of parts). Panics as [`Self::with_cell_size`].
    fn fill<T: HasSphere + Sync>(&mut self, items: &[T], cell_size: f32, parts: usize) {
        assert!(items.len() < u32::MAX as usize, "too many items");
        let spheres = || items.iter().enumerate().filter(|(_, it)| is_sphere(*it));
        let bounds = spheres().fold(Bounds3::EMPTY, |b, (_, it)| b.union_point(it.center()));
        let mut cells = CellHash::new(bounds.min, cell_size, spheres().count());
        let counts = count_entries(items, &mut cells, parts);
        let cell_starts = prefix_starts(&counts);
        let n_entries = *cell_starts.last().unwrap_or(&0) as usize;
        self.spheres.clear();
        self.spheres.resize(n_entries, GridSphere::default());
        self.indices.clear();
        self.indices.resize(n_entries, 0);
        // Pass 2: scatter the entries into their buckets' runs, each part
        // into the runs of its own range of buckets.
        let n_buckets = cells.n_buckets();
        let (mut entries, mut indices) = (&mut self.spheres[..], &mut self.indices[..]);
        let mut jobs = Vec::with_capacity(parts);
        for k in 0..parts {
            let (b0, b1) = (k * n_buckets / parts, (k + 1) * n_buckets / parts);
            let len = (cell_starts[b1] - cell_starts[b0]) as usize;
            let (e, e_rest) = std::mem::take(&mut entries).split_at_mut(len);
            let (i, i_rest) = std::mem::take(&mut indices).split_at_mut(len);
            (entries, indices) = (e_rest, i_rest);
            jobs.push((b0..b1, e, i));
        }
        let (grid, starts) = (&cells, &cell_starts);
        jobs.into_par_iter().for_each(|(range, entries, indices)| {
            let base = starts[range.start];
            let mut next: Vec<u32> = starts[range.clone()].iter().map(|s| s - base).collect();
            for (i, it) in spheres() {
                let Some((lo, hi)) = grid.cells_around(it.center(), it.radius()) else {
                    continue;
                };
                let s = GridSphere {
                    center: it.center(),
                    r2: it.radius() * it.radius(),
                };
                grid.for_each_cell_bucket(lo, hi, |b| {
                    if range.contains(&b) {
                        let slot = &mut next[b - range.start];
                        entries[*slot as usize] = s;
                        indices[*slot as usize] = i as u32;
                        *slot += 1;
                    }
                });
            }
        });
        self.cells = cells;
        self.cell_starts = cell_starts;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    /// 20 000 spheres of varied radii (some left out by a negative radius),
    /// enough entries for several parts.
    fn spheres() -> Vec<(Vec3, f32)> {
        let mut rng = Pcg32::new(3, 11);
        (0..20_000)
            .map(|i| {
                let p = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 4.0;
                let r = if i % 97 == 0 {
                    -1.0
                } else {
                    0.01 + 0.05 * rng.uniform_f32()
                };
                (p, r)
            })
            .collect()
    }

    /// What the grid finds around a lattice of points (its occupied cells
    /// included).
    fn found(grid: &SphereGrid) -> Vec<u32> {
        let mut out = Vec::new();
        for i in 0..4096u32 {
            let p = Vec3::new((i % 16) as f32, (i / 16 % 16) as f32, (i / 256) as f32) * 0.27;
            grid.for_each_containing(p, |j| out.push(j));
        }
        out
    }

    /// The grid is the same, entry for entry, whatever the number of parts
    /// its build is split into, and rebuilding into a used grid gives the
    /// grid a fresh build gives.
    #[test]
    fn parts_and_rebuilds_give_the_same_grid() {
        let items = spheres();
        let mut one = SphereGrid::default();
        one.fill(&items, 0.12, 1);
        assert!(one.entry_count() > items.len());
        for parts in [2, 3, 8] {
            let mut many = SphereGrid::default();
            many.fill(&items, 0.12, parts);
            assert_eq!(many.cell_starts, one.cell_starts, "{parts} parts");
            assert_eq!(many.spheres, one.spheres, "{parts} parts");
            assert_eq!(many.indices, one.indices, "{parts} parts");
            assert_eq!(found(&many), found(&one), "{parts} parts");
        }
        let mut reused = SphereGrid::build(&items[..5_000]);
        reused.rebuild(&items);
        let fresh = SphereGrid::build(&items);
        assert!(!found(&fresh).is_empty());
        assert_eq!(found(&reused), found(&fresh));
        assert_eq!(reused.cell_starts, fresh.cell_starts);
        assert_eq!(reused.spheres, fresh.spheres);
        assert_eq!(reused.indices, fresh.indices);
    }
}
