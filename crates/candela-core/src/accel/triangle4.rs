//! Four triangles at a time: the watertight test of
//! [`crate::shape::WatertightRay`] on SIMD lanes.
//!
//! A [`TriPack`] holds the vertices of up to four triangles in
//! structure-of-arrays form (`v[vertex][axis]` is a 4-lane vector), as the
//! kernel reads them; unused lanes hold NaN vertices, which fail every
//! comparison and so never hit. The test performs, lane by lane, exactly the
//! floating-point operations of the scalar test in the same order (translate,
//! permute, shear; edge functions; scaled-`t` range test; division; the
//! conservative `t` error bound of pbrt-v4 §6.8.4), so a lane accepts a hit
//! exactly when the scalar test does and reports the same `t` and
//! barycentrics [Woop, Benthin and Wald 2013; pbrt-v4 §6.5.3]. Lanes where an
//! edge function is exactly zero (the ray passes through an edge or vertex)
//! are handed to the scalar test, which re-evaluates them in f64. One
//! deliberate difference: a lane whose `t` comparisons are NaN (a triangle
//! with non-finite vertices) is rejected, where the scalar test's negated
//! comparisons would let it through.

use crate::math::{gamma, Vec3};
use crate::shape::{TriangleIntersection, WatertightRay};
use wide::{f32x4, CmpEq, CmpGe, CmpGt, CmpLe, CmpLt};

/// Lane id of an unused lane.
pub(super) const EMPTY_LANE: u32 = u32::MAX;
/// Tag on the lane id of an item that is not a packed triangle (the caller
/// tests it).
pub(super) const OTHER_TAG: u32 = 1 << 31;

/// Up to four triangles, laid out for [`Tri4Ray`]'s test (160 bytes).
#[derive(Clone, Copy, Debug)]
pub(super) struct TriPack {
    /// `v[vertex][axis]`: one coordinate of one vertex of the four triangles.
    v: [[f32x4; 3]; 3],
    /// Item index per lane, [`OTHER_TAG`]-tagged for items the caller
    /// tests, [`EMPTY_LANE`] for none.
    pub ids: [u32; 4],
}

impl TriPack {
    /// A pack of `lanes` (at most four): triangles with their vertices, or
    /// other items (`None`), with the item index of each.
    pub fn new(lanes: &[(u32, Option<[Vec3; 3]>)]) -> TriPack {
        debug_assert!(lanes.len() <= 4);
        let mut v = [[[f32::NAN; 4]; 3]; 3];
        let mut ids = [EMPTY_LANE; 4];
        for (lane, &(id, tri)) in lanes.iter().enumerate() {
            match tri {
                Some(p) => {
                    ids[lane] = id;
                    for (j, pj) in p.iter().enumerate() {
                        for axis in 0..3 {
                            v[j][axis][lane] = pj[axis];
                        }
                    }
                }
                None => ids[lane] = id | OTHER_TAG,
            }
        }
        TriPack {
            v: v.map(|vj| vj.map(f32x4::from)),
            ids,
        }
    }

    /// The vertices of the triangle in `lane`.
    fn vertices(&self, lane: usize) -> [Vec3; 3] {
        self.v.map(|vj| {
            let [x, y, z] = vj.map(|c| c.to_array()[lane]);
            Vec3::new(x, y, z)
        })
    }
}

/// A ray's constants for the pack test, splatted over the lanes.
pub(super) struct Tri4Ray {
    scalar: WatertightRay,
    k: [usize; 3],
    o: [f32x4; 3],
    s: [f32x4; 3],
}

/// Lanes that passed the test, with what the closest-hit choice needs.
struct Lanes {
    /// Bit i: lane i hit with `t < t_max`.
    hit: i32,
    /// Bit i: lane i needs the scalar test (an edge function is zero).
    exact: i32,
    t: f32x4,
    e: [f32x4; 3],
    inv_det: f32x4,
}

impl Tri4Ray {
    /// The constants of `wr` (permuted origin, shear) in SIMD form.
    #[inline]
    pub fn new(wr: &WatertightRay) -> Self {
        let (o, k, s) = wr.parts();
        Tri4Ray {
            scalar: *wr,
            k,
            o: k.map(|a| f32x4::splat(o[a])),
            s: [s.x, s.y, s.z].map(f32x4::splat),
        }
    }

