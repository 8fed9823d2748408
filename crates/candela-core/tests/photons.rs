//! The photon-shooting module against validation.md's closed forms: T1
//! (a point light over a plane: the fraction of photons landing in a disk,
//! and the disk-kernel density estimate with its exact kernel bias), T3
//! (every photon of a lone point light carries Φ) and T5 (in a closed diffuse
//! sphere the absorbed power totals Φ and the incident power Φ/(1 − ρ)).
//! Statistical checks use |x − expected| ≤ 5σ with σ derived from the
//! binomial or measured per-photon variance.

use candela_core::build::{build, Overrides, RenderSetup};
use candela_core::integrator::photon::{trace_photon, ShootSettings};
use candela_core::spectrum::SampledWavelengths;
use rayon::prelude::*;
use std::path::Path;

fn setup(world: &str) -> RenderSetup {
    let text = format!(
        "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nIntegrator \"path\" \"string lightsampler\" \"power\"\nWorldBegin\n{world}"
    );
    let desc = candela_scene::parse_str(&text, Path::new("photons.pbrt")).expect("parses");
    build(&desc, &Overrides::default()).expect("builds")
}

const PLANE: &str = r#"
LightSource "point" "point3 from" [0 0 2] "rgb I" [100 100 100]
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
Shape "trianglemesh" "point3 P" [-1000 -1000 0  1000 -1000 0  1000 1000 0  -1000 1000 0]
  "integer indices" [0 1 2 0 2 3]
"#;

/// First-hit horizontal distances of `n` photons (T1 geometry), and β of each.
fn first_hits(rs: &RenderSetup, n: u64) -> Vec<(f32, f32)> {
    let lambda = SampledWavelengths::sample_visible(0.37);
    let settings = ShootSettings {
        max_depth: 1,
        seed: 11,
        caustic_only: false,
    };
    (0..n)
        .into_par_iter()
        .filter_map(|i| {
            let mut hit = None;
            trace_photon(&rs.scene, &lambda, &settings, 0, i, |h| {
                hit = Some((h.v.p().truncate().length(), h.v.beta.0[0]));
            });
            hit
        })
        .collect()
}

#[test]
fn t3_photons_of_a_point_light_carry_its_total_power() {
    let rs = setup(PLANE);
    let lambda = SampledWavelengths::sample_visible(0.37);
    let phi = rs.scene.lights()[0].phi(&lambda).0[0];
    for (_, beta) in first_hits(&rs, 1000) {
        assert!((beta - phi).abs() <= 1e-5 * phi, "β₀ = {beta}, Φ = {phi}");
    }
}

#[test]
fn t1_photon_fraction_in_a_disk_and_the_disk_kernel_bias() {
    let rs = setup(PLANE);
    let n = 4_000_000u64;
    let hits = first_hits(&rs, n);
    let h = 2.0f64;
    // Fraction of Φ landing within R of the foot: (1 − h/√(h² + R²))/2.
    let frac = |r: f64| (1.0 - h / (h * h + r * r).sqrt()) / 2.0;
    let count = |r: f32| hits.iter().filter(|(d, _)| *d < r).count() as f64;
    let p = frac(2.0);
    assert!((p - 0.146447).abs() < 1e-6);
    let sigma = (p * (1.0 - p) / n as f64).sqrt();
    let got = count(2.0) / n as f64;
    assert!(
        (got - p).abs() <= 5.0 * sigma,
        "fraction {got} vs {p} ± {sigma}"
    );
    // Disk kernel r = 0.4 (r/h = 0.2): Ê = (count/N)·Φ/(πr²), whose exact
    // expectation is E(0)·(1 − 2.903 %), E(0) = Φ/(4πh²).
    let r = 0.4f64;
    let k = count(r as f32) / n as f64;
    let ratio = (k / (std::f64::consts::PI * r * r)) / (1.0 / (4.0 * std::f64::consts::PI * h * h));
    let expected = 1.0 - 0.02903;
    assert!(
        ((frac(r) / (std::f64::consts::PI * r * r)) * 4.0 * std::f64::consts::PI * h * h
            - expected)
            .abs()
            < 1e-4
    );
    let sigma = (frac(r) * (1.0 - frac(r)) / n as f64).sqrt() / frac(r) * expected;
    assert!(
        (ratio - expected).abs() <= 5.0 * sigma,
        "kernel estimate / E = {ratio} vs {expected} ± {sigma}"
    );
}

#[test]
fn t5_absorbed_power_is_phi_and_incident_power_is_phi_over_one_minus_rho() {
    let rs = setup(
        r#"LightSource "point" "point3 from" [0 0 0] "rgb I" [1 1 1]
Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
ReverseOrientation
Shape "sphere" "float radius" [1]
"#,
    );
    let lambda = SampledWavelengths::sample_visible(0.61);
    let phi = rs.scene.lights()[0].phi(&lambda).0[0] as f64;
    let settings = ShootSettings {
        max_depth: 10_000,
        seed: 5,
        caustic_only: false,
    };
    let n = 200_000u64;
    let per_photon: Vec<(f64, f64)> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut incident = 0.0f64;
            let fate = trace_photon(&rs.scene, &lambda, &settings, 3, i, |h| {
                incident += h.v.beta.0[0] as f64;
            });
            (fate.absorbed.0[0] as f64, incident)
        })
        .collect();
    let mean = |f: &dyn Fn(&(f64, f64)) -> f64| per_photon.iter().map(f).sum::<f64>() / n as f64;
    let absorbed = mean(&|x| x.0);
    assert!(
        (absorbed - phi).abs() <= 1e-5 * phi,
        "absorbed {absorbed} vs Φ {phi}"
    );
    let inc = mean(&|x| x.1);
    let var = per_photon.iter().map(|x| (x.1 - inc).powi(2)).sum::<f64>() / (n as f64 - 1.0);
    let sigma = (var / n as f64).sqrt();
    let expected = phi / (1.0 - 0.5);
    assert!(
        (inc - expected).abs() <= 5.0 * sigma,
        "incident {inc} vs {expected} ± {sigma}"
    );
}
