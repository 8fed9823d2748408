//! Deterministic identities: sample ↔ eval ↔ pdf agreement, reciprocity and
//! the adjoint relation between transport modes.
//!
//! Tolerance: 1e-4 relative. The quantities compared are the same formula
//! evaluated along two float paths (sampled ωm versus ωm rebuilt from ωo, ωi),
//! which differ by a few ulps of the half vector; 1e-4 leaves two orders of
//! magnitude of margin yet catches any missing factor (η′², 4|ωo·ωm|, G1 …).

use super::{cases, eta_of, medium_index, sample, u2, MODES};
use crate::bsdf::{Bxdf, SampleFlags, TransportMode};
use crate::math::Vec3;
use crate::sampling::{sample_uniform_sphere, Pcg32};

const TOL: f32 = 1e-4;

/// Relative agreement of two scalars.
fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= TOL * a.abs().max(b.abs())
}

#[test]
fn sample_matches_eval_and_pdf() {
    let mut fails = Vec::new();
    for case in cases() {
        let b = case.bxdf;
        for &wo in &case.wos {
            for mode in MODES {
                let mut r = Pcg32::new(17, 3);
                for _ in 0..20_000 {
                    let Some(s) = sample(&b, wo, &mut r, mode) else {
                        continue;
                    };
                    let f = b.f(wo, s.wi, mode);
                    let pdf = b.pdf(wo, s.wi, mode, SampleFlags::ALL).0;
                    let f_ok = super::close_rel(s.f, f, TOL);
                    let lobe_ok = s.flags.is_non_specular()
                        && s.is_transmission() == (wo.z * s.wi.z < 0.0)
                        && (s.is_reflection()
                            || s.eta
                                == medium_index(s.wi, eta_of(&b)) / medium_index(wo, eta_of(&b)));
                    if !f_ok || !close(s.pdf.0, pdf) || !lobe_ok || s.pdf_is_proportional {
                        fails.push(format!(
                            "{} {mode:?} wo={wo} wi={}: f {:?} vs {:?}, pdf {} vs {pdf}, flags {:?} eta {}",
                            case.name, s.wi, s.f, f, s.pdf.0, s.flags, s.eta
                        ));
                        break;
                    }
                }
            }
        }
    }
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

/// Direction pairs for reciprocity checks: half uniform over the sphere, half
/// with wi drawn by `sample_f` so narrow lobes are hit.
fn pairs(b: &Bxdf, seed: u64, n: usize) -> Vec<(Vec3, Vec3)> {
    let mut r = Pcg32::new(seed, 5);
    (0..n)
        .filter_map(|i| {
            let wo = sample_uniform_sphere(u2(&mut r));
            let wi = if i % 2 == 0 {
                sample_uniform_sphere(u2(&mut r))
            } else {
                sample(b, wo, &mut r, TransportMode::Radiance)?.wi
            };
            (wo.z.abs() > 1e-3 && wi.z.abs() > 1e-3).then_some((wo, wi))
        })
        .collect()
}

#[test]
fn reciprocity_and_mode_adjoint() {
    // Reflection: f(ωo, ωi) = f(ωi, ωo) in both modes. Transmission, radiance:
    // f(ωo, ωi)/η_o² = f(ωi, ωo)/η_i² [Veach 1997, §5.2]. Importance mode is
    // the adjoint: f_imp(ωo, ωi) = f_rad(ωi, ωo) for every pair.
    let (rad, imp) = (TransportMode::Radiance, TransportMode::Importance);
    let mut fails = Vec::new();
    for case in cases() {
        let b = case.bxdf;
        let eta = eta_of(&b);
        let mut nonzero = 0;
        for (wo, wi) in pairs(&b, 23, 40_000) {
            let (f_oi, f_io) = (b.f(wo, wi, rad), b.f(wi, wo, rad));
            let (eo, ei) = (medium_index(wo, eta), medium_index(wi, eta));
            let lhs = f_oi / (eo * eo);
            let rhs = f_io / (ei * ei);
            let adj = b.f(wo, wi, imp);
            if !f_oi.is_black() {
                nonzero += 1;
            }
            if !super::close_rel(lhs, rhs, TOL) || !super::close_rel(adj, f_io, TOL) {
                fails.push(format!(
                    "{}: wo={wo} wi={wi}: {:?}/ηo² vs {:?}/ηi², imp {:?}",
                    case.name, f_oi, f_io, adj
                ));
                break;
            }
            // Symmetric BxDFs agree across modes in reflection.
            if wo.z * wi.z > 0.0 && !super::close_rel(adj, f_oi, TOL) {
                fails.push(format!("{}: modes differ in reflection", case.name));
                break;
            }
        }
        // The test must not pass vacuously.
        if fails.is_empty() {
            assert!(nonzero > 1000, "{}: only {nonzero} nonzero", case.name);
        }
    }
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

#[test]
fn sampled_values_follow_mode_scaling() {
    // Same random numbers, both modes: identical directions and pdfs; transmitted
    // f differs by exactly η′² (radiance · η′² = importance).
    for case in cases() {
        let b = case.bxdf;
        for &wo in &case.wos {
            let (mut r1, mut r2) = (Pcg32::new(4, 4), Pcg32::new(4, 4));
            for _ in 0..5_000 {
                let s1 = sample(&b, wo, &mut r1, TransportMode::Radiance);
                let s2 = sample(&b, wo, &mut r2, TransportMode::Importance);
                let (Some(s1), Some(s2)) = (s1, s2) else {
                    assert!(s1.is_none() && s2.is_none(), "{}", case.name);
                    continue;
                };
                assert_eq!((s1.wi, s1.pdf, s1.flags), (s2.wi, s2.pdf, s2.flags));
                let scale = if s1.is_transmission() {
                    s1.eta * s1.eta
                } else {
                    1.0
                };
                assert!(super::close_rel(s1.f * scale, s2.f, TOL), "{}", case.name);
            }
        }
    }
}

#[test]
fn local_pair_evaluation_equals_f_and_both_pdfs_bit_for_bit() {
    // `Bsdf::local_pair` with `f_pair` and `pdfs_pair` is an evaluation-order
    // shortcut for bidirectional joins: it must return exactly what `f`,
    // `pdf` and the adjoint `pdf` return, in a tilted frame, in both modes,
    // including directions at (or within rounding of) the shading plane.
    let frame_n = Vec3::new(0.3, 0.8, -0.52).normalize();
    let tangent = Vec3::new(1.0, -0.2, 0.27);
    let mut checked = 0;
    for case in cases() {
        let bsdf = crate::bsdf::Bsdf::new(frame_n, tangent, case.bxdf);
        let mut r = Pcg32::new(31, 7);
        for i in 0..2_000 {
            let wo = sample_uniform_sphere(u2(&mut r));
            let wi = if i % 50 == 0 {
                bsdf.from_local(Vec3::new(wo.x, wo.y, 0.0).normalize_or_zero())
            } else {
                sample_uniform_sphere(u2(&mut r))
            };
            for mode in MODES {
                let pair = bsdf.local_pair(wo, wi);
                let f_pair = bsdf.f_pair(&pair, mode);
                let (fwd_pair, rev_pair) = bsdf.pdfs_pair(&pair, mode);
                let f = bsdf.f(wo, wi, mode);
                let fwd = bsdf.pdf(wo, wi, mode, SampleFlags::ALL);
                let rev = bsdf.pdf(wi, wo, mode.adjoint(), SampleFlags::ALL);
                assert!(
                    f_pair
                        .0
                        .iter()
                        .zip(&f.0)
                        .all(|(a, b)| a.to_bits() == b.to_bits())
                        && fwd_pair.0.to_bits() == fwd.0.to_bits()
                        && rev_pair.0.to_bits() == rev.0.to_bits(),
                    "{} {mode:?} wo={wo} wi={wi}: {f_pair:?} {fwd_pair:?} {rev_pair:?} vs \
                     {f:?} {fwd:?} {rev:?}",
                    case.name
                );
                checked += usize::from(!f.is_black() && fwd.0 > 0.0 && rev.0 > 0.0);
            }
        }
    }
    assert!(checked > 1000, "only {checked} non-zero evaluations");
}

/// A layered walk's interface samples ([`crate::bsdf::DielectricBxdf::sample_f_walk`],
/// f and density from the sampled ωm) against [`Bxdf::sample_f`] (rebuilt from
/// the half vector in f64), over every rough dielectric case, both modes and
/// each lobe choice: the same direction, lobe and η from the same numbers,
/// and no sample one of them makes that the other refuses. f and density
/// agree within [`TOL`] but where the sampled ωm's round-off is amplified
/// (grazing refraction, densities ~1e-4): at most 1 in 10⁴ samples beyond
/// it, none beyond 1e-2.
#[test]
fn walk_samples_equal_full_samples() {
    let mut fails = Vec::new();
    let (mut compared, mut loose) = (0usize, 0usize);
    for case in super::cases_named("dielectric") {
        let Bxdf::Dielectric(d) = case.bxdf else {
            unreachable!("dielectric cases hold dielectrics")
        };
        for &wo in &case.wos {
            for mode in MODES {
                let mut r = Pcg32::new(29, 11);
                for _ in 0..20_000 {
                    let (uc, u) = (r.uniform_f32(), u2(&mut r));
                    let full = d.sample_f(wo, uc, u, mode, SampleFlags::ALL);
                    let walk = d.sample_f_walk(wo, uc, u, mode, SampleFlags::ALL);
                    let same = match (&full, &walk) {
                        (None, None) => true,
                        (Some(a), Some(b)) => {
                            compared += 1;
                            let tight = super::close_rel(a.f, b.f, TOL) && close(a.pdf.0, b.pdf.0);
                            loose += usize::from(!tight);
                            a.wi == b.wi
                                && a.flags == b.flags
                                && a.eta == b.eta
                                && super::close_rel(a.f, b.f, 1e-2)
                                && (a.pdf.0 - b.pdf.0).abs() <= 1e-2 * a.pdf.0.max(b.pdf.0)
                        }
                        _ => false,
                    };
                    if !same {
                        fails.push(format!(
                            "{} {mode:?} wo={wo}: full {full:?}\n  walk {walk:?}",
                            case.name
                        ));
                        break;
                    }
                }
            }
        }
    }
    assert!(compared > 100_000, "only {compared} samples compared");
    assert!(fails.is_empty(), "{}", fails.join("\n"));
    assert!(
        loose * 10_000 <= compared,
        "{loose} of {compared} beyond {TOL}"
    );
}
