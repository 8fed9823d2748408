//! Building the light BVH top-down [pbrt-v4 §12.6.3, "Bounding volume
//! hierarchy construction"; Conty Estevez & Kulla 2018, §4.4].
//!
//! Each interior node splits its lights in two along one axis, at one of
//! the boundaries between 12 equal buckets of the centroids' extent. The
//! split minimises a surface-area-like cost that also weighs power and the
//! spread of directions: for each side, Φ·M_Ω·K_r·A, where
//! - A is the surface area of the side's box,
//! - M_Ω is the solid-angle measure of the side's cone of emission
//!   directions, the integral of cos(θ − θo) over the directions within
//!   θw = min(θo + θe, π) of the axis:
//!   M_Ω = 2π(1 − cos θo) + π/2·(2θw sin θo − cos(θo − 2θw) − 2θo sin θo + cos θo)
//!   [Conty Estevez & Kulla 2018, eq. 2],
//! - K_r = (longest extent of the node)/(extent along the split axis)
//!   penalises thin slabs cut across the long axis.
//!
//! When no bucket boundary splits the lights (all centroids in one bucket,
//! or zero cost everywhere: lights without area on a line), the lights are
//! split at the median centroid along the longest axis instead (pbrt-v4
//! splits the index range as it lies). The median split is also forced when
//! the depth would otherwise exceed the 64 bits of a light's trail.
//!
//! Nodes are stored depth-first: the first child follows its parent, the
//! parent records the second. Each light records its trail: bit d is the
//! side taken at depth d.

use super::compact::CompactLightBounds;
use super::{LightBvhNode, Slot};
use crate::light::bounds::PreparedBounds;
use crate::light::LightBounds;
use crate::math::{safe_sqrt, Bounds3, PI};

/// Buckets per axis.
const BUCKETS: usize = 12;
/// Deepest trail a light can have.
const MAX_DEPTH: u32 = 64;

/// The tree under construction.
pub(super) struct Builder<'a> {
    pub nodes: Vec<LightBvhNode>,
    /// Each node's bounds, decoded from their compact form.
    pub bounds: Vec<PreparedBounds>,
    pub slots: &'a mut [Slot],
    pub all: Bounds3,
}

impl Builder<'_> {
    /// Builds the subtree of `items` (light index, bounds) at `depth` with
    /// trail `trail`; returns its bounds.
    pub fn node(
        &mut self,
        items: &mut [(u32, LightBounds)],
        trail: u64,
        depth: u32,
    ) -> LightBounds {
        debug_assert!(!items.is_empty());
        if let [(light, lb)] = items {
            self.slots[*light as usize] = Slot::Tree(trail);
            self.nodes.push(LightBvhNode::leaf(*light));
            self.bounds.push(self.prepared(lb));
            return *lb;
        }
        let mid = split(items, depth);
        let index = self.nodes.len();
        self.nodes.push(LightBvhNode::default());
        self.bounds.push(PreparedBounds::default());
        let (left, right) = items.split_at_mut(mid);
        let b0 = self.node(left, trail, depth + 1);
        let second = self.nodes.len() as u32;
        let b1 = self.node(right, trail | (1u64 << depth), depth + 1);
        let lb = b0.union(&b1);
        self.nodes[index] = LightBvhNode::interior(second);
        self.bounds[index] = self.prepared(&lb);
        lb
    }

    /// `lb` as a node holds it: packed, decoded and prepared.
    fn prepared(&self, lb: &LightBounds) -> PreparedBounds {
        PreparedBounds::new(&CompactLightBounds::new(lb, &self.all).decode(&self.all))
    }
}

/// Reorders `items` and returns the index splitting them into two
/// non-empty halves (module doc).
fn split(items: &mut [(u32, LightBounds)], depth: u32) -> usize {
    let n = items.len();
    let levels_left = usize::BITS - (n - 1).leading_zeros();
    if depth + levels_left < MAX_DEPTH {
        if let Some((dim, bucket, centroids)) = best_bucket_split(items) {
            let mut mid = 0;
            for j in 0..n {
                if bucket_of(&centroids, items[j].1.centroid()[dim], dim) <= bucket {
                    items.swap(mid, j);
                    mid += 1;
                }
            }
            if mid > 0 && mid < n {
                return mid;
            }
        }
    }
    median_split(items)
}

/// Splits at the median centroid along the centroids' longest axis.
fn median_split(items: &mut [(u32, LightBounds)]) -> usize {
    let cb = items
        .iter()
        .fold(Bounds3::EMPTY, |b, it| b.union_point(it.1.centroid()));
    let dim = cb.max_extent();
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| {
        a.1.centroid()[dim].total_cmp(&b.1.centroid()[dim])
    });
    mid
}

/// The bucket of a centroid coordinate `c` along `dim`.
#[inline]
fn bucket_of(centroids: &Bounds3, c: f32, dim: usize) -> usize {
    let o = centroids.offset(crate::math::Vec3::splat(c))[dim];
    ((BUCKETS as f32 * o) as usize).min(BUCKETS - 1)
}

/// The cheapest bucket boundary over the three axes: (axis, last bucket of
/// the first side, centroid bounds); `None` when none has a finite,
/// positive cost.
fn best_bucket_split(items: &[(u32, LightBounds)]) -> Option<(usize, usize, Bounds3)> {
    let bounds = items
        .iter()
        .fold(Bounds3::EMPTY, |b, it| b.union(it.1.bounds));
    let centroids = items
        .iter()
        .fold(Bounds3::EMPTY, |b, it| b.union_point(it.1.centroid()));
    let mut best: Option<(f32, usize, usize)> = None;
    for dim in 0..3 {
        if centroids.max[dim] == centroids.min[dim] {
            continue;
        }
        let mut buckets: [Option<LightBounds>; BUCKETS] = [None; BUCKETS];
        for (_, lb) in items {
            let b = &mut buckets[bucket_of(&centroids, lb.centroid()[dim], dim)];
            *b = Some(b.map_or(*lb, |x| x.union(lb)));
        }
        for i in 0..BUCKETS - 1 {
            let side = |r: std::ops::Range<usize>| {
                buckets[r]
                    .iter()
                    .flatten()
                    .fold(None, |acc: Option<LightBounds>, b| {
                        Some(acc.map_or(*b, |a| a.union(b)))
                    })
            };
            let (Some(b0), Some(b1)) = (side(0..i + 1), side(i + 1..BUCKETS)) else {
                continue;
            };
            let cost = cost(&b0, &bounds, dim) + cost(&b1, &bounds, dim);
            if cost > 0.0 && cost.is_finite() && best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, dim, i));
            }
        }
    }
    best.map(|(_, dim, i)| (dim, i, centroids))
}

/// Φ·M_Ω·K_r·A of one side (module doc).
fn cost(b: &LightBounds, node: &Bounds3, dim: usize) -> f32 {
    let cos_o = b.cos_theta_o.clamp(-1.0, 1.0);
    let theta_o = cos_o.acos();
    let theta_e = b.cos_theta_e.clamp(-1.0, 1.0).acos();
    let theta_w = (theta_o + theta_e).min(PI);
    let sin_o = safe_sqrt(1.0 - cos_o * cos_o);
    let m_omega = 2.0 * PI * (1.0 - cos_o)
        + PI / 2.0
            * (2.0 * theta_w * sin_o - (theta_o - 2.0 * theta_w).cos() - 2.0 * theta_o * sin_o
                + cos_o);
    let d = node.diagonal();
    let k_r = d.max_element() / d[dim];
    b.phi * m_omega * k_r * b.bounds.surface_area()
}
