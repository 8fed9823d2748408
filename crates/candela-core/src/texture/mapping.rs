//! Texture-coordinate generation: from a hit to 2D (s, t) or 3D points.
//!
//! The four 2D mappings of pbrt-v4 (`textures.h`, §10.2): `uv` scales and
//! offsets the surface's (u, v); `spherical` and `cylindrical` take angles of
//! the point around the texture-space origin; `planar` projects the point on
//! two vectors. The 3D mapping transforms the point into texture space.
//! Texture space is the coordinate system in effect at the `Texture`
//! directive, so each non-uv mapping holds texture-from-render.
//!
//! Each mapping also carries the screen-space derivatives of its output
//! (for filtering) forward from those of the hit (the camera footprint's,
//! [`crate::camera::PixelFootprint`]).

use super::TextureEvalContext;
use crate::math::{Transform, Vec2, Vec3, INV_2PI, INV_PI, PI};

/// 2D texture coordinates and their screen-space derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexCoord2D {
    /// (s, t).
    pub st: Vec2,
    /// ∂s/∂x.
    pub dsdx: f32,
    /// ∂s/∂y.
    pub dsdy: f32,
    /// ∂t/∂x.
    pub dtdx: f32,
    /// ∂t/∂y.
    pub dtdy: f32,
}

/// A 3D texture-space point and its screen-space derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexCoord3D {
    /// Point in texture space.
    pub p: Vec3,
    /// ∂p/∂x.
    pub dpdx: Vec3,
    /// ∂p/∂y.
    pub dpdy: Vec3,
}

/// How a 2D texture finds its (s, t) (pbrt-v4 `"string mapping"`).
#[derive(Clone, Debug, PartialEq)]
pub enum TextureMapping2D {
    /// (s, t) = (su·u + du, sv·v + dv).
    Uv {
        /// `uscale`.
        su: f32,
        /// `vscale`.
        sv: f32,
        /// `udelta`.
        du: f32,
        /// `vdelta`.
        dv: f32,
    },
    /// (s, t) = (θ/π, φ/2π) of the texture-space point about the origin.
    Spherical {
        /// Texture-from-render transform.
        texture_from_render: Transform,
    },
    /// (s, t) = ((π + atan2(y, x))/2π, z) in texture space.
    Cylindrical {
        /// Texture-from-render transform.
        texture_from_render: Transform,
    },
    /// (s, t) = (ds + p·vs, dt + p·vt) in texture space.
    Planar {
        /// Texture-from-render transform.
        texture_from_render: Transform,
        /// `v1`.
        vs: Vec3,
        /// `v2`.
        vt: Vec3,
        /// `udelta`.
        ds: f32,
        /// `vdelta`.
        dt: f32,
    },
}

impl TextureMapping2D {
    /// The identity uv mapping.
    pub const UV: Self = TextureMapping2D::Uv {
        su: 1.0,
        sv: 1.0,
        du: 0.0,
        dv: 0.0,
    };

    /// Texture coordinates at a hit.
    pub fn map(&self, ctx: &TextureEvalContext) -> TexCoord2D {
        match self {
            TextureMapping2D::Uv { su, sv, du, dv } => TexCoord2D {
                st: Vec2::new(su * ctx.uv.x + du, sv * ctx.uv.y + dv),
                dsdx: su * ctx.dudx,
                dsdy: su * ctx.dudy,
                dtdx: sv * ctx.dvdx,
                dtdy: sv * ctx.dvdy,
            },
            TextureMapping2D::Spherical {
                texture_from_render: t,
            } => spherical(t, ctx),
            TextureMapping2D::Cylindrical {
                texture_from_render: t,
            } => {
                let pt = t.point(ctx.p);
                let x2y2 = pt.x * pt.x + pt.y * pt.y;
                let dsdp = safe_scale(Vec3::new(-pt.y, pt.x, 0.0), 2.0 * PI * x2y2);
                let st = Vec2::new((PI + pt.y.atan2(pt.x)) * INV_2PI, pt.z);
                with_gradients(st, dsdp, Vec3::Z, t, ctx)
            }
            TextureMapping2D::Planar {
                texture_from_render: t,
                vs,
                vt,
                ds,
                dt,
            } => {
                let v = t.point(ctx.p);
                let st = Vec2::new(ds + v.dot(*vs), dt + v.dot(*vt));
                with_gradients(st, *vs, *vt, t, ctx)
            }
        }
    }
}

/// Spherical (s, t) and its derivatives [pbrt-v4 `SphericalMapping`].
fn spherical(t: &Transform, ctx: &TextureEvalContext) -> TexCoord2D {
    let pt = t.point(ctx.p);
    let x2y2 = pt.x * pt.x + pt.y * pt.y;
    let r = x2y2.sqrt();
    // ∂φ/∂p / 2π and ∂θ/∂p / π of the spherical angles.
    let dsdp = safe_scale(Vec3::new(-pt.y, pt.x, 0.0), 2.0 * PI * x2y2);
    let dtdp = if r > 0.0 {
        safe_scale(
            Vec3::new(pt.x * pt.z / r, pt.y * pt.z / r, -r),
            PI * (x2y2 + pt.z * pt.z),
        )
    } else {
        Vec3::ZERO
    };
    let v = pt.normalize_or_zero();
    let theta = v.z.clamp(-1.0, 1.0).acos();
    let mut phi = v.y.atan2(v.x);
    if phi < 0.0 {
        phi += 2.0 * PI;
    }
    let st = Vec2::new(theta * INV_PI, phi * INV_2PI);
    with_gradients(st, dsdp, dtdp, t, ctx)
}

/// `v / d`, or zero where `d` is zero (on the mapping's axis).
fn safe_scale(v: Vec3, d: f32) -> Vec3 {
    if d != 0.0 {
        v / d
    } else {
        Vec3::ZERO
    }
}

/// Chains ∂(s,t)/∂p with the hit's texture-space ∂p/∂x and ∂p/∂y.
fn with_gradients(
    st: Vec2,
    dsdp: Vec3,
    dtdp: Vec3,
    t: &Transform,
    ctx: &TextureEvalContext,
) -> TexCoord2D {
    let (dpdx, dpdy) = (t.vector(ctx.dpdx), t.vector(ctx.dpdy));
    TexCoord2D {
        st,
        dsdx: dsdp.dot(dpdx),
        dsdy: dsdp.dot(dpdy),
        dtdx: dtdp.dot(dpdx),
        dtdy: dtdp.dot(dpdy),
    }
}

/// The 3D mapping: the hit point in texture space.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureMapping3D {
    /// Texture-from-render transform.
    pub texture_from_render: Transform,
}

impl TextureMapping3D {
    /// Texture-space point at a hit.
    pub fn map(&self, ctx: &TextureEvalContext) -> TexCoord3D {
        let t = &self.texture_from_render;
        TexCoord3D {
            p: t.point(ctx.p),
            dpdx: t.vector(ctx.dpdx),
            dpdy: t.vector(ctx.dpdy),
        }
    }
}
