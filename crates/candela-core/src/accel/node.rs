//! The wide node: eight child boxes quantised to bytes, and the ray's slab
//! test against them.
//!
//! **Why quantise.** Incoherent rays over a large mesh wait on memory: a
//! profile of the 1M-triangle bench put over half of closest-hit time on the
//! first load of a node and of a triangle pack. With full-precision boxes an
//! 8-wide node is 256 bytes (four cache lines), and the bench mesh's nodes
//! are 21 MB, more than the caches hold beside the triangles. Storing each
//! child's box as 8-bit offsets on a per-node grid (Ylitie, Karras & Laine
//! 2017, "Efficient incoherent ray traversal on GPUs through compressed wide
//! BVHs"; Embree's compressed nodes) makes a node 96 bytes.
//!
//! **Conservative by construction.** Per axis a node stores an origin `o`
//! (the smallest child bound) and a power-of-two step `s = 2^e`. A bound `q`
//! decodes as `fl(o + q·s)`: `q·s` is exact (an 8-bit integer times a power
//! of two), so the only rounding is the addition's, which is monotone. Lower
//! bounds take the largest `q` whose decoded value is ≤ the true bound and
//! upper bounds the smallest whose value is ≥ it; the build checks this on
//! the very arithmetic the traversal does, so every decoded box contains its
//! child's box and the robust slab test below misses nothing the
//! full-precision test would find. The exponent is at least −126 (normal
//! steps only), which only makes tiny nodes' grids coarser.
//!
//! **Slab test** [pbrt-v4 §6.8.2; Ize 2013, "Robust BVH ray traversal"]: the
//! far distances are widened by 1 + 2γ₃ so rounding never culls a box the
//! ray touches, and `max`/`min` return their second operand when the first
//! is NaN, so a ray lying in a slab's boundary plane (0·∞) counts as inside
//! that slab.

use crate::math::{gamma, Bounds3, Ray};

/// Children per node.
pub(super) const WIDTH: usize = 8;
/// Child code of an unused slot.
pub(super) const EMPTY_CHILD: u32 = u32::MAX;
/// Smallest grid exponent (the smallest normal power of two).
const MIN_EXP: i32 = -126;

/// Eight child boxes on a per-axis byte grid, and their child codes (96 bytes).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(super) struct Node {
    /// Grid origin per axis.
    origin: [f32; 3],
    /// Grid step exponent per axis.
    exp: [i8; 3],
    /// `q[0]` lower and `q[1]` upper bounds: `q[b][axis][child]`.
    q: [[[u8; WIDTH]; 3]; 2],
    /// Child codes ([`EMPTY_CHILD`] for unused slots).
    pub child: [u32; WIDTH],
}

const _: () = assert!(std::mem::size_of::<Node>() == 96);

/// The step 2^e as an f32 (`MIN_EXP ≤ e ≤ 127`).
#[inline(always)]
fn step(e: i8) -> f32 {
    f32::from_bits(((e as i32 + 127) as u32) << 23)
}

/// The decoded bound `fl(origin + q·step)`, exactly as the traversal computes it.
#[inline(always)]
fn decode(origin: f32, step: f32, q: u8) -> f32 {
    origin + q as f32 * step
}

/// The smallest exponent `e ≥ MIN_EXP` with `lo + 255·2^e ≥ hi` (exactly).
fn grid_exponent(lo: f32, hi: f32) -> i8 {
    let extent = hi as f64 - lo as f64;
    let mut e = MIN_EXP;
    if extent > 0.0 {
        // 2^e ≥ extent/255, from the exponent of f64 (exact for powers of two).
        e = e.max((extent / 255.0).log2().ceil() as i32 - 1);
        while 255.0 * 2f64.powi(e) < extent {
            e += 1;
        }
    }
    e as i8
}

