//! Bounding volume hierarchy over primitive bounding boxes.
//!
//! **Build.** Top-down, splitting each node with the surface area heuristic
//! along the widest axis of its primitives' centroids (pbrt-v4 §7.3.2). The
//! cost of a split is `c_trav + (N_L·A_L + N_R·A_R) / A` with `c_trav = 1/2`
//! relative to one primitive test; a node becomes a leaf when that is not
//! cheaper than testing its `N ≤ 4` primitives. Larger nodes are always
//! split; when all centroids coincide they are split in half by count.
//! Nodes of more than 16 primitives evaluate the cost at 12 bucket
//! boundaries ("binned SAH", Wald 2007, "On fast construction of SAH-based
//! bounding volume hierarchies"): one pass bins the primitives, recording
//! each bucket's count, bounds and centroid bounds, and one pass partitions
//! them; the children's bounds and centroid bounds are unions of buckets, so
//! no further pass over the primitives is needed. Smaller nodes sort their
//! centroids and evaluate every boundary, which is cheaper than binning at
//! that size and never worse. Subtrees above a size threshold build in
//! parallel with `rayon::join`, and the binning of large nodes runs in
//! parallel chunks (bounds unions and counts are exact, so chunking changes
//! nothing). Each subtree partitions its own slice of the primitive array in
//! place and leaves record their offset into it, so the result does not
//! depend on thread scheduling.
//!
//! **Layout.** Nodes are flattened depth-first into 32-byte records: the
//! first child of an interior node follows it; the record stores the second
//! child's index and the split axis. Leaves store a range of
//! [`Bvh::prim_indices`].
//!
//! **Traversal.** A stack-based walk visiting the child on the ray's near side
//! first, with a slab test that uses the precomputed reciprocal direction and
//! its signs and widens the far distance by 1 + 2γ₃ so rounding can never
//! cull a box the ray touches [pbrt-v4 §6.1.2 and §6.8.2]. Primitives are
//! tested through a caller closure, so the scene keeps its own primitive
//! storage and hit payload.

use crate::math::{gamma, Bounds3, Ray, Vec3};
use rayon::prelude::*;

/// Primitives per leaf at most.
const MAX_LEAF_PRIMS: usize = 4;
/// Number of SAH buckets.
const N_BUCKETS: usize = 12;
/// Cost of a traversal step relative to one primitive test.
const TRAVERSAL_COST: f32 = 0.5;
/// Subtrees with more primitives than this build (and bin) in parallel.
const PARALLEL_THRESHOLD: usize = 16 * 1024;
/// Primitives per parallel binning task.
const BIN_CHUNK: usize = 8 * 1024;
/// Nodes with at most this many primitives evaluate the SAH at every
/// primitive boundary instead of binning.
const SWEEP_MAX: usize = 16;
/// Traversal stack size that needs no allocation.
const SMALL_STACK: usize = 64;

/// A flattened node: 32 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
struct BvhNode {
    min: Vec3,
    max: Vec3,
    /// Leaf: first entry in `prim_indices`; interior: index of the second child.
    offset: u32,
    /// Leaf: number of primitives (> 0); interior: 0.
    count: u16,
    /// Interior: split axis.
    axis: u8,
    _pad: u8,
}

const _: () = assert!(std::mem::size_of::<BvhNode>() == 32);

/// A bounding volume hierarchy over primitives given by their bounds.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<BvhNode>,
    prim_indices: Vec<u32>,
    max_depth: usize,
}

/// A primitive during the build.
#[derive(Clone, Copy)]
struct BuildPrim {
    bounds: Bounds3,
    centroid: Vec3,
    index: u32,
}

/// The build-time tree before flattening.
enum BuildNode {
    Leaf {
        bounds: Bounds3,
        first: usize,
        count: usize,
    },
    Interior {
        bounds: Bounds3,
        axis: u8,
        children: Box<[BuildNode; 2]>,
    },
}

impl BuildNode {
    fn bounds(&self) -> Bounds3 {
        match self {
            BuildNode::Leaf { bounds, .. } | BuildNode::Interior { bounds, .. } => *bounds,
        }
    }
}

/// Subtree result: the node, its node count and its depth.
type Built = (BuildNode, usize, usize);

