//! Delta lobes: smooth conductor, smooth dielectric, index-matched and thin
//! dielectrics. Their f and pdf are zero for any given pair; only sampling
//! carries them, so they are checked against Fresnel in closed form.

use super::{dir, gold, u2};
use crate::bsdf::fresnel::{fr_complex_spectral, fr_dielectric};
use crate::bsdf::{
    Bxdf, BxdfFlags, ConductorBxdf, DielectricBxdf, SampleFlags, ThinDielectricBxdf, TransportMode,
    TrowbridgeReitz,
};
use crate::math::Vec2;
use crate::sampling::Pcg32;
use crate::spectrum::SampledSpectrum;

const ALL: SampleFlags = SampleFlags::ALL;

fn smooth() -> TrowbridgeReitz {
    TrowbridgeReitz::new(0.0, 0.0)
}

#[test]
fn smooth_conductor_reflects_fresnel() {
    let (eta, k) = gold();
    let b: Bxdf = ConductorBxdf::new(smooth(), eta, k).into();
    for wo in [dir(1.0, 0.0), dir(0.6, 1.0), dir(0.05, 2.0), dir(-0.5, 3.0)] {
        let s = b
            .sample_f(wo, 0.5, Vec2::splat(0.5), TransportMode::Radiance, ALL)
            .unwrap();
        assert_eq!(s.flags, BxdfFlags::SPECULAR_REFLECTION);
        assert!((s.wi.x + wo.x).abs() < 1e-7 && (s.wi.y + wo.y).abs() < 1e-7 && s.wi.z == wo.z);
        // f|cos θi|/p is the Fresnel reflectance, to round-off (1e-6).
        let w = s.f * (s.wi.z.abs() / s.pdf.0);
        let fr = fr_complex_spectral(wo.z.abs(), eta, k);
        assert!(super::close_rel(w, fr, 1e-6), "{w:?} vs {fr:?}");
        assert!(b.f(wo, s.wi, TransportMode::Radiance).is_black());
        assert_eq!(b.pdf(wo, s.wi, TransportMode::Radiance, ALL).0, 0.0);
    }
    // A lossless mirror: k = 0, η = 10⁴ reflects ((η−1)/(η+1))² ≈ 1 − 4/η.
    let big = ConductorBxdf::new(
        smooth(),
        SampledSpectrum::splat(1e4),
        SampledSpectrum::zero(),
    );
    let s = Bxdf::from(big)
        .sample_f(
            dir(1.0, 0.0),
            0.5,
            Vec2::ZERO,
            TransportMode::Importance,
            ALL,
        )
        .unwrap();
    let r = s.f[0] * s.wi.z / s.pdf.0;
    assert!(
        (r - (9999.0f32 / 10001.0).powi(2)).abs() < 1e-5 && r > 0.999,
        "{r}"
    );
    // Transmission-only requests get nothing.
    let b: Bxdf = big.into();
    assert!(b
        .sample_f(
            dir(0.5, 0.0),
            0.5,
            Vec2::ZERO,
            TransportMode::Radiance,
            SampleFlags::TRANSMISSION
        )
        .is_none());
}

#[test]
fn smooth_dielectric_splits_by_fresnel() {
    let n = 100_000;
    for eta in [1.5f32, 1.0 / 1.5] {
        let b: Bxdf = DielectricBxdf::new(eta, smooth()).into();
        assert_eq!(
            b.flags(),
            BxdfFlags::SPECULAR_REFLECTION | BxdfFlags::SPECULAR_TRANSMISSION
        );
        for wo in [
            dir(0.98, 0.3),
            dir(0.6, 1.1),
            dir(0.05, 2.0),
            dir(-0.6, 4.0),
            dir(-0.05, 5.0),
        ] {
            let r = fr_dielectric(wo.z, eta);
            let mut rng = Pcg32::new(31, 1);
            let mut n_refl = 0usize;
            for _ in 0..n {
                let uc = rng.uniform_f32();
                for mode in [TransportMode::Radiance, TransportMode::Importance] {
                    let s = b.sample_f(wo, uc, u2(&mut rng), mode, ALL).unwrap();
                    // Lobe probability equals the Fresnel term (1e-6 round-off).
                    let p = if s.is_reflection() { r } else { 1.0 - r };
                    assert!((s.pdf.0 - p).abs() < 1e-6);
                    // Importance weight is exactly 1 (power is conserved); radiance
                    // transmission carries 1/η′².
                    let w = s.f[0] * s.wi.z.abs() / s.pdf.0;
                    let expect = match (s.is_transmission(), mode) {
                        (true, TransportMode::Radiance) => 1.0 / (s.eta * s.eta),
                        _ => 1.0,
                    };
                    assert!((w - expect).abs() < 1e-5 * expect, "{w} vs {expect}");
                    if s.is_transmission() {
                        // Snell: η_o sin θo = η_i sin θi, with η′ = η_i/η_o.
                        let (so, si) = (wo.truncate().length(), s.wi.truncate().length());
                        assert!((so - s.eta * si).abs() < 1e-5 && s.wi.z * wo.z < 0.0);
                    }
                    if mode == TransportMode::Radiance && s.is_reflection() {
                        n_refl += 1;
                    }
                }
            }
            // Fraction of reflections: binomial, 5σ.
            let frac = n_refl as f32 / n as f32;
            let sigma = (r * (1.0 - r) / n as f32).sqrt();
            assert!(
                (frac - r).abs() <= 5.0 * sigma + 1e-6,
                "η={eta} wo={wo}: {frac} vs {r}"
            );
        }
    }
}

