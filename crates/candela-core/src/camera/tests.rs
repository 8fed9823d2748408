//! Camera tests: importance normalisation (validation T7), round trips,
//! sample_wi ↔ pdf_we ↔ we agreement, and the screen-window geometry.

use super::*;
use crate::math::{Frame, Mat4, PI};
use crate::sampling::{
    pdf_area_to_solid_angle, sample_uniform_cone, sample_uniform_hemisphere, uniform_cone_pdf,
    uniform_hemisphere_pdf, Pcg32,
};
use glam::Quat;

/// A rigid world-from-camera placement (rotation + translation).
fn world_from_camera() -> Transform {
    let m = Mat4::from_rotation_translation(
        Quat::from_axis_angle(Vec3::new(0.3, 1.0, 0.2).normalize(), 0.7),
        Vec3::new(1.0, -2.0, 3.0),
    );
    Transform::new(m, m.inverse())
}

fn params(res: UVec2) -> CameraParams {
    CameraParams::new(world_from_camera().inverse(), res)
}

fn u2(r: &mut Pcg32) -> Vec2 {
    Vec2::new(r.uniform_f32(), r.uniform_f32())
}

/// Asserts |mean − expected| ≤ 5 s/√n for per-sample estimates `xs`
/// (validation.md: k = 5, s measured in the same run, b = 0).
fn assert_mean(xs: &[f64], expected: f64, what: &str) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    let tol = 5.0 * (var / n).sqrt();
    assert!(
        (mean - expected).abs() <= tol && tol < 0.02,
        "{what}: mean {mean} vs {expected} (tol {tol})"
    );
}

/// T7 (pinhole and thin lens): ∫_lens ∫_Ω W_e cos θ dω dA = 1. Directions are
/// drawn uniformly on the forward hemisphere, lens points uniformly on the disk,
/// independent of the camera's own ray mapping.
#[test]
fn perspective_importance_integrates_to_one() {
    for (lens_radius, seed) in [(0.0f32, 1u64), (0.25, 2)] {
        let mut p = params(UVec2::new(64, 48));
        p.fov_deg = 60.0;
        p.lens_radius = lens_radius;
        p.focal_distance = 3.0;
        let cam = Camera::perspective(&p).unwrap();
        let Camera::Perspective(pc) = &cam else {
            unreachable!()
        };
        // A = (2·aspect·tan 30°)(2·tan 30°) on the plane z = 1.
        let t = (30f32).to_radians().tan();
        assert!((pc.image_plane_area() - 4.0 * (64.0 / 48.0) * t * t).abs() < 1e-5);
        let w = cam.world_from_camera();
        let frame = Frame::from_z(w.vector(Vec3::Z).normalize());
        let mut rng = Pcg32::new(seed, 7);
        let xs: Vec<f64> = (0..400_000)
            .map(|_| {
                let dl =
                    lens_radius * crate::sampling::sample_uniform_disk_concentric(u2(&mut rng));
                let p_lens_pdf = if lens_radius > 0.0 {
                    1.0 / (PI * lens_radius * lens_radius)
                } else {
                    1.0
                };
                let o = w.point(dl.extend(0.0));
                let d = frame.from_local(sample_uniform_hemisphere(u2(&mut rng)));
                let (we, _) = cam.we(o, d);
                let cos = d.dot(frame.z);
                (we * cos / (uniform_hemisphere_pdf() * p_lens_pdf)) as f64
            })
            .collect();
        assert_mean(&xs, 1.0, &format!("perspective lens {lens_radius}"));
    }
}

/// T7 for the thin-lens orthographic importance derived in `orthographic.rs`:
/// origins uniform on the film dilated by the lens radius, directions
/// uniform in a cone slightly wider than tan θ = r/f.
#[test]
fn orthographic_lens_importance_integrates_to_one() {
    let mut p = params(UVec2::new(32, 32));
    p.lens_radius = 0.3;
    p.focal_distance = 2.0;
    let cam = Camera::orthographic(&p).unwrap();
    let w = cam.world_from_camera();
    let frame = Frame::from_z(w.vector(Vec3::Z).normalize());
    let half = 1.0 + p.lens_radius;
    let cos_max = 1.0 / (1.0 + (1.05f32 * p.lens_radius / p.focal_distance).powi(2)).sqrt();
    let mut rng = Pcg32::new(3, 9);
    let xs: Vec<f64> = (0..400_000)
        .map(|_| {
            let x = (2.0 * u2(&mut rng) - Vec2::ONE) * half;
            let o = w.point(x.extend(0.0));
            let d = frame.from_local(sample_uniform_cone(u2(&mut rng), cos_max));
            let (we, _) = cam.we(o, d);
            let pdf = uniform_cone_pdf(cos_max) / (4.0 * half * half);
            (we * d.dot(frame.z) / pdf) as f64
        })
        .collect();
    assert_mean(&xs, 1.0, "orthographic lens");
}

