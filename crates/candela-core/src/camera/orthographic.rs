//! Orthographic camera [pbrt-v4 §5.2.4] and its importance (not in pbrt-v4).
//!
//! The screen window is the film itself, on the camera-space plane z = 0;
//! every pinhole ray leaves it along +z. Its area A is measured in camera
//! units (world units for a rigid `camera_from_world`).
//!
//! # Importance of the pinhole orthographic camera
//! Rays are uniform over the film (density 1/A) and have a single direction
//! ω_v, so W_e(p, ω) = δ_⊥(ω − ω_v)/A, with δ_⊥ a Dirac delta with respect to
//! projected solid angle; ∫∫ W_e cos θ dω dA = 1 as for the other cameras.
//! A delta cannot be evaluated: light paths never hit it, so [`we`] returns 0
//! (and the film-plane raster position the ray would project to), and
//! [`sample_wi`] returns the deterministic connection along −ω_v with `we` =
//! 1/A and `pdf` = 1 as delta coefficients, flagged `is_delta`. The estimator
//! `β·f·|cos θ_ref|·we/pdf` is then exact (no 1/d² falloff: a parallel
//! projection does not spread).
//!
//! # Thin-lens orthographic
//! A film point x_f (density 1/A) focuses at x_f + f·ẑ; the ray starts at
//! x_f + x_l, x_l uniform on the lens disk. (pbrt-v4 starts it at x_l alone,
//! which collapses every origin onto the disk around the axis; we keep the
//! film offset so the camera stays orthographic.) Changing variables from
//! (x_f, x_l) to (origin x₀, direction ω), dA(x_f) dA(x_l) = f²/cos³θ · dA(x₀) dω,
//! so the joint density is f²/(A πr² cos³θ) and W_e = f²/(A πr² cos⁴θ).
//!
//! [`we`]: OrthographicCamera::we
//! [`sample_wi`]: OrthographicCamera::sample_wi

use super::{check_lens, CameraError, CameraFrame, CameraParams, CameraRay, CameraSample};
use super::{CameraWiSample, ScreenMap};
use crate::interaction::Interaction;
use crate::math::{Ray, Vec2, Vec3, PI};
use crate::sampling::{pdf_area_to_solid_angle, sample_uniform_disk_concentric};
use crate::sampling::{PdfArea, PdfSolidAngle};

/// An orthographic camera; see the module docs.
#[derive(Clone, Debug)]
pub struct OrthographicCamera {
    pub(crate) frame: CameraFrame,
    screen: ScreenMap,
    lens_radius: f32,
    focal_distance: f32,
    /// Film area on the plane z = 0.
    area: f32,
}

impl OrthographicCamera {
    /// Builds the camera; the screen window is in camera-space units.
    pub fn new(p: &CameraParams) -> Result<Self, CameraError> {
        check_lens(p)?;
        let screen = ScreenMap::new(p)?;
        Ok(Self {
            frame: CameraFrame::new(p.camera_from_world),
            screen,
            lens_radius: p.lens_radius,
            focal_distance: p.focal_distance,
            area: screen.window_area(),
        })
    }

    /// Film area (camera units).
    pub fn film_area(&self) -> f32 {
        self.area
    }

    /// True for the pinhole variant, whose directional importance is a delta.
    pub fn is_delta_direction(&self) -> bool {
        self.lens_radius == 0.0
    }

    /// Parallel ray from the film point, refracted by the thin lens if any.
    pub fn generate_ray(&self, s: CameraSample) -> Option<CameraRay> {
        let sc = self.screen.raster_to_screen(s.p_film);
        let p_camera = Vec3::new(sc.x, sc.y, 0.0);
        let mut o = p_camera;
        let mut d = Vec3::Z;
        if self.lens_radius > 0.0 {
            let p_lens = self.lens_radius * sample_uniform_disk_concentric(s.p_lens);
            let p_focus = p_camera + Vec3::Z * self.focal_distance;
            o = p_camera + Vec3::new(p_lens.x, p_lens.y, 0.0);
            d = (p_focus - o).normalize();
        }
        let w = &self.frame.world_from_camera;
        let ray = Ray::new(w.point(o), w.vector(d).normalize());
        Some(CameraRay { ray, weight: 1.0 })
    }

    /// Lens area πr².
    fn lens_area(&self) -> f32 {
        PI * self.lens_radius * self.lens_radius
    }

