//! CPU intrinsics for the BVH: the only module of candela with `unsafe`
//! code (the workspace denies it elsewhere).
//!
//! What it buys, measured on the 1M-triangle bench (`bench/bvh_vs_embree.py`,
//! numbers in the issue notes): decoding a quantised node's 48 bytes into
//! eight boxes takes a few vector instructions with `pmovzx`/`punpck`
//! where portable code converts lane by lane, and AVX2 tests all eight
//! boxes in one register instead of two halves; prefetching the children a
//! traversal will pop later overlaps their cache misses.
//!
//! The safe API: [`prefetch`], and [`intersect`]/[`intersect_p`], which run
//! the BVH traversal (written once, in safe code, generic over
//! [`NodeTest`]) with the best node kernel the CPU has: AVX2 when
//! `is_x86_feature_detected!` finds it at run time, else SSE2 (part of
//! x86-64), else [`Scalar`]. The kernels perform the same IEEE operations as
//! [`Scalar`] in the same order (a fused multiply-add decodes, which is
//! exact there: the product of an 8-bit integer and a power of two needs no
//! rounding), so every CPU traverses identically; `tests` checks them
//! against [`Scalar`] bit for bit.

#![allow(unsafe_code)]

use super::bvh::{Bvh, BvhHit};
#[cfg(not(target_arch = "x86_64"))]
use super::node::Scalar;
use super::node::{Node, NodeTest, RayBoxes, WIDTH};
use crate::math::Ray;
use std::mem::MaybeUninit;

/// Asks the CPU to bring the cache line holding `r` into its caches.
#[inline(always)]
pub(super) fn prefetch<T>(r: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is a hint; it never faults nor changes memory, and
    // `r` is a valid reference anyway.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>((r as *const T).cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = r;
}

/// Prefetches every cache line `r` spans.
#[inline(always)]
pub(super) fn prefetch_all<T>(r: &T) {
    let p = (r as *const T).cast::<u8>();
    let size = std::mem::size_of::<T>();
    let lines = (p as usize + size - 1) / 64 - p as usize / 64;
    prefetch(r);
    for line in 1..=lines {
        let next = p.wrapping_add(line * 64 - p as usize % 64);
        #[cfg(target_arch = "x86_64")]
        // SAFETY: a prefetch never faults, whatever the address.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            _mm_prefetch::<_MM_HINT_T0>(next.cast());
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = next;
    }
}

/// Entries a [`Stack`] holds before it spills to the heap: enough for every
/// tree but adversarial ones (see [`super::build`]).
const STACK: usize = 64;

/// The traversal stack: [`STACK`] entries on the call stack, left
/// uninitialised (zeroing them cost ~1 % of a ray), then a heap vector.
pub(super) struct Stack<T> {
    slots: [MaybeUninit<T>; STACK],
    /// Invariant: `slots[..len]` are initialised.
    len: usize,
    /// Entries pushed while `slots` was full (popped first).
    spill: Vec<T>,
}

impl<T: Copy> Stack<T> {
    /// An empty stack.
    #[inline(always)]
    pub fn new() -> Self {
        Stack {
            slots: [const { MaybeUninit::uninit() }; STACK],
            len: 0,
            spill: Vec::new(),
        }
    }

    /// Pushes `v`.
    #[inline(always)]
    pub fn push(&mut self, v: T) {
        if self.len < STACK {
            self.slots[self.len].write(v);
            self.len += 1;
        } else {
            self.spill.push(v);
        }
    }

    /// Pops the last entry pushed.
    #[inline(always)]
    pub fn pop(&mut self) -> Option<T> {
        if let Some(v) = self.spill.pop() {
            return Some(v);
        }
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: `slots[..len]` are initialised (written by `push`).
        Some(unsafe { self.slots[self.len].assume_init() })
    }
}