#[test]
fn total_internal_reflection_reflects_everything() {
    // From the dense side beyond the critical angle (sin θc = 1/1.5) R = 1.
    let b: Bxdf = DielectricBxdf::new(1.5, smooth()).into();
    let wo = dir(-0.3, 0.7);
    assert_eq!(fr_dielectric(wo.z, 1.5), 1.0);
    for uc in [0.0, 0.5, 0.999_999] {
        let s = b
            .sample_f(wo, uc, Vec2::ZERO, TransportMode::Radiance, ALL)
            .unwrap();
        assert!(s.is_reflection() && s.pdf.0 == 1.0 && (s.f[0] * s.wi.z.abs() - 1.0).abs() < 1e-6);
    }
    assert!(b
        .sample_f(
            wo,
            0.5,
            Vec2::ZERO,
            TransportMode::Radiance,
            SampleFlags::TRANSMISSION
        )
        .is_none());
}

#[test]
fn index_matched_dielectric_passes_straight_through() {
    for a in [0.0f32, 0.3] {
        let b: Bxdf = DielectricBxdf::new(1.0, TrowbridgeReitz::new(a, a)).into();
        assert_eq!(b.flags(), BxdfFlags::SPECULAR_TRANSMISSION);
        for wo in [dir(0.7, 0.2), dir(-0.2, 3.0)] {
            for mode in [TransportMode::Radiance, TransportMode::Importance] {
                let s = b.sample_f(wo, 0.3, Vec2::splat(0.4), mode, ALL).unwrap();
                assert!((s.wi + wo).length() < 1e-6 && s.eta == 1.0);
                assert!((s.f[0] * s.wi.z.abs() / s.pdf.0 - 1.0).abs() < 1e-6);
            }
        }
    }
}

#[test]
fn thin_dielectric_conserves_energy() {
    for eta in [1.33f32, 1.5, 2.4] {
        let t = ThinDielectricBxdf::new(eta);
        let b: Bxdf = t.into();
        for wo in [dir(1.0, 0.0), dir(0.5, 1.0), dir(0.05, 2.0), dir(-0.7, 3.0)] {
            let (rp, tp) = t.reflectance_transmittance(wo.z.abs());
            assert!((rp + tp - 1.0).abs() < 1e-6);
            // Geometric series in closed form: R′ = 2R/(1 + R) ≥ R.
            let r = fr_dielectric(wo.z.abs(), eta);
            assert!((rp - 2.0 * r / (1.0 + r)).abs() < 1e-6 && rp >= r);
            let (mut sum_r, mut sum_t) = (0.0, 0.0);
            for (uc, mode) in [
                (0.0, TransportMode::Radiance),
                (0.999_999, TransportMode::Importance),
            ] {
                let s = b.sample_f(wo, uc, Vec2::ZERO, mode, ALL).unwrap();
                let w = s.f[0] * s.wi.z.abs();
                assert!(s.is_specular() && s.eta == 1.0);
                if s.is_reflection() {
                    sum_r += w;
                } else {
                    assert!((s.wi + wo).length() < 1e-6);
                    sum_t += w;
                }
            }
            assert!((sum_r + sum_t - 1.0).abs() < 1e-5, "{sum_r} + {sum_t}");
        }
    }
}
