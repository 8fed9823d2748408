//! Binary SAH build, the first stage of the wide BVH (see the module doc of
//! [`super`]).
//!
//! Top down, each node is split where the surface area heuristic is lowest
//! over all three axes (pbrt-v4 §7.3.2; Wald 2007, "On fast construction of
//! SAH-based bounding volume hierarchies"). Leaves are tested four
//! primitives at a time, so the cost of `n` primitives is the number of
//! packs `⌈n/4⌉`, and a split costs `c_trav + Σ (A_child / A) ⌈n_child/4⌉`.
//! A leaf holds one pack at most: the heuristic's probabilities (child area
//! over parent area) are those of a ray passing through, and ignore that
//! an ordered traversal skips a far child once a near one has given a
//! closer hit, so where triangles are large against the scene (walls) it
//! keeps two packs in one leaf whose box every ray enters. `c_trav` is 0.3:
//! a binary level is about a third of an eight-wide node's test, which
//! costs about as much as a pack's. Both measured (callgrind, path tracer,
//! 1 spp crops, against two packs at most and 0.5): Cornell box −4.6 %,
//! killeroo-simple −1.3 %, caustic-glass and the pool within ±1.3 %, the
//! bench's million-triangle mesh the same to 0.1 % (its leaves rarely
//! held more than four). In wall time the Cornell box gains less (two
//! threads, interleaved: path −0.7 %, BDPT −1 %), the tests it saves being
//! on data already in cache. Images are the same bit for bit.
//! Nodes of more than [`SWEEP_MAX`] primitives evaluate the cost at
//! [`MIN_BINS`]–[`N_BINS`] bin boundaries per axis: one pass bins the centroids, keeping
//! each bin's count, bounds and centroid bounds, and one pass partitions, so
//! the children's bounds come from the bins. Smaller nodes sort their
//! centroids along each axis and evaluate every boundary. Large nodes bin in
//! parallel chunks (unions and counts are exact, so the chunking changes
//! nothing), and large subtrees build in parallel with `rayon::join`; each
//! subtree reorders only its own slice, so the result does not depend on
//! scheduling.
//!
//! **Any input terminates.** Boxes that are empty or not finite are left
//! out (they bound nothing a ray can reach). Costs and bin indices are
//! computed in f64, where the areas and extents of finite f32 boxes cannot
//! overflow. Every split leaves both sides non-empty; when the heuristic
//! finds none, or below [`SAH_DEPTH`] levels (adversarial inputs such as
//! exponentially spaced boxes can make SAH splits peel one primitive at a
//! time), the node is split at the median centroid instead. So the depth is
//! at most `SAH_DEPTH + 32`, which bounds the traversal stack.

use crate::math::{Bounds3, Vec3};
use rayon::prelude::*;

/// Primitives tested together by one pack test.
pub(super) const PACK: usize = 4;
/// Primitives per leaf at most: one pack (module doc).
pub(super) const MAX_LEAF: usize = PACK;
/// SAH bins per axis at most (large nodes).
const N_BINS: usize = 32;
/// SAH bins per axis at least (small nodes).
const MIN_BINS: usize = 12;
/// Cost of one binary traversal step relative to one pack test (module doc).
const TRAVERSAL_COST: f64 = 0.3;
/// Levels split by the SAH; deeper nodes split at the median.
pub(super) const SAH_DEPTH: usize = 40;
/// Subtrees with more primitives than this build (and bin) in parallel.
const PARALLEL_THRESHOLD: usize = 16 * 1024;
/// Primitives per parallel binning task.
const BIN_CHUNK: usize = 8 * 1024;
/// Nodes with at most this many primitives sweep instead of binning.
const SWEEP_MAX: usize = 16;
/// Item indices must stay below this (the top bit tags lanes in packs).
pub(super) const MAX_ITEMS: usize = (1 << 31) - 1;

/// A primitive during the build.
#[derive(Clone, Copy, Debug)]
pub(super) struct BuildPrim {
    bounds: Bounds3,
    centroid: Vec3,
    /// Index of the item in the caller's array.
    pub index: u32,
}

/// The binary tree before it is collapsed into wide nodes.
pub(super) enum BuildNode {
    /// Primitives `first..first + count` of the reordered array.
    Leaf {
        bounds: Bounds3,
        first: usize,
        count: usize,
    },
    /// Two subtrees.
    Interior {
        bounds: Bounds3,
        children: Box<[BuildNode; 2]>,
    },
}

