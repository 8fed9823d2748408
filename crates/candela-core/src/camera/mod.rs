//! Cameras: primary rays and the importance function W_e used by light
//! tracing and BDPT.
//!
//! # Spaces
//! * **Raster space**: pixel coordinates, x right, y *down*, the image spans
//!   `[0, res.x] × [0, res.y]`.
//! * **Screen space**: the screen window `[x0, x1] × [y0, y1]`, y *up*;
//!   raster (0, 0) is the window's top-left corner `(x0, y1)` [pbrt-v4 §5.2].
//! * **Camera space**: pbrt's left-handed camera frame, looking down +z with
//!   +y up and +x to the right of the image.
//! * **Render space = world space.** candela renders in world space (pbrt-v4
//!   defaults to a camera-centred frame for precision; we do not). The camera is
//!   placed by `camera_from_world`, the current transformation matrix at the
//!   scene's `Camera` directive (what pbrt's `LookAt`, `Scale -1 1 1`, ... built).
//!   Importance is exact when that transform is rigid (a rotation, translation
//!   and possibly a reflection): lengths and angles are then the same in both
//!   spaces.
//!
//! # Importance
//! Following pbrt-v4 §5.4 (and Veach 1997 §8.2), W_e is normalised so that
//! ∫_lens ∫_Ω W_e(p, ω) cos θ dω dA(p) = 1 over the rays that reach the image,
//! i.e. W_e·cos θ is the joint density of generated rays, and a primary ray
//! carries weight 1. For the pinhole, the lens "area" is taken as 1 (pbrt's
//! convention, paired with a sampled pinhole position of density 1).
//!
//! Importance is a scalar: the camera response does not depend on wavelength.

mod footprint;
mod orthographic;
mod perspective;
mod spherical;
#[cfg(test)]
mod tests;

pub use footprint::PixelFootprint;
pub use orthographic::OrthographicCamera;
pub use perspective::PerspectiveCamera;
pub use spherical::{SphericalCamera, SphericalMapping};

use crate::interaction::Interaction;
use crate::math::{Ray, Transform, UVec2, Vec2, Vec3};
use crate::sampling::{PdfArea, PdfSolidAngle};

/// Why a camera could not be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CameraError {
    /// The film has zero width or height.
    #[error("film resolution {0}x{1} is empty")]
    EmptyFilm(u32, u32),
    /// The screen window has zero or negative extent.
    #[error("screen window {0:?} is degenerate")]
    BadScreenWindow([f32; 4]),
    /// Field of view outside (0°, 180°).
    #[error("field of view {0}° is outside (0, 180)")]
    BadFov(f32),
    /// Negative lens radius or non-positive focal distance.
    #[error("lens radius {0} / focal distance {1} invalid")]
    BadLens(f32, f32),
}

/// Plain construction values of a projective camera (pbrt's parameter names).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraParams {
    /// The CTM at the `Camera` directive: maps world points to camera space.
    pub camera_from_world: Transform,
    /// Full film resolution in pixels.
    pub film_resolution: UVec2,
    /// `[x0, x1, y0, y1]`; `None` gives pbrt's aspect-based default.
    pub screen_window: Option<[f32; 4]>,
    /// Perspective only: field of view in degrees along the shorter image axis.
    pub fov_deg: f32,
    /// Thin-lens radius (0: pinhole).
    pub lens_radius: f32,
    /// Distance to the plane in focus.
    pub focal_distance: f32,
    /// Pixel-filter radius; importance is non-zero over pbrt's film sample
    /// bounds `[0.5 − r, res − 0.5 + r]` (0.5 gives exactly the image).
    pub filter_radius: Vec2,
}

impl CameraParams {
    /// pbrt-v4 defaults (fov 90°, pinhole, focal distance 1e6, filter radius 0.5).
    pub fn new(camera_from_world: Transform, film_resolution: UVec2) -> Self {
        Self {
            camera_from_world,
            film_resolution,
            screen_window: None,
            fov_deg: 90.0,
            lens_radius: 0.0,
            focal_distance: 1e6,
            filter_radius: Vec2::splat(0.5),
        }
    }
}

