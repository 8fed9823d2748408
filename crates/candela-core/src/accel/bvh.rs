//! The wide BVH: node layout, collapse of the binary tree, and traversal.

use super::build::{build_tree, BuildNode, BuildTree, MAX_LEAF, PACK};
use super::node::{Node, NodeTest, RayBoxes, EMPTY_CHILD, WIDTH};
use super::simd::Stack;
use super::triangle4::{Tri4Ray, TriPack, EMPTY_LANE, OTHER_TAG};
use crate::math::{Bounds3, Ray, Vec3};
use crate::shape::{TriangleIntersection, WatertightRay};

/// Tag of a leaf's child code; bits 28–30 hold the pack count − 1 and bits
/// 0–27 the first pack.
const LEAF_TAG: u32 = 1 << 31;
/// Largest number of packs a tree can address.
const MAX_PACKS: usize = 1 << 28;

const _: () = assert!(MAX_LEAF.div_ceil(PACK) <= 8);

/// An 8-wide bounding volume hierarchy over items given by their bounds.
/// Items that are triangles are stored in SIMD packs and tested by the
/// hierarchy itself; other items are tested through a caller closure.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    packs: Vec<TriPack>,
    bounds: Bounds3,
    items: usize,
    has_other: bool,
    depth: usize,
    /// Prefetch children when pushing them: only for hierarchies larger
    /// than [`PREFETCH_MIN_BYTES`].
    prefetch: bool,
}

/// Below this size (nodes and packs) a hierarchy stays in the core's caches
/// after a few rays, and prefetching the children a traversal pushes only
/// costs instructions (on the Cornell box's 36 triangles, 5 % of a
/// closest-hit query's and 13 % of a shadow ray's). On the 1M-triangle
/// bench mesh prefetching saves 5–10 % of the time.
const PREFETCH_MIN_BYTES: usize = 256 * 1024;

/// The closest hit found by [`Bvh::intersect`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BvhHit {
    /// A packed triangle, with its barycentrics and `t`.
    Triangle {
        /// Item index.
        item: u32,
        /// The intersection, as [`WatertightRay::intersect`] reports it.
        hit: TriangleIntersection,
    },
    /// An item the caller tested; `t` is what its closure returned.
    Other {
        /// Item index.
        item: u32,
        /// Ray parameter.
        t: f32,
    },
}

impl BvhHit {
    /// Ray parameter of the hit.
    pub fn t(&self) -> f32 {
        match self {
            BvhHit::Triangle { hit, .. } => hit.t,
            BvhHit::Other { t, .. } => *t,
        }
    }
    /// Item index of the hit.
    pub fn item(&self) -> u32 {
        match self {
            BvhHit::Triangle { item, .. } | BvhHit::Other { item, .. } => *item,
        }
    }
}

impl Bvh {
    /// Builds a BVH over items `0..bounds.len()`, all tested by the caller;
    /// empty and non-finite boxes are left out.
    pub fn build(bounds: &[Bounds3]) -> Bvh {
        Self::build_with_triangles(bounds, |_| None)
    }

    /// Builds a BVH over items `0..bounds.len()`; items for which
    /// `triangle(i)` gives vertices are tested by the hierarchy with the
    /// watertight test, the others by the caller. Empty and non-finite
    /// boxes are left out.
    pub fn build_with_triangles<T>(bounds: &[Bounds3], triangle: T) -> Bvh
    where
        T: Fn(u32) -> Option<[Vec3; 3]>,
    {
        let Some(tree) = build_tree(bounds) else {
            return Bvh::default();
        };
        let mut bvh = Bvh {
            bounds: tree.root.bounds(),
            items: tree.prims.len(),
            depth: tree.depth,
            ..Bvh::default()
        };
        let mut out = Collapse {
            tree: &tree,
            triangle: &triangle,
            bvh: &mut bvh,
        };
        match &tree.root {
            BuildNode::Interior { .. } => {
                out.node(&tree.root);
            }
            leaf => {
                let code = out.leaf(leaf);
                let b = leaf.bounds();
                out.bvh.nodes.push(Node::new(&[(b, code)]));
            }
        }
        bvh.nodes.shrink_to_fit();
        bvh.packs.shrink_to_fit();
        bvh.prefetch = bvh.memory_bytes() >= PREFETCH_MIN_BYTES;
        bvh.has_other = bvh.packs.iter().any(|p| {
            p.ids
                .iter()
                .any(|&id| id != EMPTY_LANE && id & OTHER_TAG != 0)
        });
        bvh
    }

    /// Bounds of everything (empty for an empty BVH).
    pub fn bounds(&self) -> Bounds3 {
        self.bounds
    }

    /// Number of wide nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Number of items held (those with usable bounds).
    pub fn item_count(&self) -> usize {
        self.items
    }

