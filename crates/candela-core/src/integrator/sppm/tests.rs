//! SPPM and PPM bookkeeping against closed forms.

use super::*;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

#[test]
fn sppm_update_matches_hachisuka_jensen_on_synthetic_inputs() {
    // Expected values computed independently (Python, f64):
    // N' = N + αM, R'² = R²(N + αM)/(N + M), τ' = (τ + Φ)R'²/R².
    let s = PixelStats {
        n: 10.0,
        r2: 1.0,
        tau: [1.0, 2.0, 3.0],
        ld: [7.0, 8.0, 9.0],
    };
    let u = sppm_update(&s, 5.0, [0.5, 0.25, 0.125], ALPHA);
    assert!(close(u.n, 13.333333333333332));
    assert!(close(u.r2, 0.8888888888888888));
    for (got, want) in u
        .tau
        .iter()
        .zip([1.3333333333333333, 2.0, 2.7777777777777777])
    {
        assert!(close(*got, want), "{got} vs {want}");
    }
    assert_eq!(u.ld, s.ld, "direct light is not scaled");
    let first = PixelStats {
        n: 0.0,
        r2: 0.04,
        ..Default::default()
    };
    let u = sppm_update(&first, 3.0, [1e-3, 2e-3, 0.0], ALPHA);
    assert!(close(u.n, 2.0) && close(u.r2, 0.02666666666666667));
    assert!(close(u.tau[0], 0.0006666666666666668) && close(u.tau[1], 0.0013333333333333335));
}

#[test]
fn sppm_radius_is_unchanged_when_no_photon_arrives() {
    let s = PixelStats {
        n: 4.0,
        r2: 0.25,
        tau: [0.5, 0.5, 0.5],
        ld: [0.0; 3],
    };
    assert_eq!(sppm_update(&s, 0.0, [0.0; 3], ALPHA), s);
}

#[test]
fn ppm_radius_schedule_matches_the_closed_form() {
    // validation.md: r_N²/r_1² for α = 2/3 is 0.508516 (N = 10), 0.238389 (100), 0.110761 (1000).
    for (n, want) in [(10, 0.508516), (100, 0.238389), (1000, 0.110761)] {
        let got = ppm_radius2(n, 2.0 / 3.0);
        assert!((got - want).abs() < 1e-6, "N = {n}: {got}");
    }
    assert_eq!(ppm_radius2(1, ALPHA), 1.0);
}
