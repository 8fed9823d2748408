//! Points where light interacts with the scene: surface hits and sampled
//! points on lights, shapes and lenses.

use crate::math::{offset_ray_origin, spawn_ray, spawn_ray_to, Frame, Ray, Vec2, Vec3};

/// Index of a material in the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MaterialId(pub u32);
/// Index of a light in the scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LightId(pub u32);

/// A point on a surface (or a lens or a light), with a conservative bound on
/// its rounding error for spawning rays without epsilons.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interaction {
    /// Position.
    pub p: Vec3,
    /// Absolute error bound of `p`, per axis.
    pub p_error: Vec3,
    /// Geometric normal (zero for points in free space such as point lights).
    pub n: Vec3,
    /// Surface parameterisation.
    pub uv: Vec2,
    /// Time of the path this point belongs to (motion blur); rays spawned
    /// here carry it.
    pub time: f32,
}

impl Interaction {
    /// A point with no surface (point light, pinhole).
    pub fn at_point(p: Vec3) -> Self {
        Self {
            p,
            p_error: Vec3::ZERO,
            n: Vec3::ZERO,
            uv: Vec2::ZERO,
            time: 0.0,
        }
    }
    /// True for points on surfaces.
    pub fn is_surface(&self) -> bool {
        self.n != Vec3::ZERO
    }
    /// Ray leaving this point in direction `d`.
    pub fn spawn_ray(&self, d: Vec3) -> Ray {
        spawn_ray(self.p, self.p_error, self.n, d).at_time(self.time)
    }
    /// Shadow ray from this point towards another interaction; `t ∈ (0, 1 − ε)` spans the gap.
    pub fn spawn_ray_to(&self, to: &Interaction) -> Ray {
        let pf = offset_ray_origin(self.p, self.p_error, self.n, to.p - self.p);
        let pt = offset_ray_origin(to.p, to.p_error, to.n, pf - to.p);
        Ray::new(pf, pt - pf).at_time(self.time)
    }
    /// Shadow ray towards a bare point.
    pub fn spawn_ray_to_point(&self, p: Vec3) -> Ray {
        spawn_ray_to(self.p, self.p_error, self.n, p).at_time(self.time)
    }
}

/// Local differential geometry used for shading.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingGeometry {
    /// Shading normal (same hemisphere as the geometric normal).
    pub n: Vec3,
    /// ∂p/∂u of the shading parameterisation.
    pub dpdu: Vec3,
    /// ∂p/∂v.
    pub dpdv: Vec3,
    /// ∂n/∂u.
    pub dndu: Vec3,
    /// ∂n/∂v.
    pub dndv: Vec3,
}

/// A ray–surface hit with everything materials and lights need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceInteraction {
    /// Position, error bound, geometric normal, uv.
    pub it: Interaction,
    /// Direction back towards the ray origin (normalised).
    pub wo: Vec3,
    /// ∂p/∂u.
    pub dpdu: Vec3,
    /// ∂p/∂v.
    pub dpdv: Vec3,
    /// Shading geometry.
    pub shading: ShadingGeometry,
    /// Triangle/face index within its mesh (for `face_indices`), else 0.
    pub face_index: i32,
    /// Material of the hit primitive (`None`: an interface, pass through).
    pub material: Option<MaterialId>,
    /// Area light attached to the hit primitive.
    pub area_light: Option<LightId>,
    /// Screen-space derivatives of p and (u, v); zero until the scene
    /// estimates the pixel footprint ([`crate::camera::PixelFootprint`]).
    pub diff: Differentials,
}

/// Screen-space derivatives at a hit: how p and (u, v) change from one
/// pixel to the next [pbrt-v4 `SurfaceInteraction::dpdx` … `dvdy`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Differentials {
    /// ∂p/∂x.
    pub dpdx: Vec3,
    /// ∂p/∂y.
    pub dpdy: Vec3,
    /// ∂u/∂x.
    pub dudx: f32,
    /// ∂u/∂y.
    pub dudy: f32,
    /// ∂v/∂x.
    pub dvdx: f32,
    /// ∂v/∂y.
    pub dvdy: f32,
}

impl Differentials {
    /// (u, v) derivatives from ∂p/∂x and ∂p/∂y by least squares
    /// [pbrt-v4 `ComputeDifferentials`, book §10.1.1]: ∂p/∂x ≈ ∂p/∂u ∂u/∂x +
    /// ∂p/∂v ∂v/∂x is overdetermined (three equations, two unknowns), so
    /// solve the normal equations AᵀA (∂u/∂x, ∂v/∂x)ᵀ = Aᵀ ∂p/∂x with
    /// A = (∂p/∂u ∂p/∂v), and likewise for y. Non-finite results (a
    /// degenerate parameterisation) become 0 and the rest is clamped to ±1e8.
    pub fn from_dp(dpdx: Vec3, dpdy: Vec3, dpdu: Vec3, dpdv: Vec3) -> Self {
        let (a00, a01, a11) = (dpdu.dot(dpdu), dpdu.dot(dpdv), dpdv.dot(dpdv));
        let inv_det = 1.0 / (a00 * a11 - a01 * a01);
        let inv_det = if inv_det.is_finite() { inv_det } else { 0.0 };
        let solve = |b: Vec3| {
            let (b0, b1) = (dpdu.dot(b), dpdv.dot(b));
            let tidy = |x: f32| {
                if x.is_finite() {
                    x.clamp(-1e8, 1e8)
                } else {
                    0.0
                }
            };
            (
                tidy((a11 * b0 - a01 * b1) * inv_det),
                tidy((a00 * b1 - a01 * b0) * inv_det),
            )
        };
        let (dudx, dvdx) = solve(dpdx);
        let (dudy, dvdy) = solve(dpdy);
        Self {
            dpdx,
            dpdy,
            dudx,
            dudy,
            dvdx,
            dvdy,
        }
    }
}