/// Closest hit with the best kernel of this CPU (see [`Bvh::intersect`]).
#[inline]
pub(super) fn intersect<F>(bvh: &Bvh, ray: &Ray, t_max: f32, other: F) -> Option<BvhHit>
where
    F: FnMut(u32, &Ray, f32) -> Option<f32>,
{
    #[cfg(target_arch = "x86_64")]
    {
        if x86::has_avx2() {
            // SAFETY: the CPU has AVX2 and FMA (checked just above).
            return unsafe { x86::intersect_avx2(bvh, ray, t_max, other) };
        }
        bvh.intersect_with::<x86::Sse2, F>(ray, t_max, other)
    }
    #[cfg(not(target_arch = "x86_64"))]
    bvh.intersect_with::<Scalar, F>(ray, t_max, other)
}

/// Any hit with the best kernel of this CPU (see [`Bvh::intersect_p`]).
#[inline]
pub(super) fn intersect_p<F>(bvh: &Bvh, ray: &Ray, t_max: f32, other: F) -> bool
where
    F: FnMut(u32, &Ray, f32) -> bool,
{
    #[cfg(target_arch = "x86_64")]
    {
        if x86::has_avx2() {
            // SAFETY: the CPU has AVX2 and FMA (checked just above).
            return unsafe { x86::intersect_p_avx2(bvh, ray, t_max, other) };
        }
        bvh.intersect_p_with::<x86::Sse2, F>(ray, t_max, other)
    }
    #[cfg(not(target_arch = "x86_64"))]
    bvh.intersect_p_with::<Scalar, F>(ray, t_max, other)
}

#[cfg(target_arch = "x86_64")]
pub(super) mod x86 {
    //! The SSE2 and AVX2 node kernels and the AVX2 traversal entry points.

    use super::*;
    use crate::accel::node::widen;
    use std::arch::x86_64::*;

    /// True when the CPU runs AVX2 and FMA (cached by the standard library).
    #[inline(always)]
    pub fn has_avx2() -> bool {
        is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")
    }

    /// The traversal compiled for AVX2: the kernel below inlines into it.
    #[target_feature(enable = "avx2,fma")]
    pub fn intersect_avx2<F>(bvh: &Bvh, ray: &Ray, t_max: f32, other: F) -> Option<BvhHit>
    where
        F: FnMut(u32, &Ray, f32) -> Option<f32>,
    {
        bvh.intersect_with::<Avx2, F>(ray, t_max, other)
    }

    /// The any-hit traversal compiled for AVX2.
    #[target_feature(enable = "avx2,fma")]
    pub fn intersect_p_avx2<F>(bvh: &Bvh, ray: &Ray, t_max: f32, other: F) -> bool
    where
        F: FnMut(u32, &Ray, f32) -> bool,
    {
        bvh.intersect_p_with::<Avx2, F>(ray, t_max, other)
    }

    /// Eight bytes as the low half of a vector (a `movq` load).
    #[target_feature(enable = "sse2")]
    #[inline]
    fn low_bytes(q: &[u8; WIDTH]) -> __m128i {
        _mm_set_epi64x(0, i64::from_le_bytes(*q))
    }

    /// Eight lanes in two SSE halves.
    pub struct Sse2;

    impl NodeTest for Sse2 {
        #[inline(always)]
        fn hits(ray: &RayBoxes, n: &Node, t_max: f32) -> (u32, [f32; WIDTH]) {
            // SAFETY: SSE2 is part of x86-64.
            unsafe { sse2_hits(ray, n, t_max) }
        }
    }