/// Film and lens sample positions for one camera ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSample {
    /// Position on the film in raster coordinates.
    pub p_film: Vec2,
    /// Lens sample in [0, 1)².
    pub p_lens: Vec2,
}

/// A generated camera ray (world space, unit direction) and its weight.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraRay {
    /// The ray.
    pub ray: Ray,
    /// Importance / pdf of the ray: 1 for the cameras here.
    pub weight: f32,
}

/// A sampled connection from a scene point to the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraWiSample {
    /// Importance along the connection (for a delta: its coefficient).
    pub we: f32,
    /// Unit direction from the reference point towards the lens.
    pub wi: Vec3,
    /// Solid-angle density at the reference point (1 for a delta).
    pub pdf: PdfSolidAngle,
    /// Raster position the connection lands on.
    pub p_raster: Vec2,
    /// The sampled lens (or film-plane) point.
    pub p_lens: Interaction,
    /// True when the camera's directional importance is a Dirac delta
    /// (pinhole orthographic): `we`/`pdf` are then coefficients of the delta.
    pub is_delta: bool,
}

/// The cameras candela supports (closed set, dispatched by `match`).
#[derive(Clone, Debug)]
pub enum Camera {
    /// Pinhole or thin-lens perspective camera.
    Perspective(PerspectiveCamera),
    /// Orthographic camera (optionally thin-lens).
    Orthographic(OrthographicCamera),
    /// Every direction around a point (no importance function).
    Spherical(SphericalCamera),
}

macro_rules! dispatch {
    ($self:ident, $c:ident => $e:expr) => {
        match $self {
            Camera::Perspective($c) => $e,
            Camera::Orthographic($c) => $e,
            Camera::Spherical($c) => $e,
        }
    };
}

/// The projective cameras only (the spherical one has no W_e).
macro_rules! dispatch_projective {
    ($self:ident, $c:ident => $e:expr, $none:expr) => {
        match $self {
            Camera::Perspective($c) => $e,
            Camera::Orthographic($c) => $e,
            Camera::Spherical(_) => $none,
        }
    };
}

impl Camera {
    /// A perspective camera from plain values.
    pub fn perspective(p: &CameraParams) -> Result<Self, CameraError> {
        PerspectiveCamera::new(p).map(Camera::Perspective)
    }

    /// An orthographic camera from plain values (`fov_deg` is ignored).
    pub fn orthographic(p: &CameraParams) -> Result<Self, CameraError> {
        OrthographicCamera::new(p).map(Camera::Orthographic)
    }

    /// Ray for a film/lens sample [pbrt-v4 §5.2.3–5.2.5].
    pub fn generate_ray(&self, sample: CameraSample) -> Option<CameraRay> {
        dispatch!(self, c => c.generate_ray(sample))
    }

    /// Importance W_e of the ray (o, d) and the raster position it maps to.
    pub fn we(&self, ray_o: Vec3, ray_d: Vec3) -> (f32, Option<Vec2>) {
        dispatch_projective!(self, c => c.we(ray_o, ray_d), (0.0, None))
    }

    /// Densities of the ray's origin (area on the lens) and direction.
    pub fn pdf_we(&self, ray: &Ray) -> (PdfArea, PdfSolidAngle) {
        dispatch!(self, c => c.pdf_we(ray))
    }

    /// Samples a lens point seen from `ref_p` and the importance arriving there.
    pub fn sample_wi(&self, ref_p: &Interaction, u: Vec2) -> Option<CameraWiSample> {
        dispatch_projective!(self, c => c.sample_wi(ref_p, u), None)
    }

    /// True when directional importance is a delta (light paths cannot hit it).
    pub fn is_delta_direction(&self) -> bool {
        match self {
            Camera::Perspective(_) | Camera::Spherical(_) => false,
            Camera::Orthographic(c) => c.is_delta_direction(),
        }
    }

