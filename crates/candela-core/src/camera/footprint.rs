//! The pixel footprint: how far a surface point moves from one pixel to the
//! next, for texture filtering [pbrt-v4 `CameraBase::FindMinimumDifferentials`,
//! `CameraBase::Approximate_dp_dxy`; book §5.2.1, §10.1.1].
//!
//! pbrt-v4 traces ray differentials for camera rays and specular chains and
//! falls back to this approximation everywhere else (after diffuse and
//! glossy bounces, in the light tracer). candela uses the approximation at
//! every hit, so a camera-ray hit gets the footprint of the camera's
//! *smallest* per-pixel spread rather than its own: on a pinhole camera the
//! two agree at the image corners, where rays spread least, and elsewhere
//! the approximation is smaller (a sharper, never blurrier, filter).
//! Specular chains do not widen it.
//!
//! At build time, 512 rays along the film's diagonal are generated with the
//! lens at its centre together with the rays one pixel to the right and one
//! pixel down (for the spherical camera, 1/20 pixel scaled up, as pbrt-v4's
//! generic `GenerateRayDifferential` does). In camera space, the smallest
//! change of origin per pixel and the smallest change of unit direction per
//! pixel — measured in a frame whose z is the ray — are kept. At a hit p with
//! normal n, a ray leaving the camera towards p (z axis of a frame built
//! along p) is offset by those minima; the offset rays meet the tangent plane
//! of p at px and py, and ∂p/∂x ≈ s·(px − p), ∂p/∂y ≈ s·(py − p) with
//! s = max(1/8, 1/√spp): with many samples per pixel each sample covers less
//! of the pixel. The tangential orientation of the minima in their ray frame
//! is arbitrary (as in pbrt-v4), so ∂p/∂x's direction within the tangent
//! plane is only indicative; its length is what filters use.

use super::{Camera, CameraSample};
use crate::interaction::{Differentials, SurfaceInteraction};
use crate::math::{Frame, Transform, UVec2, Vec2, Vec3};

/// The camera's minimum per-pixel ray differentials and the spp scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelFootprint {
    /// Render (world) → camera space.
    camera_from_render: Transform,
    /// Smallest change of ray origin per pixel in x and y (camera space).
    min_pos: [Vec3; 2],
    /// Smallest change of unit direction per pixel in x and y, in the
    /// frame whose z is the ray's direction.
    min_dir: [Vec3; 2],
    /// max(1/8, 1/√spp).
    spp_scale: f32,
}

impl PixelFootprint {
    /// The footprint of `camera` on a film of `resolution` sampled with
    /// `spp` samples per pixel [pbrt-v4 `FindMinimumDifferentials`].
    pub fn new(camera: &Camera, resolution: UVec2, spp: u32) -> Self {
        // pbrt-v4's projective cameras give one-pixel differences; its
        // generic path (spherical camera) steps 1/20 pixel and scales up.
        let eps = match camera {
            Camera::Spherical(_) => 0.05,
            _ => 1.0,
        };
        let camera_from_render = camera.world_from_camera().inverse();
        let mut min_pos = [Vec3::INFINITY; 2];
        let mut min_dir = [Vec3::INFINITY; 2];
        let n = 512;
        for i in 0..n {
            let t = i as f32 / (n - 1) as f32;
            let p_film = resolution.as_vec2() * t;
            let Some((o, d)) = camera_ray(camera, &camera_from_render, p_film) else {
                continue;
            };
            let frame = Frame::from_z(d);
            for (axis, step) in [Vec2::X, Vec2::Y].into_iter().enumerate() {
                // Shift forwards, or backwards where that leaves the film.
                let Some((os, ds, e)) = [eps, -eps].into_iter().find_map(|e| {
                    camera_ray(camera, &camera_from_render, p_film + step * e)
                        .map(|(os, ds)| (os, ds, e))
                }) else {
                    continue;
                };
                let dpos = (os - o) / e;
                if dpos.length() < min_pos[axis].length() {
                    min_pos[axis] = dpos;
                }
                let d_shift = (d + (ds - d) / e).normalize_or_zero();
                let ddir = frame.to_local(d_shift).normalize_or_zero() - Vec3::Z;
                if ddir.length() < min_dir[axis].length() {
                    min_dir[axis] = ddir;
                }
            }
        }
        let finite = |v: Vec3| if v.is_finite() { v } else { Vec3::ZERO };
        Self {
            camera_from_render,
            min_pos: min_pos.map(finite),
            min_dir: min_dir.map(finite),
            spp_scale: (1.0 / (spp.max(1) as f32).sqrt()).max(0.125),
        }
    }

    /// Approximate ∂p/∂x and ∂p/∂y at point `p` with normal `n` (render
    /// space) [pbrt-v4 `Approximate_dp_dxy`]; zero where the offset rays
    /// run parallel to the tangent plane.
    pub fn dp_dxy(&self, p: Vec3, n: Vec3) -> (Vec3, Vec3) {
        let p_camera = self.camera_from_render.point(p);
        let n_camera = self.camera_from_render.normal(n);
        let down_z = Frame::from_z(p_camera.normalize_or_zero());
        let (p_down, n_down) = (down_z.to_local(p_camera), down_z.to_local(n_camera));
        // Tangent plane n·x = n·p, with p on the z axis.
        let plane_d = n_down.z * p_down.z;
        let render_from_camera = self.camera_from_render.inverse();
        let offset = |axis: usize| {
            let (o, d) = (self.min_pos[axis], Vec3::Z + self.min_dir[axis]);
            let t = (plane_d - n_down.dot(o)) / n_down.dot(d);
            let hit_offset = o + d * t - p_down;
            let v = self.spp_scale * render_from_camera.vector(down_z.from_local(hit_offset));
            if v.is_finite() {
                v
            } else {
                Vec3::ZERO
            }
        };
        (offset(0), offset(1))
    }

