//! Statistical and analytic tests of every BxDF (see `validation.md`,
//! "Statistical tests of sampling code").
//!
//! The non-delta configurations below are shared by the χ² fits, the
//! sample ↔ eval ↔ pdf agreement, reciprocity and albedo tests. Every test uses
//! fixed [`Pcg32`] seeds, so outcomes are reproducible.

mod chi2;
mod consistency;
mod delta;
mod energy;
mod layered;

use super::{
    Bxdf, ConductorBxdf, DielectricBxdf, DiffuseBxdf, DiffuseTransmissionBxdf, SampleFlags,
    TransportMode, TrowbridgeReitz,
};
use crate::math::{spherical_direction, Vec2, Vec3};
use crate::sampling::Pcg32;
use crate::spectrum::SampledSpectrum;

/// Both transport modes.
const MODES: [TransportMode; 2] = [TransportMode::Radiance, TransportMode::Importance];

/// One non-delta BxDF and the outgoing directions it is tested from.
struct Case {
    name: String,
    bxdf: Bxdf,
    wos: Vec<Vec3>,
}

/// Direction with the given cos θ at azimuth φ.
fn dir(cos_theta: f32, phi: f32) -> Vec3 {
    let sin = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    spherical_direction(sin, cos_theta, phi).normalize()
}

/// Near-normal, oblique and grazing (cos θ = 0.05) directions above the surface;
/// azimuths avoid the tangent axes so anisotropy is exercised.
fn wos_above() -> Vec<Vec3> {
    vec![dir(0.98, 0.3), dir(0.6, 1.1), dir(0.05, 2.0)]
}

/// [`wos_above`] plus oblique and grazing directions from below the surface.
fn wos_both() -> Vec<Vec3> {
    let mut v = wos_above();
    v.extend([dir(-0.6, 4.0), dir(-0.05, 5.0)]);
    v
}

/// Gold-like spectral index (η, k) at four wavelengths.
fn gold() -> (SampledSpectrum, SampledSpectrum) {
    (
        SampledSpectrum([1.45, 0.95, 0.27, 0.16]),
        SampledSpectrum([1.95, 1.85, 2.77, 3.6]),
    )
}

/// Every non-delta configuration of the suite.
fn cases() -> Vec<Case> {
    let mut out = vec![Case {
        name: "diffuse".into(),
        bxdf: DiffuseBxdf::new(SampledSpectrum([0.2, 0.5, 0.8, 1.0])).into(),
        wos: wos_above(),
    }];
    out.push(Case {
        name: "diffuse transmission".into(),
        bxdf: DiffuseTransmissionBxdf::new(
            SampledSpectrum([0.2, 0.5, 0.3, 0.6]),
            SampledSpectrum([0.7, 0.1, 0.3, 0.4]),
        )
        .into(),
        wos: wos_both(),
    });
    let (eta, k) = gold();
    for (ax, ay) in [(0.05, 0.05), (0.3, 0.3), (0.1, 0.4)] {
        out.push(Case {
            name: format!("conductor α=({ax},{ay})"),
            bxdf: ConductorBxdf::new(TrowbridgeReitz::new(ax, ay), eta, k).into(),
            wos: wos_above(),
        });
    }
    for eta in [1.5f32, 1.0 / 1.5] {
        for a in [0.1f32, 0.5] {
            out.push(Case {
                name: format!("dielectric η={eta:.3} α={a}"),
                bxdf: DielectricBxdf::new(eta, TrowbridgeReitz::new(a, a)).into(),
                wos: wos_both(),
            });
        }
    }
    out
}

/// Cases whose name starts with `prefix`.
fn cases_named(prefix: &str) -> Vec<Case> {
    cases()
        .into_iter()
        .filter(|c| c.name.starts_with(prefix))
        .collect()
}

/// Uniform 2-D sample.
fn u2(r: &mut Pcg32) -> Vec2 {
    Vec2::new(r.uniform_f32(), r.uniform_f32())
}

/// |a − b| ≤ tol·max(|a|, |b|) per wavelength.
fn close_rel(a: SampledSpectrum, b: SampledSpectrum, tol: f32) -> bool {
    (0..4).all(|i| (a[i] - b[i]).abs() <= tol * a[i].abs().max(b[i].abs()))
}

/// Relative index η_side/η_above of the medium `w` lies in (`eta` below, 1 above).
fn medium_index(w: Vec3, eta: f32) -> f32 {
    if w.z > 0.0 {
        1.0
    } else {
        eta
    }
}

/// Index below the surface for a dielectric case (1 for reflectors).
fn eta_of(b: &Bxdf) -> f32 {
    match b {
        Bxdf::Dielectric(d) => d.eta,
        _ => 1.0,
    }
}

/// Mean and standard error of `n` draws of `w`.
fn mean_se(n: usize, mut w: impl FnMut() -> f64) -> (f64, f64) {
    let (mut s, mut sq) = (0.0, 0.0);
    for _ in 0..n {
        let x = w();
        s += x;
        sq += x * x;
    }
    let m = s / n as f64;
    (m, ((sq / n as f64 - m * m).max(0.0) / n as f64).sqrt())
}

/// Samples of `sample_f` with all lobes allowed.
fn sample(b: &Bxdf, wo: Vec3, r: &mut Pcg32, mode: TransportMode) -> Option<super::BsdfSample> {
    let uc = r.uniform_f32();
    b.sample_f(wo, uc, u2(r), mode, SampleFlags::ALL)
}
