//! Goniometric and projection lights: a constant goniometric map against the
//! point light, Φ of both against an independent quadrature of I(ω) over
//! the sphere, the projector's exact texel solid angles and its in-texel
//! sampling, and pbrt-v4's `power` normalisation. Their χ² tests live in
//! `chi2.rs`; their β₀ = Φ bookkeeping in `power.rs`. Images are
//! synthesised in memory.

use super::*;
use crate::image::{MapImage, PixelFormat};
use crate::light::projection::{rect_solid_angle, sample_rect_solid_angle};
use crate::math::{Frame, Mat4, Ray, Transform, PI};
use crate::spectrum::{ColorSpace, Rgb, SpectrumKind};

/// A `w`×`h` image of `C` channels from `f(u, v)` at texel centres.
fn image<const C: usize>(w: usize, h: usize, f: impl Fn(f32, f32) -> [f32; C]) -> MapImage {
    let mut data = Vec::with_capacity(w * h * C);
    for y in 0..h {
        for x in 0..w {
            data.extend(f((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32));
        }
    }
    MapImage::new(w, h, C, data, PixelFormat::Float)
}

/// A 16×16 goniometric map: a gradient, a bright spot and a black band.
pub(super) fn gonio_map() -> MapImage {
    image(16, 16, |u, v| {
        let d2 = (u - 0.35).powi(2) + (v - 0.6).powi(2);
        if (0.8..0.9).contains(&u) {
            [0.0]
        } else {
            [0.1 + 2.0 * u * v + 30.0 * (-d2 / 0.003).exp()]
        }
    })
}

/// A 12×8 RGB slide (aspect 1.5): coloured gradient, a bright spot, a black column.
pub(super) fn slide() -> MapImage {
    image(12, 8, |u, v| {
        let d2 = (u - 0.3).powi(2) + (v - 0.7).powi(2);
        let b = 0.2 + u + 20.0 * (-d2 / 0.01).exp();
        if (0.5..0.6).contains(&u) {
            [0.0; 3]
        } else {
            [b, 0.5 * b + v, 0.3 * b]
        }
    })
}

/// A rotation about (1, 2, 3) followed by a translation to (0.3, −0.2, 1).
pub(super) fn placed() -> Transform {
    let m = Mat4::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    Transform::translate(Vec3::new(0.3, -0.2, 1.0)).then_after(&Transform::new(m, m.inverse()))
}

/// The goniometric test light (I = 3, scale 1 before pbrt-v4's 1-nit normalisation).
pub(super) fn gonio_light() -> Light {
    Light::Goniometric(goniometric_light(
        &placed(),
        constant(3.0),
        1.0,
        None,
        Some(&gonio_map()),
    ))
}

/// The projection test light: the slide at 60°.
pub(super) fn projector() -> Light {
    Light::Projection(projection_light(
        &placed(),
        &slide(),
        ColorSpace::srgb(),
        1.0,
        None,
        60.0,
    ))
}

/// The projector's axis in render space.
pub(super) fn projector_axis() -> Vec3 {
    placed().vector(Vec3::Z).normalize()
}

/// Position of a delta-position light (from a sample_li at distance 1).
fn light_pos(light: &Light) -> Vec3 {
    let s = light.sample_le(Vec2::splat(0.5), Vec2::splat(0.5), &lambda());
    s.expect("a sample").ray.o
}

/// I(ω) through `sample_li` from the point one unit away along −ω.
fn intensity_towards(light: &Light, p: Vec3, w: Vec3) -> f64 {
    let ctx = LightSampleContext::at_point(p + w);
    light
        .sample_li(&ctx, Vec2::ZERO, &lambda())
        .map_or(0.0, |s| s.l[0] as f64)
}

/// ∫ I(ω) dω over cos θ ∈ [c0, c1] about `axis` by an n×2n midpoint rule in (cos θ, φ).
fn cap_integral(light: &Light, axis: Vec3, c: [f64; 2], n: usize) -> f64 {
    let f = Frame::from_z(axis);
    let p = light_pos(light);
    let (dc, dp) = ((c[1] - c[0]) / n as f64, PI as f64 / n as f64);
    let mut s = 0.0f64;
    for i in 0..n {
        let z = c[0] + (i as f64 + 0.5) * dc;
        let r = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..2 * n {
            let ph = (j as f64 + 0.5) * dp;
            let wl = Vec3::new((r * ph.cos()) as f32, (r * ph.sin()) as f32, z as f32);
            s += intensity_towards(light, p, f.from_local(wl));
        }
    }
    s * dc * dp
}

#[test]
fn constant_goniometric_map_is_the_point_light() {
    // Same I, scale and place: identical incident radiance, Φ = 4πI, and
    // uniform emission densities 1/(4π).
    let t = placed();
    let map = image(8, 8, |_, _| [1.0f32; 3]);
    let gonio = Light::Goniometric(goniometric_light(&t, constant(3.0), 2.0, None, Some(&map)));
    let point = Light::Point(point_light(&t, constant(3.0), 2.0, None, Vec3::ZERO));
    let lam = lambda();
    let close = |a: f32, b: f32| (a - b).abs() <= 1e-5 * b.abs();
    let mut r = Pcg32::new(9, 1);
    for _ in 0..200 {
        let p = Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32()) * 4.0 - 2.0;
        let ctx = LightSampleContext::at_point(p);
        let (a, b) = (
            gonio.sample_li(&ctx, u2(&mut r), &lam).unwrap(),
            point.sample_li(&ctx, u2(&mut r), &lam).unwrap(),
        );
        assert!(close(a.l[0], b.l[0]) && a.wi.distance(b.wi) < 1e-6);
        assert!(a.pdf == b.pdf && a.p_light.p.distance(b.p_light.p) < 1e-6);
        let s = gonio.sample_le(u2(&mut r), u2(&mut r), &lam).unwrap();
        let (pp, pd) = gonio.pdf_le(&s.ray);
        assert!(close(pd.0, 1.0 / (4.0 * PI)) && close(s.pdf_dir.0, pd.0) && pp.0 == 1.0);
        assert!(close(s.beta0(1.0)[0], point.phi(&lam)[0]));
        assert!(s.ray.o.distance(b.p_light.p) < 1e-6);
    }
    for i in 0..4 {
        assert!(close(gonio.phi(&lam)[i], point.phi(&lam)[i]));
    }
    assert_eq!(gonio.light_type(), LightType::DeltaPosition);
}

