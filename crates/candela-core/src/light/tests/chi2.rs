//! χ² tests of light sampling against the lights' densities (validation.md,
//! "Statistical tests of sampling code").
//!
//! Directions are binned in an equal-area (cos θ, φ) grid about an axis;
//! expected counts integrate the pdf over each cell by a 16×16 midpoint
//! rule, 256×256 on cells the support's boundary cuts; cells expecting < 5 are pooled; the p-value of the statistic must
//! exceed the Šidák-corrected α' for α = 0.01 over [`N_TESTS`] tests. The
//! test also fails if the pdf integrates above 1 or a sample lands where the
//! pdf is zero (checked per sample: a cell-level check would flag slivers of
//! silhouette the quadrature misses). The grid is
//! local (it zooms on the light's cone about an axis, where the shared
//! full-sphere grid of `sampling::chi2` would be too coarse); the χ²
//! distribution itself comes from `sampling::chi2`.

use super::*;
use crate::math::{Frame, Ray, Transform, PI};

/// Number of χ² tests in this file (for the Šidák correction).
const N_TESTS: i32 = 8;
const N_SAMPLES: usize = 1_000_000;
const N_THETA: usize = 48;
const N_PHI: usize = 64;
const SUB: usize = 16;

/// Cell index of direction `w` (local frame), grid over cos θ ∈ [cos_lo, 1]
/// plus one last cell for cos θ < cos_lo.
fn cell(w: Vec3, cos_lo: f32) -> usize {
    if w.z < cos_lo {
        return N_THETA * N_PHI;
    }
    let t = (((w.z - cos_lo) / (1.0 - cos_lo)) * N_THETA as f32) as usize;
    let phi = w.y.atan2(w.x).rem_euclid(2.0 * PI);
    let p = ((phi / (2.0 * PI)) * N_PHI as f32) as usize;
    t.min(N_THETA - 1) * N_PHI + p.min(N_PHI - 1)
}

/// ∫ pdf dω over cos θ ∈ [c0, c1], φ ∈ [p0, p1] by an `sub`×`sub` midpoint
/// rule; also reports whether the cell straddles the pdf's support boundary.
fn integrate(
    pdf: &dyn Fn(Vec3) -> f64,
    f: &Frame,
    c: [f64; 2],
    p: [f64; 2],
    sub: usize,
) -> (f64, bool) {
    let (dc, dp) = ((c[1] - c[0]) / sub as f64, (p[1] - p[0]) / sub as f64);
    let (mut s, mut zeros) = (0.0, 0);
    for i in 0..sub {
        let z = c[0] + (i as f64 + 0.5) * dc;
        let r = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..sub {
            let ph = p[0] + (j as f64 + 0.5) * dp;
            let wl = Vec3::new((r * ph.cos()) as f32, (r * ph.sin()) as f32, z as f32);
            let v = pdf(f.from_local(wl));
            s += v;
            zeros += (v == 0.0) as usize;
        }
    }
    (s * dc * dp, zeros > 0 && zeros < sub * sub)
}

/// Cell integral, refined 16× per axis on cells cut by the support's
/// boundary, where the midpoint rule's error is first order.
fn integrate_cell(pdf: &dyn Fn(Vec3) -> f64, f: &Frame, c: [f64; 2], p: [f64; 2]) -> f64 {
    match integrate(pdf, f, c, p, SUB) {
        (_, true) => integrate(pdf, f, c, p, SUB * 16).0,
        (v, false) => v,
    }
}

/// Expected probability of every cell (grid cells, then the rest cell).
fn expected(pdf: &dyn Fn(Vec3) -> f64, f: &Frame, cos_lo: f32) -> Vec<f64> {
    let lo = cos_lo as f64;
    let (dc, dp) = (
        (1.0 - lo) / N_THETA as f64,
        2.0 * std::f64::consts::PI / N_PHI as f64,
    );
    let mut e = Vec::with_capacity(N_THETA * N_PHI + 1);
    for t in 0..N_THETA {
        for p in 0..N_PHI {
            let c = [lo + t as f64 * dc, lo + (t + 1) as f64 * dc];
            e.push(integrate_cell(
                pdf,
                f,
                c,
                [p as f64 * dp, (p + 1) as f64 * dp],
            ));
        }
    }
    let rest = if cos_lo > -1.0 {
        integrate(pdf, f, [-1.0, lo], [0.0, 2.0 * std::f64::consts::PI], 256).0
    } else {
        0.0
    };
    e.push(rest);
    e
}