    /// Sets the hit's screen-space differentials: ∂p/∂x, ∂p/∂y from the
    /// footprint and (u, v) derivatives by least squares.
    pub fn set_differentials(&self, si: &mut SurfaceInteraction) {
        let (dpdx, dpdy) = self.dp_dxy(si.p(), si.n());
        si.diff = Differentials::from_dp(dpdx, dpdy, si.dpdu, si.dpdv);
    }
}

/// Origin and unit direction, in camera space, of the ray through `p_film`
/// with the lens at its centre.
fn camera_ray(
    camera: &Camera,
    camera_from_render: &Transform,
    p_film: Vec2,
) -> Option<(Vec3, Vec3)> {
    let r = camera.generate_ray(CameraSample {
        p_film,
        p_lens: Vec2::splat(0.5),
    })?;
    let o = camera_from_render.point(r.ray.o);
    let d = camera_from_render.vector(r.ray.d).normalize_or_zero();
    (d != Vec3::ZERO).then_some((o, d))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::CameraParams;

    /// Camera at the origin looking down +z, 100×100 pixels, 64 spp (s = 1/8).
    fn footprint(perspective: bool) -> PixelFootprint {
        let p = CameraParams::new(Transform::IDENTITY, UVec2::new(100, 100));
        let cam = if perspective {
            Camera::perspective(&p).unwrap()
        } else {
            Camera::orthographic(&p).unwrap()
        };
        PixelFootprint::new(&cam, p.film_resolution, 64)
    }

    /// On a plane facing the camera at distance d, the offset ray of
    /// direction Z + Δ (|Δ| the chord between unit rays one pixel apart)
    /// lands d·tan α from the axis, α the angle between those rays. Rays
    /// spread least per pixel at the largest |q| on the image plane z = 1:
    /// the last diagonal sample, raster (100, 100) → (101, 100), i.e.
    /// q = (1, −1, 1) → (1.02, −1, 1) (90° fov: screen ±1 over 100 pixels).
    /// Tolerance 1e-3 relative: the one-pixel chord (α ≈ 0.0068) is formed
    /// from f32 unit vectors, losing about ε/α ≈ 2e-5.
    #[test]
    fn perspective_footprint_is_the_smallest_pixel_angle_at_distance() {
        let f = footprint(true);
        let (q0, q1) = (Vec3::new(1.0, -1.0, 1.0), Vec3::new(1.02, -1.0, 1.0));
        let alpha = (q0.dot(q1) as f64 / (q0.length() * q1.length()) as f64).acos();
        for d in [2.0f32, 8.0] {
            let (dpdx, dpdy) = f.dp_dxy(Vec3::new(0.0, 0.0, d), -Vec3::Z);
            let want = 0.125 * d as f64 * alpha.tan();
            for (v, name) in [(dpdx, "x"), (dpdy, "y")] {
                let got = v.length() as f64;
                assert!(
                    (got / want - 1.0).abs() < 1e-3,
                    "d={d} {name}: {got} vs {want}"
                );
                assert!(v.z.abs() < 1e-6 * d, "{name} leaves the plane: {v}");
            }
        }
    }

    /// Orthographic: one pixel is 2/100 camera units at every distance
    /// (on the axis, where the frame along p is the camera's own; off it the
    /// offsets are taken in a frame tilted by θ and land up to 1/cos θ
    /// further, as in pbrt-v4). Tolerance: f32 rounding of 0.0025.
    #[test]
    fn orthographic_footprint_is_a_pixel_times_the_spp_scale() {
        let f = footprint(false);
        for d in [1.0f32, 50.0] {
            let (dpdx, dpdy) = f.dp_dxy(Vec3::new(0.0, 0.0, d), -Vec3::Z);
            assert!(
                (dpdx - Vec3::new(0.02 * 0.125, 0.0, 0.0)).length() < 1e-7,
                "{dpdx}"
            );
            assert!(
                (dpdy - Vec3::new(0.0, -0.02 * 0.125, 0.0)).length() < 1e-7,
                "{dpdy}"
            );
            let p = Vec3::new(0.3, 0.1, d);
            let (dpdx, _) = f.dp_dxy(p, -Vec3::Z);
            let cos = d / p.length();
            let len = dpdx.length() / 0.0025;
            assert!(
                (1.0 - 1e-5..=1.0 / cos / cos + 1e-5).contains(&len),
                "{len}"
            );
        }
        // A plane seen edge-on gives no finite footprint: zero, not NaN.
        let (dpdx, _) = f.dp_dxy(Vec3::new(0.0, 0.0, 2.0), Vec3::X);
        assert_eq!(dpdx, Vec3::ZERO);
    }
}
