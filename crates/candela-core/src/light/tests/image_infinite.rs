//! The image infinite light: χ² of its incident and emitted direction
//! sampling against its densities (the shared full-sphere harness of
//! `sampling::chi2`), the densities' normalisation, irradiance by light
//! sampling and by cosine sampling of `le` against quadrature, power, the
//! constant map against the uniform sky, and pbrt-v4's illuminance rule.
//! Images are synthesised in memory.

use super::*;
use crate::image::{MapImage, PixelFormat};
use crate::math::{Mat4, Ray, Transform, PI};
use crate::sampling::chi2::{chi2_test, sidak_alpha, Chi2Config};
use crate::sampling::{equal_area_square_to_sphere, sample_cosine_hemisphere};
use crate::spectrum::{ColorSpace, Rgb, Spectrum};
use std::sync::Arc;

/// χ² tests in this file (Šidák correction at family level 0.01).
const N_CHI2: usize = 2;

/// An n×n RGB map from `f(u, v)` at texel centres.
fn map(n: usize, f: impl Fn(f32, f32) -> [f32; 3]) -> Arc<MapImage> {
    let mut data = Vec::with_capacity(n * n * 3);
    for y in 0..n {
        for x in 0..n {
            data.extend(f((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32));
        }
    }
    Arc::new(MapImage::new(n, n, 3, data, PixelFormat::Float))
}

/// A dim, slightly coloured sky with a bright spot, and a black band (pdf 0).
fn spot_map() -> Arc<MapImage> {
    map(24, |u, v| {
        let d2 = (u - 0.3).powi(2) + (v - 0.6).powi(2);
        let b = 0.05 + 40.0 * (-d2 / 0.004).exp();
        if (0.8..0.9).contains(&u) {
            [0.0; 3]
        } else {
            [b, 0.8 * b + 0.02, 0.5 * b]
        }
    })
}

/// A rotation by `deg` about (1, 2, 3), to exercise the light frame.
fn tilted() -> Transform {
    let m = Mat4::from_axis_angle(crate::math::Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    Transform::new(m, m.inverse())
}

fn image_light(img: Arc<MapImage>, t: Transform) -> Light {
    let mut l = Light::ImageInfinite(ImageInfiniteLight::new(t, img, ColorSpace::srgb(), 1.0));
    l.preprocess(&unit_scene());
    l
}

fn at_origin() -> LightSampleContext {
    LightSampleContext::at_point(Vec3::ZERO)
}

#[test]
fn chi2_image_light_li_and_consistency() {
    let light = image_light(spot_map(), tilted());
    let (ctx, lam) = (at_origin(), lambda());
    // The density and radiance of a sample agree with pdf_li and le, but for
    // directions on a texel edge, which float round trips may move across.
    let mut mismatches = 0usize;
    let sample = |u1: f32, u2: f32, _: f32| {
        let s = light.sample_li(&ctx, Vec2::new(u1, u2), &lam)?;
        let p = light.pdf_li(&ctx, s.wi).0;
        let le = light.le(&Ray::new(Vec3::ZERO, s.wi), &lam);
        if (p - s.pdf.0).abs() > 1e-3 * s.pdf.0 || (le[0] - s.l[0]).abs() > 1e-4 * s.l[0] {
            mismatches += 1;
        }
        Some(s.wi)
    };
    let cfg = Chi2Config::default();
    let report = chi2_test(&cfg, sample, |w| light.pdf_li(&ctx, w).0);
    eprintln!("image light li: {report}; {mismatches} samples off their texel");
    assert!(mismatches * 10_000 < cfg.samples, "{mismatches} mismatches");
    report.check(sidak_alpha(0.01, N_CHI2)).unwrap();
    // The density integrates to 1 (quadrature error ≪ 2·10⁻³).
    assert!((report.pdf_integral - 1.0).abs() < 2e-3, "{report}");
}

#[test]
fn chi2_image_light_le_directions() {
    let light = image_light(spot_map(), tilted());
    let lam = lambda();
    let mut mismatches = 0usize;
    let sample = |u1: f32, u2: f32, u3: f32| {
        let s = light.sample_le(Vec2::new(u1, u2), Vec2::new(u3, 0.5), &lam)?;
        let (pp, pd) = light.pdf_le(&s.ray);
        assert!((pp.0 - s.pdf_pos.0).abs() <= 1e-6 * s.pdf_pos.0);
        if (pd.0 - s.pdf_dir.0).abs() > 1e-3 * s.pdf_dir.0 {
            mismatches += 1;
        }
        Some(s.ray.d)
    };
    // A seed apart from the incident test's, so the two are independent.
    let cfg = Chi2Config {
        seed: 1,
        ..Chi2Config::default()
    };
    let report = chi2_test(&cfg, sample, |w| {
        light.pdf_le(&Ray::new(Vec3::ZERO, w)).1 .0
    });
    eprintln!("image light le: {report}; {mismatches} samples off their texel");
    assert!(mismatches * 10_000 < cfg.samples, "{mismatches} mismatches");
    report.check(sidak_alpha(0.01, N_CHI2)).unwrap();
}

/// E at the origin on a +z patch by quadrature of `le` over the equal-area
/// square (midpoint rule, `k`² points per texel).
fn irradiance_quadrature(light: &Light, n: usize, k: usize) -> f64 {
    let lam = lambda();
    let m = n * k;
    let mut s = 0.0f64;
    for j in 0..m {
        for i in 0..m {
            let uv = Vec2::new((i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32);
            let w = equal_area_square_to_sphere(uv);
            if w.z > 0.0 {
                s += (light.le(&Ray::new(Vec3::ZERO, w), &lam)[0] * w.z) as f64;
            }
        }
    }
    s * 4.0 * std::f64::consts::PI / (m * m) as f64
}

#[test]
fn one_bright_texel_light_and_cosine_sampling_agree() {
    // A 16×16 map, black but for one texel above the horizon (identity frame).
    let n = 16;
    let img = map(n, |u, v| {
        let hit = (u * 16.0) as usize == 9 && (v * 16.0) as usize == 6;
        if hit {
            [20.0, 10.0, 5.0]
        } else {
            [0.0; 3]
        }
    });
    let light = image_light(img, Transform::IDENTITY);
    let exact = irradiance_quadrature(&light, n, 64);
    assert!(exact > 0.0);
    let (ctx, lam) = (LightSampleContext::at_point(Vec3::ZERO), lambda());
    let mut r = Pcg32::new(21, 4);
    let (mut nee, mut bsdf) = (Stats::default(), Stats::default());
    for _ in 0..400_000 {
        // Next-event estimation: light sampling.
        let e = light
            .sample_li(&ctx, u2(&mut r), &lam)
            .map_or(0.0, |s| (s.l[0] * s.wi.z.max(0.0) / s.pdf.0) as f64);
        nee.add(e);
        // BSDF-style: cosine-weighted directions, L·cos/p = π·L.
        let w = sample_cosine_hemisphere(u2(&mut r));
        bsdf.add((PI * light.le(&Ray::new(Vec3::ZERO, w), &lam)[0]) as f64);
    }
    eprintln!(
        "E exact {exact:.5}, NEE {:.5} ± {:.5}, cosine {:.5} ± {:.5}",
        nee.mean(),
        nee.sem(),
        bsdf.mean(),
        bsdf.sem()
    );
    nee.assert_mean(exact, 1e-4 * exact, "NEE irradiance");
    bsdf.assert_mean(exact, 1e-4 * exact, "cosine-sampled irradiance");
}

#[test]
fn power_is_the_mean_initial_throughput() {
    // E[β₀] over sample_le is Φ = 4π²R²·mean radiance (seed §3.2).
    let light = image_light(spot_map(), tilted());
    let lam = lambda();
    let phi = light.phi(&lam)[0] as f64;
    let mut r = Pcg32::new(5, 6);
    let mut st = Stats::default();
    for _ in 0..200_000 {
        let b = light
            .sample_le(u2(&mut r), u2(&mut r), &lam)
            .map_or(0.0, |s| s.beta0(1.0)[0] as f64);
        st.add(b);
    }
    eprintln!("Φ {phi:.4}, mean β₀ {:.4} ± {:.4}", st.mean(), st.sem());
    st.assert_mean(phi, 1e-4 * phi, "β₀ of the image light");
}

#[test]
fn constant_map_is_the_uniform_sky() {
    // A grey map is exact through the table, so it equals the uniform light
    // of the same RGB everywhere; its densities are uniform.
    let cs = ColorSpace::srgb();
    let img = map(8, |_, _| [0.7; 3]);
    let light = image_light(img, tilted());
    let mut sky = Light::UniformInfinite(UniformInfiniteLight::new(
        Spectrum::rgb_illuminant(cs, Rgb::new(0.7, 0.7, 0.7)),
        1.0,
    ));
    sky.preprocess(&unit_scene());
    let lam = lambda();
    let close = |a: f32, b: f32| (a - b).abs() <= 1e-5 * b.abs().max(1e-6);
    let mut r = Pcg32::new(2, 2);
    for _ in 0..100 {
        let w = crate::sampling::sample_uniform_sphere(u2(&mut r));
        let ray = Ray::new(Vec3::ZERO, w);
        for i in 0..4 {
            assert!(close(light.le(&ray, &lam)[i], sky.le(&ray, &lam)[i]));
        }
        let (p, q) = (light.pdf_li(&at_origin(), w).0, 1.0 / (4.0 * PI));
        assert!(close(p, q), "{p} vs {q}");
    }
    for i in 0..4 {
        assert!(close(light.phi(&lam)[i], sky.phi(&lam)[i]));
    }
}

#[test]
fn illuminance_follows_pbrt_v4() {
    // pbrt-v4 normalises by (2π/N)·Σ Y·cos θ over the upper texels, half the
    // map's illuminance (see light::create): a unit grey map asked for
    // E_v = π renders L = 2 (luminance), i.e. twice the uniform sky's
    // radiance for the same request, within the 64×64 Riemann sum.
    let cs = ColorSpace::srgb();
    let img = map(64, |_, _| [1.0; 3]);
    let t = Transform::IDENTITY;
    let light = image_infinite_light(&t, img, cs, 1.0, Some(PI));
    let sky = uniform_infinite_light(cs.illuminant.clone(), 1.0, Some(PI));
    let lam = lambda();
    let ray = Ray::new(Vec3::ZERO, Vec3::Z);
    let ratio = light.le(&ray, &lam)[0] / sky.le(&ray, &lam)[0];
    assert!((ratio - 2.0).abs() < 2e-3, "ratio {ratio}");
}
