//! Bump mapping: shading geometry from a scalar displacement texture.
//!
//! The surface is displaced along its shading normal, p′(u, v) = p(u, v) +
//! d(u, v) n(u, v), and shaded with the normal of p′ [Blinn 1978]. Its
//! partial derivatives, dropping the term in d's second-order smallness as
//! pbrt-v4 does (book §10.5.1, `BumpMap` in `materials.h`), are
//!
//!   ∂p′/∂u ≈ ∂p/∂u + (∂d/∂u) n + d ∂n/∂u,   and likewise for v,
//!
//! with ∂d/∂u taken by a forward difference over Δu = ½(|∂u/∂x| + |∂u/∂y|),
//! from the hit's screen-space differentials (the camera footprint), or
//! 0.0005 where those are zero.
//! The shading normal becomes ∂p′/∂u × ∂p′/∂v, turned to the geometric
//! normal's side.
//!
//! Normal mapping (pbrt-v4's `normalmap` material parameter, book §10.5.2)
//! instead reads the shading normal from an RGB image in tangent space:
//! n_t = 2·rgb − 1 at (u, 1 − v), bilinearly filtered with repeat wrapping,
//! expressed in the frame whose x follows ∂p/∂u and whose z is the shading
//! normal. ∂p/∂u is then made perpendicular to n_t (Gram–Schmidt) keeping its
//! length, and ∂p/∂v = n_t × ∂p/∂u keeps its own, so the new shading normal
//! ∂p/∂u × ∂p/∂v is n_t. When a material has both, the normal map wins, as in
//! pbrt-v4.

use crate::image::{MapImage, WrapMode};
use crate::interaction::SurfaceInteraction;
use crate::math::{Frame, Vec2, Vec3};
use crate::texture::{FloatTexture, TextureEvalContext};
use std::sync::Arc;

/// How a material perturbs the shading normal.
#[derive(Clone, Debug)]
pub enum Bump {
    /// A scalar displacement texture (bump mapping).
    Displacement(FloatTexture),
    /// A tangent-space normal map: a linear RGB image.
    NormalMap(Arc<MapImage>),
}

impl Bump {
    /// Replaces the hit's shading geometry by the perturbed one.
    pub fn apply(&self, si: &mut SurfaceInteraction) {
        let (dpdu, dpdv) = match self {
            Bump::Displacement(d) => bump_map(si, |ctx| d.evaluate(ctx)),
            Bump::NormalMap(image) => normal_map(si, image),
        };
        set_shading(si, dpdu, dpdv);
    }
}

/// The shading ∂p/∂u and ∂p/∂v whose cross product is the mapped normal.
pub fn normal_map(si: &SurfaceInteraction, image: &MapImage) -> (Vec3, Vec3) {
    let sh = &si.shading;
    let st = Vec2::new(si.it.uv.x, 1.0 - si.it.uv.y);
    let [r, g, b] = std::array::from_fn(|c| 2.0 * image.bilerp(st, c, WrapMode::Repeat) - 1.0);
    let local = Vec3::new(r, g, b).normalize_or_zero();
    if local == Vec3::ZERO {
        return (sh.dpdu, sh.dpdv);
    }
    let ns = Frame::from_xz(sh.dpdu.normalize_or_zero(), sh.n).from_local(local);
    let (ulen, vlen) = (sh.dpdu.length(), sh.dpdv.length());
    let dpdu = (sh.dpdu - ns * ns.dot(sh.dpdu)).normalize_or_zero() * ulen;
    let dpdv = ns.cross(dpdu).normalize_or_zero() * vlen;
    (dpdu, dpdv)
}

/// Finite-difference step used when the hit has no (u, v) differentials [pbrt-v4].
const DEFAULT_STEP: f32 = 0.0005;

/// The displaced surface's ∂p/∂u and ∂p/∂v for displacement function `d`.
pub fn bump_map(si: &SurfaceInteraction, d: impl Fn(&TextureEvalContext) -> f32) -> (Vec3, Vec3) {
    let ctx = TextureEvalContext::from_si(si);
    let sh = &si.shading;
    let step = |a: f32, b: f32| {
        let s = 0.5 * (a.abs() + b.abs());
        if s == 0.0 {
            DEFAULT_STEP
        } else {
            s
        }
    };
    let du = step(ctx.dudx, ctx.dudy);
    let dv = step(ctx.dvdx, ctx.dvdy);
    let shifted = |dp: Vec3, duv: Vec2| TextureEvalContext {
        p: ctx.p + dp,
        uv: ctx.uv + duv,
        ..ctx
    };
    let d_u = d(&shifted(du * sh.dpdu, Vec2::new(du, 0.0)));
    let d_v = d(&shifted(dv * sh.dpdv, Vec2::new(0.0, dv)));
    let d0 = d(&ctx);
    let dpdu = sh.dpdu + (d_u - d0) / du * sh.n + d0 * sh.dndu;
    let dpdv = sh.dpdv + (d_v - d0) / dv * sh.n + d0 * sh.dndv;
    (dpdu, dpdv)
}

/// Replaces the hit's shading geometry by the bump-mapped one.
pub fn apply_bump(si: &mut SurfaceInteraction, displacement: &FloatTexture) {
    let (dpdu, dpdv) = bump_map(si, |ctx| displacement.evaluate(ctx));
    set_shading(si, dpdu, dpdv);
}

