//! Balanced point kd-tree stored implicitly in one array.
//!
//! **Layout.** The items are permuted so that every subtree occupies a
//! contiguous range `lo..hi` of the array and its splitting item sits at the
//! middle, `mid = lo + (hi − lo)/2`; the left subtree is `lo..mid` and the
//! right one `mid+1..hi`. No child pointers are stored: a traversal carries the
//! range. Ranges of at most `LEAF_SIZE` = 32 items are leaves, scanned
//! linearly, which saves the deepest, least selective levels: on the bench,
//! leaves of 32 beat 8 by about a quarter for k = 50, and 64 gained little. The
//! tree walk reads a compact array of 16-byte nodes (position and split axis)
//! kept beside the caller's items, which are permuted into the same order. This
//! is the median-split ("balanced") layout of Mitsuba 0.6's `PointKDTree`
//! without its explicit right-child index; Jensen's left-balanced heap layout
//! (children at 2i+1, 2i+2) would equally need no pointers, but needs a
//! separate permutation pass, and its subtrees are not contiguous in memory.
//!
//! **Build.** Top down: split the range at the median along the widest axis of
//! the cell it covers (the scene bounds cut by the ancestors' split planes, as
//! in Mitsuba), found with `select_nth_unstable_by` in O(n); the whole build is
//! O(n log n). Items equal to the median may land on either side, so both sides
//! of a split plane are searched when the query centre lies on it.
//!
//! **Queries.** One stack-based depth-first walk serves both queries: it enters
//! the child on the query's side first and stacks the other child with the
//! squared distance from the query to that child's cell, tracked incrementally
//! per axis [Arya & Mount 1993, "Algorithms for fast vector quantization"].
//! That prunes at least as much as the distance to the last split plane alone,
//! which Jensen and Mitsuba use, for two more flops per stacked cell (on the
//! bench the difference was within the noise). Stacked cells are re-checked
//! when popped, since a k-nearest search radius shrinks meanwhile.
//!
//! **k nearest.** Jensen (2001, §6.4) and Mitsuba's `nnSearch` keep the best k
//! in a bounded max-heap whose top is the search radius. Here candidates within
//! the radius are appended to a buffer; when it holds 2k, a linear selection
//! (`select_nth_unstable`) keeps the best k and the radius becomes the k-th
//! distance. That is amortised O(1) per candidate instead of O(log k) per
//! improvement, at the price of a radius that shrinks in steps; on 1M uniform
//! points with k = 50 it took a quarter to a third less time than a
//! `BinaryHeap` (`PeekMut` replacement). Candidates are ordered by (distance²,
//! index), so ties at the k-th distance resolve to the lowest indices and the
//! answer does not depend on traversal order.

use super::HasPosition;
use crate::math::Bounds3;
use glam::Vec3;
use std::cmp::Ordering;

/// Ranges of at most this many items are leaves.
const LEAF_SIZE: usize = 32;
/// Traversal stack size: one entry per level, and there are at most 32.
const STACK_SIZE: usize = 64;

/// A position and the split axis when the node is interior: 16 bytes.
#[derive(Clone, Copy, Debug)]
struct KdNode {
    p: Vec3,
    axis: u32,
}

/// A k-nearest-neighbour result: an index into [`PointKdTree::items`] and its
/// squared distance to the query. Ordered by distance², then index.
#[derive(Clone, Copy, Debug)]
pub struct Neighbor {
    /// Squared distance from the query point.
    pub dist2: f32,
    /// Index into [`PointKdTree::items`].
    pub index: u32,
}

