//! The scene's scale as the photon integrators see it: the default gather
//! radius of SPPM and PPM, the memory their iterations need, and warnings
//! for written radii far from the scene's scale.
//!
//! **Default radius.** pbrt-v4's SPPM starts from `radius` 1 whatever the
//! scene's size: on the 2-unit Cornell box every photon then lands in the
//! disks of thousands of visible points (7.9 GB and 40 s per iteration at
//! 256², against 52 MB and 0.23 s at r = 0.035). Without a written radius,
//! candela starts from [`FOOTPRINT_PIXELS`] pixel footprints at the median
//! first-hit distance: camera rays through a 16 × 16 grid of pixel centres
//! of the full film, each paired with the ray through the next pixel to the
//! right, give the world-space distance between the two rays at the first
//! ray's hit; the median over the rays that hit is the footprint. A scene
//! the grid never hits falls back to [`FALLBACK_SHARE`] of the bounding
//! box's diagonal. The full film, not the crop window, is measured, so a
//! crop renders the same pixels as the whole image.
//!
//! **Memory of one SPPM/PPM iteration** (the dominant terms, from the
//! settings):
//! * visible points: N_pix · (size of a pixel visit + a grid sphere of 16
//!   bytes + its radius) and up to 8 grid entries each (cells of twice the
//!   radius: a sphere spans at most 2 × 2 × 2) of 20 bytes, plus a 4-byte
//!   bucket per entry; with G > 1 wavelength groups, G BSDF slots a pixel
//!   (a visible point seen directly is weighed at every group's
//!   wavelengths);
//! * the photon–point contributions, 24 bytes each: N_photons photons, each
//!   stored once after its first bounce (a lower bound: a photon stores one
//!   record per bounce after the first), each inside
//!   k = min(N_pix, N_pix · πr² / A) visible points' disks, with A the surface
//!   area of the scene's bounding box (the visible surface of a closed room);
//! * SPPM's per-pixel statistics, 64 bytes a pixel, and the per-pixel
//!   gathered sums, 16 bytes per group and 8 for the count.
//!
//! On the Cornell box at 256² with r = 1 this estimates 13 GB (11 GB at the
//! 20 bytes a contribution took when 7.9 GB was measured); at r = 0.035,
//! about 40 MB.

use super::budget::Budget;
use super::check::Check;
use super::BuildError;
use crate::bsdf::Bsdf;
use crate::camera::{Camera, CameraSample};
use crate::film::Film;
use crate::integrator::photonmap::Photon;
use crate::integrator::sppm::passes::PixelVisit;
use crate::integrator::vcm;
use crate::integrator::{IntegratorKind, PhotonMapSettings};
use crate::math::{Bounds3, Vec2};
use crate::scene::Scene;
use candela_scene::Loc;

/// The default SPPM/PPM radius in pixel footprints (module docs).
pub const FOOTPRINT_PIXELS: f32 = 3.0;

/// The default VCM merge radius in pixel footprints. Smaller than the
/// photon integrators': VCM's merges compete under MIS with connections,
/// and at one light path per pixel a merge's density π r² N_light p outweighs
/// a connection's on diffuse paths well below SPPM's radius, so on diffuse
/// light the radius sets the kernel bias of most of the image rather than
/// the noise of its caustics (module docs of `integrator::vcm`). It is the
/// unit of VCM's radius warnings and the starting point of its pilot, which
/// replaces it by the light vertices' density radius (`integrator::vcm::pilot`).
pub const VCM_FOOTPRINT_PIXELS: f32 = 1.0;

/// Default radius as a share of the bounding box's diagonal, for scenes the
/// camera grid does not hit.
pub const FALLBACK_SHARE: f32 = 0.005;

/// Photon–point pairs per second and core, measured on the Cornell box
/// (400 M pairs in 40 s on 2 cores, radius 1): only for the time warning.
const PAIRS_PER_SECOND: f64 = 5e6;

/// Iterations above this many seconds' worth of gathering are warned about.
const SLOW_ITERATION_SECONDS: f64 = 10.0;

/// What the photon integrators need to know of the scene's size.
#[derive(Clone, Debug)]
pub struct SceneScale {
    /// World bounds of the geometry.
    pub bounds: Bounds3,
    /// Median world-space width of a pixel at the first hit, if any ray hit.
    pub footprint: Option<f32>,
    /// Pixels rendered (the film's pixel bounds).
    pub pixels: u64,
}