    /// The pack test on all four lanes (see the module doc).
    #[inline(always)]
    fn test(&self, pack: &TriPack, t_max: f32) -> Lanes {
        let [kx, ky, kz] = self.k;
        // Translate to the ray origin, permute, shear x and y.
        let sheared = |j: usize| {
            let z = pack.v[j][kz] - self.o[2];
            let x = (pack.v[j][kx] - self.o[0]) + self.s[0] * z;
            let y = (pack.v[j][ky] - self.o[1]) + self.s[1] * z;
            (x, y, z)
        };
        let (x0, y0, z0) = sheared(0);
        let (x1, y1, z1) = sheared(1);
        let (x2, y2, z2) = sheared(2);
        let e0 = x1 * y2 - y1 * x2;
        let e1 = x2 * y0 - y2 * x0;
        let e2 = x0 * y1 - y0 * x1;
        let zero = f32x4::ZERO;
        let exact = (e0.cmp_eq(zero) | e1.cmp_eq(zero) | e2.cmp_eq(zero)).move_mask();
        let any_neg = e0.cmp_lt(zero) | e1.cmp_lt(zero) | e2.cmp_lt(zero);
        let any_pos = e0.cmp_gt(zero) | e1.cmp_gt(zero) | e2.cmp_gt(zero);
        let det = e0 + e1 + e2;
        let (z0, z1, z2) = (z0 * self.s[2], z1 * self.s[2], z2 * self.s[2]);
        let ts = e0 * z0 + e1 * z1 + e2 * z2;
        let tm_det = f32x4::splat(t_max) * det;
        let neg_ok = det.cmp_lt(zero) & ts.cmp_lt(zero) & ts.cmp_ge(tm_det);
        let pos_ok = det.cmp_gt(zero) & ts.cmp_gt(zero) & ts.cmp_le(tm_det);
        let pass = (neg_ok | pos_ok) & !(any_neg & any_pos);
        let mut lanes = Lanes {
            hit: pass.move_mask() & !exact,
            exact,
            t: zero,
            e: [e0, e1, e2],
            inv_det: zero,
        };
        if lanes.hit == 0 {
            return lanes;
        }
        let inv_det = f32x4::ONE / det;
        let t = ts * inv_det;
        // The conservative bound on t's rounding error [pbrt-v4 eqs. 6.58–6.62].
        let max3 = |a: f32x4, b: f32x4, c: f32x4| zero.max(a.abs()).max(b.abs()).max(c.abs());
        let max_zt = max3(z0, z1, z2);
        let max_xt = max3(x0, x1, x2);
        let max_yt = max3(y0, y1, y2);
        let g = |n| f32x4::splat(gamma(n));
        let delta_z = g(3) * max_zt;
        let delta_x = g(5) * (max_xt + max_zt);
        let delta_y = g(5) * (max_yt + max_zt);
        let delta_e =
            f32x4::splat(2.0) * (g(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let bound = f32x4::splat(3.0)
            * (g(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e)
            * inv_det.abs();
        let ok = t.cmp_gt(bound) & t.cmp_lt(f32x4::splat(t_max));
        lanes.hit &= ok.move_mask();
        lanes.t = t;
        lanes.inv_det = inv_det;
        lanes
    }

    /// The closest hit in the pack with `t < t_max`: its lane and intersection.
    #[inline(always)]
    pub fn closest(&self, pack: &TriPack, t_max: f32) -> Option<(usize, TriangleIntersection)> {
        let lanes = self.test(pack, t_max);
        if lanes.hit | lanes.exact == 0 {
            return None;
        }
        let mut best = None;
        let mut t_best = t_max;
        if lanes.hit != 0 {
            let t = lanes.t.to_array();
            for (lane, &t) in t.iter().enumerate() {
                if lanes.hit & (1 << lane) != 0 && t < t_best {
                    t_best = t;
                    best = Some(lane);
                }
            }
        }
        let mut found = best.map(|lane| {
            let inv = lanes.inv_det.to_array()[lane];
            let b = lanes.e.map(|e| e.to_array()[lane] * inv);
            (lane, TriangleIntersection { b, t: t_best })
        });
        for lane in (0..4).filter(|l| lanes.exact & (1 << l) != 0) {
            if let Some(h) = self.exact(pack, lane, t_best) {
                t_best = h.t;
                found = Some((lane, h));
            }
        }
        found
    }

    /// True if some triangle of the pack is hit with `t < t_max`.
    #[inline(always)]
    pub fn any(&self, pack: &TriPack, t_max: f32) -> bool {
        let lanes = self.test(pack, t_max);
        lanes.hit != 0
            || (lanes.exact != 0
                && (0..4)
                    .any(|l| lanes.exact & (1 << l) != 0 && self.exact(pack, l, t_max).is_some()))
    }

    /// The scalar test of one lane (for rays through an edge or vertex).
    #[cold]
    fn exact(&self, pack: &TriPack, lane: usize, t_max: f32) -> Option<TriangleIntersection> {
        let [p0, p1, p2] = pack.vertices(lane);
        self.scalar
            .intersect(t_max, p0, p1, p2)
            .filter(|h| h.t < t_max)
    }
}
