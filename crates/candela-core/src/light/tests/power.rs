//! T3: power bookkeeping — Φ closed forms, β₀ of emitted samples, light selection.

use super::*;
use crate::image::{MapImage, PixelFormat};
use crate::math::{Ray, Transform, PI};
use crate::spectrum::{ColorSpace, Rgb, SpectrumKind};
use std::sync::Arc;

fn point(i: f32, at: Vec3) -> Light {
    Light::Point(PointLight::new(Transform::translate(at), constant(i), 1.0))
}

fn spot() -> Light {
    let t = Transform::translate(Vec3::new(0.3, -0.2, 1.0));
    Light::Spot(SpotLight::new(t, constant(50.0), 1.0, 30.0, 25.0))
}

fn area(geo: Geo, l: f32, two_sided: bool) -> Light {
    Light::DiffuseArea(DiffuseAreaLight::new(
        geo.shape(),
        constant(l),
        1.0,
        two_sided,
    ))
}

/// The lights of a parallelogram (two triangles), as a mesh quad in a scene.
fn areas(geo: Geo, l: f32, two_sided: bool) -> Vec<Light> {
    geo.shapes()
        .into_iter()
        .map(|s| Light::DiffuseArea(DiffuseAreaLight::new(s, constant(l), 1.0, two_sided)))
        .collect()
}

/// One light of every type and shape, with its closed-form Φ.
pub(crate) fn lights_with_phi() -> Vec<(&'static str, Light, f64)> {
    let mut v = punctual_lights_with_phi();
    v.extend(area_lights_with_phi());
    v
}

/// Area lights and their closed-form Φ.
fn area_lights_with_phi() -> Vec<(&'static str, Light, f64)> {
    let pi = std::f64::consts::PI;
    let a = 0.25f64; // 0.5 × 0.5 square
    let sphere = Geo::Sphere {
        center: Vec3::new(0.0, 1.0, 0.0),
        radius: 0.5,
    };
    let tri = Geo::Triangle {
        p: [
            Vec3::ZERO,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.5),
        ],
    };
    let tri_area = 0.5
        * Vec3::new(1.0, 0.0, 0.0)
            .cross(Vec3::new(0.0, 2.0, 0.5))
            .length() as f64;
    let disk = Geo::Disk {
        center: Vec3::ZERO,
        n: Vec3::new(0.0, 0.6, 0.8),
        radius: 0.7,
    };
    vec![
        (
            "half quad",
            areas(square(Vec3::Z, 0.5, true), 10.0, false).remove(0),
            pi * a / 2.0 * 10.0,
        ),
        (
            "half quad 2-sided",
            areas(square(Vec3::Z, 0.5, true), 10.0, true).remove(1),
            2.0 * pi * a / 2.0 * 10.0,
        ),
        ("sphere", area(sphere.clone(), 3.0, false), pi * pi * 3.0),
        (
            "sphere 2-sided",
            area(sphere, 3.0, true),
            2.0 * pi * pi * 3.0,
        ),
        ("triangle", area(tri, 4.0, false), pi * tri_area * 4.0),
        (
            "disk 2-sided",
            area(disk, 1.5, true),
            2.0 * pi * pi * 0.49 * 1.5,
        ),
    ]
}

/// Punctual, directional and infinite lights and their closed-form Φ.
fn punctual_lights_with_phi() -> Vec<(&'static str, Light, f64)> {
    let pi = std::f64::consts::PI;
    let r2 = 3.0f64; // bounding radius² of unit_scene()
    let mut distant = Light::Distant(DistantLight::new(Transform::IDENTITY, constant(2.0), 1.0));
    distant.preprocess(&unit_scene());
    let mut inf = Light::UniformInfinite(UniformInfiniteLight::new(constant(0.5), 1.0));
    inf.preprocess(&unit_scene());
    let (ce, cs) = (30f64.to_radians().cos(), 25f64.to_radians().cos());
    // Goniometric: Φ = 4π·I·mean(Y); projector of a white 6×4 slide at 60°:
    // Φ = I·4·asin(sin α·sin β), tan α = 1.5·tan 30°, tan β = tan 30°
    // (the solid angle of a rectangular pyramid).
    let map = super::punctual_maps::gonio_map();
    let mean_y = map.data.iter().map(|&v| v as f64).sum::<f64>() / map.data.len() as f64;
    let gonio = Light::Goniometric(GoniometricLight::new(
        Transform::translate(Vec3::new(0.0, 2.0, 0.0)),
        constant(3.0),
        1.0,
        Arc::new(map),
    ));
    let srgb = ColorSpace::srgb();
    let white = MapImage::new(6, 4, 3, vec![1.0; 72], PixelFormat::Float);
    let proj = Light::Projection(ProjectionLight::new(
        Transform::translate(Vec3::new(0.5, 0.0, 0.0)),
        Arc::new(white),
        srgb,
        1.0,
        60.0,
    ));
    let i_white = srgb.sample_rgb(Rgb::new(1.0, 1.0, 1.0), SpectrumKind::Illuminant, &lambda())[0];
    let t = (30f64).to_radians().tan();
    let (sa, sb) = ((1.5 * t).atan().sin(), t.atan().sin());
    vec![
        ("point", point(100.0, Vec3::ONE), 4.0 * pi * 100.0),
        ("goniometric", gonio, 4.0 * pi * 3.0 * mean_y),
        ("projection", proj, i_white as f64 * 4.0 * (sa * sb).asin()),
        (
            "spot",
            spot(),
            50.0 * 2.0 * pi * ((1.0 - cs) + (cs - ce) / 2.0),
        ),
        ("distant", distant, 2.0 * pi * r2),
        ("infinite", inf, 0.5 * 4.0 * pi * pi * r2),
    ]
}