impl Node {
    /// A node over up to [`WIDTH`] `(bounds, child code)` pairs with finite bounds.
    pub fn new(children: &[(Bounds3, u32)]) -> Node {
        debug_assert!(children.len() <= WIDTH);
        let mut node = Node {
            origin: [0.0; 3],
            exp: [MIN_EXP as i8; 3],
            // Unused slots decode to inverted boxes; their code is checked anyway.
            q: [[[u8::MAX; WIDTH]; 3], [[0; WIDTH]; 3]],
            child: [EMPTY_CHILD; WIDTH],
        };
        for axis in 0..3 {
            let lo = children
                .iter()
                .map(|c| c.0.min[axis])
                .fold(f32::INFINITY, f32::min);
            let hi = children
                .iter()
                .map(|c| c.0.max[axis])
                .fold(f32::NEG_INFINITY, f32::max);
            if children.is_empty() {
                continue;
            }
            let mut e = grid_exponent(lo, hi);
            // Guards against the f64 extent having rounded down.
            while decode(lo, step(e), u8::MAX) < hi {
                e += 1;
            }
            node.origin[axis] = lo;
            node.exp[axis] = e;
            for (i, (b, _)) in children.iter().enumerate() {
                node.q[0][axis][i] = quantise_down(lo, step(e), b.min[axis]);
                node.q[1][axis][i] = quantise_up(lo, step(e), b.max[axis]);
            }
        }
        for (i, (_, code)) in children.iter().enumerate() {
            node.child[i] = *code;
        }
        node
    }

    /// The decoded box of child `i` (for tests).
    #[cfg(test)]
    pub fn child_box(&self, i: usize) -> ([f32; 3], [f32; 3]) {
        let d = |b: usize, a: usize| decode(self.origin[a], step(self.exp[a]), self.q[b][a][i]);
        ([0, 1, 2].map(|a| d(0, a)), [0, 1, 2].map(|a| d(1, a)))
    }

    /// The grid step along `axis`.
    #[inline(always)]
    pub fn step(&self, axis: usize) -> f32 {
        step(self.exp[axis])
    }

    /// The grid origin along `axis`.
    #[inline(always)]
    pub fn origin(&self, axis: usize) -> f32 {
        self.origin[axis]
    }

    /// The quantised bounds `b` (0 lower, 1 upper) of every child along `axis`.
    #[inline(always)]
    pub fn q(&self, b: usize, axis: usize) -> &[u8; WIDTH] {
        &self.q[b][axis]
    }
}

/// The largest `q` with `decode(q) ≤ x` (0 decodes to `origin ≤ x`).
fn quantise_down(origin: f32, step: f32, x: f32) -> u8 {
    let guess = ((x as f64 - origin as f64) / step as f64)
        .floor()
        .clamp(0.0, 255.0) as u8;
    let mut q = guess;
    while q > 0 && decode(origin, step, q) > x {
        q -= 1;
    }
    while q < u8::MAX && decode(origin, step, q + 1) <= x {
        q += 1;
    }
    q
}

/// The smallest `q` with `decode(q) ≥ x` (255 decodes to at least the node's
/// upper bound, by [`grid_exponent`] and monotone rounding).
fn quantise_up(origin: f32, step: f32, x: f32) -> u8 {
    let guess = ((x as f64 - origin as f64) / step as f64)
        .ceil()
        .clamp(0.0, 255.0) as u8;
    let mut q = guess;
    while q < u8::MAX && decode(origin, step, q) < x {
        q += 1;
    }
    while q > 0 && decode(origin, step, q - 1) >= x {
        q -= 1;
    }
    debug_assert!(decode(origin, step, q) >= x);
    q
}

/// A ray's constants for the slab test.
pub(super) struct RayBoxes {
    /// Origin.
    pub o: [f32; 3],
    /// Reciprocal direction.
    pub inv_dir: [f32; 3],
    /// Per axis: 1 when the direction is negative (the near plane is the upper one).
    pub neg: [usize; 3],
}

/// Far distances are widened by this factor [pbrt-v4 eq. 6.29 and §6.8.2].
#[inline(always)]
pub(super) fn widen() -> f32 {
    1.0 + 2.0 * gamma(3)
}

impl RayBoxes {
    /// Reciprocal direction and its signs.
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        let inv = ray.d.recip();
        RayBoxes {
            o: ray.o.to_array(),
            inv_dir: inv.to_array(),
            neg: [inv.x < 0.0, inv.y < 0.0, inv.z < 0.0].map(usize::from),
        }
    }
}

/// The slab test of a node's eight boxes against `(0, t_max)` (see the
/// module doc): the mask of hit children and their entry distances. Every
/// implementation performs the same IEEE operations in the same order, so
/// all return the same bits.
pub(super) trait NodeTest {
    /// Hit mask (bit i: child i) and entry distances.
    fn hits(ray: &RayBoxes, n: &Node, t_max: f32) -> (u32, [f32; WIDTH]);
}

/// One lane at a time: the reference the SIMD kernels are tested against,
/// and the kernel on targets without one.
#[cfg(any(test, not(target_arch = "x86_64")))]
pub(super) struct Scalar;