impl Ord for Neighbor {
    fn cmp(&self, o: &Self) -> Ordering {
        self.dist2
            .total_cmp(&o.dist2)
            .then(self.index.cmp(&o.index))
    }
}
impl PartialOrd for Neighbor {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl PartialEq for Neighbor {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Neighbor {}

/// A kd-tree over owned items with a position.
#[derive(Clone, Debug)]
pub struct PointKdTree<T> {
    nodes: Vec<KdNode>,
    items: Vec<T>,
}

impl<T> Default for PointKdTree<T> {
    fn default() -> Self {
        Self {
            nodes: Vec::new(),
            items: Vec::new(),
        }
    }
}

/// One item during the build: its position and where it came from.
#[derive(Clone, Copy)]
struct BuildEntry {
    p: Vec3,
    source: u32,
}

impl<T: HasPosition> PointKdTree<T> {
    /// Builds the tree in O(n log n); the items are reordered (see [`Self::items`]).
    pub fn build(mut items: Vec<T>) -> Self {
        assert!(items.len() <= u32::MAX as usize, "too many items");
        let mut entries: Vec<BuildEntry> = items
            .iter()
            .enumerate()
            .map(|(i, it)| BuildEntry {
                p: it.position(),
                source: i as u32,
            })
            .collect();
        let bounds = entries
            .iter()
            .fold(Bounds3::EMPTY, |b, e| b.union_point(e.p));
        let mut axes = vec![0u32; entries.len()];
        build_range(&mut entries, &mut axes, bounds);
        let mut order: Vec<u32> = entries.iter().map(|e| e.source).collect();
        permute_in_place(&mut items, &mut order);
        let nodes = entries
            .iter()
            .zip(&axes)
            .map(|(e, &axis)| KdNode { p: e.p, axis })
            .collect();
        Self { nodes, items }
    }
}

/// Splits `entries` at the median of the widest axis of `bounds`, recursively.
fn build_range(entries: &mut [BuildEntry], axes: &mut [u32], bounds: Bounds3) {
    if entries.len() <= LEAF_SIZE {
        return;
    }
    let mid = entries.len() / 2;
    let axis = bounds.max_extent();
    entries.select_nth_unstable_by(mid, |a, b| a.p[axis].total_cmp(&b.p[axis]));
    axes[mid] = axis as u32;
    let split = entries[mid].p[axis];
    let (left, rest) = entries.split_at_mut(mid);
    let (left_axes, rest_axes) = axes.split_at_mut(mid);
    let (mut left_bounds, mut right_bounds) = (bounds, bounds);
    left_bounds.max[axis] = split;
    right_bounds.min[axis] = split;
    build_range(left, left_axes, left_bounds);
    build_range(&mut rest[1..], &mut rest_axes[1..], right_bounds);
}

/// Reorders `items` so that `items[i]` becomes the old `items[order[i]]`,
/// following the permutation's cycles with swaps; `order` is consumed.
fn permute_in_place<T>(items: &mut [T], order: &mut [u32]) {
    for start in 0..items.len() {
        let mut cur = start;
        while order[cur] as usize != start {
            let next = order[cur] as usize;
            items.swap(cur, next);
            order[cur] = cur as u32;
            cur = next;
        }
        order[cur] = cur as u32;
    }
}

impl<T> PointKdTree<T> {
    /// The items in tree order; query results index into this slice.
    pub fn items(&self) -> &[T] {
        &self.items
    }

    /// Number of items.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True when the tree holds no item.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Position of item `i` (tree order).
    #[inline]
    pub fn position(&self, i: u32) -> Vec3 {
        self.nodes[i as usize].p
    }

    /// Calls `f(item, dist²)` for every item within `radius` of `p` (inclusive).
    pub fn for_each_within(&self, p: Vec3, radius: f32, f: impl FnMut(&T, f32)) {
        let mut g = Within {
            r2: radius * radius,
            items: &self.items,
            f,
        };
        self.gather(p, &mut g);
    }

    /// Finds the `k` items nearest to `p` within `max_radius` (inclusive) and
    /// writes them to `out`, unordered; ties at the k-th distance keep the
    /// lowest indices. Returns the squared radius of the searched ball: the
    /// k-th distance² when `k` items were found, `max_radius²` when fewer
    /// were, and 0 for `k = 0`. `out` keeps its capacity across calls.
    pub fn k_nearest(&self, p: Vec3, k: usize, max_radius: f32, out: &mut Vec<Neighbor>) -> f32 {
        out.clear();
        if k == 0 {
            return 0.0;
        }
        let max_r2 = max_radius * max_radius;
        // With k ≥ n the buffer never fills, and fewer than k are found.
        let k_buf = k.min(self.len());
        if k_buf == 0 {
            return max_r2;
        }
        let mut knn = KnnBuffer {
            buf: std::mem::take(out),
            k: k_buf,
            bound: max_r2,
        };
        knn.buf.reserve(2 * k_buf);
        self.gather(p, &mut knn);
        let r2 = if knn.buf.len() >= k {
            knn.shrink()
        } else {
            max_r2
        };
        *out = knn.buf;
        r2
    }

