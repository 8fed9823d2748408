//! Hashed uniform grid over points, built by counting sort.
//!
//! **Cells and buckets.** Space is cut into cubes of side `cell_size`
//! anchored at the points' lower bound; integer cell coordinates are hashed
//! [Teschner et al. 2003, "Optimized Spatial Hashing for Collision Detection
//! of Deformable Objects", §4: `(x·73856093) xor (y·19349663) xor
//! (z·83492791)`] and mapped to one of B buckets, B about the number of
//! points, so memory stays O(n) however sparse the points are. Several cells
//! may share a bucket; queries filter by distance anyway.
//!
//! **Build** (SmallVCM's `HashGrid::Build`): count the points per bucket,
//! take a prefix sum to get each bucket's start, then scatter the points
//! into one array ordered by bucket. There is no list or `Vec` per cell,
//! just `cell_starts` (B + 1 offsets) and the sorted entries. Unlike SmallVCM,
//! the positions are copied next to the indices, coordinate by coordinate
//! ([`SoaPoints`]), so a query reads one contiguous run per bucket instead
//! of gathering from the caller's array, and tests eight distances at a
//! time.
//!
//! **Query.** With `cell_size = 2r` the ball of radius r around p overlaps at
//! most 2×2×2 cells, the "8 cells around p" of SmallVCM's `Process`. Here
//! the cells are the ones overlapping the ball's bounding box, so a query
//! radius other than the build radius is answered exactly too (more cells
//! when larger). Two details SmallVCM skips: a query just outside the points'
//! bounding box still finds the points within reach (the cell range is
//! clipped to the occupied cells instead of the query being dropped), and a
//! bucket hit by two of the visited cells is read once, so no point is
//! reported twice. Cell coordinates saturate at the `i32` range; the
//! mapping stays monotone, so distant points are merely crowded into the
//! border cells, never lost.

use super::soa_points::SoaPoints;
use super::HasPosition;
use crate::math::Bounds3;
use glam::{IVec3, Vec3};

/// Relative padding of the query box: a point whose rounded distance² passes
/// the `≤ r²` test lies within r·(1 + 4ε) of p; this covers that.
const BOX_PADDING: f32 = 1.0 + 1e-5;
/// Absolute padding of the query box: offsets below about 1e-19 square to
/// zero, so such points pass `≤ r²` whatever the radius.
const BOX_PADDING_ABS: f32 = 1e-18;
/// Cell ranges up to this many cells de-duplicate buckets on the stack.
const SMALL_RANGE: usize = 32;

/// The cell geometry and hash shared by [`HashGrid`] and `SphereGrid`.
#[derive(Clone, Debug)]
pub(super) struct CellHash {
    origin: Vec3,
    inv_cell_size: f32,
    /// Inclusive range of the cells that hold something; empty when lo > hi.
    lo: IVec3,
    hi: IVec3,
    n_buckets: u32,
}

impl CellHash {
    /// Cells of side `cell_size` from `origin`, hashed into `n_buckets ≥ 1`.
    pub(super) fn new(origin: Vec3, cell_size: f32, n_buckets: usize) -> Self {
        assert!(
            cell_size > 0.0 && cell_size.is_finite(),
            "cell size must be positive and finite, got {cell_size}"
        );
        Self {
            origin: if origin.is_finite() {
                origin
            } else {
                Vec3::ZERO
            },
            inv_cell_size: 1.0 / cell_size,
            lo: IVec3::MAX,
            hi: IVec3::MIN,
            n_buckets: n_buckets.clamp(1, u32::MAX as usize) as u32,
        }
    }

    /// Number of buckets.
    #[inline]
    pub(super) fn n_buckets(&self) -> usize {
        self.n_buckets as usize
    }

    /// Integer coordinates of the cell holding `p`; saturates far away.
    #[inline]
    pub(super) fn cell(&self, p: Vec3) -> IVec3 {
        // `as` casts saturate (and send NaN to 0), so this is monotone in p.
        ((p - self.origin) * self.inv_cell_size).floor().as_ivec3()
    }

    /// Bucket of cell `c` [Teschner et al. 2003], reduced to `0..n_buckets`
    /// by a multiply-shift after a Fibonacci scramble of the hash.
    #[inline]
    pub(super) fn bucket(&self, c: IVec3) -> usize {
        let h = (c.x as u32).wrapping_mul(73_856_093)
            ^ (c.y as u32).wrapping_mul(19_349_663)
            ^ (c.z as u32).wrapping_mul(83_492_791);
        let h = h.wrapping_mul(0x9E37_79B9);
        ((h as u64 * self.n_buckets as u64) >> 32) as usize
    }

