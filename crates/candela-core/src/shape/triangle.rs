//! Triangles of a render-space mesh: watertight intersection and sampling.
//!
//! Intersection follows Woop, Benthin and Wald 2013, "Watertight
//! ray/triangle intersection" (JCGT 2(1)), as pbrt-v4 §6.5.3 presents it:
//! the vertices are translated to the ray origin, the axes permuted so the
//! ray's dominant direction is z, and the vertices sheared so the ray runs
//! along +z. The 2D edge functions of the sheared vertices then decide the
//! hit. A shared edge yields the same edge function (up to sign) in both
//! triangles, so a ray can never slip between them; exact zeros are
//! re-evaluated in f64. The hit's `t` is accepted only when it exceeds a
//! conservative bound on its rounding error [pbrt-v4 §6.8.4], and the hit
//! point carries the bound γ₇ Σ|bᵢ pᵢ| [pbrt-v4 eq. 6.56].
//!
//! Zero-area triangles have a zero determinant and are never hit.

use super::{ShapeIntersection, ShapeSample, ShapeSampleContext, TriangleMesh};
use crate::interaction::{Interaction, SurfaceInteraction};
use crate::math::{gamma, Bounds3, Frame, Ray, Vec2, Vec3, Vec3A};
use crate::sampling::{sample_uniform_triangle, PdfArea, PdfSolidAngle};
use std::sync::Arc;

/// Barycentrics and ray parameter of a ray–triangle hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleIntersection {
    /// Barycentric weights of the three vertices.
    pub b: [f32; 3],
    /// Ray parameter.
    pub t: f32,
}

/// One triangle of a shared mesh.
#[derive(Clone, Debug)]
pub struct Triangle {
    /// The mesh holding vertex data.
    pub mesh: Arc<TriangleMesh>,
    /// Triangle index within the mesh.
    pub index: u32,
}

/// Default per-vertex uv when the mesh has none [pbrt-v4].
const DEFAULT_UV: [Vec2; 3] = [
    Vec2::new(0.0, 0.0),
    Vec2::new(1.0, 0.0),
    Vec2::new(1.0, 1.0),
];

/// Per-ray constants of the watertight test (axis permutation and shear),
/// computed once per ray and reused for every triangle it meets.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    o: Vec3,
    k: [usize; 3],
    s: Vec3,
}

impl WatertightRay {
    /// Precomputes the permutation (z = dominant axis) and shear of `ray`.
    #[inline]
    pub fn new(ray: &Ray) -> Self {
        let kz = max_dimension(ray.d.abs());
        let kx = (kz + 1) % 3;
        let ky = (kx + 1) % 3;
        let d = Vec3::new(ray.d[kx], ray.d[ky], ray.d[kz]);
        let sz = 1.0 / d.z;
        Self {
            o: ray.o,
            k: [kx, ky, kz],
            s: Vec3::new(-d.x * sz, -d.y * sz, sz),
        }
    }

    /// The ray origin, the axis permutation `[kx, ky, kz]` (`kz` the dominant
    /// axis) and the shear `(-dx/dz, -dy/dz, 1/dz)`, for batched tests that
    /// must round exactly as [`Self::intersect`] does.
    #[inline]
    pub(crate) fn parts(&self) -> (Vec3, [usize; 3], Vec3) {
        (self.o, self.k, self.s)
    }

