//! A light's total flux in radiometric and photometric units.
//!
//! Φ_e = ∫ Φ(λ) dλ \[W\] and Φ_v = K_m ∫ Φ(λ) V(λ) dλ \[lm\], V = ȳ of the CIE
//! 1931 observer and K_m = 683 lm/W [CIE S 017/E:2011, 17-21-039], summed
//! over 360–830 nm at 1 nm (the spacing of the CIE tables, so the sum is
//! the tables' own integral). Distant and infinite lights report the flux
//! through the scene's bounding disk, as their `phi` does.

use super::Light;
use crate::spectrum::{
    cie_xyz, SampledWavelengths, K_M, LAMBDA_MAX, LAMBDA_MIN, N_SPECTRUM_SAMPLES,
};

/// Total flux of a light.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Flux {
    /// Radiant flux \[W\] over 360–830 nm.
    pub watts: f64,
    /// Luminous flux \[lm\].
    pub lumens: f64,
}

impl std::ops::AddAssign for Flux {
    fn add_assign(&mut self, o: Flux) {
        self.watts += o.watts;
        self.lumens += o.lumens;
    }
}

impl Light {
    /// Total radiant and luminous flux (1 nm sums of [`Light::phi`]).
    pub fn flux(&self) -> Flux {
        let n = (LAMBDA_MAX - LAMBDA_MIN) as usize + 1;
        let mut f = Flux::default();
        for start in (0..n).step_by(N_SPECTRUM_SAMPLES) {
            let lambda: [f32; N_SPECTRUM_SAMPLES] =
                std::array::from_fn(|k| LAMBDA_MIN + ((start + k).min(n - 1)) as f32);
            let wl = SampledWavelengths::from_parts(lambda, [1.0; N_SPECTRUM_SAMPLES]);
            let phi = self.phi(&wl);
            for (k, &l) in lambda.iter().enumerate() {
                if start + k >= n {
                    break;
                }
                let p = phi[k] as f64;
                f.watts += p;
                f.lumens += K_M as f64 * cie_xyz(l)[1] as f64 * p;
            }
        }
        f
    }
}