    /// True when light paths can be connected to the camera (t = 1
    /// strategies): projective cameras whose importance is not a delta.
    pub fn is_connectable(&self) -> bool {
        !self.is_delta_direction() && !matches!(self, Camera::Spherical(_))
    }

    /// World-space transform from camera space.
    pub fn world_from_camera(&self) -> Transform {
        dispatch!(self, c => c.frame.world_from_camera)
    }
}

/// Camera placement shared by the projective cameras.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CameraFrame {
    pub camera_from_world: Transform,
    pub world_from_camera: Transform,
    /// Unit viewing direction (camera +z) in world space.
    pub forward: Vec3,
}

impl CameraFrame {
    /// From the CTM at the camera directive.
    pub fn new(camera_from_world: Transform) -> Self {
        let world_from_camera = camera_from_world.inverse();
        let forward = world_from_camera.vector(Vec3::Z).normalize();
        Self {
            camera_from_world,
            world_from_camera,
            forward,
        }
    }

    /// Camera-space point to a world-space lens interaction facing forward.
    pub fn lens_interaction(&self, p_camera: Vec3) -> Interaction {
        let (p, p_error) = self.world_from_camera.point_with_error(p_camera);
        Interaction {
            p,
            p_error,
            n: self.forward,
            uv: Vec2::ZERO,
            time: 0.0,
        }
    }
}

/// The affine map between raster and screen space, plus the sample bounds.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ScreenMap {
    res: Vec2,
    win_min: Vec2,
    win_max: Vec2,
    bounds_min: Vec2,
    bounds_max: Vec2,
}

impl ScreenMap {
    /// Validates and builds the map; pbrt's default window is ±aspect on the
    /// longer axis and ±1 on the shorter one.
    pub fn new(p: &CameraParams) -> Result<Self, CameraError> {
        let r = p.film_resolution;
        if r.x == 0 || r.y == 0 {
            return Err(CameraError::EmptyFilm(r.x, r.y));
        }
        let res = r.as_vec2();
        let aspect = res.x / res.y;
        let w = p.screen_window.unwrap_or(if aspect > 1.0 {
            [-aspect, aspect, -1.0, 1.0]
        } else {
            [-1.0, 1.0, -1.0 / aspect, 1.0 / aspect]
        });
        if !(w[1] > w[0] && w[3] > w[2]) {
            return Err(CameraError::BadScreenWindow(w));
        }
        let fr = p.filter_radius.max(Vec2::ZERO);
        Ok(Self {
            res,
            win_min: Vec2::new(w[0], w[2]),
            win_max: Vec2::new(w[1], w[3]),
            bounds_min: Vec2::splat(0.5) - fr,
            bounds_max: res - Vec2::splat(0.5) + fr,
        })
    }

    /// Raster → screen (y flips).
    pub fn raster_to_screen(&self, r: Vec2) -> Vec2 {
        let e = self.win_max - self.win_min;
        Vec2::new(
            self.win_min.x + r.x / self.res.x * e.x,
            self.win_max.y - r.y / self.res.y * e.y,
        )
    }

    /// Screen → raster.
    pub fn screen_to_raster(&self, s: Vec2) -> Vec2 {
        let e = self.win_max - self.win_min;
        Vec2::new(
            (s.x - self.win_min.x) / e.x * self.res.x,
            (self.win_max.y - s.y) / e.y * self.res.y,
        )
    }

    /// Area of the screen window.
    pub fn window_area(&self) -> f32 {
        let e = self.win_max - self.win_min;
        e.x * e.y
    }

    /// True inside pbrt's film sample bounds (inclusive).
    pub fn inside(&self, r: Vec2) -> bool {
        r.cmpge(self.bounds_min).all() && r.cmple(self.bounds_max).all()
    }
}

/// Checks the thin-lens parameters.
pub(crate) fn check_lens(p: &CameraParams) -> Result<(), CameraError> {
    if !(p.lens_radius >= 0.0 && p.focal_distance > 0.0) {
        return Err(CameraError::BadLens(p.lens_radius, p.focal_distance));
    }
    Ok(())
}
