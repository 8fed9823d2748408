//! Geometry of one bilinear patch: ray intersection, surface area and the
//! inverse of the bilinear map.
//!
//! A patch with corners p₀₀, p₁₀, p₀₁, p₁₁ is
//! p(u, v) = lerp(v, lerp(u, p₀₀, p₁₀), lerp(u, p₀₁, p₁₁)) on \[0,1\]².
//!
//! **Intersection** follows Reshetov 2019, "Cool Patches: A Geometric
//! Approach to Ray/Bilinear Patch Intersections" (Ray Tracing Gems, ch. 8),
//! as pbrt-v4 §6.6.1 uses it. For fixed u the patch contains the segment
//! from pa(u) = lerp(u, p₀₀, p₁₀) to pb(u) = lerp(u, p₀₁, p₁₁); the ray
//! meets that segment's line iff the two lines are coplanar, i.e.
//! (pa − o)·(d × (pb − pa)) = 0, a quadratic a + bu + cu² in u. Each root
//! in [0, 1] gives the closest points of the two lines, hence t and v. We
//! evaluate it in double precision: pbrt-v4 leaves the rounding error of t
//! unbounded ("TODO: reject hits with sufficiently small t"). In f64 the
//! error of t is about 2⁻⁵³·|pa|/|d| (pa: the operand from the ray origin to
//! the patch), far below the offset of a spawned ray, which moves the origin
//! by at least one f32 ulp (2⁻²⁴ relative) off the surface, so roots with
//! t ≤ 10⁻¹⁰·|pa|/|d| are rejected as the origin's own surface. That offset
//! is zero where the patch lies in a coordinate plane (its corners' error
//! bound vanishes there), so a ray leaving such a patch starts exactly on it
//! and, without the bound, re-hit it at t ≈ 10⁻¹⁷ forever (an `interface`
//! floor at y = 0 hung the path tracer, which does not count crossings of
//! material-less surfaces as bounces). Roots within 1e-9 of the patch's
//! parameter edges are accepted and clamped, so a ray through the edge shared
//! by two patches cannot slip between them.
//!
//! **Area**: ∂p/∂u × ∂p/∂v = c₀ + u·c_u + v·c_v is affine in (u, v). When its
//! four corner values are parallel and point the same way (every planar patch
//! that does not fold over), |c| is affine on the square and the area is
//! exactly |c(½, ½)|. Otherwise the area is integrated with 8-point
//! Gauss–Legendre rules on each quarter of the square (pbrt-v4 instead sums
//! the areas of 3 × 3 × 2 triangles).
//!
//! **Inverse map** (for texture coordinates): p − p₀₀ = u·e + v·f + uv·g in
//! 2D gives, after a cross product with e + v·g, the quadratic
//! k₂v² + k₁v + k₀ = 0 with k₂ = g × f, k₁ = e × f + h × g, k₀ = h × e
//! [Quílez, "Inverse bilinear interpolation", 2010].

use crate::math::{Ray, Vec2, Vec3};
use glam::{DVec2, DVec3};

/// Parameter slack at the patch edges (see the module doc).
const EDGE_EPS: f64 = 1e-9;

/// Parameters of a ray–patch hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BilinearIntersection {
    /// Patch parameters (u, v) ∈ \[0,1\]².
    pub uv: Vec2,
    /// Ray parameter.
    pub t: f32,
}

/// Relative rounding bound of a root's t (module docs).
const T_EPS: f64 = 1e-10;

/// Closest hit of `ray` with the patch `[p00, p10, p01, p11]` for
/// `t ∈ (0, t_max)` [Reshetov 2019].
pub fn intersect_bilinear_patch(
    ray: &Ray,
    t_max: f32,
    p: &[Vec3; 4],
) -> Option<BilinearIntersection> {
    let (o, d) = (ray.o.as_dvec3(), ray.d.as_dvec3());
    let [p00, p10, p01, p11] = p.map(|q| q.as_dvec3());
    let (q00, q10) = (p00 - o, p10 - o);
    let (e00, e11, e10) = (p01 - p00, p11 - p10, p10 - p00);
    // f(u) = lerp(u, q00, q10) · (d × lerp(u, e00, e11)) = a + b u + c u².
    let a = q00.cross(d).dot(e00);
    let c = e10.cross(e00 - e11).dot(d);
    let b = q10.cross(d).dot(e11) - a - c;
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    // Stable roots; c = 0 (a trapezoid) leaves the single root −a/b in a/q.
    let q = -0.5 * (b + disc.sqrt().copysign(b));
    let mut best: Option<(f64, f64, f64)> = None;
    for u in [q / c, a / q] {
        if !(-EDGE_EPS..=1.0 + EDGE_EPS).contains(&u) {
            continue; // also rejects NaN
        }
        let pa = q00.lerp(q10, u);
        let pb = e00.lerp(e11, u);
        // Closest points of the ray and the line pa + v·pb.
        let n = d.cross(pb);
        let det = n.length_squared();
        if det == 0.0 {
            continue;
        }
        let m = n.cross(pa);
        let (t, v) = (m.dot(pb) / det, m.dot(d) / det);
        let v_ok = (-EDGE_EPS..=1.0 + EDGE_EPS).contains(&v);
        let t_min = T_EPS * pa.length() / d.length();
        if v_ok && t > t_min && best.is_none_or(|(tb, _, _)| t < tb) {
            best = Some((t, u, v));
        }
    }
    let (t, u, v) = best?;
    let t = t as f32;
    if !(t > 0.0 && t < t_max) {
        return None;
    }
    Some(BilinearIntersection {
        uv: Vec2::new(u.clamp(0.0, 1.0) as f32, v.clamp(0.0, 1.0) as f32),
        t,
    })
}