/// χ² test of directions from `sample` against the solid-angle `pdf`,
/// binned about `axis`; panics with a report on failure.
fn chi2_directions(
    name: &str,
    axis: Vec3,
    cos_lo: f32,
    mut sample: impl FnMut(&mut Pcg32) -> Option<Vec3>,
    pdf: &dyn Fn(Vec3) -> f64,
) {
    let f = Frame::from_z(axis.normalize());
    let mut obs = vec![0.0f64; N_THETA * N_PHI + 1];
    let mut r = Pcg32::new(17, name.len() as u64);
    for _ in 0..N_SAMPLES {
        if let Some(w) = sample(&mut r) {
            assert!(pdf(w) > 0.0, "{name}: sampled {w} where the pdf is 0");
            obs[cell(f.to_local(w.normalize()), cos_lo)] += 1.0;
        }
    }
    let mut exp = expected(pdf, &f, cos_lo);
    let total: f64 = exp.iter().sum();
    assert!(total <= 1.0 + 1e-3, "{name}: pdf integrates to {total}");
    for e in exp.iter_mut() {
        *e *= N_SAMPLES as f64;
    }
    let (stat, dof) = pooled_chi2(&obs, &exp);
    // CHI2_DEBUG=1 prints the worst cells.
    if std::env::var("CHI2_DEBUG").is_ok() {
        eprintln!("{name}: total {total}");
        let mut v: Vec<usize> = (0..obs.len()).filter(|&i| exp[i] > 5.0).collect();
        v.sort_by(|&a, &b| {
            ((obs[b] - exp[b]).powi(2) / exp[b]).total_cmp(&((obs[a] - exp[a]).powi(2) / exp[a]))
        });
        for &i in v.iter().take(12) {
            eprintln!(
                "cell t{} p{} obs {} exp {:.1}",
                i / N_PHI,
                i % N_PHI,
                obs[i],
                exp[i]
            );
        }
    }
    let alpha = 1.0 - (1.0 - 0.01f64).powf(1.0 / N_TESTS as f64);
    let p = crate::sampling::chi2::chi2_survival(stat, dof);
    assert!(
        p > alpha,
        "{name}: χ² = {stat:.1}, dof = {dof}, p = {p:.2e} < {alpha:.2e}"
    );
}

/// χ² statistic with cells expecting < 5 pooled; returns (statistic, dof).
fn pooled_chi2(obs: &[f64], exp: &[f64]) -> (f64, usize) {
    let mut idx: Vec<usize> = (0..obs.len()).collect();
    idx.sort_by(|&a, &b| exp[a].total_cmp(&exp[b]));
    let (mut stat, mut cells) = (0.0, 0usize);
    let (mut po, mut pe) = (0.0, 0.0);
    for i in idx {
        if exp[i] < 5.0 {
            po += obs[i];
            pe += exp[i];
            continue;
        }
        stat += (obs[i] - exp[i]).powi(2) / exp[i];
        cells += 1;
    }
    if pe > 0.0 {
        stat += (po - pe).powi(2) / pe;
        cells += 1;
    }
    (stat, cells.saturating_sub(1).max(1))
}

fn area(geo: Geo, two_sided: bool) -> Light {
    Light::DiffuseArea(DiffuseAreaLight::new(
        geo.shape(),
        constant(1.0),
        1.0,
        two_sided,
    ))
}

/// One of the two triangles of a parallelogram light.
fn half(geo: Geo, which: usize, two_sided: bool) -> Light {
    Light::DiffuseArea(DiffuseAreaLight::new(
        geo.shapes().remove(which),
        constant(1.0),
        1.0,
        two_sided,
    ))
}

