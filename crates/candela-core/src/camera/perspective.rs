//! Perspective camera: pinhole or thin lens [pbrt-v4 §5.2.3–5.2.5, §5.4].
//!
//! The screen window lies on the plane z = 1 scaled by tan(fov/2), so the
//! window's ±1 (the shorter image axis by default) subtends the field of view.
//! A is the image's area on the plane z = 1.
//!
//! Importance [pbrt-v4 §5.4.1]: a pinhole generates directions with density
//! p(ω) = 1/(A cos³θ) (the image plane at distance 1/cos θ, foreshortened by
//! cos θ), so W_e(ω) = p(ω)/cos θ = 1/(A cos⁴θ). A thin lens spreads the
//! origin uniformly over its disk (density 1/(πr²)), and the direction to the
//! point in focus has the same density, giving W_e = 1/(A πr² cos⁴θ).

use super::{check_lens, CameraError, CameraFrame, CameraParams, CameraRay, CameraSample};
use super::{CameraWiSample, ScreenMap};
use crate::interaction::Interaction;
use crate::math::{Mat3, Ray, Vec2, Vec3, PI};
use crate::sampling::{pdf_area_to_solid_angle, sample_uniform_disk_concentric};
use crate::sampling::{PdfArea, PdfSolidAngle};

/// A perspective camera; see the module docs.
#[derive(Clone, Debug)]
pub struct PerspectiveCamera {
    pub(crate) frame: CameraFrame,
    screen: ScreenMap,
    tan_half_fov: f32,
    lens_radius: f32,
    focal_distance: f32,
    /// Image area on the plane z = 1 in camera space.
    area: f32,
    /// The lens point of a pinhole (the camera's position), made once.
    pinhole: Interaction,
    /// For a pinhole, world direction d to homogeneous raster position:
    /// (h.x, h.y)/h.z is where the ray from the pinhole along d meets the
    /// film ([`Self::pinhole_raster`]).
    raster_from_dir: Mat3,
}

impl PerspectiveCamera {
    /// Builds the camera; the fov applies to screen coordinates ±1.
    pub fn new(p: &CameraParams) -> Result<Self, CameraError> {
        if !(p.fov_deg > 0.0 && p.fov_deg < 180.0) {
            return Err(CameraError::BadFov(p.fov_deg));
        }
        check_lens(p)?;
        let screen = ScreenMap::new(p)?;
        let tan_half_fov = (0.5 * p.fov_deg.to_radians()).tan();
        let frame = CameraFrame::new(p.camera_from_world);
        Ok(Self {
            raster_from_dir: raster_from_dir(&frame, &screen, tan_half_fov),
            pinhole: frame.lens_interaction(Vec3::ZERO),
            frame,
            screen,
            tan_half_fov,
            lens_radius: p.lens_radius,
            focal_distance: p.focal_distance,
            area: screen.window_area() * tan_half_fov * tan_half_fov,
        })
    }

    /// Image area on the plane z = 1 (the `A` of pbrt-v4 §5.4.1).
    pub fn image_plane_area(&self) -> f32 {
        self.area
    }

    /// Lens area; 1 for a pinhole by pbrt's convention.
    fn lens_area(&self) -> f32 {
        if self.lens_radius > 0.0 {
            PI * self.lens_radius * self.lens_radius
        } else {
            1.0
        }
    }

    /// Camera ray through `p_film`, refracted by the thin lens when present.
    pub fn generate_ray(&self, s: CameraSample) -> Option<CameraRay> {
        let sc = self.screen.raster_to_screen(s.p_film);
        let p_camera = Vec3::new(sc.x * self.tan_half_fov, sc.y * self.tan_half_fov, 1.0);
        let mut o = Vec3::ZERO;
        let mut d = p_camera.normalize();
        if self.lens_radius > 0.0 {
            // Every ray through the lens towards the focus point of the pinhole ray.
            let p_lens = self.lens_radius * sample_uniform_disk_concentric(s.p_lens);
            let p_focus = d * (self.focal_distance / d.z);
            o = Vec3::new(p_lens.x, p_lens.y, 0.0);
            d = (p_focus - o).normalize();
        }
        let w = &self.frame.world_from_camera;
        let ray = Ray::new(w.point(o), w.vector(d).normalize());
        Some(CameraRay { ray, weight: 1.0 })
    }

