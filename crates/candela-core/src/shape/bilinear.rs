//! Bilinear patch meshes stored in render space (pbrt-v4's `bilinearmesh`).
//!
//! Each patch has four corners p₀₀, p₁₀, p₀₁, p₁₁ (that order in `indices`)
//! and is the doubly ruled surface p(u, v) = lerp(v, lerp(u, p₀₀, p₁₀),
//! lerp(u, p₀₁, p₁₁)); a planar parallelogram is the special case
//! [pbrt-v4 §6.6]. Intersection, area and the inverse map are in
//! `bilinear_math`.
//!
//! Surface geometry [pbrt-v4 §6.6.2]: ∂p/∂u, ∂p/∂v from the lerps; the
//! second derivatives vanish except ∂²p/∂u∂v = p₀₀ − p₁₀ − p₀₁ + p₁₁, which
//! the Weingarten equations turn into ∂n/∂u, ∂n/∂v. With per-vertex texture
//! coordinates (s, t) the derivatives are re-expressed in (s, t) by the
//! inverse Jacobian of the map (u, v) → (s, t) (pbrt-v4 approximates it by
//! its diagonal), keeping the normal's side. Per-vertex normals give the
//! shading normal; the tangents are rotated onto it, and the geometric
//! normal is flipped to its side, as for triangles.
//!
//! Area sampling [pbrt-v4 §6.6.3]: (u, v) is drawn from the bilinear density
//! whose corner values are the corner area elements |∂p/∂u × ∂p/∂v|, so the
//! density per area is p(u, v) / |∂p/∂u × ∂p/∂v|. For every planar patch that
//! does not fold, |∂p/∂u × ∂p/∂v| is itself bilinear (affine), and the
//! density is exactly 1/A: uniform, as pbrt-v4's rectangle special case.
//! Solid-angle sampling converts area samples (pbrt-v4 samples the
//! spherical rectangle for rectangles seen from nearby; not done here).

use super::bilinear_math::{
    bilerp2, bilerp3, corner_area_weights, intersect_bilinear_patch, invert_bilinear, partials,
    patch_area,
};
use super::mesh::{render_normals, validate};
use super::sphere::weingarten;
use super::{MeshError, ShapeIntersection, ShapeSample};
use crate::interaction::{Interaction, SurfaceInteraction};
use crate::math::{face_forward, gamma, Bounds3, Frame, Ray, Transform, Vec2, Vec3};
use crate::sampling::{bilinear_pdf, sample_bilinear, PdfArea};
use std::sync::Arc;

/// A mesh of bilinear patches in render space.
#[derive(Clone, Debug, PartialEq)]
pub struct BilinearPatchMesh {
    /// Vertex positions (render space).
    pub p: Vec<Vec3>,
    /// Per-vertex shading normals (render space, already flipped by `reverse_orientation`).
    pub n: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates.
    pub uv: Option<Vec<Vec2>>,
    /// Four vertex indices per patch: p₀₀, p₁₀, p₀₁, p₁₁.
    pub indices: Vec<u32>,
    /// Per-patch face index.
    pub face_indices: Option<Vec<i32>>,
    /// The shape's `ReverseOrientation` flag.
    pub reverse_orientation: bool,
    /// Whether the object-to-render transform flips handedness.
    pub transform_swaps_handedness: bool,
}

impl BilinearPatchMesh {
    /// Builds a render-space mesh from object-space data.
    pub fn new(
        render_from_object: &Transform,
        reverse_orientation: bool,
        indices: Vec<u32>,
        p: Vec<Vec3>,
        n: Option<Vec<Vec3>>,
        uv: Option<Vec<Vec2>>,
        face_indices: Option<Vec<i32>>,
    ) -> Result<Self, MeshError> {
        validate(4, &indices, p.len(), &n, &uv, &face_indices)?;
        Ok(Self {
            p: p.iter().map(|&q| render_from_object.point(q)).collect(),
            n: n.map(|ns| render_normals(render_from_object, reverse_orientation, &ns)),
            uv,
            indices,
            face_indices,
            reverse_orientation,
            transform_swaps_handedness: render_from_object.swaps_handedness(),
        })
    }

    /// Number of patches.
    pub fn patch_count(&self) -> usize {
        self.indices.len() / 4
    }

    /// The four vertex indices of patch `i`.
    #[inline]
    pub fn vertex_indices(&self, i: u32) -> [usize; 4] {
        let k = 4 * i as usize;
        [0, 1, 2, 3].map(|j| self.indices[k + j] as usize)
    }
}

/// One patch of a shared mesh.
#[derive(Clone, Debug)]
pub struct BilinearPatch {
    /// The mesh holding vertex data.
    pub mesh: Arc<BilinearPatchMesh>,
    /// Patch index within the mesh.
    pub index: u32,
    area: f32,
}

/// Per-vertex attribute values at the corners of a patch.
fn corners<T: Copy>(v: &[T], idx: [usize; 4]) -> [T; 4] {
    idx.map(|i| v[i])
}