impl BuildNode {
    /// The node's bounds.
    pub fn bounds(&self) -> Bounds3 {
        match self {
            BuildNode::Leaf { bounds, .. } | BuildNode::Interior { bounds, .. } => *bounds,
        }
    }
}

/// A built binary tree, its depth, and the primitives in leaf order.
pub(super) struct BuildTree {
    pub root: BuildNode,
    pub depth: usize,
    pub prims: Vec<BuildPrim>,
}

/// Builds the binary tree over the usable boxes (`None` when there are none).
pub(super) fn build_tree(prim_bounds: &[Bounds3]) -> Option<BuildTree> {
    let mut prims: Vec<BuildPrim> = prim_bounds
        .par_iter()
        .enumerate()
        .take(MAX_ITEMS)
        .filter(|(_, b)| usable(b))
        .map(|(i, b)| BuildPrim {
            bounds: *b,
            // Halves first: `min + max` can overflow for finite boxes.
            centroid: 0.5 * b.min + 0.5 * b.max,
            index: i as u32,
        })
        .collect();
    if prims.is_empty() {
        return None;
    }
    let (root, depth) = build_recursive(Span::new(&mut prims, 0), 0);
    Some(BuildTree { root, depth, prims })
}

/// A box the tree can hold: non-empty and finite.
fn usable(b: &Bounds3) -> bool {
    !b.is_empty() && b.min.is_finite() && b.max.is_finite()
}

/// Number of pack tests for `n` primitives.
fn packs(n: usize) -> f64 {
    n.div_ceil(PACK) as f64
}

/// Surface area in f64 (finite for any finite f32 box).
fn area(b: &Bounds3) -> f64 {
    if b.is_empty() {
        return 0.0;
    }
    let d = b.max.as_dvec3() - b.min.as_dvec3();
    2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
}

/// A node's primitives with their bounds and centroid bounds.
struct Span<'a> {
    prims: &'a mut [BuildPrim],
    /// Index of `prims[0]` in the full array.
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

    /// Splits after `mid` primitives, with known child bounds.
    fn split_at(self, mid: usize, l: (Bounds3, Bounds3), r: (Bounds3, Bounds3)) -> Split<'a> {
        let (lp, rp) = self.prims.split_at_mut(mid);
        let left = Span {
            prims: lp,
            first: self.first,
            bounds: l.0,
            centroids: l.1,
        };
        let right = Span {
            prims: rp,
            first: self.first + mid,
            bounds: r.0,
            centroids: r.1,
        };
        Split::Children(left, right)
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

/// How a node ends: as a leaf, or split into two non-empty spans.
enum Split<'a> {
    Leaf(Span<'a>),
    Children(Span<'a>, Span<'a>),
}

/// Builds the subtree over a span at `depth` (root 0); returns it and its depth.
fn build_recursive(span: Span, depth: usize) -> (BuildNode, usize) {
    let bounds = span.bounds;
    let (left, right) = match split(span, depth) {
        Split::Leaf(s) => {
            let (first, count) = (s.first, s.prims.len());
            return (
                BuildNode::Leaf {
                    bounds,
                    first,
                    count,
                },
                1,
            );
        }
        Split::Children(l, r) => (l, r),
    };
    debug_assert!(!left.prims.is_empty() && !right.prims.is_empty());
    let ((l, ld), (r, rd)) = if left.prims.len() + right.prims.len() > PARALLEL_THRESHOLD {
        rayon::join(
            || build_recursive(left, depth + 1),
            || build_recursive(right, depth + 1),
        )
    } else {
        (
            build_recursive(left, depth + 1),
            build_recursive(right, depth + 1),
        )
    };
    let node = BuildNode::Interior {
        bounds,
        children: Box::new([l, r]),
    };
    (node, 1 + ld.max(rd))
}

/// A candidate split: cost, axis and position (bin or sorted index).
#[derive(Clone, Copy)]
struct Candidate {
    cost: f64,
    axis: usize,
    at: usize,
}

/// Keeps the cheaper of two candidates (the first on ties).
fn cheaper(a: Option<Candidate>, b: Candidate) -> Option<Candidate> {
    match a {
        Some(a) if a.cost <= b.cost => Some(a),
        _ => Some(b),
    }
}