    /// Depth of the binary tree the wide one was collapsed from (0 when empty).
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// Bytes held by nodes and triangle packs.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node>()
            + self.packs.capacity() * std::mem::size_of::<TriPack>()
    }

    /// The item indices of every leaf, in leaf order (for tests).
    pub fn leaf_items(&self) -> Vec<Vec<u32>> {
        let mut leaves = Vec::new();
        for n in &self.nodes {
            for &c in n
                .child
                .iter()
                .filter(|&&c| c != EMPTY_CHILD && c & LEAF_TAG != 0)
            {
                let items = self.leaf_packs(c).iter().flat_map(|p| p.ids);
                leaves.push(
                    items
                        .filter(|&id| id != EMPTY_LANE)
                        .map(|id| id & !OTHER_TAG)
                        .collect(),
                );
            }
        }
        leaves
    }

    /// Prefetches the first cache lines of a child.
    #[inline(always)]
    fn prefetch_child(&self, code: u32) {
        if !self.prefetch {
            return;
        }
        if code & LEAF_TAG == 0 {
            super::simd::prefetch_all(&self.nodes[code as usize]);
        } else {
            self.leaf_packs(code)
                .iter()
                .for_each(super::simd::prefetch_all);
        }
    }

    /// The packs of a leaf code.
    #[inline(always)]
    fn leaf_packs(&self, code: u32) -> &[TriPack] {
        let first = (code & (MAX_PACKS as u32 - 1)) as usize;
        let count = ((code >> 28) & 7) as usize + 1;
        &self.packs[first..first + count]
    }

    /// Closest hit with `t < t_max`: packed triangles are tested here, other
    /// items by `other(item, ray, t_max)`, which returns the item's hit `t`
    /// (`< t_max`) or `None`.
    pub fn intersect<F>(&self, ray: &Ray, t_max: f32, other: F) -> Option<BvhHit>
    where
        F: FnMut(u32, &Ray, f32) -> Option<f32>,
    {
        super::simd::intersect(self, ray, t_max, other)
    }

    /// [`Bvh::intersect`] with node kernel `K` (see [`super::simd`]).
    #[inline(always)]
    pub(super) fn intersect_with<K: NodeTest, F>(
        &self,
        ray: &Ray,
        t_max: f32,
        mut other: F,
    ) -> Option<BvhHit>
    where
        F: FnMut(u32, &Ray, f32) -> Option<f32>,
    {
        if self.nodes.is_empty() {
            return None;
        }
        let boxes = RayBoxes::new(ray);
        let tri = Tri4Ray::new(&WatertightRay::new(ray));
        let mut stack = Stack::<(u32, f32)>::new();
        let (mut t_max, mut best) = (t_max, None);
        let mut current = 0u32;
        loop {
            if current & LEAF_TAG == 0 {
                let mut order = [(0u32, 0.0f32); WIDTH];
                let node = &self.nodes[current as usize];
                let k = hit_children_nearest_first(node, K::hits(&boxes, node, t_max), &mut order);
                if k > 0 {
                    for &e in order[1..k].iter().rev() {
                        self.prefetch_child(e.0);
                        stack.push(e);
                    }
                    current = order[0].0;
                    continue;
                }
            } else {
                for pack in self.leaf_packs(current) {
                    if let Some((lane, hit)) = tri.closest(pack, t_max) {
                        t_max = hit.t;
                        let item = pack.ids[lane];
                        best = Some(BvhHit::Triangle { item, hit });
                    }
                    if self.has_other {
                        for item in other_items(pack) {
                            if let Some(t) = other(item, ray, t_max) {
                                debug_assert!(t < t_max);
                                t_max = t;
                                best = Some(BvhHit::Other { item, t });
                            }
                        }
                    }
                }
            }
            // Pop the next subtree that can still hold a closer hit.
            loop {
                let Some((code, t)) = stack.pop() else {
                    return best;
                };
                if t <= t_max {
                    current = code;
                    break;
                }
            }
        }
    }

    /// Any hit with `t < t_max`: true as soon as a packed triangle or
    /// `other(item, ray, t_max)` reports one.
    pub fn intersect_p<F>(&self, ray: &Ray, t_max: f32, other: F) -> bool
    where
        F: FnMut(u32, &Ray, f32) -> bool,
    {
        super::simd::intersect_p(self, ray, t_max, other)
    }

    /// [`Bvh::intersect_p`] with node kernel `K` (see [`super::simd`]).
    #[inline(always)]
    pub(super) fn intersect_p_with<K: NodeTest, F>(
        &self,
        ray: &Ray,
        t_max: f32,
        mut other: F,
    ) -> bool
    where
        F: FnMut(u32, &Ray, f32) -> bool,
    {
        if self.nodes.is_empty() {
            return false;
        }
        let boxes = RayBoxes::new(ray);
        let tri = Tri4Ray::new(&WatertightRay::new(ray));
        let mut stack = Stack::<u32>::new();
        let mut current = 0u32;
        loop {
            if current & LEAF_TAG == 0 {
                let node = &self.nodes[current as usize];
                let (mut mask, _) = K::hits(&boxes, node, t_max);
                while mask != 0 {
                    let i = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    if node.child[i] != EMPTY_CHILD {
                        self.prefetch_child(node.child[i]);
                        stack.push(node.child[i]);
                    }
                }
            } else {
                for pack in self.leaf_packs(current) {
                    if tri.any(pack, t_max) {
                        return true;
                    }
                    if self.has_other && other_items(pack).any(|item| other(item, ray, t_max)) {
                        return true;
                    }
                }
            }
            match stack.pop() {
                Some(code) => current = code,
                None => return false,
            }
        }
    }
}