/// Shading geometry with normal ∂p/∂u × ∂p/∂v (unchanged if degenerate).
fn set_shading(si: &mut SurfaceInteraction, dpdu: Vec3, dpdv: Vec3) {
    let ns = dpdu.cross(dpdv).normalize_or_zero();
    if ns == Vec3::ZERO || !ns.is_finite() {
        return;
    }
    let (dndu, dndv) = (si.shading.dndu, si.shading.dndv);
    // candela's `true` keeps the geometric orientation and turns the shading
    // normal to its side (pbrt-v4 passes `orientationIsAuthoritative = false`).
    si.set_shading_geometry(ns, dpdu, dpdv, dndu, dndv, true);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::PI;
    use crate::texture::{Bilerp, TextureMapping2D};
    use std::sync::Arc;

    /// A hit on the plane z = 0 with (u, v) = (x, y).
    fn plane_hit(u: f32, v: f32, flip: bool) -> SurfaceInteraction {
        SurfaceInteraction::new(
            Vec3::new(u, v, 0.0),
            Vec3::ZERO,
            Vec2::new(u, v),
            Vec3::Z,
            Vec3::X,
            Vec3::Y,
            Vec3::ZERO,
            Vec3::ZERO,
            flip,
        )
    }

    #[test]
    fn sine_displacement_gives_the_analytic_normal() {
        // d = A sin(ωu) cos(ωv): the surface (u, v, d) has normal
        // (−∂d/∂u, −∂d/∂v, 1)/‖·‖. The forward difference errs by about
        // A ω² Δu / 2 ≈ 5e-4 in slope, inside the 1e-3 tolerance.
        let (a, w) = (0.05f32, 2.0 * PI);
        let d = |c: &TextureEvalContext| a * (w * c.uv.x).sin() * (w * c.uv.y).cos();
        for i in 0..40 {
            let (u, v) = (i as f32 * 0.0731, 0.37 - i as f32 * 0.019);
            let si = plane_hit(u, v, false);
            let (dpdu, dpdv) = bump_map(&si, d);
            let n = dpdu.cross(dpdv).normalize();
            let du = a * w * (w * u).cos() * (w * v).cos();
            let dv = -a * w * (w * u).sin() * (w * v).sin();
            let want = Vec3::new(-du, -dv, 1.0).normalize();
            assert!((n - want).length() < 1e-3, "at ({u}, {v}): {n} vs {want}");
        }
    }

    #[test]
    fn bilerp_ramp_tilts_the_shading_normal_on_the_geometric_side() {
        // d = 0.5 u: a constant slope, so n = (−0.5, 0, 1)/‖·‖ everywhere.
        let ramp = FloatTexture::Bilerp(Arc::new(Bilerp {
            map: TextureMapping2D::UV,
            v: [0.0, 0.0, 0.5, 0.5],
        }));
        let want = Vec3::new(-0.5, 0.0, 1.0).normalize();
        let mut si = plane_hit(0.3, 0.6, false);
        apply_bump(&mut si, &ramp);
        assert!((si.shading.n - want).length() < 1e-3, "{}", si.shading.n);
        assert_eq!(si.n(), Vec3::Z, "geometric normal unchanged");
        // Reversed orientation: the displacement goes along −z, giving the
        // surface z = −0.5u, whose normal on the −z side is (−0.5, 0, −1).
        let mut si = plane_hit(0.3, 0.6, true);
        apply_bump(&mut si, &ramp);
        let want = Vec3::new(-0.5, 0.0, -1.0).normalize();
        assert!((si.shading.n - want).length() < 1e-3, "{}", si.shading.n);
        assert_eq!(si.n(), -Vec3::Z);
    }

    /// The map is read at (u, 1 − v) (row 0 at the top of the image), in the
    /// frame x = ∂p/∂u, z = n: texels tilting towards +x in the top half and
    /// towards −y in the bottom half turn the shading normal that way where
    /// v is high and low respectively, keeping |∂p/∂u| and |∂p/∂v|.
    #[test]
    fn normal_map_reads_upright_in_the_tangent_frame() {
        use crate::image::{MapImage, PixelFormat};
        let (s, c) = (0.6f32, 0.8f32);
        let up = [0.5 * (s + 1.0), 0.5, 0.5 * (c + 1.0)];
        let down = [0.5, 0.5 * (1.0 - s), 0.5 * (c + 1.0)];
        let data = [up, up, down, down].concat();
        let image = MapImage {
            width: 1,
            height: 4,
            channels: 3,
            data,
            format: PixelFormat::Float,
        };
        let hit = |v: f32| {
            let mut si = SurfaceInteraction::new(
                Vec3::ZERO,
                Vec3::ZERO,
                Vec2::new(0.5, v),
                Vec3::Z,
                2.0 * Vec3::X,
                3.0 * Vec3::Y,
                Vec3::ZERO,
                Vec3::ZERO,
                false,
            );
            Bump::NormalMap(Arc::new(image.clone())).apply(&mut si);
            si
        };
        for (v, want) in [(0.8, Vec3::new(s, 0.0, c)), (0.2, Vec3::new(0.0, -s, c))] {
            let si = hit(v);
            let sh = si.shading;
            assert!(sh.n.distance(want) < 1e-5, "v = {v}: {} vs {want}", sh.n);
            assert!((sh.dpdu.length() - 2.0).abs() < 1e-5 && sh.dpdu.dot(sh.n).abs() < 1e-5);
            assert!((sh.dpdv.length() - 3.0).abs() < 1e-5);
        }
    }
}