fn all_cameras() -> Vec<(&'static str, Camera)> {
    let mut p = params(UVec2::new(40, 30));
    p.fov_deg = 50.0;
    let mut lens = p;
    lens.lens_radius = 0.1;
    lens.focal_distance = 4.0;
    vec![
        ("pinhole", Camera::perspective(&p).unwrap()),
        ("thin lens", Camera::perspective(&lens).unwrap()),
        ("ortho", Camera::orthographic(&p).unwrap()),
        ("ortho lens", Camera::orthographic(&lens).unwrap()),
    ]
}

/// `we` of a generated ray maps back to the raster position it came from.
#[test]
fn generated_rays_round_trip_through_we() {
    let mut rng = Pcg32::new(11, 0);
    for (name, cam) in all_cameras() {
        for _ in 0..2000 {
            let p_film = u2(&mut rng) * Vec2::new(40.0, 30.0);
            let s = CameraSample {
                p_film,
                p_lens: u2(&mut rng),
            };
            let r = cam.generate_ray(s).unwrap();
            assert_eq!(r.weight, 1.0);
            assert!((r.ray.d.length() - 1.0).abs() < 1e-5);
            let (we, raster) = cam.we(r.ray.o, r.ray.d);
            let raster = raster.unwrap();
            assert!(
                (raster - p_film).abs().max_element() < 1e-3,
                "{name}: {raster} vs {p_film}"
            );
            assert_eq!(we > 0.0, !cam.is_delta_direction(), "{name}");
            let (pa, pd) = cam.pdf_we(&r.ray);
            assert!(pa.0 > 0.0 && pd.0 > 0.0, "{name}");
            if !cam.is_delta_direction() {
                // W_e cos θ equals the joint density of the generated ray.
                let cos = r
                    .ray
                    .d
                    .dot(cam.world_from_camera().vector(Vec3::Z).normalize());
                let rel = (we * cos / (pa.0 * pd.0) - 1.0).abs();
                assert!(rel < 1e-4, "{name}: We cos / pdf − 1 = {rel}");
            }
        }
    }
}

/// sample_wi agrees with we, with pdf_we converted to solid angle, and with
/// generate_ray from the returned raster position and the same lens sample.
#[test]
fn sample_wi_agrees_with_we_pdf_we_and_generate_ray() {
    let mut rng = Pcg32::new(5, 3);
    for (name, cam) in all_cameras() {
        let mut hits = 0;
        for _ in 0..2000 {
            let s0 = CameraSample {
                p_film: u2(&mut rng) * Vec2::new(40.0, 30.0),
                p_lens: u2(&mut rng),
            };
            let ray = cam.generate_ray(s0).unwrap().ray;
            let ref_p = Interaction::at_point(ray.at(0.5 + 8.0 * rng.uniform_f32()));
            let u = u2(&mut rng);
            let Some(s) = cam.sample_wi(&ref_p, u) else {
                continue;
            };
            hits += 1;
            assert_eq!(s.is_delta, cam.is_delta_direction(), "{name}");
            let (we, r) = cam.we(s.p_lens.p, -s.wi);
            if !s.is_delta {
                assert!((we / s.we - 1.0).abs() < 1e-4, "{name}: {we} vs {}", s.we);
                assert!(
                    (r.unwrap() - s.p_raster).abs().max_element() < 1e-3,
                    "{name}"
                );
            }
            if let Camera::Perspective(_) = cam {
                let (pa, _) = cam.pdf_we(&Ray::new(s.p_lens.p, -s.wi));
                let d2 = (s.p_lens.p - ref_p.p).length_squared();
                let conv = pdf_area_to_solid_angle(pa, d2, s.p_lens.n.dot(s.wi).abs());
                assert!((conv.0 / s.pdf.0 - 1.0).abs() < 1e-4, "{name}");
            }
            let back = cam
                .generate_ray(CameraSample {
                    p_film: s.p_raster,
                    p_lens: u,
                })
                .unwrap()
                .ray;
            assert!((back.o - s.p_lens.p).length() < 1e-3, "{name}: origin");
            assert!((back.d + s.wi).length() < 1e-3, "{name}: direction");
        }
        assert!(hits > 1000, "{name}: only {hits} connections");
    }
}