impl SceneScale {
    /// Measures `scene` through `camera` on `film` (module docs).
    pub fn measure(scene: &Scene, camera: &Camera, film: &Film) -> Self {
        let (lo, hi) = film.pixel_bounds();
        let pixels = (hi.x - lo.x) as u64 * (hi.y - lo.y) as u64;
        let res = film.resolution().as_vec2();
        let n = 16;
        let mut widths = Vec::with_capacity(n * n);
        for j in 0..n {
            for i in 0..n {
                let p = Vec2::new(
                    ((i as f32 + 0.5) / n as f32 * res.x).floor() + 0.5,
                    ((j as f32 + 0.5) / n as f32 * res.y).floor() + 0.5,
                );
                let ray = |p_film| {
                    camera.generate_ray(CameraSample {
                        p_film,
                        p_lens: Vec2::splat(0.5),
                    })
                };
                let (Some(a), Some(b)) = (ray(p), ray(p + Vec2::X)) else {
                    continue;
                };
                let Some(si) = scene.intersect(&a.ray, f32::INFINITY) else {
                    continue;
                };
                let t = (si.p() - a.ray.o).length();
                let w = (b.ray.o + b.ray.d.normalize() * t).distance(si.p());
                if w.is_finite() && w > 0.0 {
                    widths.push(w);
                }
            }
        }
        widths.sort_by(f32::total_cmp);
        SceneScale {
            bounds: scene.bounds(),
            footprint: widths.get(widths.len() / 2).copied(),
            pixels,
        }
    }

    /// No scene (for integrators that do not look at its scale).
    pub fn none() -> Self {
        SceneScale {
            bounds: Bounds3::EMPTY,
            footprint: None,
            pixels: 0,
        }
    }

    /// Length of the bounding box's diagonal (0 for an empty or non-finite box).
    pub fn diagonal(&self) -> f32 {
        let d = (self.bounds.max - self.bounds.min).length();
        if d.is_finite() {
            d
        } else {
            0.0
        }
    }

    /// A default radius of `footprints` pixel footprints; for a scene the
    /// camera grid does not hit, [`FALLBACK_SHARE`] of the diagonal scaled
    /// by `footprints` / [`FOOTPRINT_PIXELS`].
    pub fn default_radius_in(&self, footprints: f32) -> f32 {
        let d = self.diagonal();
        match self.footprint {
            Some(w) => footprints * w,
            None if d > 0.0 => FALLBACK_SHARE * d * footprints / FOOTPRINT_PIXELS,
            None => 1.0,
        }
    }

    /// Visible points whose disk of radius `r` holds a photon (module docs).
    fn points_per_photon(&self, r: f32) -> f64 {
        let area = self.bounds.surface_area() as f64;
        let n = self.pixels as f64;
        if !(area.is_finite() && area > 0.0) {
            return n;
        }
        (n * std::f64::consts::PI * (r as f64).powi(2) / area).min(n)
    }
}

/// Photons of one iteration: `n` if positive, else one per pixel.
pub fn photons(n: i64, scale: &SceneScale) -> u64 {
    if n > 0 {
        n as u64
    } else {
        scale.pixels
    }
}

/// A warning when single precision cannot place the scene's geometry to
/// within a pixel: positions are f32, spaced |x|·2⁻²³ apart at coordinate
/// x, so where the scene reaches further from the origin than the pixel
/// footprint at the visible surfaces allows, its surfaces there are
/// rounded by more than a pixel and rays can miss or find them wrongly (a
/// triangle of 10¹⁰ units drawn across a 2-unit room vanished from camera
/// rays yet shadowed the room). pbrt-v4 has the same limit and no warning.
pub fn precision_warning(scale: &SceneScale) -> Option<String> {
    let width = scale.footprint?;
    let b = scale.bounds;
    let reach = b.min.abs().max(b.max.abs()).max_element();
    let spacing = reach * f32::EPSILON;
    (reach.is_finite() && spacing > width).then(|| {
        format!(
            "the scene reaches {reach:.3e} from the origin, where single-precision positions are {spacing:.2e} apart, more than a pixel's width at the visible surfaces ({width:.2e}): geometry there can be misplaced or missed (keep the scene near the origin, or its far parts smaller)"
        )
    })
}