/// Chooses how to end or split a span (see the module doc).
fn split(span: Span, depth: usize) -> Split {
    let n = span.prims.len();
    if n == 1 {
        return Split::Leaf(span);
    }
    let c = span.centroids;
    let flat = c.min == c.max;
    if flat && n <= MAX_LEAF {
        return Split::Leaf(span);
    }
    if flat || depth >= SAH_DEPTH {
        return if n <= MAX_LEAF {
            Split::Leaf(span)
        } else {
            median_split(span)
        };
    }
    let (binner, bins) = if n <= SWEEP_MAX {
        (None, None)
    } else {
        let binner = Binner::new(&c, n);
        let bins = Bins::of(span.prims, &binner);
        (Some(binner), Some(bins))
    };
    let best = match &bins {
        None => sweep(&mut *span.prims),
        Some(bins) => bins.cheapest(),
    };
    let Some(best) = best else {
        return median_split(span);
    };
    let a = area(&span.bounds);
    let cost = TRAVERSAL_COST + if a > 0.0 { best.cost / a } else { packs(n) };
    if n <= MAX_LEAF && packs(n) <= cost {
        return Split::Leaf(span);
    }
    let (Some(binner), Some(bins)) = (binner, bins) else {
        return sorted_split(span, best);
    };
    let (mid, lc, rc) = partition(span.prims, |p| binner.bin(p.centroid, best.axis) <= best.at);
    if mid == 0 || mid == n {
        return median_split(span);
    }
    let (lb, rb) = bins.sides(best);
    span.split_at(mid, (lb, lc), (rb, rc))
}

/// Splits in half by count at the median centroid along the widest centroid axis.
fn median_split(span: Span) -> Split {
    let d = span.centroids.max.as_dvec3() - span.centroids.min.as_dvec3();
    let axis = if d.x >= d.y && d.x >= d.z {
        0
    } else if d.y >= d.z {
        1
    } else {
        2
    };
    let mid = span.prims.len() / 2;
    span.prims
        .select_nth_unstable_by(mid, |a, b| a.centroid[axis].total_cmp(&b.centroid[axis]));
    let (l, r) = (bounds_of(&span.prims[..mid]), bounds_of(&span.prims[mid..]));
    span.split_at(mid, l, r)
}

/// Sorts the primitives along `axis` by centroid.
fn sort_along(prims: &mut [BuildPrim], axis: usize) {
    prims.sort_unstable_by(|a, b| {
        a.centroid[axis]
            .total_cmp(&b.centroid[axis])
            .then(a.index.cmp(&b.index))
    });
}

/// The cheapest boundary between sorted primitives over all three axes
/// (cost Σ area · packs, not yet divided by the parent's area).
fn sweep(prims: &mut [BuildPrim]) -> Option<Candidate> {
    let n = prims.len();
    let mut best = None;
    for axis in 0..3 {
        sort_along(prims, axis);
        // below[i]: bounds of prims[..=i]; above[i]: bounds of prims[i..].
        let mut above = [Bounds3::EMPTY; SWEEP_MAX];
        let mut b = Bounds3::EMPTY;
        for i in (1..n).rev() {
            b = b.union(prims[i].bounds);
            above[i] = b;
        }
        let mut below = Bounds3::EMPTY;
        for i in 0..n - 1 {
            below = below.union(prims[i].bounds);
            let cost = area(&below) * packs(i + 1) + area(&above[i + 1]) * packs(n - i - 1);
            best = cheaper(best, Candidate { cost, axis, at: i });
        }
    }
    best
}

/// Splits a small span after sorted position `best.at` along `best.axis`.
fn sorted_split(span: Span, best: Candidate) -> Split {
    sort_along(span.prims, best.axis);
    let mid = best.at + 1;
    let (l, r) = (bounds_of(&span.prims[..mid]), bounds_of(&span.prims[mid..]));
    span.split_at(mid, l, r)
}

/// Maps a centroid to one of `n` equal slices of the centroid bounds, per
/// axis; axes where the centroids coincide are not binned.
struct Binner {
    min: [f64; 3],
    scale: [f64; 3],
    /// Bins per axis, at most [`N_BINS`].
    n: usize,
}

impl Binner {
    /// The binning of the centroid bounds `c` of `prims` primitives: a
    /// quarter as many bins as primitives, between [`MIN_BINS`] and
    /// [`N_BINS`], since choosing among 3 × 32 bins costs as much as binning
    /// a few dozen primitives (on caustic-glass, with the children's bounds
    /// taken from the bins, the build's instructions fell 6 % and a path
    /// tracing pass's rose 0.2 %, under callgrind).
    fn new(c: &Bounds3, prims: usize) -> Self {
        let n = (prims / 4).clamp(MIN_BINS, N_BINS);
        let (min, max) = (c.min.as_dvec3(), c.max.as_dvec3());
        let scale = |a: usize| {
            let e = max[a] - min[a];
            if e > 0.0 {
                n as f64 / e
            } else {
                0.0
            }
        };
        Binner {
            min: [min.x, min.y, min.z],
            scale: [scale(0), scale(1), scale(2)],
            n,
        }
    }