/// Corners and centre go where the screen window says; fov 90° puts the
/// shorter axis's edges at 45°.
#[test]
fn screen_window_geometry() {
    let check = |res: UVec2, raster: Vec2, d_cam: Vec3| {
        let cam = Camera::perspective(&params(res)).unwrap();
        let s = CameraSample {
            p_film: raster,
            p_lens: Vec2::splat(0.5),
        };
        let d = cam.generate_ray(s).unwrap().ray.d;
        let want = world_from_camera().vector(d_cam.normalize());
        assert!((d - want).length() < 1e-5, "{res} {raster}: {d} vs {want}");
    };
    let wide = UVec2::new(200, 100);
    check(wide, Vec2::new(100.0, 50.0), Vec3::Z);
    check(wide, Vec2::new(100.0, 0.0), Vec3::new(0.0, 1.0, 1.0)); // 45° up
    check(wide, Vec2::new(0.0, 50.0), Vec3::new(-2.0, 0.0, 1.0)); // aspect 2
    check(wide, Vec2::new(0.0, 0.0), Vec3::new(-2.0, 1.0, 1.0));
    check(wide, Vec2::new(200.0, 100.0), Vec3::new(2.0, -1.0, 1.0));
    let tall = UVec2::new(100, 200);
    check(tall, Vec2::new(0.0, 100.0), Vec3::new(-1.0, 0.0, 1.0)); // 45° left
    check(tall, Vec2::new(100.0, 0.0), Vec3::new(1.0, 2.0, 1.0));
    // Orthographic: the window is the film in camera units.
    let cam = Camera::orthographic(&params(wide)).unwrap();
    let s = CameraSample {
        p_film: Vec2::ZERO,
        p_lens: Vec2::ZERO,
    };
    let r = cam.generate_ray(s).unwrap().ray;
    assert!((r.o - world_from_camera().point(Vec3::new(-2.0, 1.0, 0.0))).length() < 1e-5);
}

/// The pinhole orthographic connection is a delta with coefficient 1/A.
#[test]
fn orthographic_delta_connection() {
    let cam = Camera::orthographic(&params(UVec2::new(200, 100))).unwrap();
    let w = world_from_camera();
    let ref_p = Interaction::at_point(w.point(Vec3::new(1.0, 0.5, 7.0)));
    let s = cam.sample_wi(&ref_p, Vec2::splat(0.3)).unwrap();
    assert!(s.is_delta && s.pdf.0 == 1.0);
    assert!((s.we - 1.0 / 8.0).abs() < 1e-6); // window 4 × 2
    assert!((s.p_raster - Vec2::new(150.0, 25.0)).length() < 1e-3);
    assert!((s.p_lens.p - w.point(Vec3::new(1.0, 0.5, 0.0))).length() < 1e-4);
    let behind = Interaction::at_point(w.point(Vec3::new(0.0, 0.0, -1.0)));
    assert!(cam.sample_wi(&behind, Vec2::ZERO).is_none());
    assert_eq!(cam.we(s.p_lens.p, -s.wi).0, 0.0);
}

#[test]
fn invalid_parameters_are_errors() {
    let mut p = params(UVec2::new(0, 10));
    assert_eq!(
        Camera::perspective(&p).unwrap_err(),
        CameraError::EmptyFilm(0, 10)
    );
    p.film_resolution = UVec2::new(10, 10);
    p.fov_deg = 180.0;
    assert!(Camera::perspective(&p).is_err());
    p.fov_deg = 45.0;
    p.screen_window = Some([1.0, -1.0, -1.0, 1.0]);
    assert!(Camera::orthographic(&p).is_err());
}