impl Bvh {
    /// Builds a BVH over primitives `0..prim_bounds.len()`; empty boxes are skipped.
    pub fn build(prim_bounds: &[Bounds3]) -> Bvh {
        let mut prims: Vec<BuildPrim> = prim_bounds
            .iter()
            .enumerate()
            .filter(|(_, b)| !b.is_empty())
            .map(|(i, b)| BuildPrim {
                bounds: *b,
                centroid: b.centroid(),
                index: i as u32,
            })
            .collect();
        if prims.is_empty() {
            return Bvh::default();
        }
        let (root, n_nodes, depth) = build_recursive(Span::new(&mut prims, 0));
        let mut nodes = Vec::with_capacity(n_nodes);
        flatten(&root, &mut nodes);
        Bvh {
            nodes,
            prim_indices: prims.iter().map(|p| p.index).collect(),
            max_depth: depth,
        }
    }

    /// Bounds of everything (empty for an empty BVH).
    pub fn bounds(&self) -> Bounds3 {
        self.nodes.first().map_or(Bounds3::EMPTY, |n| Bounds3 {
            min: n.min,
            max: n.max,
        })
    }

    /// Number of flattened nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Primitive indices in leaf order.
    pub fn prim_indices(&self) -> &[u32] {
        &self.prim_indices
    }

    /// Depth of the deepest leaf (root = 1; 0 when empty).
    pub fn depth(&self) -> usize {
        self.max_depth
    }

    /// Closest hit: `hit(prim, ray, t_max)` returns the primitive's hit `t`
    /// (which must be `< t_max`) or `None`; the closest `(prim, t)` is returned.
    pub fn intersect<F>(&self, ray: &Ray, t_max: f32, mut hit: F) -> Option<(u32, f32)>
    where
        F: FnMut(u32, &Ray, f32) -> Option<f32>,
    {
        let t_start = t_max;
        let mut t_max = t_max;
        let mut best = None;
        self.traverse(ray, t_start, |prims| {
            for &p in prims {
                if let Some(t) = hit(p, ray, t_max) {
                    debug_assert!(t < t_max);
                    t_max = t;
                    best = Some((p, t));
                }
            }
            (false, t_max)
        });
        best
    }

    /// Any hit: true as soon as `hit(prim, ray, t_max)` reports one.
    pub fn intersect_p<F>(&self, ray: &Ray, t_max: f32, mut hit: F) -> bool
    where
        F: FnMut(u32, &Ray, f32) -> bool,
    {
        let mut found = false;
        self.traverse(ray, t_max, |prims| {
            found = prims.iter().any(|&p| hit(p, ray, t_max));
            (found, t_max)
        });
        found
    }

    /// Walks the nodes the ray overlaps, near child first; `leaf` tests a
    /// leaf's primitives and returns (stop, new t_max).
    #[inline]
    fn traverse<L>(&self, ray: &Ray, t_max: f32, mut leaf: L)
    where
        L: FnMut(&[u32]) -> (bool, f32),
    {
        if self.nodes.is_empty() {
            return;
        }
        let inv_dir = ray.d.recip();
        let neg = [inv_dir.x < 0.0, inv_dir.y < 0.0, inv_dir.z < 0.0];
        let mut small = [0u32; SMALL_STACK];
        let mut big = Vec::new();
        let stack: &mut [u32] = if self.max_depth < SMALL_STACK {
            &mut small
        } else {
            big.resize(self.max_depth + 1, 0);
            &mut big
        };
        let (mut sp, mut current, mut t_max) = (0usize, 0usize, t_max);
        loop {
            let node = &self.nodes[current];
            if slab_test(node, ray.o, inv_dir, neg, t_max) {
                if node.count > 0 {
                    let first = node.offset as usize;
                    let prims = &self.prim_indices[first..first + node.count as usize];
                    let (stop, t) = leaf(prims);
                    if stop {
                        return;
                    }
                    t_max = t;
                } else {
                    // Visit the near child first, defer the far one.
                    let (near, far) = if neg[node.axis as usize] {
                        (node.offset as usize, current + 1)
                    } else {
                        (current + 1, node.offset as usize)
                    };
                    stack[sp] = far as u32;
                    sp += 1;
                    current = near;
                    continue;
                }
            }
            if sp == 0 {
                return;
            }
            sp -= 1;
            current = stack[sp] as usize;
        }
    }
}