    /// The SSE2 node kernel (see [`NodeTest`]).
    #[target_feature(enable = "sse2")]
    #[inline]
    fn sse2_hits(ray: &RayBoxes, n: &Node, t_max: f32) -> (u32, [f32; WIDTH]) {
        let zero = _mm_setzero_ps();
        let widen = _mm_set1_ps(widen());
        // Bounds b of children 4h..4h+4 along `axis`: zero-extend, convert, scale, shift.
        let decode = |b: usize, axis: usize| {
            let w = _mm_unpacklo_epi8(low_bytes(n.q(b, axis)), _mm_setzero_si128());
            let (s, o) = (_mm_set1_ps(n.step(axis)), _mm_set1_ps(n.origin(axis)));
            [
                _mm_unpacklo_epi16(w, _mm_setzero_si128()),
                _mm_unpackhi_epi16(w, _mm_setzero_si128()),
            ]
            .map(|q| _mm_add_ps(_mm_mul_ps(_mm_cvtepi32_ps(q), s), o))
        };
        let (mut t0, mut t1) = ([zero; 2], [_mm_set1_ps(t_max); 2]);
        for axis in 0..3 {
            let neg = ray.neg[axis];
            let (lo, hi) = (decode(neg, axis), decode(1 - neg, axis));
            let (o, inv) = (_mm_set1_ps(ray.o[axis]), _mm_set1_ps(ray.inv_dir[axis]));
            for h in 0..2 {
                let near = _mm_mul_ps(_mm_sub_ps(lo[h], o), inv);
                let far = _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(hi[h], o), inv), widen);
                t0[h] = _mm_max_ps(near, t0[h]);
                t1[h] = _mm_min_ps(far, t1[h]);
            }
        }
        let mask = |h: usize| _mm_movemask_ps(_mm_cmple_ps(t0[h], t1[h])) as u32;
        let entry: [[f32; 4]; 2] = t0.map(|t| {
            let mut a = [0.0; 4];
            // SAFETY: `a` has room for the four lanes `storeu` writes.
            unsafe { _mm_storeu_ps(a.as_mut_ptr(), t) };
            a
        });
        let mut out = [0.0; WIDTH];
        out[..4].copy_from_slice(&entry[0]);
        out[4..].copy_from_slice(&entry[1]);
        (mask(0) | mask(1) << 4, out)
    }

    /// Eight lanes in one AVX register; only valid inside the `*_avx2`
    /// entry points above, whose AVX2 code generation it inlines into.
    pub struct Avx2;

    impl NodeTest for Avx2 {
        #[inline(always)]
        fn hits(ray: &RayBoxes, n: &Node, t_max: f32) -> (u32, [f32; WIDTH]) {
            // SAFETY: `Avx2` is only used by the traversals compiled in
            // `intersect_avx2`/`intersect_p_avx2`, which run only once
            // `has_avx2` has found AVX2 and FMA.
            unsafe { avx2_hits(ray, n, t_max) }
        }
    }

    /// The AVX2 node kernel (see [`NodeTest`]).
    #[target_feature(enable = "avx2,fma")]
    #[inline]
    fn avx2_hits(ray: &RayBoxes, n: &Node, t_max: f32) -> (u32, [f32; WIDTH]) {
        let widen = _mm256_set1_ps(widen());
        let (mut t0, mut t1) = (_mm256_setzero_ps(), _mm256_set1_ps(t_max));
        for axis in 0..3 {
            let neg = ray.neg[axis];
            let (s, orig) = (_mm256_set1_ps(n.step(axis)), _mm256_set1_ps(n.origin(axis)));
            let lo = _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(low_bytes(n.q(neg, axis))));
            let hi = _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(low_bytes(n.q(1 - neg, axis))));
            // Exact products: one rounding, as the scalar multiply-then-add.
            let (lo, hi) = (_mm256_fmadd_ps(lo, s, orig), _mm256_fmadd_ps(hi, s, orig));
            let (o, inv) = (
                _mm256_set1_ps(ray.o[axis]),
                _mm256_set1_ps(ray.inv_dir[axis]),
            );
            let near = _mm256_mul_ps(_mm256_sub_ps(lo, o), inv);
            let far = _mm256_mul_ps(_mm256_mul_ps(_mm256_sub_ps(hi, o), inv), widen);
            t0 = _mm256_max_ps(near, t0);
            t1 = _mm256_min_ps(far, t1);
        }
        let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(t0, t1)) as u32;
        let mut entry = [0.0; WIDTH];
        // SAFETY: `entry` has room for the eight lanes `storeu` writes.
        unsafe { _mm256_storeu_ps(entry.as_mut_ptr(), t0) };
        (mask, entry)
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::x86::{has_avx2, Avx2, Sse2};
    use super::*;
    use crate::accel::node::Scalar;
    use crate::math::{Bounds3, Vec3};
    use crate::sampling::{sample_uniform_sphere, Pcg32};
    use glam::Vec2;

    #[target_feature(enable = "avx2,fma")]
    fn avx2_hits(ray: &RayBoxes, n: &Node, t_max: f32) -> (u32, [f32; WIDTH]) {
        Avx2::hits(ray, n, t_max)
    }

    /// Random nodes (some with empty slots and flat boxes) and rays (some
    /// axis-parallel, starting in a slab plane): SSE2 and AVX2 return the
    /// scalar reference's bits.
    #[test]
    fn stack_is_last_in_first_out_past_its_inline_slots() {
        let mut s = Stack::new();
        for round in 0..2 {
            for i in 0..3 * STACK as u32 {
                s.push(i + round);
            }
            for i in (0..3 * STACK as u32).rev() {
                assert_eq!(s.pop(), Some(i + round));
            }
            assert_eq!(s.pop(), None);
        }
    }

    #[test]
    fn kernels_match_the_scalar_reference_bit_for_bit() {
        let mut r = Pcg32::new(3, 9);
        let mut u = move || r.uniform_f32();
        let (mut hits, mut misses) = (0, 0);
        for k in 0..50_000 {
            let kids: Vec<(Bounds3, u32)> = (0..1 + k % 8)
                .map(|i| {
                    let a = Vec3::new(u(), u(), u()) * 2.0 - 1.0;
                    let flat = Vec3::new(u(), u(), u()) * if k % 5 == 0 { 0.0 } else { 0.5 };
                    (Bounds3::from_points(a, a + flat), i as u32)
                })
                .collect();
            let node = Node::new(&kids);
            let o = if k % 11 == 0 {
                Vec3::new(node.origin(0), u(), u())
            } else {
                Vec3::new(u(), u(), u()) * 4.0 - 2.0
            };
            // Most rays aim at a child's centre, the others anywhere.
            let aim = kids[k % kids.len()].0;
            let mut d = if k % 4 == 0 {
                sample_uniform_sphere(Vec2::new(u(), u()))
            } else {
                ((aim.min + aim.max) * 0.5 - o).normalize_or(Vec3::X)
            };
            if k % 7 == 0 {
                d = Vec3::new(0.0, 0.0, if u() < 0.5 { 1.0 } else { -1.0 });
            }
            let ray = RayBoxes::new(&Ray::new(o, d));
            let t_max = if k % 3 == 0 { f32::INFINITY } else { 3.0 * u() };
            let want = Scalar::hits(&ray, &node, t_max);
            let bits = |(m, t): (u32, [f32; WIDTH])| (m, t.map(f32::to_bits));
            assert_eq!(bits(Sse2::hits(&ray, &node, t_max)), bits(want));
            if has_avx2() {
                // SAFETY: the CPU has AVX2 and FMA.
                assert_eq!(bits(unsafe { avx2_hits(&ray, &node, t_max) }), bits(want));
            }
            hits += (want.0 & ((1 << kids.len()) - 1)).count_ones();
            misses += (!want.0 & ((1 << kids.len()) - 1)).count_ones();
        }
        // Both outcomes must be common for the comparison to mean anything.
        assert!(
            hits > 10_000 && misses > 10_000,
            "{hits} hits, {misses} misses"
        );
    }
}
