//! pbrt-v4's `spherical` camera: every direction around a point, mapped to
//! the film by the equal-area octahedral map [Clarberg 2008] (`mapping
//! "equalarea"`, the default; the film must be square) or by latitude and
//! longitude (`"equirectangular"`: θ = π v, φ = 2π u). As in pbrt-v4 the
//! camera-space direction has y and z swapped, so the image's pole axis is
//! camera +y.
//!
//! The camera is a point with a non-delta direction distribution, so BDPT's
//! camera-side densities exist (uniform 1/(4π) for equal-area, 1/(2π² sin θ)
//! for equirectangular), but it has no importance function to connect light
//! paths to: light tracing rejects it and BDPT drops its t = 1 strategies.

use super::{CameraFrame, CameraRay, CameraSample};
use crate::math::{Ray, UVec2, Vec2, Vec3, PI};
use crate::sampling::equal_area_square_to_sphere;
use crate::sampling::{PdfArea, PdfSolidAngle};

/// How directions are laid out on the film.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SphericalMapping {
    /// Clarberg's equal-area octahedral map (square film).
    EqualArea,
    /// Latitude/longitude.
    Equirectangular,
}

/// The spherical camera.
#[derive(Clone, Debug)]
pub struct SphericalCamera {
    pub(crate) frame: CameraFrame,
    res: Vec2,
    mapping: SphericalMapping,
}

impl SphericalCamera {
    /// A spherical camera at the CTM's origin.
    pub fn new(
        camera_from_world: crate::math::Transform,
        resolution: UVec2,
        mapping: SphericalMapping,
    ) -> Self {
        Self {
            frame: CameraFrame::new(camera_from_world),
            res: resolution.as_vec2(),
            mapping,
        }
    }

    /// Camera-space direction of film point `uv` ∈ \[0,1\]² (y and z swapped as pbrt).
    fn direction(&self, uv: Vec2) -> Vec3 {
        let d = match self.mapping {
            SphericalMapping::Equirectangular => {
                let (theta, phi) = (PI * uv.y, 2.0 * PI * uv.x);
                Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                )
            }
            SphericalMapping::EqualArea => equal_area_square_to_sphere(wrap_unit(uv)),
        };
        Vec3::new(d.x, d.z, d.y)
    }

    /// Ray through raster point `s.p_film` (the lens sample is unused).
    pub fn generate_ray(&self, s: CameraSample) -> Option<CameraRay> {
        let uv = s.p_film / self.res;
        let d = self.direction(uv);
        let w = &self.frame.world_from_camera;
        let ray = Ray::new(w.point(Vec3::ZERO), w.vector(d).normalize());
        Some(CameraRay { ray, weight: 1.0 })
    }

    /// Position density 1 (a point) and the solid-angle density of `ray`'s direction.
    pub fn pdf_we(&self, ray: &Ray) -> (PdfArea, PdfSolidAngle) {
        let d = self.frame.camera_from_world.vector(ray.d).normalize();
        let d = Vec3::new(d.x, d.z, d.y);
        let pdf = match self.mapping {
            SphericalMapping::EqualArea => 1.0 / (4.0 * PI),
            SphericalMapping::Equirectangular => {
                let sin_theta = (1.0 - d.z * d.z).max(0.0).sqrt();
                if sin_theta == 0.0 {
                    0.0
                } else {
                    1.0 / (2.0 * PI * PI * sin_theta)
                }
            }
        };
        (PdfArea(1.0), PdfSolidAngle(pdf))
    }
}

/// Wraps film coordinates outside \[0,1\]² (filter tails) back onto the square
/// by the octahedral map's mirror symmetry, as pbrt's `WrapEqualAreaSquare`.
fn wrap_unit(uv: Vec2) -> Vec2 {
    let mut p = uv;
    if p.x < 0.0 {
        p.x = -p.x;
        p.y = 1.0 - p.y;
    } else if p.x > 1.0 {
        p.x = 2.0 - p.x;
        p.y = 1.0 - p.y;
    }
    if p.y < 0.0 {
        p.x = 1.0 - p.x;
        p.y = -p.y;
    } else if p.y > 1.0 {
        p.x = 1.0 - p.x;
        p.y = 2.0 - p.y;
    }
    p.clamp(Vec2::ZERO, Vec2::ONE)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Transform;
    use crate::sampling::Pcg32;

    fn cam(mapping: SphericalMapping) -> SphericalCamera {
        SphericalCamera::new(Transform::IDENTITY, UVec2::new(64, 64), mapping)
    }

    #[test]
    fn equirectangular_centre_row_quarter_looks_forward() {
        // θ = π/2, φ = π/2 is camera +y before pbrt's y/z swap, so +z after it.
        let c = cam(SphericalMapping::Equirectangular);
        let s = CameraSample {
            p_film: Vec2::new(16.0, 32.0),
            p_lens: Vec2::ZERO,
        };
        let d = c.generate_ray(s).expect("ray").ray.d;
        assert!((d - Vec3::Z).length() < 1e-5, "{d}");
    }

    #[test]
    fn direction_density_matches_uniform_film_sampling() {
        // Film points uniform over the image give directions whose density is
        // pdf_we: E[1/pdf] over them is the sphere's 4π (5σ, σ measured).
        for mapping in [
            SphericalMapping::EqualArea,
            SphericalMapping::Equirectangular,
        ] {
            let c = cam(mapping);
            let mut r = Pcg32::new(3, 1);
            let n = 200_000;
            let (mut s, mut sq) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let p_film = Vec2::new(r.uniform_f32(), r.uniform_f32()) * 64.0;
                let ray = c
                    .generate_ray(CameraSample {
                        p_film,
                        p_lens: Vec2::ZERO,
                    })
                    .expect("ray")
                    .ray;
                let pdf = c.pdf_we(&ray).1 .0 as f64;
                // Exactly at a pole (u = 0 gives θ = 0) the density has no value.
                let v = if pdf > 0.0 { 1.0 / pdf } else { 0.0 };
                s += v;
                sq += v * v;
            }
            let m = s / n as f64;
            let se = ((sq / n as f64 - m * m) / n as f64).sqrt();
            let want = 4.0 * std::f64::consts::PI;
            assert!(
                (m - want).abs() <= 5.0 * se + 1e-4,
                "{mapping:?}: {m} ± {se}"
            );
        }
    }
}