/// χ² of `sample_li` directions from `p` against `pdf_li`.
fn chi2_li(name: &str, light: &Light, p: Vec3, n: Vec3, axis: Vec3, cos_lo: f32) {
    let ctx = LightSampleContext {
        p,
        p_error: Vec3::ZERO,
        n,
        ns: n,
    };
    let lam = lambda();
    let sample = |r: &mut Pcg32| light.sample_li(&ctx, u2(r), &lam).map(|s| s.wi);
    chi2_directions(name, axis, cos_lo, sample, &|w| {
        light.pdf_li(&ctx, w).0 as f64
    });
}

#[test]
fn chi2_sphere_light_li() {
    // Sphere of radius 1 at distance 2: cone cos θ_max = 0.866; grid on [0.8, 1].
    let light = area(
        Geo::Sphere {
            center: Vec3::new(0.0, 0.0, 2.0),
            radius: 1.0,
        },
        false,
    );
    chi2_li("sphere li", &light, Vec3::ZERO, Vec3::Z, Vec3::Z, 0.8);
}

#[test]
fn chi2_quad_light_li() {
    // 2×2 square at distance 1, receiver off-centre; and a grazing view
    // (incidence on the light 75°–84° from its normal).
    // One triangle (half) of the square: a mesh quad is two triangle lights.
    let light = half(square(Vec3::Z, 2.0, true), 0, false);
    chi2_li(
        "quad li",
        &light,
        Vec3::new(0.3, -0.2, 0.0),
        Vec3::Z,
        Vec3::Z,
        -1.0,
    );
    let p = Vec3::new(2.5, 0.0, 0.6);
    chi2_li("quad li grazing", &light, p, Vec3::X, -p + Vec3::Z, 0.5);
}

#[test]
fn chi2_area_light_le() {
    // Directions of sample_le against pdf_le_area's direction density; the
    // square is planar, so every point shares the normal −z.
    for (name, two, which) in [("quad le", false, 0), ("quad le two-sided", true, 1)] {
        let light = half(square(Vec3::Z, 2.0, true), which, two);
        let it = Interaction {
            p: Vec3::Z,
            p_error: Vec3::ZERO,
            n: -Vec3::Z,
            uv: Vec2::ZERO,
            time: 0.0,
        };
        let lam = lambda();
        let sample = |r: &mut Pcg32| light.sample_le(u2(r), u2(r), &lam).map(|s| s.ray.d);
        chi2_directions(name, -Vec3::Z, -1.0, sample, &|w| {
            light.pdf_le_area(&it, w).1 .0 as f64
        });
    }
}

#[test]
fn chi2_spot_light_le() {
    // Spot aimed along (1, 1, 0): cone 30°, falloff from 20°; grid on [0.8, 1].
    let dir = Vec3::new(1.0, 1.0, 0.0).normalize();
    let light = Light::Spot(spot_light(
        &Transform::IDENTITY,
        constant(1.0),
        1.0,
        30.0,
        10.0,
        None,
        Vec3::ZERO,
        dir,
    ));
    let lam = lambda();
    let sample = |r: &mut Pcg32| light.sample_le(u2(r), u2(r), &lam).map(|s| s.ray.d);
    let pdf = |w: Vec3| light.pdf_le(&Ray::new(Vec3::ZERO, w)).1 .0 as f64;
    chi2_directions("spot le", dir, 0.8, sample, &pdf);
}

#[test]
fn chi2_goniometric_and_projection_le() {
    // Emitted directions against pdf_le: the goniometric map over the whole
    // sphere, the 60° projector on the cap cos θ > 0.6 about its axis (the
    // frustum's corners are at cos θ = 0.693; the rest cell must stay empty).
    use super::punctual_maps::{gonio_light, projector, projector_axis};
    let lam = lambda();
    for (name, light, axis, cos_lo) in [
        ("goniometric le", gonio_light(), Vec3::Z, -1.0),
        ("projection le", projector(), projector_axis(), 0.6),
    ] {
        let sample = |r: &mut Pcg32| light.sample_le(u2(r), u2(r), &lam).map(|s| s.ray.d);
        let pdf = |w: Vec3| light.pdf_le(&Ray::new(Vec3::ZERO, w)).1 .0 as f64;
        chi2_directions(name, axis, cos_lo, sample, &pdf);
    }
}
