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