/// The point p(u, v) of the patch.
#[inline]
pub fn bilerp3(p: &[Vec3; 4], uv: Vec2) -> Vec3 {
    let pu0 = p[0].lerp(p[2], uv.y);
    let pu1 = p[1].lerp(p[3], uv.y);
    pu0.lerp(pu1, uv.x)
}

/// The texture coordinate of (u, v) for corner values `t`.
#[inline]
pub fn bilerp2(t: &[Vec2; 4], uv: Vec2) -> Vec2 {
    let a = t[0].lerp(t[2], uv.y);
    let b = t[1].lerp(t[3], uv.y);
    a.lerp(b, uv.x)
}

/// ∂p/∂u and ∂p/∂v at (u, v).
#[inline]
pub fn partials(p: &[Vec3; 4], uv: Vec2) -> (Vec3, Vec3) {
    let dpdu = p[1].lerp(p[3], uv.y) - p[0].lerp(p[2], uv.y);
    let dpdv = p[2].lerp(p[3], uv.x) - p[0].lerp(p[1], uv.x);
    (dpdu, dpdv)
}

/// |∂p/∂u × ∂p/∂v| at the corners (0,0), (1,0), (0,1), (1,1): the weights of
/// pbrt-v4's approximately area-uniform bilinear warp.
pub fn corner_area_weights(p: &[Vec3; 4]) -> [f32; 4] {
    let [p00, p10, p01, p11] = *p;
    [
        (p10 - p00).cross(p01 - p00).length(),
        (p10 - p00).cross(p11 - p10).length(),
        (p11 - p01).cross(p01 - p00).length(),
        (p11 - p01).cross(p11 - p10).length(),
    ]
}

/// Gauss–Legendre nodes and weights on [0, 1] (8 points).
const GL8: [(f64, f64); 8] = {
    const X: [f64; 4] = [
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ];
    const W: [f64; 4] = [
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ];
    let mut out = [(0.0, 0.0); 8];
    let mut i = 0;
    while i < 4 {
        out[2 * i] = (0.5 * (1.0 - X[i]), 0.5 * W[i]);
        out[2 * i + 1] = (0.5 * (1.0 + X[i]), 0.5 * W[i]);
        i += 1;
    }
    out
};

/// Surface area ∫∫ |∂p/∂u × ∂p/∂v| du dv (see the module doc).
pub fn patch_area(p: &[Vec3; 4]) -> f32 {
    let [p00, p10, p01, p11] = p.map(|q| q.as_dvec3());
    let (e10, e00) = (p10 - p00, p01 - p00);
    let g = p00 - p10 - p01 + p11;
    let (c0, cu, cv) = (e10.cross(e00), e10.cross(g), g.cross(e00));
    let c = |u: f64, v: f64| c0 + u * cu + v * cv;
    let centre = c(0.5, 0.5);
    let corners = [c(0.0, 0.0), c(1.0, 0.0), c(0.0, 1.0), c(1.0, 1.0)];
    let aligned = |k: &DVec3| {
        let tol = 1e-7 * k.length() * centre.length();
        k.dot(centre) >= 0.0 && k.cross(centre).length() <= tol
    };
    if corners.iter().all(aligned) {
        return centre.length() as f32;
    }
    let mut sum = 0.0;
    for (u0, v0) in [(0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (0.5, 0.5)] {
        for &(x, wx) in &GL8 {
            for &(y, wy) in &GL8 {
                sum += wx * wy * c(u0 + 0.5 * x, v0 + 0.5 * y).length();
            }
        }
    }
    (0.25 * sum) as f32
}

/// The (u, v) ∈ \[0,1\]² with bilerp(`t`, (u, v)) = `p` for 2D corner values
/// `t` = [t₀₀, t₁₀, t₀₁, t₁₁] [Quílez 2010]; `None` if no solution lies in
/// (or within 1e-4 of) the square.
pub fn invert_bilinear(p: Vec2, t: &[Vec2; 4]) -> Option<Vec2> {
    let [a, b, c, d] = t.map(|q| q.as_dvec2());
    let (e, f, g, h) = (b - a, c - a, a - b - c + d, p.as_dvec2() - a);
    let k2 = g.perp_dot(f);
    let k1 = e.perp_dot(f) + h.perp_dot(g);
    let k0 = h.perp_dot(e);
    let scale = e.perp_dot(f).abs().max(1e-300);
    let vs: [f64; 2] = if k2.abs() <= 1e-12 * scale {
        [-k0 / k1, f64::NAN]
    } else {
        let disc = k1 * k1 - 4.0 * k2 * k0;
        if disc < 0.0 {
            return None;
        }
        let q = -0.5 * (k1 + disc.sqrt().copysign(k1));
        [q / k2, k0 / q]
    };
    let solve_u = |v: f64| {
        let dir = e + v * g;
        let r = h - v * f;
        DVec2::new(r.dot(dir) / dir.length_squared(), v)
    };
    let inside = |s: &DVec2| {
        let tol = 1e-4;
        s.is_finite() && s.min_element() >= -tol && s.max_element() <= 1.0 + tol
    };
    vs.iter()
        .filter(|v| v.is_finite())
        .map(|&v| solve_u(v))
        .find(inside)
        .map(|s| s.clamp(DVec2::ZERO, DVec2::ONE).as_vec2())
}