/// Ray–box slab test with precomputed reciprocal direction and signs; the far
/// distances are widened by 1 + 2γ₃ [pbrt-v4 §6.8.2]. `f32::max`/`min` ignore
/// the NaN of a ray lying in a slab's boundary plane, so such a ray counts as
/// inside that slab (conservative) [Ize 2013, "Robust BVH ray traversal"].
#[inline(always)]
fn slab_test(n: &BvhNode, o: Vec3, inv_dir: Vec3, neg: [bool; 3], ray_t_max: f32) -> bool {
    let widen = 1.0 + 2.0 * gamma(3);
    let (mut t0, mut t1) = (0.0f32, ray_t_max);
    for axis in 0..3 {
        let (near, far) = if neg[axis] {
            (n.max[axis], n.min[axis])
        } else {
            (n.min[axis], n.max[axis])
        };
        t0 = t0.max((near - o[axis]) * inv_dir[axis]);
        t1 = t1.min((far - o[axis]) * inv_dir[axis] * widen);
    }
    t0 <= t1
}

/// A node's primitives with their bounds and centroid bounds.
struct Span<'a> {
    prims: &'a mut [BuildPrim],
    /// Index of `prims[0]` in the full primitive array.
    first: usize,
    bounds: Bounds3,
    centroids: Bounds3,
}

impl<'a> Span<'a> {
    /// A span whose bounds are computed from its primitives.
    fn new(prims: &'a mut [BuildPrim], first: usize) -> Self {
        let (bounds, centroids) = bounds_of(prims);
        Span {
            prims,
            first,
            bounds,
            centroids,
        }
    }
}

/// Bounds and centroid bounds of `prims` (in parallel for many).
fn bounds_of(prims: &[BuildPrim]) -> (Bounds3, Bounds3) {
    let fold =
        |(b, c): (Bounds3, Bounds3), p: &BuildPrim| (b.union(p.bounds), c.union_point(p.centroid));
    let empty = (Bounds3::EMPTY, Bounds3::EMPTY);
    if prims.len() < PARALLEL_THRESHOLD {
        return prims.iter().fold(empty, fold);
    }
    prims
        .par_chunks(BIN_CHUNK)
        .map(|c| c.iter().fold(empty, fold))
        .reduce(|| empty, |a, b| (a.0.union(b.0), a.1.union(b.1)))
}

/// How a node ends: as a leaf, or split into two spans.
enum Split<'a> {
    Leaf(Span<'a>),
    Children(Span<'a>, Span<'a>),
}

/// Builds the subtree over a span.
fn build_recursive(span: Span) -> Built {
    let bounds = span.bounds;
    let axis = span.centroids.max_extent();
    let (left, right) = match split(span, axis) {
        Split::Leaf(s) => {
            let (first, count) = (s.first, s.prims.len());
            return (
                BuildNode::Leaf {
                    bounds,
                    first,
                    count,
                },
                1,
                1,
            );
        }
        Split::Children(l, r) => (l, r),
    };
    let ((l, ln, ld), (r, rn, rd)) = if left.prims.len() + right.prims.len() > PARALLEL_THRESHOLD {
        rayon::join(|| build_recursive(left), || build_recursive(right))
    } else {
        (build_recursive(left), build_recursive(right))
    };
    let node = BuildNode::Interior {
        bounds,
        axis: axis as u8,
        children: Box::new([l, r]),
    };
    (node, 1 + ln + rn, 1 + ld.max(rd))
}

/// Splits a span at the cheapest boundary along `axis` by the SAH (in half
/// by count when the centroids coincide), or keeps it as a leaf.
fn split(span: Span, axis: usize) -> Split {
    let n = span.prims.len();
    let (c0, c1) = (span.centroids.min[axis], span.centroids.max[axis]);
    if n == 1 || (c0 == c1 && n <= MAX_LEAF_PRIMS) {
        return Split::Leaf(span);
    }
    let first = span.first;
    if c0 == c1 {
        let (l, r) = span.prims.split_at_mut(n / 2);
        return Split::Children(Span::new(l, first), Span::new(r, first + n / 2));
    }
    if n <= SWEEP_MAX {
        return sweep_split(span, axis);
    }
    let binner = Binner::new(c0, c1, axis);
    let buckets = Buckets::of(span.prims, &binner);
    let Some((best, lb, rb)) = buckets.cheapest(&span.bounds, n) else {
        return Split::Leaf(span);
    };
    let mid = partition(span.prims, |p| binner.bucket(p.centroid) <= best);
    debug_assert_eq!(mid, buckets.counts[..=best].iter().sum::<usize>());
    let (lc, rc) = buckets.centroid_bounds(best);
    let (l, r) = span.prims.split_at_mut(mid);
    Split::Children(
        Span {
            prims: l,
            first,
            bounds: lb,
            centroids: lc,
        },
        Span {
            prims: r,
            first: first + mid,
            bounds: rb,
            centroids: rc,
        },
    )
}

