//! χ² goodness of fit of `sample_f` against `pdf` for every non-delta case.
//!
//! Tolerance: family level α = 1 % over all configurations tested (cases ×
//! outgoing directions × both transport modes), split per run with Šidák's
//! correction, so the whole suite rejects a correct sampler with probability
//! 1 % for a random seed (the seeds are fixed, so the outcome is deterministic).
//! Set `CHI2_VERBOSE=1` (with `--nocapture`) to print every run's statistic.

use super::{cases, cases_named, Case, MODES};
use crate::bsdf::SampleFlags;
use crate::math::Vec2;
use crate::sampling::chi2::{chi2_test, sidak_alpha, Chi2Config};

/// Number of χ² runs in the whole suite: the m of the Šidák correction.
fn total_runs() -> usize {
    cases().iter().map(|c| c.wos.len()).sum::<usize>() * MODES.len()
}

/// Runs χ² for every direction and mode of `cases`; returns the failures.
fn run(cases: &[Case]) -> Vec<String> {
    let alpha = sidak_alpha(0.01, total_runs());
    let mut failures = Vec::new();
    for (ci, case) in cases.iter().enumerate() {
        for (wi, &wo) in case.wos.iter().enumerate() {
            for (mi, &mode) in MODES.iter().enumerate() {
                let cfg = Chi2Config {
                    seed: (ci * 100 + wi * 10 + mi) as u64,
                    ..Chi2Config::default()
                };
                let b = case.bxdf;
                let report = chi2_test(
                    &cfg,
                    |uc, a, c| {
                        let s = b.sample_f(wo, uc, Vec2::new(a, c), mode, SampleFlags::ALL)?;
                        assert!(!s.is_specular(), "{}: delta sample", case.name);
                        Some(s.wi)
                    },
                    |wi| b.pdf(wo, wi, mode, SampleFlags::ALL).0,
                );
                if std::env::var("CHI2_VERBOSE").is_ok() {
                    eprintln!("{} wo={wo} {mode:?}: {report}", case.name);
                }
                if let Err(e) = report.check(alpha) {
                    failures.push(format!("{} wo={wo} {mode:?}: {e}", case.name));
                }
            }
        }
    }
    failures
}

#[test]
fn chi2_diffuse_and_conductor() {
    let mut cs = cases_named("diffuse");
    cs.extend(cases_named("conductor"));
    let f = run(&cs);
    assert!(f.is_empty(), "{}", f.join("\n"));
}

#[test]
fn chi2_dielectric_dense_side_above() {
    let f = run(&cases_named("dielectric η=1.500"));
    assert!(f.is_empty(), "{}", f.join("\n"));
}

#[test]
fn chi2_dielectric_dense_side_below() {
    let f = run(&cases_named("dielectric η=0.667"));
    assert!(f.is_empty(), "{}", f.join("\n"));
}