    /// Records that cell range `lo..=hi` holds something.
    pub(super) fn mark_occupied(&mut self, lo: IVec3, hi: IVec3) {
        self.lo = self.lo.min(lo);
        self.hi = self.hi.max(hi);
    }

    /// Records the occupied cells of `other` (the same grid) too.
    pub(super) fn merge_occupied(&mut self, other: &CellHash) {
        self.mark_occupied(other.lo, other.hi);
    }

    /// Inclusive range of cells overlapping the box `p ± r` (padded against
    /// rounding), or `None` for a negative or NaN radius. When r² overflows,
    /// the `≤ r²` test passes at any distance, so every cell is in range.
    #[inline]
    pub(super) fn cells_around(&self, p: Vec3, r: f32) -> Option<(IVec3, IVec3)> {
        if r.is_nan() || r < 0.0 {
            return None;
        }
        if (r * r).is_infinite() {
            return Some((IVec3::MIN, IVec3::MAX));
        }
        let r = Vec3::splat(r * BOX_PADDING + BOX_PADDING_ABS);
        Some((self.cell(p - r), self.cell(p + r)))
    }

    /// `lo..=hi` clipped to the occupied cells, or `None` when they miss.
    #[inline]
    pub(super) fn clip(&self, lo: IVec3, hi: IVec3) -> Option<(IVec3, IVec3)> {
        let (lo, hi) = (lo.max(self.lo), hi.min(self.hi));
        (lo.cmple(hi).all()).then_some((lo, hi))
    }

    /// Number of cells in `lo..=hi` (non-empty), saturating.
    #[inline]
    fn cell_count(lo: IVec3, hi: IVec3) -> i64 {
        let ext = hi.as_i64vec3() - lo.as_i64vec3() + 1;
        ext.x.saturating_mul(ext.y).saturating_mul(ext.z)
    }

    /// Calls `f` once for every distinct bucket of the cells `lo..=hi`
    /// (non-empty); when there are at least as many cells as buckets, for
    /// every bucket.
    pub(super) fn for_each_bucket(&self, lo: IVec3, hi: IVec3, mut f: impl FnMut(usize)) {
        let n_cells = Self::cell_count(lo, hi);
        if n_cells >= self.n_buckets as i64 {
            (0..self.n_buckets()).for_each(f);
        } else if n_cells as usize <= SMALL_RANGE {
            let mut seen = [0usize; SMALL_RANGE];
            let mut n_seen = 0;
            self.for_each_cell(lo, hi, |b| {
                if !seen[..n_seen].contains(&b) {
                    seen[n_seen] = b;
                    n_seen += 1;
                    f(b);
                }
            });
        } else {
            let mut seen = Vec::with_capacity(n_cells as usize);
            self.for_each_cell(lo, hi, |b| seen.push(b));
            seen.sort_unstable();
            seen.dedup();
            seen.into_iter().for_each(f);
        }
    }

    /// Like [`Self::for_each_bucket`], but a bucket shared by several cells
    /// of the range comes once per cell, in a row of calls.
    pub(super) fn for_each_cell_bucket(&self, lo: IVec3, hi: IVec3, f: impl FnMut(usize)) {
        if Self::cell_count(lo, hi) >= self.n_buckets as i64 {
            (0..self.n_buckets()).for_each(f);
        } else {
            self.for_each_cell(lo, hi, f);
        }
    }

    /// Calls `f` with the bucket of every cell in `lo..=hi`.
    #[inline]
    fn for_each_cell(&self, lo: IVec3, hi: IVec3, mut f: impl FnMut(usize)) {
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    f(self.bucket(IVec3::new(x, y, z)));
                }
            }
        }
    }
}

/// Exclusive prefix sum of per-bucket counts: `starts[b]..starts[b + 1]` is
/// bucket b's run, and `starts.last()` the total.
pub(super) fn prefix_starts(counts: &[u32]) -> Vec<u32> {
    let mut starts = Vec::with_capacity(counts.len() + 1);
    let mut sum = 0u32;
    starts.push(0);
    for &c in counts {
        sum = sum.checked_add(c).expect("more than 2³² grid entries");
        starts.push(sum);
    }
    starts
}

