//! T1 and T2: irradiance at a receiver through `sample_li`.

use super::*;
use crate::math::Transform;

/// Receiver at `p` with normal `n` (geometric = shading).
fn receiver(p: Vec3, n: Vec3) -> LightSampleContext {
    LightSampleContext {
        p,
        p_error: Vec3::ZERO,
        n,
        ns: n,
    }
}

#[test]
fn t1_point_light_over_plane() {
    // E(d) = I·h/(h² + d²)^{3/2}, I = 100, h = 2; deterministic, so only
    // f32 round-off and the 6 printed digits: relative 1e-5.
    let light = Light::Point(PointLight::new(
        Transform::translate(Vec3::new(0.0, 0.0, 2.0)),
        constant(100.0),
        1.0,
    ));
    for (d, e) in [(0.0, 25.0), (1.0, 17.8885), (2.0, 8.83883), (4.0, 2.23607)] {
        let ctx = receiver(Vec3::new(d, 0.0, 0.0), Vec3::Z);
        let s = light
            .sample_li(&ctx, Vec2::new(0.5, 0.5), &lambda())
            .unwrap();
        assert!(light.light_type().is_delta() && s.pdf.0 == 1.0);
        let got = s.l[0] * s.wi.dot(ctx.n).max(0.0) / s.pdf.0;
        assert!((got - e).abs() <= 1e-5 * e, "d={d}: E={got} expected {e}");
    }
}

/// Monte Carlo E = ∫ L cos dω through `sample_li`, with pdf_li checked per sample.
fn irradiance(light: &Light, ctx: &LightSampleContext, seed: u64, n: usize) -> Stats {
    irradiance_sum(std::slice::from_ref(light), ctx, seed, n)
}

/// E = Σ over lights of one `sample_li` estimate ∫ L cos dω each, per trial
/// (a mesh quad is two triangle lights whose irradiances add).
fn irradiance_sum(lights: &[Light], ctx: &LightSampleContext, seed: u64, n: usize) -> Stats {
    let lam = lambda();
    let mut r = Pcg32::new(seed, 9);
    let mut st = Stats::default();
    for _ in 0..n {
        let mut e = 0.0f64;
        for light in lights {
            let Some(s) = light.sample_li(ctx, u2(&mut r), &lam) else {
                continue;
            };
            let p = light.pdf_li(ctx, s.wi);
            assert!(
                (p.0 - s.pdf.0).abs() <= 1e-3 * s.pdf.0,
                "pdf_li {} vs {}",
                p.0,
                s.pdf.0
            );
            e += (s.l[0] * s.wi.dot(ctx.n).max(0.0) / s.pdf.0) as f64;
        }
        st.add(e);
    }
    st
}

fn disk_light(center: Vec3, radius: f32) -> Light {
    let shape = Geo::Disk {
        center,
        n: -Vec3::Z,
        radius,
    };
    Light::DiffuseArea(DiffuseAreaLight::new(
        shape.shape(),
        constant(1.0),
        1.0,
        false,
    ))
}

#[test]
fn t2_disk_irradiance() {
    // Coaxial: πL·R²/(h² + R²); offset (R, h, d) = (1, 1, 0.5): 1.375963 L.
    let pi = std::f64::consts::PI;
    let at = receiver(Vec3::ZERO, Vec3::Z);
    for (r, h, e) in [(1.0f32, 1.0f32, pi / 2.0), (0.5, 2.0, pi * 0.25 / 4.25)] {
        let st = irradiance(&disk_light(Vec3::new(0.0, 0.0, h), r), &at, 1, 100_000);
        st.assert_mean(e, 1e-6, "coaxial disk");
    }
    let st = irradiance(&disk_light(Vec3::new(0.5, 0.0, 1.0), 1.0), &at, 2, 100_000);
    st.assert_mean(1.375963, 1e-6, "offset disk");
}

#[test]
fn t2_square_irradiance() {
    // Centred 2×2 square at distance 1: 1.7408395 L; receiver tilted 45°: 1.2309594 L.
    let lights: Vec<Light> = square(Vec3::Z, 2.0, true)
        .shapes()
        .into_iter()
        .map(|s| Light::DiffuseArea(DiffuseAreaLight::new(s, constant(1.0), 1.0, false)))
        .collect();
    let st = irradiance_sum(&lights, &receiver(Vec3::ZERO, Vec3::Z), 3, 100_000);
    st.assert_mean(1.7408395, 1e-6, "square");
    let tilted = Vec3::new(1.0, 0.0, 1.0).normalize();
    let st = irradiance_sum(&lights, &receiver(Vec3::ZERO, tilted), 4, 100_000);
    st.assert_mean(1.2309594, 1e-6, "tilted square");
}

#[test]
fn one_sided_light_is_dark_behind() {
    // The receiver is above a downward-facing disk: no radiance, and L()
    // honours the orientation while a two-sided light emits both ways.
    let light = disk_light(Vec3::ZERO, 1.0);
    let ctx = receiver(Vec3::new(0.0, 0.0, 1.0), -Vec3::Z);
    assert!(light
        .sample_li(&ctx, Vec2::new(0.3, 0.6), &lambda())
        .is_none());
    let l = |two: bool, w: Vec3| {
        let shape = Geo::Disk {
            center: Vec3::ZERO,
            n: Vec3::Z,
            radius: 1.0,
        };
        let a = Light::DiffuseArea(DiffuseAreaLight::new(
            shape.shape(),
            constant(2.0),
            1.0,
            two,
        ));
        a.l(Vec3::ZERO, Vec3::Z, Vec2::ZERO, w, &lambda())[0]
    };
    assert_eq!((l(false, Vec3::Z), l(false, -Vec3::Z)), (2.0, 0.0));
    assert_eq!((l(true, Vec3::Z), l(true, -Vec3::Z)), (2.0, 2.0));
}