#[test]
fn goniometric_phi_matches_quadrature_over_the_sphere() {
    // Midpoint rule in (cos θ, φ) about render +z with 1500×3000 cells; the
    // map's texel edges cut cells, a first-order error that averages out to
    // well below 2·10⁻³ (measured: printed).
    let light = gonio_light();
    let quad = cap_integral(&light, Vec3::Z, [-1.0, 1.0], 1500);
    let phi = light.phi(&lambda())[0] as f64;
    eprintln!(
        "goniometric: quadrature {quad:.6}, Φ {phi:.6}, rel {:.2e}",
        quad / phi - 1.0
    );
    assert!(
        (quad - phi).abs() <= 2e-3 * phi,
        "quadrature {quad} Φ {phi}"
    );
}

#[test]
fn projection_phi_matches_quadrature_over_the_sphere() {
    // The frustum (corner at cos θ = 0.693) lies inside the cap cos θ > 0.6,
    // integrated with 1500×3000 cells; the rest of the sphere must be dark.
    let light = projector();
    let axis = projector_axis();
    let quad = cap_integral(&light, axis, [0.6, 1.0], 1500);
    let rest = cap_integral(&light, axis, [-1.0, 0.6], 200);
    let phi = light.phi(&lambda())[0] as f64;
    eprintln!(
        "projection: quadrature {quad:.6}, Φ {phi:.6}, rel {:.2e}",
        quad / phi - 1.0
    );
    assert_eq!(rest, 0.0, "light outside the frustum");
    assert!(
        (quad - phi).abs() <= 2e-3 * phi,
        "quadrature {quad} Φ {phi}"
    );
}

#[test]
fn projection_image_orientation_follows_pbrt_v4() {
    // Identity transform: the top row (v = 0) lights +y, the left column −x,
    // since pbrt-v4 flips y. A 2×2 slide with four distinct greys.
    let lum = [[1.0f32; 3], [2.0; 3], [3.0; 3], [4.0; 3]];
    let img = image(2, 2, |u, v| {
        lum[(v > 0.5) as usize * 2 + (u > 0.5) as usize]
    });
    let light = Light::Projection(projection_light(
        &Transform::IDENTITY,
        &img,
        ColorSpace::srgb(),
        1.0,
        None,
        90.0,
    ));
    let at =
        |x: f32, y: f32| intensity_towards(&light, Vec3::ZERO, Vec3::new(x, y, 1.0).normalize());
    let one = at(-0.5, 0.5);
    for (x, y, k) in [
        (-0.5, 0.5, 1.0),
        (0.5, 0.5, 2.0),
        (-0.5, -0.5, 3.0),
        (0.5, -0.5, 4.0),
    ] {
        let v = at(x, y);
        assert!((v / one - k).abs() < 1e-4, "({x}, {y}): {v} vs {k}·{one}");
    }
    // Outside the 90° window and behind the light: dark.
    assert_eq!(at(1.01, 0.0), 0.0);
    assert_eq!(intensity_towards(&light, Vec3::ZERO, -Vec3::Z), 0.0);
}