/// The SAH evaluated at every boundary between the centroid-sorted
/// primitives of a small span (cheaper than binning when `n ≤ SWEEP_MAX`).
fn sweep_split(span: Span, axis: usize) -> Split {
    let n = span.prims.len();
    span.prims
        .sort_unstable_by(|a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
    // below[i]: bounds of prims[..=i]; above[i]: bounds of prims[i..].
    let (mut below, mut above) = ([Bounds3::EMPTY; SWEEP_MAX], [Bounds3::EMPTY; SWEEP_MAX]);
    let mut b = Bounds3::EMPTY;
    for (i, p) in span.prims.iter().enumerate() {
        b = b.union(p.bounds);
        below[i] = b;
    }
    b = Bounds3::EMPTY;
    for (i, p) in span.prims.iter().enumerate().rev() {
        b = b.union(p.bounds);
        above[i] = b;
    }
    let cost = |i: usize| {
        (i + 1) as f32 * below[i].surface_area() + (n - i - 1) as f32 * above[i + 1].surface_area()
    };
    let (best, best_cost) = (0..n - 1)
        .map(|i| (i, cost(i)))
        .fold((0, f32::INFINITY), |a, c| if c.1 < a.1 { c } else { a });
    if !split_pays(best_cost, &span.bounds, n) {
        return Split::Leaf(span);
    }
    let (first, mid) = (span.first, best + 1);
    let centroids = |ps: &[BuildPrim]| {
        ps.iter()
            .fold(Bounds3::EMPTY, |c, p| c.union_point(p.centroid))
    };
    let (l, r) = span.prims.split_at_mut(mid);
    let (lc, rc) = (centroids(l), centroids(r));
    Split::Children(
        Span {
            prims: l,
            first,
            bounds: below[best],
            centroids: lc,
        },
        Span {
            prims: r,
            first: first + mid,
            bounds: above[mid],
            centroids: rc,
        },
    )
}

/// Whether splitting `n` primitives at SAH cost `best_cost` (Σ count·area of
/// the children) beats a leaf; nodes above `MAX_LEAF_PRIMS` always split.
fn split_pays(best_cost: f32, bounds: &Bounds3, n: usize) -> bool {
    let area = bounds.surface_area();
    let split_cost = if area > 0.0 {
        TRAVERSAL_COST + best_cost / area
    } else {
        f32::INFINITY
    };
    n > MAX_LEAF_PRIMS || split_cost < n as f32
}

/// Maps a centroid to one of `N_BUCKETS` equal slices of `[c0, c1]` along an axis.
#[derive(Clone, Copy)]
struct Binner {
    axis: usize,
    min: f32,
    scale: f32,
}

impl Binner {
    fn new(c0: f32, c1: f32, axis: usize) -> Self {
        Binner {
            axis,
            min: c0,
            scale: N_BUCKETS as f32 / (c1 - c0),
        }
    }

    /// The bucket of centroid `c` (the float-to-int cast saturates at 0).
    #[inline]
    fn bucket(&self, c: Vec3) -> usize {
        (((c[self.axis] - self.min) * self.scale) as usize).min(N_BUCKETS - 1)
    }
}

/// Per-bucket primitive counts, bounds and centroid bounds.
#[derive(Clone, Copy)]
struct Buckets {
    counts: [usize; N_BUCKETS],
    boxes: [Bounds3; N_BUCKETS],
    centroids: [Bounds3; N_BUCKETS],
}

impl Buckets {
    const EMPTY: Buckets = Buckets {
        counts: [0; N_BUCKETS],
        boxes: [Bounds3::EMPTY; N_BUCKETS],
        centroids: [Bounds3::EMPTY; N_BUCKETS],
    };

    /// Bins `prims` (in parallel chunks for many; bounds unions and counts
    /// are exact, so the result does not depend on the chunking).
    fn of(prims: &[BuildPrim], binner: &Binner) -> Buckets {
        let bin = |chunk: &[BuildPrim]| {
            let mut b = Buckets::EMPTY;
            for p in chunk {
                let i = binner.bucket(p.centroid);
                b.counts[i] += 1;
                b.boxes[i] = b.boxes[i].union(p.bounds);
                b.centroids[i] = b.centroids[i].union_point(p.centroid);
            }
            b
        };
        if prims.len() < PARALLEL_THRESHOLD {
            return bin(prims);
        }
        prims
            .par_chunks(BIN_CHUNK)
            .map(bin)
            .reduce(|| Buckets::EMPTY, Buckets::merge)
    }

    fn merge(mut self, o: Buckets) -> Buckets {
        for i in 0..N_BUCKETS {
            self.counts[i] += o.counts[i];
            self.boxes[i] = self.boxes[i].union(o.boxes[i]);
            self.centroids[i] = self.centroids[i].union(o.centroids[i]);
        }
        self
    }

    /// Centroid bounds of the buckets up to and including `best`, and after it.
    fn centroid_bounds(&self, best: usize) -> (Bounds3, Bounds3) {
        let u =
            |r: std::ops::Range<usize>| r.fold(Bounds3::EMPTY, |c, i| c.union(self.centroids[i]));
        (u(0..best + 1), u(best + 1..N_BUCKETS))
    }

    /// The bucket after which splitting is cheapest by the SAH, with the
    /// bounds of both sides, or `None` when a leaf of these `n` primitives
    /// is cheaper (only for `n ≤ MAX_LEAF_PRIMS`).
    fn cheapest(&self, bounds: &Bounds3, n: usize) -> Option<(usize, Bounds3, Bounds3)> {
        // below[i]: buckets ..=i; above[i]: buckets i..; cost[i] for the split after bucket i.
        let (mut below, mut above) = ([Bounds3::EMPTY; N_BUCKETS], [Bounds3::EMPTY; N_BUCKETS]);
        let mut cost = [0.0f32; N_BUCKETS - 1];
        let (mut count, mut b) = (0usize, Bounds3::EMPTY);
        for i in 0..N_BUCKETS - 1 {
            count += self.counts[i];
            b = b.union(self.boxes[i]);
            below[i] = b;
            cost[i] = count as f32 * b.surface_area();
        }
        let (mut count, mut b) = (0usize, Bounds3::EMPTY);
        for i in (1..N_BUCKETS).rev() {
            count += self.counts[i];
            b = b.union(self.boxes[i]);
            above[i] = b;
            cost[i - 1] += count as f32 * b.surface_area();
        }
        let (best, best_cost) =
            cost.iter().enumerate().fold(
                (0, f32::INFINITY),
                |acc, (i, &c)| if c < acc.1 { (i, c) } else { acc },
            );
        split_pays(best_cost, bounds, n).then_some((best, below[best], above[best + 1]))
    }
}

/// In-place partition; returns the number of elements satisfying `pred`,
/// which end up first.
fn partition<T, P: Fn(&T) -> bool>(v: &mut [T], pred: P) -> usize {
    let mut i = 0;
    for j in 0..v.len() {
        if pred(&v[j]) {
            v.swap(i, j);
            i += 1;
        }
    }
    i
}

/// Appends `node`'s subtree depth-first; returns the index of `node`.
fn flatten(node: &BuildNode, nodes: &mut Vec<BvhNode>) -> u32 {
    let index = nodes.len();
    let b = node.bounds();
    nodes.push(BvhNode {
        min: b.min,
        max: b.max,
        offset: 0,
        count: 0,
        axis: 0,
        _pad: 0,
    });
    match node {
        BuildNode::Leaf { first, count, .. } => {
            nodes[index].offset = *first as u32;
            nodes[index].count = *count as u16;
        }
        BuildNode::Interior { axis, children, .. } => {
            flatten(&children[0], nodes);
            nodes[index].offset = flatten(&children[1], nodes);
            nodes[index].axis = *axis;
        }
    }
    index as u32
}