#[test]
fn point_phi_is_4pi_i() {
    let phi = point(100.0, Vec3::ZERO).phi(&lambda());
    assert!(
        (phi[0] - 4.0 * PI * 100.0).abs() <= 1e-6 * phi[0],
        "{phi:?}"
    );
}

#[test]
fn area_phi_is_pi_a_l() {
    // A = 0.25, L = 10 → πAL = 7.853982; two-sided 2πAL = 15.707964.
    // The square is two triangle lights; their powers add.
    let sum = |two: bool| {
        areas(square(Vec3::Z, 0.5, true), 10.0, two)
            .iter()
            .fold(SampledSpectrum::zero(), |acc, l| acc + l.phi(&lambda()))
    };
    let (one, two) = (sum(false), sum(true));
    assert!((one[0] - 7.853982).abs() < 2e-6, "{one:?}");
    assert!((two[0] - 15.707964).abs() < 4e-6, "{two:?}");
}

#[test]
fn spot_phi_matches_quadrature_of_falloff() {
    // Φ = ∫ I(ω) dω = 2π ∫ I(cos θ) d(cos θ): midpoint rule in cos θ with
    // 2·10⁵ cells; the integrand is C¹ so the error is far below 1e-3.
    let Light::Spot(s) = spot() else {
        unreachable!()
    };
    let lam = lambda();
    let n = 200_000;
    let h = 2.0 / n as f64;
    let mut sum = 0.0f64;
    for k in 0..n {
        let c = -1.0 + (k as f64 + 0.5) * h;
        let sn = (1.0 - c * c).max(0.0).sqrt();
        let wl = Vec3::new(sn as f32, 0.0, c as f32);
        sum += s.intensity(wl, &lam)[0] as f64 * h;
    }
    let quad = 2.0 * std::f64::consts::PI * sum;
    let phi = s.phi(&lam)[0] as f64;
    assert!(
        (quad - phi).abs() <= 1e-3 * phi,
        "quadrature {quad} phi {phi}"
    );
}

#[test]
fn phi_matches_closed_forms() {
    for (name, light, phi) in lights_with_phi() {
        let got = light.phi(&lambda())[0] as f64;
        assert!(
            (got - phi).abs() <= 1e-5 * phi,
            "{name}: phi {got} expected {phi}"
        );
    }
}

#[test]
fn emitted_samples_carry_phi() {
    // Mean of Le·|cos|/(p_pos·p_dir) = Φ (5σ + b, b = 1e-5·Φ for f32 round-off);
    // the densities are also recomputed with pdf_le and must agree (1e-4).
    let lam = lambda();
    for (name, light, phi) in lights_with_phi() {
        let mut r = Pcg32::new(7, name.len() as u64);
        let mut st = Stats::default();
        for _ in 0..20_000 {
            let Some(s) = light.sample_le(u2(&mut r), u2(&mut r), &lam) else {
                st.add(0.0);
                continue;
            };
            st.add(s.beta0(1.0)[0] as f64);
            let (pp, pd) = match &s.intr {
                Some(it) => light.pdf_le_area(it, s.ray.d),
                None => light.pdf_le(&s.ray),
            };
            assert!(
                (pp.0 - s.pdf_pos.0).abs() <= 1e-4 * s.pdf_pos.0,
                "{name}: pdf_pos"
            );
            assert!(
                (pd.0 - s.pdf_dir.0).abs() <= 1e-4 * s.pdf_dir.0,
                "{name}: pdf_dir"
            );
        }
        st.assert_mean(phi, 1e-5 * phi, name);
    }
}