    /// cos θ to the view axis and raster position of a world ray, `None` if
    /// the ray points backwards.
    fn raster_of(&self, o: Vec3, d: Vec3) -> Option<(f32, Vec2)> {
        let d = d.normalize();
        let cos_theta = d.dot(self.frame.forward);
        if cos_theta <= 0.0 || cos_theta.is_nan() {
            return None;
        }
        if self.lens_radius == 0.0 {
            return self.pinhole_raster(d).map(|r| (cos_theta, r));
        }
        // Where the ray meets the plane of focus.
        let z = self.focal_distance;
        let pc = self.frame.camera_from_world.point(o + d * (z / cos_theta));
        let s = Vec2::new(pc.x, pc.y) / (pc.z * self.tan_half_fov);
        Some((cos_theta, self.screen.screen_to_raster(s)))
    }

    /// Raster position of the ray from the pinhole along `d`: with p_c =
    /// M·d + (the camera's position in camera space, 0) for the linear part M
    /// of camera-from-world, the screen point is p_c.xy/(p_c.z tan(fov/2))
    /// whatever the distance along the ray, and screen to raster is affine,
    /// so one 3×3 map and a division give it (`raster_from_dir`). `None`
    /// behind the camera.
    #[inline]
    fn pinhole_raster(&self, d: Vec3) -> Option<Vec2> {
        let h = self.raster_from_dir * d;
        (h.z > 0.0).then(|| Vec2::new(h.x, h.y) / h.z)
    }

    /// W_e = 1/(A · lens area · cos⁴θ) inside the film sample bounds.
    pub fn we(&self, o: Vec3, d: Vec3) -> (f32, Option<Vec2>) {
        let Some((cos_theta, r)) = self.raster_of(o, d) else {
            return (0.0, None);
        };
        if !self.screen.inside(r) {
            return (0.0, Some(r));
        }
        let c2 = cos_theta * cos_theta;
        (1.0 / (self.area * self.lens_area() * c2 * c2), Some(r))
    }

    /// (1/lens area, 1/(A cos³θ)) inside the film sample bounds, else zeros.
    pub fn pdf_we(&self, ray: &Ray) -> (PdfArea, PdfSolidAngle) {
        match self.raster_of(ray.o, ray.d) {
            Some((c, r)) if self.screen.inside(r) => (
                PdfArea(1.0 / self.lens_area()),
                PdfSolidAngle(1.0 / (self.area * c * c * c)),
            ),
            _ => (PdfArea(0.0), PdfSolidAngle(0.0)),
        }
    }

    /// Samples the lens uniformly and converts its area density to solid
    /// angle at the reference point [pbrt-v4 §5.4.2].
    pub fn sample_wi(&self, ref_p: &Interaction, u: Vec2) -> Option<CameraWiSample> {
        let lens = if self.lens_radius > 0.0 {
            let p_lens = self.lens_radius * sample_uniform_disk_concentric(u);
            self.frame
                .lens_interaction(Vec3::new(p_lens.x, p_lens.y, 0.0))
        } else {
            self.pinhole
        };
        let to_lens = lens.p - ref_p.p;
        let dist2 = to_lens.length_squared();
        if dist2 == 0.0 {
            return None;
        }
        let wi = to_lens / dist2.sqrt();
        let pdf =
            pdf_area_to_solid_angle(PdfArea(1.0 / self.lens_area()), dist2, lens.n.dot(wi).abs());
        let (we, p_raster) = self.we(lens.p, -wi);
        if we == 0.0 || pdf.0 == 0.0 {
            return None;
        }
        Some(CameraWiSample {
            we,
            wi,
            pdf,
            p_raster: p_raster?,
            p_lens: lens,
            is_delta: false,
        })
    }
}

/// The map of [`PerspectiveCamera::pinhole_raster`]: rows k_x(M₀/t − x₀M₂),
/// k_y(y₁M₂ − M₁/t) and M₂, from the rows Mᵢ of camera-from-world's linear
/// part, t = tan(fov/2), the screen window's x₀ (left) and y₁ (top), and
/// k = resolution / window extent [pbrt-v4 §5.2.3, raster from screen].
fn raster_from_dir(frame: &CameraFrame, screen: &ScreenMap, tan_half_fov: f32) -> Mat3 {
    let m = Mat3::from_mat4(frame.camera_from_world.m);
    let (m0, m1, m2) = (m.row(0), m.row(1), m.row(2));
    let k = screen.res / (screen.win_max - screen.win_min);
    Mat3::from_cols(
        k.x * (m0 / tan_half_fov - screen.win_min.x * m2),
        k.y * (screen.win_max.y * m2 - m1 / tan_half_fov),
        m2,
    )
    .transpose()
}