    /// Watertight ray–triangle test; `None` unless the hit has `t ∈ (0, t_max)`
    /// conservatively [Woop et al. 2013; pbrt-v4 §6.5.3].
    #[inline]
    pub fn intersect(
        &self,
        t_max: f32,
        p0: Vec3,
        p1: Vec3,
        p2: Vec3,
    ) -> Option<TriangleIntersection> {
        // Translate to the ray origin, permute so z is the dominant axis, shear x and y.
        let [kx, ky, kz] = self.k;
        let mut pt = [p0, p1, p2].map(|p| {
            let q = p - self.o;
            let z = q[kz];
            Vec3::new(q[kx] + self.s.x * z, q[ky] + self.s.y * z, z)
        });
        let mut e = edge_functions(&pt);
        if e.contains(&0.0) {
            e = edge_functions_f64(&pt);
        }
        let any_neg = e[0] < 0.0 || e[1] < 0.0 || e[2] < 0.0;
        let any_pos = e[0] > 0.0 || e[1] > 0.0 || e[2] > 0.0;
        if any_neg && any_pos {
            return None;
        }
        let det = e[0] + e[1] + e[2];
        if det == 0.0 {
            return None;
        }
        for p in pt.iter_mut() {
            p.z *= self.s.z;
        }
        // Scaled t test avoids the division for most misses.
        let t_scaled = e[0] * pt[0].z + e[1] * pt[1].z + e[2] * pt[2].z;
        if det < 0.0 && (t_scaled >= 0.0 || t_scaled < t_max * det) {
            return None;
        }
        if det > 0.0 && (t_scaled <= 0.0 || t_scaled > t_max * det) {
            return None;
        }
        let inv_det = 1.0 / det;
        let b = [e[0] * inv_det, e[1] * inv_det, e[2] * inv_det];
        let t = t_scaled * inv_det;
        if t <= t_error_bound(&pt, &e, inv_det) {
            return None;
        }
        Some(TriangleIntersection { b, t })
    }
}

/// Watertight ray–triangle test for a single triangle (see [`WatertightRay`]).
pub fn intersect_triangle(
    ray: &Ray,
    t_max: f32,
    p0: Vec3,
    p1: Vec3,
    p2: Vec3,
) -> Option<TriangleIntersection> {
    WatertightRay::new(ray).intersect(t_max, p0, p1, p2)
}

/// Index of the largest component.
#[inline]
fn max_dimension(v: Vec3) -> usize {
    if v.x > v.y {
        if v.x > v.z {
            0
        } else {
            2
        }
    } else if v.y > v.z {
        1
    } else {
        2
    }
}

/// Edge functions of the sheared vertices (the same products for a shared
/// edge in both triangles, hence watertight).
#[inline]
fn edge_functions(p: &[Vec3; 3]) -> [f32; 3] {
    [
        p[1].x * p[2].y - p[1].y * p[2].x,
        p[2].x * p[0].y - p[2].y * p[0].x,
        p[0].x * p[1].y - p[0].y * p[1].x,
    ]
}

/// Edge functions in f64, for rays passing exactly through an edge or vertex.
#[cold]
fn edge_functions_f64(p: &[Vec3; 3]) -> [f32; 3] {
    let f = |a: Vec3, b: Vec3| (a.x as f64 * b.y as f64 - a.y as f64 * b.x as f64) as f32;
    [f(p[1], p[2]), f(p[2], p[0]), f(p[0], p[1])]
}

/// Conservative bound on the rounding error of the computed `t`
/// [pbrt-v4 §6.8.4, eqs. 6.58–6.62].
#[inline]
fn t_error_bound(pt: &[Vec3; 3], e: &[f32; 3], inv_det: f32) -> f32 {
    let max_abs = |f: fn(&Vec3) -> f32| pt.iter().map(|p| f(p).abs()).fold(0.0, f32::max);
    let max_zt = max_abs(|p| p.z);
    let max_xt = max_abs(|p| p.x);
    let max_yt = max_abs(|p| p.y);
    let delta_z = gamma(3) * max_zt;
    let delta_x = gamma(5) * (max_xt + max_zt);
    let delta_y = gamma(5) * (max_yt + max_zt);
    let delta_e = 2.0 * (gamma(2) * max_xt * max_yt + delta_y * max_xt + delta_x * max_yt);
    let max_e = e[0].abs().max(e[1].abs()).max(e[2].abs());
    3.0 * (gamma(3) * max_e * max_zt + delta_e * max_zt + delta_z * max_e) * inv_det.abs()
}

impl Triangle {
    /// Triangle `index` of `mesh`.
    pub fn new(mesh: Arc<TriangleMesh>, index: u32) -> Self {
        debug_assert!((index as usize) < mesh.triangle_count());
        Self { mesh, index }
    }

    /// All triangles of a mesh.
    pub fn all(mesh: &Arc<TriangleMesh>) -> Vec<Triangle> {
        (0..mesh.triangle_count() as u32)
            .map(|i| Self::new(mesh.clone(), i))
            .collect()
    }

