//! Light selection by a bounding volume hierarchy over the lights, given the
//! receiving point [pbrt-v4 §12.6.3 `BVHLightSampler`; Conty Estevez &
//! Kulla 2018, "Importance Sampling of Many Lights with Adaptive Tree
//! Splitting"].
//!
//! Every light with bounds ([`super::LightBounds`]: all but distant and infinite
//! lights) and non-zero power is a leaf of a binary tree whose nodes store
//! the union of their lights' bounds ([`build`]). Lights without bounds are
//! chosen beside the tree: with n∞ of them, each is picked with probability
//! 1/(n∞ + 1) and the tree with the remaining 1/(n∞ + 1) (pbrt-v4's fixed
//! split; all n∞/(n∞ + 0) when there is no tree).
//!
//! **Sampling.** From the root, at each interior node the two children's
//! importances I₀, I₁ at the receiver (position p and shading normal n,
//! zero in free space) give the probabilities I_k/(I₀ + I₁); one child is
//! chosen with the uniform number u, which is then rescaled to [0, 1) for
//! the next level. The light's pmf is the product of the choices' probabilities
//! times the tree's share. When both children have zero importance the
//! sample fails (`None`): no light below can reach the receiver by the
//! bounds. A tree that is a single leaf is taken only if its importance is
//! positive.
//!
//! **PMF.** The probability of a given light repeats the walk without a
//! random number: the light's trail (bit d = the side taken at depth d)
//! leads from the root to its leaf, multiplying the same probabilities,
//! computed by the same function as in sampling, so `pmf` returns exactly
//! the probability `sample` uses. A light of zero power, never in the tree,
//! has pmf 0 (pbrt-v4 gives it the infinite lights' share).
//!
//! u carries ~24 bits: a leaf's actual selection probability differs from
//! its pmf by at most the spacing of u's values, negligible unless a light's
//! pmf approaches 2⁻²⁰ (deep trees of near-equal importances); pbrt-v4 has
//! the same limit.

mod build;
mod compact;
#[cfg(test)]
mod tests;

use super::bounds::{PreparedBounds, PreparedPair};
use super::{Light, LightSampleContext};
use crate::interaction::LightId;
use crate::math::{Bounds3, Vec3};
use crate::sampling::ONE_MINUS_EPSILON;

/// A node: the second child's index (interior) or the light's index
/// (leaf), and for an interior node the index of its children's bounds in
/// the sampler's `pairs`. Bounds are those of pbrt-v4's compact bounds,
/// decoded and prepared for the importance once, not at every evaluation.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct LightBvhNode {
    /// Bit 31: leaf. Bits 0–30: light (leaf) or second child (interior).
    index: u32,
    /// Interior nodes: index into `pairs`.
    pair: u32,
}

const LEAF: u32 = 1 << 31;

impl LightBvhNode {
    fn leaf(light: u32) -> Self {
        debug_assert!(light < LEAF);
        Self {
            index: light | LEAF,
            pair: u32::MAX,
        }
    }
    fn interior(second: u32) -> Self {
        debug_assert!(second < LEAF);
        Self {
            index: second,
            pair: u32::MAX,
        }
    }
    #[inline]
    fn is_leaf(&self) -> bool {
        self.index & LEAF != 0
    }
    #[inline]
    fn target(&self) -> u32 {
        self.index & !LEAF
    }
}

/// Where a light is found by the sampler.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    /// Beside the tree (no bounds).
    Infinite,
    /// In the tree, at the end of this trail.
    Tree(u64),
    /// Never chosen (zero power).
    Never,
}

/// The BVH light sampler (module doc).
#[derive(Clone, Debug)]
pub struct BvhLightSampler {
    nodes: Vec<LightBvhNode>,
    /// The children's bounds of each interior node, side by side.
    pairs: Vec<PreparedPair>,
    /// The root's bounds (a tree of one light needs them).
    root: PreparedBounds,
    infinite: Vec<LightId>,
    slots: Vec<Slot>,
}

