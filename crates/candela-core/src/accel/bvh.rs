//! Bounding volume hierarchy over primitive bounding boxes.
//!
//! **Build.** Top-down, splitting each node with the surface area heuristic
//! evaluated at bucket boundaries of the centroids' extent along the widest
//! axis ("binned SAH", Wald 2007, "On fast construction of SAH-based bounding
//! volume hierarchies"; pbrt-v4 §7.3.2). The cost of a split is
//! `c_trav + (N_L·A_L + N_R·A_R) / A` with `c_trav = 1/2` relative to one
//! primitive test; a node becomes a leaf when that is not cheaper than testing
//! its `N ≤ 4` primitives. Larger nodes are always split; when all centroids
//! coincide they are split in half by count. Subtrees above a size threshold
//! build in parallel with `rayon::join`. Each subtree partitions its own slice
//! of the primitive array in place and leaves record their offset into it,
//! so the result does not depend on thread scheduling.
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

/// Primitives per leaf at most.
const MAX_LEAF_PRIMS: usize = 4;
/// Number of SAH buckets.
const N_BUCKETS: usize = 16;
/// Cost of a traversal step relative to one primitive test.
const TRAVERSAL_COST: f32 = 0.5;
/// Subtrees with more primitives than this build in parallel.
const PARALLEL_THRESHOLD: usize = 16 * 1024;
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
        let (root, n_nodes, depth) = build_recursive(&mut prims, 0);
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

/// Builds the subtree over `prims`, whose first element sits at `first` in
/// the full primitive array.
fn build_recursive(prims: &mut [BuildPrim], first: usize) -> Built {
    let bounds = prims.iter().fold(Bounds3::EMPTY, |b, p| b.union(p.bounds));
    let n = prims.len();
    let leaf = |first, count| {
        (
            BuildNode::Leaf {
                bounds,
                first,
                count,
            },
            1,
            1,
        )
    };
    if n == 1 {
        return leaf(first, n);
    }
    let cb = prims
        .iter()
        .fold(Bounds3::EMPTY, |b, p| b.union_point(p.centroid));
    let axis = cb.max_extent();
    let mid = if cb.max[axis] == cb.min[axis] {
        if n <= MAX_LEAF_PRIMS {
            return leaf(first, n);
        }
        n / 2
    } else {
        match sah_split(prims, &bounds, &cb, axis) {
            Some(mid) => mid,
            None => return leaf(first, n),
        }
    };
    let (left, right) = prims.split_at_mut(mid);
    let ((l, ln, ld), (r, rn, rd)) = if n > PARALLEL_THRESHOLD {
        rayon::join(
            || build_recursive(left, first),
            || build_recursive(right, first + mid),
        )
    } else {
        (
            build_recursive(left, first),
            build_recursive(right, first + mid),
        )
    };
    let node = BuildNode::Interior {
        bounds,
        axis: axis as u8,
        children: Box::new([l, r]),
    };
    (node, 1 + ln + rn, 1 + ld.max(rd))
}

/// Chooses the cheapest bucket boundary and partitions `prims` around it;
/// returns the size of the left part, or `None` when a leaf is cheaper.
fn sah_split(
    prims: &mut [BuildPrim],
    bounds: &Bounds3,
    cb: &Bounds3,
    axis: usize,
) -> Option<usize> {
    let bucket_of = |c: Vec3| {
        let b = (N_BUCKETS as f32 * cb.offset(c)[axis]) as usize;
        b.min(N_BUCKETS - 1)
    };
    let mut counts = [0usize; N_BUCKETS];
    let mut boxes = [Bounds3::EMPTY; N_BUCKETS];
    for p in prims.iter() {
        let b = bucket_of(p.centroid);
        counts[b] += 1;
        boxes[b] = boxes[b].union(p.bounds);
    }
    // Sweep from both ends: cost[i] for the split after bucket i.
    let mut cost = [0.0f32; N_BUCKETS - 1];
    let (mut below_n, mut below_b) = (0usize, Bounds3::EMPTY);
    for i in 0..N_BUCKETS - 1 {
        below_n += counts[i];
        below_b = below_b.union(boxes[i]);
        cost[i] = below_n as f32 * below_b.surface_area();
    }
    let (mut above_n, mut above_b) = (0usize, Bounds3::EMPTY);
    for i in (1..N_BUCKETS).rev() {
        above_n += counts[i];
        above_b = above_b.union(boxes[i]);
        cost[i - 1] += above_n as f32 * above_b.surface_area();
    }
    let (best, best_cost) =
        cost.iter().enumerate().fold(
            (0, f32::INFINITY),
            |acc, (i, &c)| if c < acc.1 { (i, c) } else { acc },
        );
    let n = prims.len();
    let area = bounds.surface_area();
    let split_cost = if area > 0.0 {
        TRAVERSAL_COST + best_cost / area
    } else {
        f32::INFINITY
    };
    if n <= MAX_LEAF_PRIMS && split_cost >= n as f32 {
        return None;
    }
    Some(partition(prims, |p| bucket_of(p.centroid) <= best))
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