#[test]
fn goniometric_map_centre_points_along_user_y() {
    // pbrt-v4 swaps y and z: the equal-area map's centre texel (light-frame
    // +z) lights the user's +y, its corners (−z) the user's −y. Identity
    // transform; a map bright only in the centre 2×2 texels.
    let map = image(8, 8, |u, v| {
        if (u - 0.5).abs() < 0.2 && (v - 0.5).abs() < 0.2 {
            [5.0f32]
        } else {
            [1.0]
        }
    });
    let light = Light::Goniometric(goniometric_light(
        &Transform::IDENTITY,
        constant(1.0),
        1.0,
        None,
        Some(&map),
    ));
    let up = intensity_towards(&light, Vec3::ZERO, Vec3::Y);
    for w in [Vec3::Z, -Vec3::Z, Vec3::X, -Vec3::Y] {
        let v = intensity_towards(&light, Vec3::ZERO, w);
        assert!((up / v - 5.0).abs() < 1e-5, "{w}: {v} vs up {up}");
    }
}

#[test]
fn texel_solid_angles_match_closed_form_and_quadrature() {
    // The whole 90° square window: 4·asin(sin²45°) = 2π/3 [rectangular
    // pyramid]; a 1.5×1 window at 60°: 4·asin(sin α sin β).
    let third = rect_solid_angle(-1.0, 1.0, -1.0, 1.0);
    assert!(
        (third - 2.0 * std::f64::consts::PI / 3.0).abs() < 1e-12,
        "{third}"
    );
    let t = (30f64).to_radians().tan();
    let (a, b) = ((1.5 * t).atan(), t.atan());
    let want = 4.0 * (a.sin() * b.sin()).asin();
    let got = rect_solid_angle(-1.5 * t, 1.5 * t, -t, t);
    assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    // An off-axis texel against ∫∫ dX dY/(1 + X² + Y²)^{3/2} (midpoint, 400², error ~1e-7).
    let (xa, xb, ya, yb) = (0.3, 0.45, -0.8, -0.62);
    let n = 400;
    let mut q = 0.0;
    for i in 0..n {
        for j in 0..n {
            let x = xa + (i as f64 + 0.5) * (xb - xa) / n as f64;
            let y = ya + (j as f64 + 0.5) * (yb - ya) / n as f64;
            q += (1.0 + x * x + y * y).powf(-1.5);
        }
    }
    q *= (xb - xa) * (yb - ya) / (n * n) as f64;
    let got = rect_solid_angle(xa, xb, ya, yb);
    assert!((got - q).abs() < 1e-6 * q, "{got} vs {q}");
}

#[test]
fn in_texel_sampling_is_uniform_in_solid_angle() {
    // Directions into one off-axis texel, binned 8×8 in (X, Y) on the plane:
    // each bin's count must match its solid-angle share (χ², 63 dof, p > 10⁻³),
    // and the inverse map is checked where it is monotone: the quantiles of
    // u.x are the X-marginal's.
    let (xa, xb, ya, yb) = (0.4, 0.9, -1.2, -0.5);
    let total = rect_solid_angle(xa, xb, ya, yb);
    let nb = 8;
    let (bx, by) = ((xb - xa) / nb as f64, (yb - ya) / nb as f64);
    let mut obs = vec![0.0f64; nb * nb];
    let mut r = Pcg32::new(4, 4);
    let n = 200_000;
    for _ in 0..n {
        let (x, y) = sample_rect_solid_angle(xa, xb, ya, yb, u2(&mut r));
        assert!(
            (xa..=xb).contains(&x) && (ya..=yb).contains(&y),
            "({x}, {y})"
        );
        let i = (((x - xa) / bx) as usize).min(nb - 1);
        let j = (((y - ya) / by) as usize).min(nb - 1);
        obs[j * nb + i] += 1.0;
    }
    let mut chi2 = 0.0;
    for j in 0..nb {
        for i in 0..nb {
            let (x0, y0) = (xa + i as f64 * bx, ya + j as f64 * by);
            let e = n as f64 * rect_solid_angle(x0, x0 + bx, y0, y0 + by) / total;
            chi2 += (obs[j * nb + i] - e).powi(2) / e;
        }
    }
    let p = crate::sampling::chi2::chi2_survival(chi2, nb * nb - 1);
    eprintln!("in-texel sampling: χ² = {chi2:.1}, p = {p:.3}");
    assert!(p > 1e-3, "χ² = {chi2}, p = {p}");
    for u in [0.1f32, 0.37, 0.5, 0.83] {
        let (x, _) = sample_rect_solid_angle(xa, xb, ya, yb, Vec2::new(u, 0.5));
        let f = rect_solid_angle(xa, x, ya, yb) / total;
        assert!((f - u as f64).abs() < 1e-9, "u {u}: CDF {f}");
    }
}