impl BvhLightSampler {
    /// Builds the tree over `lights` (after [`Light::preprocess`]).
    pub fn new(lights: &[Light]) -> Self {
        let mut slots = vec![Slot::Never; lights.len()];
        let mut infinite = Vec::new();
        let mut items = Vec::new();
        let mut all = Bounds3::EMPTY;
        for (i, light) in lights.iter().enumerate() {
            match light.bounds() {
                None => {
                    slots[i] = Slot::Infinite;
                    infinite.push(LightId(i as u32));
                }
                Some(lb) if lb.phi > 0.0 => {
                    all = all.union(lb.bounds);
                    items.push((i as u32, lb));
                }
                Some(_) => {}
            }
        }
        let mut b = build::Builder {
            nodes: Vec::with_capacity(2 * items.len()),
            bounds: Vec::with_capacity(2 * items.len()),
            slots: &mut slots,
            all,
        };
        if !items.is_empty() {
            b.node(&mut items, 0, 0);
        }
        let (mut nodes, bounds) = (b.nodes, b.bounds);
        let mut pairs = Vec::with_capacity(nodes.len() / 2);
        for (i, node) in nodes.iter_mut().enumerate() {
            if !node.is_leaf() {
                node.pair = pairs.len() as u32;
                pairs.push(PreparedPair::new(
                    &bounds[i + 1],
                    &bounds[node.target() as usize],
                ));
            }
        }
        Self {
            nodes,
            pairs,
            root: bounds.first().copied().unwrap_or_default(),
            infinite,
            slots,
        }
    }

    /// Number of tree nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Probability of choosing among the lights without bounds.
    #[inline]
    fn p_infinite(&self) -> f32 {
        let n = self.infinite.len() as f32;
        n / (n + if self.nodes.is_empty() { 0.0 } else { 1.0 })
    }

    /// Importance of the root at the receiver.
    #[inline]
    fn root_importance(&self, p: Vec3, n: Vec3) -> f32 {
        self.root.importance(p, n)
    }

    /// Probabilities of the two children of interior node `i`: I_k/(I₀ + I₁),
    /// or zeros when both importances are zero.
    #[inline]
    fn child_probabilities(&self, i: usize, p: Vec3, n: Vec3) -> [f32; 2] {
        let [c0, c1] = self.pairs[self.nodes[i].pair as usize]
            .importances(p, n)
            .map(f64::from);
        let sum = c0 + c1;
        if sum == 0.0 {
            return [0.0; 2];
        }
        [(c0 / sum) as f32, (c1 / sum) as f32]
    }

    /// Chooses a light for the receiver `ctx` with `u ∈ [0, 1)`; returns it
    /// and its probability, `None` when no light can reach `ctx` by the bounds.
    pub fn sample(&self, ctx: &LightSampleContext, u: f32) -> Option<(LightId, f32)> {
        let p_inf = self.p_infinite();
        if u < p_inf {
            let n = self.infinite.len();
            let k = ((u / p_inf * n as f32) as usize).min(n - 1);
            return Some((self.infinite[k], p_inf / n as f32));
        }
        if self.nodes.is_empty() {
            return None;
        }
        let (p, n) = (ctx.p, ctx.ns);
        let mut u = ((u - p_inf) / (1.0 - p_inf)).min(ONE_MINUS_EPSILON);
        let mut pmf = 1.0 - p_inf;
        let mut i = 0;
        loop {
            let node = &self.nodes[i];
            if node.is_leaf() {
                if i == 0 && self.root_importance(p, n) <= 0.0 {
                    return None;
                }
                return Some((LightId(node.target()), pmf));
            }
            let pr = self.child_probabilities(i, p, n);
            if pr == [0.0; 2] {
                return None;
            }
            if u < pr[0] {
                u = (u / pr[0]).min(ONE_MINUS_EPSILON);
                pmf *= pr[0];
                i += 1;
            } else {
                u = ((u - pr[0]) / pr[1]).min(ONE_MINUS_EPSILON);
                pmf *= pr[1];
                i = node.target() as usize;
            }
        }
    }

    /// Probability that [`sample`](Self::sample) returns `light` at `ctx`.
    pub fn pmf(&self, ctx: &LightSampleContext, light: LightId) -> f32 {
        let mut trail = match self.slots.get(light.0 as usize) {
            Some(Slot::Tree(t)) => *t,
            Some(Slot::Infinite) => return self.p_infinite() / self.infinite.len() as f32,
            Some(Slot::Never) | None => return 0.0,
        };
        let (p, n) = (ctx.p, ctx.ns);
        let mut pmf = 1.0 - self.p_infinite();
        let mut i = 0;
        loop {
            let node = &self.nodes[i];
            if node.is_leaf() {
                debug_assert_eq!(node.target(), light.0);
                if i == 0 && self.root_importance(p, n) <= 0.0 {
                    return 0.0;
                }
                return pmf;
            }
            let side = (trail & 1) as usize;
            let pr = self.child_probabilities(i, p, n);
            if pr[side] == 0.0 {
                return 0.0;
            }
            pmf *= pr[side];
            i = if side == 0 {
                i + 1
            } else {
                node.target() as usize
            };
            trail >>= 1;
        }
    }
}