impl BilinearPatch {
    /// Patch `index` of `mesh`.
    pub fn new(mesh: Arc<BilinearPatchMesh>, index: u32) -> Self {
        debug_assert!((index as usize) < mesh.patch_count());
        let p = corners(&mesh.p, mesh.vertex_indices(index));
        Self {
            area: patch_area(&p),
            mesh,
            index,
        }
    }

    /// All patches of a mesh.
    pub fn all(mesh: &Arc<BilinearPatchMesh>) -> Vec<BilinearPatch> {
        (0..mesh.patch_count() as u32)
            .map(|i| Self::new(mesh.clone(), i))
            .collect()
    }

    /// Render-space corners p₀₀, p₁₀, p₀₁, p₁₁.
    #[inline]
    pub fn positions(&self) -> [Vec3; 4] {
        corners(&self.mesh.p, self.mesh.vertex_indices(self.index))
    }

    /// Bounding box of the corners (the patch lies in their convex hull).
    pub fn bounds(&self) -> Bounds3 {
        let [a, b, c, d] = self.positions();
        Bounds3::from_points(a, b).union_point(c).union_point(d)
    }

    /// Surface area.
    pub fn area(&self) -> f32 {
        self.area
    }

    /// Closest hit with `t ∈ (0, t_max)`.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeIntersection> {
        let hit = intersect_bilinear_patch(ray, t_max, &self.positions())?;
        Some(ShapeIntersection {
            si: self.interaction(hit.uv, -ray.d),
            t_hit: hit.t,
        })
    }

    /// True when the ray hits for some `t ∈ (0, t_max)`.
    pub fn intersect_p(&self, ray: &Ray, t_max: f32) -> bool {
        intersect_bilinear_patch(ray, t_max, &self.positions()).is_some()
    }

    /// True when the unit geometric normal must be negated
    /// (`reverse_orientation` xor handedness swap).
    fn flips(&self) -> bool {
        self.mesh.reverse_orientation ^ self.mesh.transform_swaps_handedness
    }

    /// Conservative rounding bound of a point computed by two lerps of the corners.
    fn point_error(p: &[Vec3; 4]) -> Vec3 {
        gamma(7) * p[0].abs().max(p[1].abs()).max(p[2].abs().max(p[3].abs()))
    }

    /// Interpolated per-vertex normal at (u, v), if the mesh has normals.
    fn shading_normal_at(&self, uv: Vec2) -> Option<(Vec3, [Vec3; 4])> {
        let ns = self.mesh.n.as_ref()?;
        let n = corners(ns, self.mesh.vertex_indices(self.index));
        Some((bilerp3(&n, uv), n))
    }

    /// Builds the surface interaction at patch parameters `uv` [pbrt-v4 §6.6.2].
    fn interaction(&self, uv: Vec2, wo: Vec3) -> SurfaceInteraction {
        let p = self.positions();
        let (mut dpdu, mut dpdv) = partials(&p, uv);
        let c = dpdu.cross(dpdv);
        if c.length_squared().is_nan() || c.length_squared() <= 0.0 {
            // A collapsed edge or corner: take the frame of the patch centre.
            let n = partials(&p, Vec2::splat(0.5));
            let f = Frame::from_z(n.0.cross(n.1).normalize_or(Vec3::Z));
            (dpdu, dpdv) = (f.x, f.y);
        }
        let d2pduv = p[0] - p[1] - p[2] + p[3];
        let (mut dndu, mut dndv) = weingarten(dpdu, dpdv, Vec3::ZERO, d2pduv, Vec3::ZERO);
        let mut st = uv;
        if let Some(tex) = &self.mesh.uv {
            let tex = corners(tex, self.mesh.vertex_indices(self.index));
            st = bilerp2(&tex, uv);
            if let Some(m) = texture_jacobian_inverse(&tex, uv) {
                (dpdu, dpdv) = m.apply(dpdu, dpdv);
                (dndu, dndv) = m.apply(dndu, dndv);
            }
        }
        let mut si = SurfaceInteraction::new(
            bilerp3(&p, uv),
            Self::point_error(&p),
            st,
            wo.normalize_or_zero(),
            dpdu,
            dpdv,
            dndu,
            dndv,
            self.flips(),
        );
        si.face_index = self
            .mesh
            .face_indices
            .as_ref()
            .map_or(0, |f| f[self.index as usize]);
        if let Some((ns, n)) = self.shading_normal_at(uv) {
            set_shading(&mut si, ns, &n, uv);
        }
        si
    }

    /// Density per area of [`BilinearPatch::sample_area`] at patch parameters `uv`.
    fn pdf_at(&self, p: &[Vec3; 4], uv: Vec2) -> PdfArea {
        let (dpdu, dpdv) = partials(p, uv);
        let pdf = bilinear_pdf(uv, corner_area_weights(p)) / dpdu.cross(dpdv).length();
        PdfArea(if pdf.is_finite() { pdf } else { 0.0 })
    }

    /// Density of [`BilinearPatch::sample_area`] at a point of the patch,
    /// found from its (texture) coordinates [pbrt-v4 `BilinearPatch::PDF`].
    pub fn pdf_area(&self, intr: &Interaction) -> PdfArea {
        let uv = match &self.mesh.uv {
            Some(tex) => {
                let tex = corners(tex, self.mesh.vertex_indices(self.index));
                match invert_bilinear(intr.uv, &tex) {
                    Some(uv) => uv,
                    None => return PdfArea(0.0),
                }
            }
            None => intr.uv,
        };
        self.pdf_at(&self.positions(), uv)
    }

    /// A point sampled by the bilinear warp of the corner area elements
    /// (uniform by area for flat patches); `None` for degenerate patches.
    pub fn sample_area(&self, u: Vec2) -> Option<ShapeSample> {
        let p = self.positions();
        let uv = sample_bilinear(u, corner_area_weights(&p));
        let pdf = self.pdf_at(&p, uv);
        if pdf.0.is_nan() || pdf.0 <= 0.0 {
            return None;
        }
        let (dpdu, dpdv) = partials(&p, uv);
        let mut n = dpdu.cross(dpdv).normalize();
        match self.shading_normal_at(uv) {
            Some((ns, _)) => n = face_forward(n, ns),
            None if self.flips() => n = -n,
            None => {}
        }
        let st = match &self.mesh.uv {
            Some(tex) => bilerp2(&corners(tex, self.mesh.vertex_indices(self.index)), uv),
            None => uv,
        };
        let intr = Interaction {
            p: bilerp3(&p, uv),
            p_error: Self::point_error(&p),
            n,
            uv: st,
            time: 0.0,
        };
        Some(ShapeSample { intr, pdf })
    }
}