    /// Render-space vertex positions.
    #[inline]
    pub fn positions(&self) -> [Vec3; 3] {
        self.mesh.positions(self.index)
    }

    /// Bounding box of the three vertices.
    pub fn bounds(&self) -> Bounds3 {
        let [p0, p1, p2] = self.positions();
        Bounds3::from_points(p0, p1).union_point(p2)
    }

    /// Area: half the cross-product length.
    pub fn area(&self) -> f32 {
        let [p0, p1, p2] = self.positions();
        0.5 * (p1 - p0).cross(p2 - p0).length()
    }

    /// Closest hit with `t ∈ (0, t_max)`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeIntersection> {
        let [p0, p1, p2] = self.positions();
        let ti = intersect_triangle(ray, t_max, p0, p1, p2)?;
        let si = self.interaction(&ti, -ray.d);
        Some(ShapeIntersection { si, t_hit: ti.t })
    }

    /// The raw hit (t and barycentrics) for a precomputed ray, without building the interaction.
    #[inline]
    pub fn intersect_raw(&self, wr: &WatertightRay, t_max: f32) -> Option<TriangleIntersection> {
        let [p0, p1, p2] = self.positions();
        wr.intersect(t_max, p0, p1, p2)
    }

    /// True when the ray hits for some `t ∈ (0, t_max)`.
    pub fn intersect_p(&self, ray: &Ray, t_max: f32) -> bool {
        let [p0, p1, p2] = self.positions();
        intersect_triangle(ray, t_max, p0, p1, p2).is_some()
    }

    /// Per-vertex uv (or the default parameterisation).
    #[inline]
    fn uvs_of(&self, v: [usize; 3]) -> [Vec2; 3] {
        match &self.mesh.uv {
            Some(uv) => [uv[v[0]], uv[v[1]], uv[v[2]]],
            None => DEFAULT_UV,
        }
    }

    /// True when the unit geometric normal must be negated
    /// (`reverse_orientation` xor handedness swap).
    fn flips(&self) -> bool {
        self.mesh.reverse_orientation ^ self.mesh.transform_swaps_handedness
    }

    /// Builds the surface interaction of a hit [pbrt-v4 §6.5.4].
    ///
    /// The arithmetic runs on 16-byte `Vec3A` vectors: lane by lane the same
    /// operations in the same order as on `Vec3` (so the same bits), but as
    /// whole-register SIMD instead of the shuffles the compiler makes of
    /// three-float vectors.
    pub(crate) fn interaction(&self, ti: &TriangleIntersection, wo: Vec3) -> SurfaceInteraction {
        let mesh = &*self.mesh;
        let v = mesh.vertex_indices(self.index);
        let p0 = Vec3A::from(mesh.p[v[0]]);
        let p1 = Vec3A::from(mesh.p[v[1]]);
        let p2 = Vec3A::from(mesh.p[v[2]]);
        let uv = self.uvs_of(v);
        let (dpdu, dpdv) = position_derivatives([p0, p1, p2], uv);
        let b = ti.b;
        let p_hit = b[0] * p0 + b[1] * p1 + b[2] * p2;
        let uv_hit = b[0] * uv[0] + b[1] * uv[1] + b[2] * uv[2];
        let abs_sum = (b[0] * p0).abs() + (b[1] * p1).abs() + (b[2] * p2).abs();
        // The geometric normal comes from the vertices, not from dpdu × dpdv.
        let mut n = (p0 - p2).cross(p1 - p2).normalize_or_zero();
        if self.flips() {
            n = -n;
        }
        let it = Interaction {
            p: p_hit.into(),
            p_error: (gamma(7) * abs_sum).into(),
            n: n.into(),
            uv: uv_hit,
            time: 0.0,
        };
        let wo = Vec3A::from(wo).normalize_or_zero();
        let mut si = SurfaceInteraction::from_geometry(it, wo.into(), dpdu.into(), dpdv.into());
        si.face_index = mesh
            .face_indices
            .as_ref()
            .map_or(0, |f| f[self.index as usize]);
        if let Some(ns) = &mesh.n {
            let ns_v = [
                Vec3A::from(ns[v[0]]),
                Vec3A::from(ns[v[1]]),
                Vec3A::from(ns[v[2]]),
            ];
            set_shading(&mut si, n, dpdu, ns_v, b, uv);
        }
        si
    }

    /// The triangle's sampling data, computed once (see [`TriangleSampler`]).
    pub fn sampler(&self) -> TriangleSampler {
        let mesh = &*self.mesh;
        let v = mesh.vertex_indices(self.index);
        let p = [mesh.p[v[0]], mesh.p[v[1]], mesh.p[v[2]]];
        TriangleSampler {
            p,
            uv: self.uvs_of(v),
            n: (p[0] - p[2]).cross(p[1] - p[2]).normalize_or_zero(),
            ns: mesh.n.as_ref().map(|ns| [ns[v[0]], ns[v[1]], ns[v[2]]]),
            flip: self.flips(),
            area: self.area(),
        }
    }

    /// A point uniformly distributed by area; `None` for zero-area triangles.
    pub fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        self.sampler().sample_area(u)
    }
}