/// The untagged indices of a pack's items that the caller tests.
#[inline]
fn other_items(pack: &TriPack) -> impl Iterator<Item = u32> + '_ {
    pack.ids
        .iter()
        .filter(|&&id| id != EMPTY_LANE && id & OTHER_TAG != 0)
        .map(|&id| id & !OTHER_TAG)
}

/// Flattening of the binary tree into wide nodes and packs.
struct Collapse<'a, T> {
    tree: &'a BuildTree,
    triangle: &'a T,
    bvh: &'a mut Bvh,
}

impl<T: Fn(u32) -> Option<[Vec3; 3]>> Collapse<'_, T> {
    /// Emits the wide node for an interior node: its children are grown to
    /// `WIDTH` by repeatedly opening the interior child of largest surface
    /// area (Wald et al. 2008, "Getting rid of packets"). `need` is the
    /// stack a traversal may hold on reaching it. Returns its index.
    fn node(&mut self, node: &BuildNode) -> u32 {
        let mut kids: Vec<&BuildNode> = match node {
            BuildNode::Interior { children, .. } => children.iter().collect(),
            leaf => vec![leaf],
        };
        while kids.len() < WIDTH {
            let open = kids
                .iter()
                .enumerate()
                .filter(|(_, k)| matches!(k, BuildNode::Interior { .. }))
                .max_by(|a, b| {
                    a.1.bounds()
                        .surface_area()
                        .total_cmp(&b.1.bounds().surface_area())
                })
                .map(|(i, _)| i);
            let Some(i) = open else { break };
            if let BuildNode::Interior { children, .. } = kids.swap_remove(i) {
                kids.extend(children.iter());
            }
        }
        let index = self.bvh.nodes.len();
        self.bvh.nodes.push(Node::new(&[]));
        let children: Vec<(Bounds3, u32)> = kids
            .iter()
            .map(|k| {
                let code = match k {
                    BuildNode::Interior { .. } => self.node(k),
                    leaf => self.leaf(leaf),
                };
                (k.bounds(), code)
            })
            .collect();
        self.bvh.nodes[index] = Node::new(&children);
        index as u32
    }

    /// Packs a leaf's items (triangles first) and returns its child code.
    fn leaf(&mut self, leaf: &BuildNode) -> u32 {
        let BuildNode::Leaf { first, count, .. } = leaf else {
            unreachable!("leaf() is called on leaves only")
        };
        let mut lanes: Vec<(u32, Option<[Vec3; 3]>)> = self.tree.prims[*first..first + count]
            .iter()
            .map(|p| (p.index, (self.triangle)(p.index)))
            .collect();
        lanes.sort_by_key(|l| l.1.is_none());
        let start = self.bvh.packs.len();
        self.bvh.packs.extend(lanes.chunks(PACK).map(TriPack::new));
        let n = self.bvh.packs.len() - start;
        // Beyond MAX_PACKS packs (a billion triangles) items would be unaddressable.
        assert!(
            start + n <= MAX_PACKS,
            "BVH exceeds {MAX_PACKS} triangle packs"
        );
        LEAF_TAG | ((n as u32 - 1) << 28) | start as u32
    }
}

/// Writes the children of `node` that the ray hits (`hits`, from
/// [`NodeTest::hits`]) into `order`, nearest first (insertion sort over at
/// most 8), and returns how many.
#[inline(always)]
fn hit_children_nearest_first(
    node: &Node,
    (mut mask, t_near): (u32, [f32; WIDTH]),
    order: &mut [(u32, f32); WIDTH],
) -> usize {
    let mut k = 0;
    while mask != 0 {
        let i = mask.trailing_zeros() as usize;
        mask &= mask - 1;
        if node.child[i] == EMPTY_CHILD {
            continue; // Only for rays with non-finite parts.
        }
        let entry = (node.child[i], t_near[i]);
        let mut j = k;
        while j > 0 && order[j - 1].1 > entry.1 {
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = entry;
        k += 1;
    }
    k
}