    /// Offers `g` every item in a cell that may lie within `g.bound2()` of
    /// `p`: near child first, far children stacked with the squared distance
    /// from `p` to their cell, which is re-checked when they are popped.
    fn gather(&self, p: Vec3, g: &mut impl Gather) {
        let mut stack = [Pending::default(); STACK_SIZE];
        let mut sp = 0;
        let mut cur = Pending {
            hi: self.nodes.len() as u32,
            ..Pending::default()
        };
        loop {
            let (lo, hi) = (cur.lo as usize, cur.hi as usize);
            if hi - lo <= LEAF_SIZE {
                for (i, node) in self.nodes[lo..hi].iter().enumerate() {
                    g.offer((node.p - p).length_squared(), lo + i);
                }
                loop {
                    if sp == 0 {
                        return;
                    }
                    sp -= 1;
                    if stack[sp].dist2 <= g.bound2() {
                        cur = stack[sp];
                        break;
                    }
                }
                continue;
            }
            let mid = lo + (hi - lo) / 2;
            let node = self.nodes[mid];
            g.offer((node.p - p).length_squared(), mid);
            let axis = node.axis as usize;
            let plane = p[axis] - node.p[axis];
            // Offsets from p to the far cell: the parent's, with this axis
            // replaced by the distance to the split plane [Arya & Mount 1993].
            // Each is at most the same rounded difference for any point in
            // the cell, and summed in the same order they stay below that
            // point's rounded distance² (rounding is monotone), so no point
            // at exactly the bound is pruned.
            let mut off = cur.off;
            off[axis] = plane;
            let far_dist2 = off.length_squared();
            let (near, far) = children(lo, mid, hi, plane);
            if far_dist2 <= g.bound2() {
                stack[sp] = Pending {
                    lo: far.0 as u32,
                    hi: far.1 as u32,
                    dist2: far_dist2,
                    off,
                };
                sp += 1;
            }
            cur.lo = near.0 as u32;
            cur.hi = near.1 as u32;
        }
    }
}

/// A subtree still to visit: its item range, and the per-axis offsets and
/// squared distance from the query point to its cell.
#[derive(Clone, Copy, Default)]
struct Pending {
    lo: u32,
    hi: u32,
    dist2: f32,
    off: Vec3,
}

/// What a traversal feeds candidates to.
trait Gather {
    /// Squared radius beyond which no candidate is wanted (may shrink).
    fn bound2(&self) -> f32;
    /// Considers item `i` at squared distance `d2`.
    fn offer(&mut self, d2: f32, i: usize);
}

/// Fixed-radius gathering: every item within the radius goes to `f`.
struct Within<'a, T, F> {
    r2: f32,
    items: &'a [T],
    f: F,
}

impl<T, F: FnMut(&T, f32)> Gather for Within<'_, T, F> {
    #[inline]
    fn bound2(&self) -> f32 {
        self.r2
    }
    #[inline]
    fn offer(&mut self, d2: f32, i: usize) {
        if d2 <= self.r2 {
            (self.f)(&self.items[i], d2);
        }
    }
}

/// The (near, far) child ranges of node `mid` for a query at signed distance
/// `plane` from its split plane.
#[inline]
fn children(lo: usize, mid: usize, hi: usize, plane: f32) -> ((usize, usize), (usize, usize)) {
    if plane <= 0.0 {
        ((lo, mid), (mid + 1, hi))
    } else {
        ((mid + 1, hi), (lo, mid))
    }
}

/// The candidates within the current search radius², unordered. When the
/// buffer reaches `2k` entries it keeps its best `k` (a linear-time
/// selection) and the radius shrinks to the k-th distance.
struct KnnBuffer {
    buf: Vec<Neighbor>,
    k: usize,
    bound: f32,
}

impl KnnBuffer {
    /// Keeps the best `k` entries and returns the largest distance² kept.
    fn shrink(&mut self) -> f32 {
        if self.buf.len() > self.k {
            self.buf.select_nth_unstable(self.k - 1);
            self.buf.truncate(self.k);
            self.buf[self.k - 1].dist2
        } else {
            self.buf.iter().map(|n| n.dist2).fold(0.0, f32::max)
        }
    }
}

impl Gather for KnnBuffer {
    #[inline]
    fn bound2(&self) -> f32 {
        self.bound
    }
    #[inline]
    fn offer(&mut self, d2: f32, i: usize) {
        if d2 <= self.bound {
            self.buf.push(Neighbor {
                dist2: d2,
                index: i as u32,
            });
            if self.buf.len() == 2 * self.k {
                self.bound = self.shrink();
            }
        }
    }
}