/// Shading geometry from the interpolated per-vertex normals `ns_v` (`n`
/// and `dpdu`: the hit's geometric normal and ∂p/∂u); the geometric normal
/// is flipped to the shading normal's side [pbrt-v4 §6.5.4].
fn set_shading(
    si: &mut SurfaceInteraction,
    n: Vec3A,
    dpdu: Vec3A,
    ns_v: [Vec3A; 3],
    b: [f32; 3],
    uv: [Vec2; 3],
) {
    let ns = b[0] * ns_v[0] + b[1] * ns_v[1] + b[2] * ns_v[2];
    let ns = if ns.length_squared() > 0.0 {
        normalize(ns)
    } else {
        n
    };
    let mut ss = dpdu;
    let mut ts = ns.cross(ss);
    if ts.length_squared() > 0.0 {
        ss = ts.cross(ns);
    } else {
        let f = Frame::from_z(ns.into());
        (ss, ts) = (f.x.into(), f.y.into());
    }
    let (dndu, dndv) = normal_derivatives(ns_v, uv);
    // candela's flag `false` means: the geometric normal follows the shading normal.
    si.set_shading_geometry(
        ns.into(),
        ss.into(),
        ts.into(),
        dndu.into(),
        dndv.into(),
        false,
    );
}

/// What sampling a point on one triangle needs, gathered once (area lights
/// sample the same triangle for every shadow ray): the vertices, their uv
/// and shading normals, and the unit normal and area, computed as
/// [`Triangle::sample_area`] computes them on the fly.
#[derive(Clone, Debug)]
pub struct TriangleSampler {
    p: [Vec3; 3],
    uv: [Vec2; 3],
    /// Unit (p₀ − p₂) × (p₁ − p₂), before orientation.
    n: Vec3,
    /// Per-vertex shading normals, which orient `n` at each point.
    ns: Option<[Vec3; 3]>,
    /// Negate `n` (meshes without shading normals).
    flip: bool,
    area: f32,
}