/// A hashed grid over points for fixed-radius queries.
#[derive(Clone, Debug)]
pub struct HashGrid {
    cells: CellHash,
    /// Bucket b owns entries `cell_starts[b]..cell_starts[b + 1]`.
    cell_starts: Vec<u32>,
    /// Positions ordered by bucket.
    points: SoaPoints,
    /// The caller's index of each entry of `points`.
    indices: Vec<u32>,
}

impl HashGrid {
    /// Builds a grid for queries of radius `radius` (cells of side 2·radius).
    ///
    /// # Panics
    /// If `radius` is not positive and finite, or there are 2³² items or more.
    pub fn build<T: HasPosition>(items: &[T], radius: f32) -> Self {
        Self::with_cell_size(items, 2.0 * radius)
    }

    /// Builds a grid with cells of side `cell_size`.
    ///
    /// # Panics
    /// If `cell_size` is not positive and finite, or there are 2³² items or
    /// more.
    pub fn with_cell_size<T: HasPosition>(items: &[T], cell_size: f32) -> Self {
        assert!(items.len() < u32::MAX as usize, "too many items");
        let bounds = items
            .iter()
            .fold(Bounds3::EMPTY, |b, it| b.union_point(it.position()));
        let mut cells = CellHash::new(bounds.min, cell_size, items.len());
        let mut counts = vec![0u32; cells.n_buckets()];
        let buckets: Vec<u32> = items
            .iter()
            .map(|it| {
                let c = cells.cell(it.position());
                cells.mark_occupied(c, c);
                let b = cells.bucket(c);
                counts[b] += 1;
                b as u32
            })
            .collect();
        let cell_starts = prefix_starts(&counts);
        let mut next = cell_starts.clone();
        let mut points = SoaPoints::zeros(items.len());
        let mut indices = vec![0u32; items.len()];
        for (i, (it, &b)) in items.iter().zip(&buckets).enumerate() {
            let slot = next[b as usize] as usize;
            next[b as usize] += 1;
            points.set(slot, it.position());
            indices[slot] = i as u32;
        }
        Self {
            cells,
            cell_starts,
            points,
            indices,
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True when the grid holds no point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Calls `f(index, dist²)` once for every point within `radius` of `p`
    /// (inclusive); `index` is the point's position in the build slice.
    pub fn for_each_within(&self, p: Vec3, radius: f32, mut f: impl FnMut(u32, f32)) {
        self.for_each_slot_within(p, radius, |slot| {
            f(
                self.indices[slot],
                (self.points.get(slot) - p).length_squared(),
            )
        });
    }

    /// Calls `f(slot)` once for every point within `radius` of `p`
    /// (inclusive), with its entry slot: the point's position in
    /// [`Self::entry_order`]. For a caller that keeps its records in entry
    /// order and reads one only when its point is found, the distances
    /// being tested here on the grid's own packed positions (module doc of
    /// `soa_points`).
    #[inline]
    pub fn for_each_slot_within(&self, p: Vec3, radius: f32, mut f: impl FnMut(usize)) {
        let r2 = radius * radius;
        self.for_each_candidate_run(p, radius, |run| {
            self.points.for_each_within(run, p, r2, &mut f)
        });
    }

    /// The build-slice index of every entry, in entry (bucket) order: a
    /// caller that copies its items in this order into an array of its own
    /// reads that array front to back within each bucket when it looks
    /// them up by the entry slots of [`Self::for_each_slot_within`],
    /// instead of jumping through the build slice (a cache miss per point).
    pub fn entry_order(&self) -> &[u32] {
        &self.indices
    }

    /// Calls `f` with the entry slots of every bucket that may hold points
    /// within `radius` of `p`, each bucket once: the runs whose distances
    /// [`Self::for_each_slot_within`] tests.
    pub(super) fn for_each_candidate_run(
        &self,
        p: Vec3,
        radius: f32,
        mut f: impl FnMut(std::ops::Range<usize>),
    ) {
        let Some((lo, hi)) = self.cells.cells_around(p, radius) else {
            return;
        };
        let Some((lo, hi)) = self.cells.clip(lo, hi) else {
            return;
        };
        self.cells.for_each_bucket(lo, hi, |b| {
            f(self.cell_starts[b] as usize..self.cell_starts[b + 1] as usize);
        });
    }
}