    /// The bin of centroid `c` along `axis` (the cast saturates at 0).
    #[inline]
    fn bin(&self, c: Vec3, axis: usize) -> usize {
        (((c[axis] as f64 - self.min[axis]) * self.scale[axis]) as usize).min(self.n - 1)
    }
}

/// Per-axis, per-bin primitive counts and bounds.
#[derive(Clone)]
struct Bins {
    counts: [[u32; N_BINS]; 3],
    boxes: [[Bounds3; N_BINS]; 3],
    binned: [bool; 3],
    /// Bins in use per axis.
    n: usize,
}

impl Bins {
    /// Bins `prims` along every axis with a non-zero centroid extent (in
    /// parallel chunks for many).
    fn of(prims: &[BuildPrim], binner: &Binner) -> Bins {
        let empty = Bins {
            counts: [[0; N_BINS]; 3],
            boxes: [[Bounds3::EMPTY; N_BINS]; 3],
            binned: binner.scale.map(|s| s > 0.0),
            n: binner.n,
        };
        let bin = |chunk: &[BuildPrim]| {
            let mut b = empty.clone();
            for p in chunk {
                for axis in 0..3 {
                    let i = binner.bin(p.centroid, axis);
                    b.counts[axis][i] += 1;
                    b.boxes[axis][i] = b.boxes[axis][i].union(p.bounds);
                }
            }
            b
        };
        if prims.len() < PARALLEL_THRESHOLD {
            return bin(prims);
        }
        prims
            .par_chunks(BIN_CHUNK)
            .map(bin)
            .reduce(|| empty.clone(), Bins::merge)
    }

    /// Sums two binnings.
    fn merge(mut self, o: Bins) -> Bins {
        for axis in 0..3 {
            for i in 0..self.n {
                self.counts[axis][i] += o.counts[axis][i];
                self.boxes[axis][i] = self.boxes[axis][i].union(o.boxes[axis][i]);
            }
        }
        self
    }

    /// The cheapest split after a bin with primitives on both sides.
    fn cheapest(&self) -> Option<Candidate> {
        let mut best = None;
        for axis in (0..3).filter(|&a| self.binned[a]) {
            let (counts, boxes) = (&self.counts[axis], &self.boxes[axis]);
            // right[i]: (count, area) of bins i.. .
            let mut right = [(0u32, 0.0f64); N_BINS];
            let (mut n, mut b) = (0, Bounds3::EMPTY);
            for i in (1..self.n).rev() {
                n += counts[i];
                b = b.union(boxes[i]);
                right[i] = (n, area(&b));
            }
            let (mut n, mut b) = (0, Bounds3::EMPTY);
            for i in 0..self.n - 1 {
                n += counts[i];
                b = b.union(boxes[i]);
                let (nr, ar) = right[i + 1];
                if n == 0 || nr == 0 {
                    continue;
                }
                let cost = area(&b) * packs(n as usize) + ar * packs(nr as usize);
                best = cheaper(best, Candidate { cost, axis, at: i });
            }
        }
        best
    }
}

impl Bins {
    /// Bounds of the primitives in bins `..=at` and `at + 1..` along `axis`
    /// (exact: the unions of the bins' boxes).
    fn sides(&self, c: Candidate) -> (Bounds3, Bounds3) {
        let boxes = &self.boxes[c.axis][..self.n];
        let union = |b: &[Bounds3]| b.iter().fold(Bounds3::EMPTY, |a, x| a.union(*x));
        (union(&boxes[..=c.at]), union(&boxes[c.at + 1..]))
    }
}

/// In-place partition; returns the number of primitives satisfying `pred`,
/// which end up first, and the centroid bounds of both sides.
fn partition<P: Fn(&BuildPrim) -> bool>(v: &mut [BuildPrim], pred: P) -> (usize, Bounds3, Bounds3) {
    let (mut i, mut lc, mut rc) = (0, Bounds3::EMPTY, Bounds3::EMPTY);
    for j in 0..v.len() {
        if pred(&v[j]) {
            lc = lc.union_point(v[j].centroid);
            v.swap(i, j);
            i += 1;
        } else {
            rc = rc.union_point(v[j].centroid);
        }
    }
    (i, lc, rc)
}