impl SurfaceInteraction {
    /// Builds a hit from geometry; shading geometry starts equal to it.
    /// `flip` reverses the normal (ReverseOrientation xor handedness swap).
    pub fn new(
        p: Vec3,
        p_error: Vec3,
        uv: Vec2,
        wo: Vec3,
        dpdu: Vec3,
        dpdv: Vec3,
        dndu: Vec3,
        dndv: Vec3,
        flip: bool,
    ) -> Self {
        let mut n = dpdu.cross(dpdv).normalize_or_zero();
        if flip {
            n = -n;
        }
        Self {
            it: Interaction {
                p,
                p_error,
                n,
                uv,
                time: 0.0,
            },
            wo,
            dpdu,
            dpdv,
            shading: ShadingGeometry {
                n,
                dpdu,
                dpdv,
                dndu,
                dndv,
            },
            face_index: 0,
            material: None,
            area_light: None,
            diff: Differentials::default(),
        }
    }

    /// A hit whose geometric normal `it.n` is already known (so not
    /// recomputed from ∂p/∂u × ∂p/∂v); shading geometry starts equal to it.
    #[inline]
    pub fn from_geometry(it: Interaction, wo: Vec3, dpdu: Vec3, dpdv: Vec3) -> Self {
        Self {
            it,
            wo,
            dpdu,
            dpdv,
            shading: ShadingGeometry {
                n: it.n,
                dpdu,
                dpdv,
                dndu: Vec3::ZERO,
                dndv: Vec3::ZERO,
            },
            face_index: 0,
            material: None,
            area_light: None,
            diff: Differentials::default(),
        }
    }

    /// Position.
    #[inline]
    pub fn p(&self) -> Vec3 {
        self.it.p
    }
    /// Geometric normal.
    #[inline]
    pub fn n(&self) -> Vec3 {
        self.it.n
    }

    /// Sets the shading geometry; the shading normal is flipped to the
    /// geometric normal's side when `orientation_is_authoritative`, else the
    /// geometric normal follows the shading normal [pbrt-v4 §4.1.4, `SetShadingGeometry`].
    pub fn set_shading_geometry(
        &mut self,
        ns: Vec3,
        dpdus: Vec3,
        dpdvs: Vec3,
        dndus: Vec3,
        dndvs: Vec3,
        orientation_is_authoritative: bool,
    ) {
        let mut ns = ns;
        if orientation_is_authoritative {
            if ns.dot(self.it.n) < 0.0 {
                ns = -ns;
            }
        } else if self.it.n.dot(ns) < 0.0 {
            self.it.n = -self.it.n;
        }
        self.shading = ShadingGeometry {
            n: ns,
            dpdu: dpdus,
            dpdv: dpdvs,
            dndu: dndus,
            dndv: dndvs,
        };
    }

    /// Adjoint correction for shading normals in importance transport,
    /// |wo·ns||wi·ng| / (|wo·ng||wi·ns|) [Veach 1997, eq. 5.19]; 0 when degenerate.
    pub fn importance_shading_correction(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (ns, ng) = (self.shading.n, self.it.n);
        let den = wo.dot(ng).abs() * wi.dot(ns).abs();
        if den == 0.0 {
            return 0.0;
        }
        wo.dot(ns).abs() * wi.dot(ng).abs() / den
    }

    /// The shading frame: z = shading normal, x along ∂p/∂u.
    pub fn shading_frame(&self) -> Frame {
        Frame::from_xz(self.shading.dpdu.normalize_or_zero(), self.shading.n)
    }

    /// Ray leaving the hit in direction `d`.
    #[inline]
    pub fn spawn_ray(&self, d: Vec3) -> Ray {
        self.it.spawn_ray(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A skewed parameterisation of the plane z = 0: ∂p/∂u = (2, 0, 0),
    /// ∂p/∂v = (1, 3, 0). Screen steps built as ∂p/∂u·a + ∂p/∂v·b (plus an
    /// out-of-plane part for y, which least squares projects away) must give
    /// back (a, b) to rounding.
    #[test]
    fn uv_derivatives_solve_the_least_squares_system() {
        let (dpdu, dpdv) = (Vec3::new(2.0, 0.0, 0.0), Vec3::new(1.0, 3.0, 0.0));
        let dpdx = dpdu * 0.1 + dpdv * 0.2;
        let dpdy = dpdu * -0.05 + dpdv * 0.4 + Vec3::new(0.0, 0.0, 5.0);
        let d = Differentials::from_dp(dpdx, dpdy, dpdu, dpdv);
        for (got, want) in [(d.dudx, 0.1), (d.dvdx, 0.2), (d.dudy, -0.05), (d.dvdy, 0.4)] {
            assert!((got - want).abs() < 1e-6, "{got} vs {want}");
        }
        assert_eq!((d.dpdx, d.dpdy), (dpdx, dpdy));
        // A degenerate parameterisation gives zeros, not NaN.
        let z = Differentials::from_dp(dpdx, dpdy, Vec3::ZERO, dpdv);
        assert_eq!((z.dudx, z.dvdx, z.dudy, z.dvdy), (0.0, 0.0, 0.0, 0.0));
        // Nearly parallel ∂p/∂u, ∂p/∂v: huge but finite values are clamped.
        let h = Differentials::from_dp(Vec3::Y, Vec3::Y, Vec3::X, Vec3::new(1.0, 1e-9, 0.0));
        assert!(h.dudx.abs() <= 1e8 && h.dvdx.abs() <= 1e8, "{h:?}");
    }
}