#[test]
fn power_selection_starts_every_subpath_with_total_phi() {
    // Single point light: pmf = 1 and β₀ = 4πI = Φ_total exactly (f32 round-off).
    let lam = lambda();
    let one = vec![point(100.0, Vec3::ZERO)];
    let ls = LightSampler::power(&one);
    let mut r = Pcg32::new(3, 0);
    for _ in 0..100 {
        let (id, pmf) = ls.sample(r.uniform_f32()).unwrap();
        let s = one[id.0 as usize]
            .sample_le(u2(&mut r), u2(&mut r), &lam)
            .unwrap();
        let b = s.beta0(pmf)[0];
        assert!((b - 4.0 * PI * 100.0).abs() <= 1e-6 * b, "β₀ = {b}");
    }
    // Each light alone, with exact emission sampling (β₀ = Φ per sample),
    // including the projector, whose spectrum is the colour space's
    // illuminant rather than a constant.
    for (name, light, phi) in lights_with_phi() {
        let ls = LightSampler::power(std::slice::from_ref(&light));
        let mut r = Pcg32::new(3, 1);
        for _ in 0..1000 {
            let (_, pmf) = ls.sample(r.uniform_f32()).unwrap();
            if let Some(s) = light.sample_le(u2(&mut r), u2(&mut r), &lam) {
                let b = s.beta0(pmf)[0] as f64;
                assert!((b - phi).abs() <= 1e-4 * phi, "{name}: β₀ {b} vs Φ {phi}");
            }
        }
    }
    // Several lights: β₀ = Φ_total per sample (constant spectra, exact
    // emission sampling) and hence in expectation; uniform selection only
    // in expectation (5σ). The selection weighs each light by ∫Φ(λ)dλ, so
    // β₀ is the same at every wavelength only when all spectra share one
    // shape: the projector (illuminant spectrum) is left out here.
    let with_phi = || {
        lights_with_phi()
            .into_iter()
            .filter(|(name, _, _)| *name != "projection")
    };
    let lights: Vec<Light> = with_phi().map(|(_, l, _)| l).collect();
    let total: f64 = with_phi().map(|(_, _, p)| p).sum();
    for (kind, ls) in [
        ("power", LightSampler::power(&lights)),
        ("uniform", LightSampler::uniform(&lights)),
    ] {
        let mut st = Stats::default();
        let mut r = Pcg32::new(5, 1);
        for _ in 0..40_000 {
            let (id, pmf) = ls.sample(r.uniform_f32()).unwrap();
            assert_eq!(pmf, ls.pmf(id));
            let b = match lights[id.0 as usize].sample_le(u2(&mut r), u2(&mut r), &lam) {
                Some(s) => s.beta0(pmf)[0] as f64,
                None => 0.0,
            };
            if kind == "power" {
                assert!(
                    (b - total).abs() <= 1e-4 * total,
                    "power: β₀ {b} vs Φ {total}"
                );
            }
            st.add(b);
        }
        st.assert_mean(total, 1e-5 * total, kind);
    }
}

#[test]
fn pmfs_sum_to_one() {
    let lights: Vec<Light> = lights_with_phi().into_iter().map(|(_, l, _)| l).collect();
    for ls in [LightSampler::power(&lights), LightSampler::uniform(&lights)] {
        let s: f32 = (0..lights.len())
            .map(|i| ls.pmf(crate::interaction::LightId(i as u32)))
            .sum();
        assert!((s - 1.0).abs() < 1e-5, "{s}");
    }
    assert!(LightSampler::power(&[]).sample(0.5).is_none());
}

#[test]
fn create_applies_pbrt_v4_scaling() {
    // With `power`/`illuminance` given, Φ (resp. E) equals the target divided
    // by SpectrumToPhotometric(s) of the unit-scale spectrum — pbrt-v4's
    // "1 nit" convention — whatever the spectrum's magnitude (here 7).
    let lam = lambda();
    let y = spectrum_photometric(&constant(1.0)) as f64;
    let s = || constant(7.0);
    let id = Transform::IDENTITY;
    let check = |what: &str, got: f64, want: f64| {
        assert!((got - want).abs() <= 1e-5 * want, "{what}: {got} vs {want}");
    };
    let p = point_light(&id, s(), 2.0, Some(1000.0), Vec3::ONE);
    check("point power", p.phi(&lam)[0] as f64, 2.0 * 1000.0 / y);
    let p = point_light(&id, s(), 2.0, None, Vec3::ONE);
    check(
        "point scale",
        p.phi(&lam)[0] as f64,
        4.0 * std::f64::consts::PI * 2.0 / y,
    );
    let sp = spot_light(&id, s(), 1.0, 40.0, 10.0, Some(500.0), Vec3::ZERO, Vec3::X);
    check("spot power", sp.phi(&lam)[0] as f64, 500.0 / y);
    for two in [false, true] {
        // pbrt-v4 normalises "power" per shape: each triangle of the square emits it.
        for shape in square(Vec3::Z, 0.5, true).shapes() {
            let a = diffuse_area_light(shape, s(), 1.0, two, Some(300.0));
            check("area power", a.phi(&lam)[0] as f64, 300.0 / y);
        }
    }
    // Distant: E_v on a surface facing the light; sky: E = πL on an upward patch.
    let ctx = LightSampleContext::at_point(Vec3::ZERO);
    let d = distant_light(
        &id,
        s(),
        1.0,
        Some(80.0),
        Vec3::new(0.0, 3.0, 4.0),
        Vec3::ZERO,
    );
    let li = d.sample_li(&ctx, Vec2::ZERO, &lam).unwrap();
    check("distant illuminance", li.l[0] as f64, 80.0 / y);
    check(
        "distant direction",
        li.wi.dot(Vec3::new(0.0, 0.6, 0.8)) as f64,
        1.0,
    );
    let sky = uniform_infinite_light(s(), 1.0, Some(120.0));
    let le = sky.le(&Ray::new(Vec3::ZERO, Vec3::Z), &lam)[0] as f64;
    check("sky illuminance", std::f64::consts::PI * le, 120.0 / y);
}
