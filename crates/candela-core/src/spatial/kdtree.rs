//! Balanced point kd-tree stored implicitly in one array.
//!
//! **Layout.** The items are permuted so that every subtree occupies a
//! contiguous range `lo..hi` of the array and its splitting item sits at the
//! middle, `mid = lo + (hi − lo)/2`; the left subtree is `lo..mid` and the
//! right one `mid+1..hi`. No child pointers are stored: a traversal carries
//! the range. Ranges of at most [`LEAF_SIZE`] items are leaves, scanned
//! linearly, which saves the deepest, least selective levels. The tree walk
//! reads a compact array of 16-byte nodes (position and split axis) kept
//! beside the caller's items, which are permuted into the same order. This is
//! the median-split ("balanced") layout of Mitsuba 0.6's `PointKDTree`
//! without its explicit right-child index; Jensen's left-balanced heap layout
//! (children at 2i+1, 2i+2) would equally need no pointers, but needs a
//! separate permutation pass, and its subtrees are not contiguous in memory.
//!
//! **Build.** Top down: split the range at the median along the widest axis
//! of the cell it covers (the scene bounds cut by the ancestors' split
//! planes, as in Mitsuba), found with `select_nth_unstable_by` in O(n); the
//! whole build is O(n log n). Items equal to the median may land on either
//! side, so both sides of a split plane are searched when the query centre
//! lies on it.
//!
//! **Queries.** A stack-based depth-first walk that enters the child on the
//! query's side first and pushes the other child only when the split plane
//! is within the search radius. The k-nearest query keeps the best k in a
//! bounded max-heap; once it is full, the search radius shrinks to the heap's
//! top [Jensen 2001, §6.4; Mitsuba's `nnSearch`]. Candidates are ordered by
//! (distance², index), so ties at the k-th distance resolve to the lowest
//! indices and the answer does not depend on traversal order.

use super::HasPosition;
use crate::math::Bounds3;
use glam::Vec3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Ranges of at most this many items are leaves.
const LEAF_SIZE: usize = 8;
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
    pub fn for_each_within(&self, p: Vec3, radius: f32, mut f: impl FnMut(&T, f32)) {
        let r2 = radius * radius;
        let mut stack = [(0u32, 0u32); STACK_SIZE];
        let mut sp = 0;
        let (mut lo, mut hi) = (0, self.nodes.len());
        loop {
            if hi - lo <= LEAF_SIZE {
                for i in lo..hi {
                    let d2 = (self.nodes[i].p - p).length_squared();
                    if d2 <= r2 {
                        f(&self.items[i], d2);
                    }
                }
                if sp == 0 {
                    return;
                }
                sp -= 1;
                (lo, hi) = (stack[sp].0 as usize, stack[sp].1 as usize);
                continue;
            }
            let mid = lo + (hi - lo) / 2;
            let node = self.nodes[mid];
            let d2 = (node.p - p).length_squared();
            if d2 <= r2 {
                f(&self.items[mid], d2);
            }
            let plane = p[node.axis as usize] - node.p[node.axis as usize];
            let (near, far) = children(lo, mid, hi, plane);
            if plane * plane <= r2 {
                stack[sp] = (far.0 as u32, far.1 as u32);
                sp += 1;
            }
            (lo, hi) = near;
        }
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
        let mut heap = KnnHeap {
            heap: BinaryHeap::from(std::mem::take(out)),
            k,
            bound: max_radius * max_radius,
        };
        let max_r2 = heap.bound;
        let mut stack = [(0u32, 0u32, 0f32); STACK_SIZE];
        let mut sp = 0;
        let (mut lo, mut hi) = (0, self.nodes.len());
        loop {
            if hi - lo <= LEAF_SIZE {
                for i in lo..hi {
                    heap.offer((self.nodes[i].p - p).length_squared(), i);
                }
                // Pop the next subtree whose split plane is still in range.
                loop {
                    if sp == 0 {
                        *out = heap.heap.into_vec();
                        return if out.len() == k { heap.bound } else { max_r2 };
                    }
                    sp -= 1;
                    let (l, h, plane2) = stack[sp];
                    if plane2 <= heap.bound {
                        (lo, hi) = (l as usize, h as usize);
                        break;
                    }
                }
                continue;
            }
            let mid = lo + (hi - lo) / 2;
            let node = self.nodes[mid];
            heap.offer((node.p - p).length_squared(), mid);
            let plane = p[node.axis as usize] - node.p[node.axis as usize];
            let (near, far) = children(lo, mid, hi, plane);
            if plane * plane <= heap.bound {
                stack[sp] = (far.0 as u32, far.1 as u32, plane * plane);
                sp += 1;
            }
            (lo, hi) = near;
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

/// The best `k` candidates so far in a max-heap, and the current search
/// radius²: the heap's top once it is full.
struct KnnHeap {
    heap: BinaryHeap<Neighbor>,
    k: usize,
    bound: f32,
}

impl KnnHeap {
    /// Keeps item `i` at squared distance `d2` if it is among the best `k`.
    #[inline]
    fn offer(&mut self, d2: f32, i: usize) {
        // Also rejects NaN.
        if d2 > self.bound || d2.is_nan() {
            return;
        }
        let c = Neighbor {
            dist2: d2,
            index: i as u32,
        };
        if self.heap.len() < self.k {
            self.heap.push(c);
            if self.heap.len() < self.k {
                return;
            }
        } else {
            match self.heap.peek_mut() {
                Some(mut top) if c < *top => *top = c,
                _ => return,
            }
        }
        self.bound = self.heap.peek().map_or(self.bound, |t| t.dist2);
    }
}