    /// The ray in camera space: (cos θ, point on the film plane z = 0, unit
    /// direction); `None` for backward rays.
    fn to_film_plane(&self, o: Vec3, d: Vec3) -> Option<(f32, Vec3, Vec3)> {
        let c = &self.frame.camera_from_world;
        let dc = c.vector(d).normalize();
        if dc.z <= 0.0 || dc.z.is_nan() {
            return None;
        }
        let oc = c.point(o);
        Some((dc.z, oc - dc * (oc.z / dc.z), dc))
    }

    /// Pinhole: 0 (a delta) and the film position the ray projects to.
    /// Thin lens: f²/(A πr² cos⁴θ) when the ray passes the lens and its focus
    /// point lies inside the film sample bounds.
    pub fn we(&self, o: Vec3, d: Vec3) -> (f32, Option<Vec2>) {
        let Some((cos_theta, x0, dc)) = self.to_film_plane(o, d) else {
            return (0.0, None);
        };
        if self.is_delta_direction() {
            return (0.0, Some(self.screen.screen_to_raster(x0.truncate())));
        }
        let f = self.focal_distance;
        let p_focus = x0 + dc * (f / dc.z);
        let r = self.screen.screen_to_raster(p_focus.truncate());
        // Tolerance: samples on the disk's rim survive the round trip.
        let on_lens = (x0 - p_focus).truncate().length() <= self.lens_radius * (1.0 + 1e-4);
        if !self.screen.inside(r) || !on_lens {
            return (0.0, Some(r));
        }
        let c2 = cos_theta * cos_theta;
        (f * f / (self.area * self.lens_area() * c2 * c2), Some(r))
    }

    /// Pinhole: (1/A, 1 for the delta). Thin lens: (1/A, f²/(πr² cos³θ)),
    /// whose product is the exact joint density of (origin, direction); the
    /// split is a factorisation, not a marginal and a conditional.
    pub fn pdf_we(&self, ray: &Ray) -> (PdfArea, PdfSolidAngle) {
        let Some((cos_theta, _, _)) = self.to_film_plane(ray.o, ray.d) else {
            return (PdfArea(0.0), PdfSolidAngle(0.0));
        };
        let (we, r) = self.we(ray.o, ray.d);
        let inside = r.is_some_and(|r| self.screen.inside(r));
        if self.is_delta_direction() {
            if !inside {
                return (PdfArea(0.0), PdfSolidAngle(0.0));
            }
            return (PdfArea(1.0 / self.area), PdfSolidAngle(1.0));
        }
        if we == 0.0 {
            return (PdfArea(0.0), PdfSolidAngle(0.0));
        }
        let f = self.focal_distance;
        let c3 = cos_theta * cos_theta * cos_theta;
        (
            PdfArea(1.0 / self.area),
            PdfSolidAngle(f * f / (self.lens_area() * c3)),
        )
    }

    /// Connection from `ref_p` to the film: the delta along the view axis for
    /// the pinhole; for the thin lens a lens offset is sampled uniformly.
    pub fn sample_wi(&self, ref_p: &Interaction, u: Vec2) -> Option<CameraWiSample> {
        let pc = self.frame.camera_from_world.point(ref_p.p);
        if pc.z <= 0.0 || pc.z.is_nan() {
            return None;
        }
        if self.is_delta_direction() {
            let p_raster = self.screen.screen_to_raster(pc.truncate());
            if !self.screen.inside(p_raster) {
                return None;
            }
            return Some(CameraWiSample {
                we: 1.0 / self.area,
                wi: -self.frame.forward,
                pdf: PdfSolidAngle(1.0),
                p_raster,
                p_lens: self.frame.lens_interaction(Vec3::new(pc.x, pc.y, 0.0)),
                is_delta: true,
            });
        }
        // Rays through p with lens offset x_l start at x₀ = p_xy + x_l·z_p/f,
        // so x₀ is uniform on a disk of radius r·z_p/f.
        let scale = pc.z / self.focal_distance;
        let x_l = self.lens_radius * sample_uniform_disk_concentric(u);
        let x0 = pc.truncate() + x_l * scale;
        let lens = self.frame.lens_interaction(x0.extend(0.0));
        let pdf_area = PdfArea(1.0 / (self.lens_area() * scale * scale));
        let to_lens = lens.p - ref_p.p;
        let dist2 = to_lens.length_squared();
        let wi = to_lens / dist2.sqrt();
        let pdf = pdf_area_to_solid_angle(pdf_area, dist2, lens.n.dot(wi).abs());
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