/// What the default radius of `kind` is, in words and in scene units, for
/// the warnings: SPPM's and PPM's [`FOOTPRINT_PIXELS`] footprints, or VCM's
/// radius from the light vertices' density, within its pilot's bounds.
pub fn default_radius_text(kind: IntegratorKind, scale: &SceneScale) -> String {
    if kind == IntegratorKind::Vcm {
        let (lo, hi) = (vcm::pilot::MIN_FOOTPRINTS, vcm::pilot::MAX_FOOTPRINTS);
        let fp = VCM_FOOTPRINT_PIXELS;
        format!(
            "the default, chosen from the light vertices' density between {lo} and {hi} pixel footprints ({:.3e} to {:.3e} here)",
            scale.default_radius_in(lo * fp),
            scale.default_radius_in(hi * fp)
        )
    } else {
        format!(
            "the default of {FOOTPRINT_PIXELS} pixel footprints ({:.3e} here)",
            scale.default_radius_in(FOOTPRINT_PIXELS)
        )
    }
}

/// A warning for a written radius far from the scene's scale; `default`
/// says what leaving it out gives ([`default_radius_text`]).
pub fn radius_warning(
    loc: &Loc,
    name: &str,
    radius: f32,
    scale: &SceneScale,
    default: &str,
) -> Option<String> {
    let diagonal = scale.diagonal();
    if diagonal <= 0.0 {
        return None;
    }
    let share = radius / diagonal;
    if share > 0.05 {
        Some(format!(
            "{loc}: {name} \"radius\" {radius} is {:.0}% of the scene's diagonal ({diagonal:.3}): expect blur (each photon's light spread over a disk of that radius) and slow early passes; leave it out for {default}",
            share * 100.0
        ))
    } else if share < 1e-5 {
        Some(format!(
            "{loc}: {name} \"radius\" {radius} is tiny against the scene's diagonal ({diagonal:.3}): visible points will gather almost no photons; leave it out for {default}"
        ))
    } else {
        None
    }
}

/// Claims the memory of one SPPM/PPM iteration of `photons` photons at
/// radius `radius` (module docs) and warns when its gathering will be slow.
pub fn claim_progressive(
    ck: &Check<'_>,
    radius: f32,
    photons: u64,
    groups: u32,
    scale: &SceneScale,
    budget: &mut Budget,
    warnings: &mut Vec<String>,
) -> Result<(), BuildError> {
    let n = scale.pixels as f64;
    let g = f64::from(groups.max(1));
    let visit = std::mem::size_of::<PixelVisit>() as f64 + 20.0;
    let group_bsdfs = if groups > 1 {
        g * std::mem::size_of::<Option<Bsdf>>() as f64
    } else {
        0.0
    };
    let sums = 16.0 * g + 8.0;
    let points = n * (visit + group_bsdfs + 8.0 * (20.0 + 4.0) + 64.0 + sums);
    budget
        .claim(
            points as u64,
            &format!("{} visible points and their grid", scale.pixels),
            "lower the Film's resolution or crop it",
        )
        .map_err(|m| BuildError::at(ck.loc, m))?;
    let pairs = photons as f64 * scale.points_per_photon(radius);
    let written = ck.params.param_loc("radius").is_some();
    let fix = if written {
        "lower \"radius\" (or leave it out for the scene-scaled default) or \"photonsperiteration\""
    } else {
        "lower \"photonsperiteration\""
    };
    let name = if written {
        "radius"
    } else {
        "photonsperiteration"
    };
    budget
        .claim(
            (pairs * 24.0).min(u64::MAX as f64) as u64,
            &format!(
                "the photon contributions of one iteration ({photons} photons, each in the disks of about {:.0} visible points of radius {radius})",
                scale.points_per_photon(radius)
            ),
            fix,
        )
        .map_err(|m| ck.error(name, m))?;
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get()) as f64;
    let seconds = pairs / (PAIRS_PER_SECOND * threads);
    if seconds > SLOW_ITERATION_SECONDS {
        warnings.push(format!(
            "{}: {} gathers about {pairs:.1e} photon–point pairs per iteration (roughly {seconds:.0} s each on this machine): {fix}",
            ck.loc_of(name),
            ck.what
        ));
    }
    Ok(())
}