/// ∂(u, v)/∂(s, t): the inverse Jacobian of the texture map, with the sign
/// of the t column chosen so that ∂p/∂s × ∂p/∂t keeps the side of ∂p/∂u × ∂p/∂v.
struct InverseJacobian {
    du_ds: f32,
    dv_ds: f32,
    du_dt: f32,
    dv_dt: f32,
}

impl InverseJacobian {
    /// Chain rule: (∂x/∂s, ∂x/∂t) from (∂x/∂u, ∂x/∂v).
    fn apply(&self, xu: Vec3, xv: Vec3) -> (Vec3, Vec3) {
        (
            xu * self.du_ds + xv * self.dv_ds,
            xu * self.du_dt + xv * self.dv_dt,
        )
    }
}

/// The inverse Jacobian of (u, v) → (s, t) at `uv`; `None` where the
/// texture map is degenerate (then (u, v) derivatives are kept, as pbrt-v4).
fn texture_jacobian_inverse(tex: &[Vec2; 4], uv: Vec2) -> Option<InverseJacobian> {
    let dst_du = tex[1].lerp(tex[3], uv.y) - tex[0].lerp(tex[2], uv.y);
    let dst_dv = tex[2].lerp(tex[3], uv.x) - tex[0].lerp(tex[1], uv.x);
    let det = dst_du.perp_dot(dst_dv);
    let scale = dst_du.length() * dst_dv.length();
    if det.is_nan() || det.abs() <= 1e-6 * scale {
        return None;
    }
    let inv = 1.0 / det;
    // Negating the t column flips ∂p/∂s × ∂p/∂t back when det < 0.
    let sign = det.signum();
    Some(InverseJacobian {
        du_ds: dst_dv.y * inv,
        dv_ds: -dst_du.y * inv,
        du_dt: -dst_dv.x * inv * sign,
        dv_dt: dst_du.x * inv * sign,
    })
}

/// Shading geometry from interpolated per-vertex normals: the tangents are
/// rotated by the rotation taking the geometric normal to the shading
/// normal, and the geometric normal follows the shading normal's side
/// [pbrt-v4 §6.6.2].
fn set_shading(si: &mut SurfaceInteraction, ns: Vec3, n_corner: &[Vec3; 4], uv: Vec2) {
    if ns.length_squared().is_nan() || ns.length_squared() <= 0.0 {
        return;
    }
    let ns = ns.normalize();
    let n = si.it.n;
    let axis = n.cross(ns);
    let (mut sdpdu, sdpdv) = if axis.length_squared() > 1e-14 {
        let k = axis.normalize();
        let cos = n.dot(ns);
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        // Rodrigues: v cos θ + (k × v) sin θ + k (k·v)(1 − cos θ).
        let rot = |v: Vec3| v * cos + k.cross(v) * sin + k * k.dot(v) * (1.0 - cos);
        (rot(si.dpdu), rot(si.dpdv))
    } else if n.dot(ns) >= 0.0 {
        (si.dpdu, si.dpdv)
    } else {
        (si.dpdu, -si.dpdv)
    };
    sdpdu -= sdpdu.dot(ns) * ns;
    let [n00, n10, n01, n11] = *n_corner;
    let dndu = n10.lerp(n11, uv.y) - n00.lerp(n01, uv.y);
    let dndv = n01.lerp(n11, uv.x) - n00.lerp(n10, uv.x);
    // candela's flag `false`: the geometric normal follows the shading normal.
    si.set_shading_geometry(ns, sdpdu, sdpdv, dndu, dndv, false);
}