impl TriangleSampler {
    /// A point uniformly distributed by area [pbrt-v4 `Triangle::Sample`];
    /// `None` for zero-area triangles.
    #[inline]
    pub fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        let area = self.area;
        if area.is_nan() || area <= 0.0 {
            return None;
        }
        let [p0, p1, p2] = self.p;
        let b = sample_uniform_triangle(u);
        let p = b[0] * p0 + b[1] * p1 + b[2] * p2;
        let abs_sum = (b[0] * p0).abs() + (b[1] * p1).abs() + (b[2] * p2).abs();
        let uv = self.uv;
        let intr = Interaction {
            p,
            p_error: gamma(6) * abs_sum,
            n: self.oriented_normal(b),
            uv: b[0] * uv[0] + b[1] * uv[1] + b[2] * uv[2],
            time: 0.0,
        };
        Some(ShapeSample {
            intr,
            pdf: PdfArea(1.0 / area),
        })
    }

    /// Density of [`Self::sample_area`] by solid angle at `ctx` for direction
    /// `wi`, 0 when the ray misses: [`Shape::pdf_from`] for a triangle
    /// without building the hit's surface interaction (the same hit point,
    /// normal and arithmetic, so the same value).
    ///
    /// [`Shape::pdf_from`]: super::Shape::pdf_from
    pub fn pdf_from(&self, ctx: &ShapeSampleContext, wi: Vec3) -> PdfSolidAngle {
        let [p0, p1, p2] = self.p;
        let Some(ti) = intersect_triangle(&ctx.spawn_ray(wi), f32::INFINITY, p0, p1, p2) else {
            return PdfSolidAngle(0.0);
        };
        let b = ti.b;
        let p =
            Vec3::from(b[0] * Vec3A::from(p0) + b[1] * Vec3A::from(p1) + b[2] * Vec3A::from(p2));
        super::pdf_at_point(ctx, wi, p, self.n, self.pdf_area())
    }

    /// Area density of [`Self::sample_area`]: 1/A.
    pub fn pdf_area(&self) -> PdfArea {
        PdfArea(1.0 / self.area)
    }

    /// The geometric normal at barycentrics `b`, oriented as pbrt-v4 does:
    /// towards the interpolated shading normal if the mesh has normals, else
    /// by the orientation flag.
    #[inline]
    fn oriented_normal(&self, b: [f32; 3]) -> Vec3 {
        let n = self.n;
        match &self.ns {
            Some(ns) => {
                let nsi = b[0] * ns[0] + b[1] * ns[1] + b[2] * ns[2];
                if n.dot(nsi) < 0.0 {
                    -n
                } else {
                    n
                }
            }
            None if self.flip => -n,
            None => n,
        }
    }
}

/// `v` scaled to unit length as `Vec3::normalize` does it (by the
/// reciprocal length; `Vec3A::normalize` divides, which rounds differently).
#[inline]
fn normalize(v: Vec3A) -> Vec3A {
    v * v.length_recip()
}

/// ∂p/∂u and ∂p/∂v from vertex positions and uv; falls back to an arbitrary
/// tangent frame for degenerate uv [pbrt-v4 §6.5.4].
#[inline]
fn position_derivatives(p: [Vec3A; 3], uv: [Vec2; 3]) -> (Vec3A, Vec3A) {
    let (duv02, duv12) = (uv[0] - uv[2], uv[1] - uv[2]);
    let (dp02, dp12) = (p[0] - p[2], p[1] - p[2]);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    if det.abs() >= 1e-9 {
        let inv = 1.0 / det;
        let dpdu = (duv12.y * dp02 - duv02.y * dp12) * inv;
        let dpdv = (duv02.x * dp12 - duv12.x * dp02) * inv;
        if dpdu.cross(dpdv).length_squared() > 0.0 {
            return (dpdu, dpdv);
        }
    }
    let (dx, dy) = fallback_frame(p.map(Vec3::from));
    (dx.into(), dy.into())
}

/// A tangent frame around the triangle's normal, for degenerate uv.
#[cold]
fn fallback_frame(p: [Vec3; 3]) -> (Vec3, Vec3) {
    let ng = (p[2] - p[0]).cross(p[1] - p[0]);
    let ng = if ng.length_squared() > 0.0 {
        ng
    } else {
        let d = |v: Vec3| v.as_dvec3();
        d(p[2] - p[0]).cross(d(p[1] - p[0])).as_vec3()
    };
    let f = Frame::from_z(ng.normalize_or(Vec3::Z));
    (f.x, f.y)
}

/// ∂n/∂u and ∂n/∂v of the interpolated shading normal [pbrt-v4 §6.5.4].
#[inline]
fn normal_derivatives(n: [Vec3A; 3], uv: [Vec2; 3]) -> (Vec3A, Vec3A) {
    let (duv02, duv12) = (uv[0] - uv[2], uv[1] - uv[2]);
    let (dn1, dn2) = (n[0] - n[2], n[1] - n[2]);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    if det.abs() >= 1e-9 {
        let inv = 1.0 / det;
        return (
            (duv12.y * dn1 - duv02.y * dn2) * inv,
            (duv02.x * dn2 - duv12.x * dn1) * inv,
        );
    }
    let dn = (n[2] - n[0]).cross(n[1] - n[0]);
    if dn.length_squared() == 0.0 {
        return (Vec3A::ZERO, Vec3A::ZERO);
    }
    let f = Frame::from_z(normalize(dn).into());
    (f.x.into(), f.y.into())
}