/// Claims the memory of one VCM iteration of `light_paths` light paths:
/// its stored light vertices, counted at one per path (a lower bound: the
/// vertices per path depend on the scene, 3.1 on the Cornell box and 0.3 on
/// caustic-glass at one light path per pixel), and, with the variance pilot
/// (`pilot`), both pilot passes' per-pixel estimates.
pub fn claim_vcm(
    ck: &Check<'_>,
    light_paths: u64,
    pilot: bool,
    scale: &SceneScale,
    budget: &mut Budget,
) -> Result<(), BuildError> {
    let each = (vcm::STORED_VERTEX_BYTES + 4) as u64;
    budget
        .claim(
            light_paths.saturating_mul(each),
            &format!("the light vertices of one iteration ({light_paths} light paths, {each} B each at least)"),
            "lower \"photonsperiteration\"",
        )
        .map_err(|m| ck.error("photonsperiteration", m))?;
    if pilot {
        claim_pilot(ck, scale, budget)?;
    }
    Ok(())
}

/// Claims the variance pilot's per-pixel estimates of both pilot passes
/// (`integrator::lt_weights`), for `vcm` and `bdpt`.
pub fn claim_pilot(
    ck: &Check<'_>,
    scale: &SceneScale,
    budget: &mut Budget,
) -> Result<(), BuildError> {
    budget
        .claim(
            scale
                .pixels
                .saturating_mul(2 * vcm::PILOT_BYTES_PER_PIXEL as u64),
            &format!(
                "the variance pilot's estimates of {} pixels in two passes",
                scale.pixels
            ),
            "lower the Film's resolution or crop it, or set \"string ltweights\" \"density\"",
        )
        .map_err(|m| BuildError::at(ck.loc, m))?;
    Ok(())
}

/// Claims the photon maps of `Integrator "photonmap"`: at least one stored
/// photon per path of each map (module docs), and the kd-tree's copy of them
/// while it is built.
pub fn claim_photon_map(
    ck: &Check<'_>,
    s: &PhotonMapSettings,
    budget: &mut Budget,
) -> Result<(), BuildError> {
    let each = 2 * std::mem::size_of::<Photon>() as u64;
    for (name, paths) in [
        ("photons", s.photons),
        ("causticphotons", s.caustic_photons),
    ] {
        budget
            .claim(
                paths.saturating_mul(each),
                &format!("a photon map of {paths} photon paths (\"{name}\")"),
                &format!("lower \"{name}\""),
            )
            .map_err(|m| ck.error(name, m))?;
    }
    Ok(())
}

/// The memory of the film: one pass block, the accumulated state and the
/// checkpoint serialised from it (as large as the state), and the developed
/// RGB image (12 bytes a pixel).
pub fn film_bytes(film: &Film) -> u64 {
    let (block, state) = film.memory_estimate();
    let developed = film.pixel_count() as u64 * 12;
    block
        .saturating_add(state.saturating_mul(2))
        .saturating_add(developed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;

    fn scale(footprint: Option<f32>) -> SceneScale {
        SceneScale {
            bounds: Bounds3::from_points(Vec3::ZERO, Vec3::new(3.0, 4.0, 0.0)),
            footprint,
            pixels: 100,
        }
    }

    #[test]
    fn default_radii_count_pixel_footprints_or_fall_back_to_the_diagonal() {
        let s = scale(Some(0.02));
        assert_eq!(
            s.default_radius_in(FOOTPRINT_PIXELS),
            FOOTPRINT_PIXELS * 0.02
        );
        assert_eq!(
            s.default_radius_in(VCM_FOOTPRINT_PIXELS),
            VCM_FOOTPRINT_PIXELS * 0.02
        );
        // No hit: the share of the diagonal (5 here), scaled alike.
        let s = scale(None);
        assert_eq!(s.default_radius_in(FOOTPRINT_PIXELS), FALLBACK_SHARE * 5.0);
        let vcm = s.default_radius_in(VCM_FOOTPRINT_PIXELS);
        let want = FALLBACK_SHARE * 5.0 * VCM_FOOTPRINT_PIXELS / FOOTPRINT_PIXELS;
        assert!((vcm - want).abs() <= 1e-6 * want, "{vcm} vs {want}");
    }
}