#[cfg(any(test, not(target_arch = "x86_64")))]
impl NodeTest for Scalar {
    #[inline(always)]
    fn hits(ray: &RayBoxes, n: &Node, t_max: f32) -> (u32, [f32; WIDTH]) {
        let (mut mask, mut entry) = (0, [0.0; WIDTH]);
        for (i, t_entry) in entry.iter_mut().enumerate() {
            let (mut t0, mut t1) = (0.0f32, t_max);
            for axis in 0..3 {
                let (neg, s) = (ray.neg[axis], n.step(axis));
                let lo = decode(n.origin[axis], s, n.q[neg][axis][i]);
                let hi = decode(n.origin[axis], s, n.q[1 - neg][axis][i]);
                let near = (lo - ray.o[axis]) * ray.inv_dir[axis];
                let far = (hi - ray.o[axis]) * ray.inv_dir[axis] * widen();
                // SSE's max/min: the second operand unless the first is greater/less.
                t0 = if near > t0 { near } else { t0 };
                t1 = if far < t1 { far } else { t1 };
            }
            mask |= u32::from(t0 <= t1) << i;
            *t_entry = t0;
        }
        (mask, entry)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::sampling::Pcg32;

    /// Random boxes at scales from 1e-30 to 1e30 around random centres.
    fn random_children(r: &mut Pcg32, n: usize) -> Vec<(Bounds3, u32)> {
        let scale = 10f32.powf(r.uniform_f32() * 60.0 - 30.0);
        let centre = Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32()) * 1e3 - 500.0;
        (0..n)
            .map(|i| {
                let p = |r: &mut Pcg32| {
                    centre * scale.min(1.0)
                        + Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32()) * scale
                };
                let (a, b) = (p(r), p(r));
                (Bounds3::from_points(a, b), i as u32)
            })
            .collect()
    }

    #[test]
    fn decoded_boxes_contain_the_children_tightly() {
        let mut r = Pcg32::new(7, 1);
        for _ in 0..20_000 {
            let n = 1 + (r.uniform_f32() * 8.0) as usize % 8;
            let kids = random_children(&mut r, n);
            let node = Node::new(&kids);
            for (i, (b, code)) in kids.iter().enumerate() {
                assert_eq!(node.child[i], *code);
                let (lo, hi) = node.child_box(i);
                for a in 0..3 {
                    assert!(
                        lo[a] <= b.min[a] && hi[a] >= b.max[a],
                        "{lo:?} {hi:?} {b:?}"
                    );
                    // Tight: one grid step less would cut the child.
                    let s = step(node.exp[a]);
                    let q = node.q[0][a][i];
                    assert!(q == 255 || decode(node.origin[a], s, q + 1) > b.min[a]);
                    let q = node.q[1][a][i];
                    assert!(q == 0 || decode(node.origin[a], s, q - 1) < b.max[a]);
                }
            }
        }
    }

    #[test]
    fn extreme_extents_stay_conservative() {
        let big = Bounds3::from_points(Vec3::splat(-3.0e38), Vec3::splat(3.0e38));
        let tiny = Bounds3::from_points(Vec3::splat(1e-40), Vec3::splat(2e-40));
        let flat = Bounds3::from_points(Vec3::splat(5.0), Vec3::splat(5.0));
        for kids in [
            vec![(big, 0), (tiny, 1)],
            vec![(tiny, 0)],
            vec![(flat, 0), (tiny, 1)],
        ] {
            let node = Node::new(&kids);
            for (i, (b, _)) in kids.iter().enumerate() {
                let (lo, hi) = node.child_box(i);
                for a in 0..3 {
                    assert!(
                        lo[a] <= b.min[a] && hi[a] >= b.max[a],
                        "{lo:?} {hi:?} {b:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_grid_exponent_one_smaller_would_not_reach_the_top() {
        for (lo, hi) in [
            (0.0f32, 255.0f32),
            (0.0, 255.5),
            (-1.0, 1.0),
            (3.0, 3.0),
            (1e-3, 7e5),
        ] {
            let e = grid_exponent(lo, hi) as i32;
            let reach = |e: i32| lo as f64 + 255.0 * 2f64.powi(e);
            assert!(reach(e) >= hi as f64);
            assert!(e == MIN_EXP || reach(e - 1) < hi as f64, "{lo} {hi} {e}");
        }
    }
}