#[test]
fn emission_densities_agree_and_integrate_to_one() {
    // pdf_le of each sample equals the sample's p_dir (but on texel edges,
    // where float round trips may cross), and ∫ p_dir dω = 1 by quadrature.
    let lam = lambda();
    for (name, light, axis, c0) in [
        ("goniometric", gonio_light(), Vec3::Z, -1.0),
        ("projection", projector(), projector_axis(), 0.6),
    ] {
        let mut r = Pcg32::new(8, 2);
        let mut off = 0;
        for _ in 0..20_000 {
            let s = light.sample_le(u2(&mut r), u2(&mut r), &lam).unwrap();
            let pd = light.pdf_le(&s.ray).1 .0;
            off += ((pd - s.pdf_dir.0).abs() > 1e-3 * s.pdf_dir.0) as usize;
            assert!(s.pdf_pos.0 == 1.0 && !s.beta0(1.0).has_non_finite());
        }
        assert!(off < 10, "{name}: {off} samples off their texel");
        let f = Frame::from_z(axis);
        let n = 600;
        let (dc, dp) = ((1.0 - c0) / n as f64, PI as f64 / n as f64);
        let mut s = 0.0;
        for i in 0..n {
            let z = c0 + (i as f64 + 0.5) * dc;
            let rr = (1.0 - z * z).max(0.0).sqrt();
            for j in 0..2 * n {
                let ph = (j as f64 + 0.5) * dp;
                let w = Vec3::new((rr * ph.cos()) as f32, (rr * ph.sin()) as f32, z as f32);
                s += light.pdf_le(&Ray::new(Vec3::ZERO, f.from_local(w))).1 .0 as f64;
            }
        }
        s *= dc * dp;
        eprintln!("{name}: ∫ p_dir = {s:.5}");
        assert!((s - 1.0).abs() < 3e-3, "{name}: ∫ p_dir = {s}");
    }
}

#[test]
fn power_follows_pbrt_v4() {
    let lam = lambda();
    let cs = ColorSpace::srgb();
    let y_illum = spectrum_photometric(&cs.illuminant) as f64;
    // Goniometric: Φ = scale·power/SpectrumToPhotometric(I), whatever the map.
    let y = spectrum_photometric(&constant(1.0)) as f64;
    let g = goniometric_light(
        &placed(),
        constant(7.0),
        2.0,
        Some(1000.0),
        Some(&gonio_map()),
    );
    let got = g.phi(&lam)[0] as f64;
    assert!((got - 2000.0 / y).abs() <= 1e-5 * got, "goniometric: {got}");
    // Projection of a grey slide (spectrum = grey·illuminant): the
    // photometric power ∫ȳΦ = Φ(λ)·Y(illuminant)/illuminant(λ).
    let photometric = |l: &ProjectionLight| {
        let illum = cs.illuminant.sample(&lam)[0] as f64;
        l.phi(&lam)[0] as f64 * y_illum / illum
    };
    // A fine 64×48 slide at 50°: the emitted power is the requested one up
    // to pbrt-v4's midpoint estimate of ∫cos³θ (below 10⁻³ here).
    let fine = image(64, 48, |u, v| [0.2 + u * v; 3]);
    let l = projection_light(&placed(), &fine, cs, 2.0, Some(500.0), 50.0);
    let got = photometric(&l);
    eprintln!("projection 64×48: Φ_v = {got:.4} for power 1000");
    assert!(
        (got - 1000.0).abs() <= 1e-3 * 1000.0,
        "fine projection: {got}"
    );
    // A 1×1 white slide at 90°: pbrt-v4's k = A·cos³0 = 4 while the true
    // solid angle is 2π/3, so Φ_v = power·(2π/3)/4 (pbrt-v4 renders this).
    let one = image(1, 1, |_, _| [1.0f32; 3]);
    let l = projection_light(&Transform::IDENTITY, &one, cs, 1.0, Some(100.0), 90.0);
    let want = 100.0 * (2.0 * std::f64::consts::PI / 3.0) / 4.0;
    let got = photometric(&l);
    assert!(
        (got - want).abs() <= 1e-4 * want,
        "1×1 projection: {got} vs {want}"
    );
    // Without power: I = scale·rgb, normalised by the illuminant's photometric value.
    let l = projection_light(&Transform::IDENTITY, &one, cs, 3.0, None, 90.0);
    let i = l.intensity(Vec3::Z, &lam)[0] as f64;
    let s = cs.sample_rgb(Rgb::new(1.0, 1.0, 1.0), SpectrumKind::Illuminant, &lam)[0] as f64;
    assert!((i - 3.0 * s / y_illum).abs() <= 1e-5 * i, "{i}");
}
