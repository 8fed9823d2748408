//! Stratified wavelength groups of a photon pass (`sppm`, `ppm`,
//! `photonmap`).
//!
//! A photon estimate forms f·ΔΦ spectrally, so a photon and the pixel that
//! gathers it must carry the same wavelengths. If a whole pass shares one
//! set of four, every pixel of the pass sees the same colour error and the
//! image mean is tinted at random from pass to pass: one SPPM iteration on
//! the Cornell box had mean blue 0.012 where 0.058 is right. Instead each
//! pass has G *groups*, each with its own four wavelengths; photon `i` of
//! the pass belongs to group `i mod G`, and a pixel belongs to the group
//! (hash(seed, pixel index) + pass) mod G and gathers only its group's
//! photons. The colour noise then differs from pixel to pixel and averages
//! out over the image instead of tinting it.
//!
//! **A pixel's groups over passes.** The hash places neighbouring pixels in
//! unrelated groups; adding the pass makes every pixel visit the G groups
//! in turn, once in any G consecutive passes, so its wavelengths over
//! passes fill the strata below evenly (with u's low-discrepancy sequence,
//! a rank-1 lattice) instead of drawing a stratum at random each pass.
//! Measured with `sppm`, 32 iterations, relMSE between renders of seeds
//! (1, 2), (3, 4), (5, 6) (twice the variance; bias cancels):
//! caustic-glass at half size 0.0550/0.0516/0.0524 with a group hashed per
//! pass against 0.0516/0.0483/0.0499 in turn (−5 to −6 %; mean absolute
//! error −5 %), the Cornell box at half size 0.00685/0.00399/0.00432
//! against 0.00678/0.00355/0.00386 (−1 to −11 %; mean absolute error
//! 0.0109/0.0108/0.0112 against 0.0092/0.0087/0.0094, −15 to −20 %).
//!
//! **Stratification.** With a pass position u ∈ [0, 1) (stratified or
//! low-discrepancy over passes, chosen by the integrator) and a hashed
//! quarter k_g ∈ {0, 1, 2, 3}, group g takes the four wavelengths at CDF
//! positions ξ_{g,j} = frac((u + g + G·k_g)/(4G) + j/4), j = 0..3
//! ([`SampledWavelengths::sample_visible`] with offset
//! (u + g + G·k_g)/(4G)): the 4G wavelengths of a pass fill the 4G strata
//! of [0, 1) once each, the same jitter u in all of them [stratified
//! sampling, Pharr et al. 2023, §8.2]. The hero (j = 0, the wavelength a
//! dispersive refraction keeps) lands in quarter k_g; k_g is hashed per
//! (pass, group) so that the hero, like every other of the four, is
//! uniformly distributed over [0, 1) when the group is uniformly
//! distributed — which a pixel's group is over seeds (its hash), as u is
//! over seeds (its offset).
//!
//! **Unbiasedness.** A pixel in group g sees only the N_g photons of its
//! group; each carries β·N/N_g, so its estimate is the usual one for N
//! photons of power Φ/N [Jensen 2001, eq. 5.1] evaluated at that group's
//! wavelengths, and each wavelength's marginal density is the visible-range
//! density, as for a single sampled set [pbrt-v4 `SampleVisibleWavelengths`].
//! The cost: a pixel's photon estimate in one pass rests on N/G photons
//! instead of N. `wavelengthgroups` 1 is the old scheme (one set per pass).

use crate::sampling::hash_u64s;
use crate::spectrum::SampledWavelengths;

/// Default number of wavelength groups per pass.
pub const DEFAULT_GROUPS: u32 = 4;

/// Largest accepted number of groups.
pub const MAX_GROUPS: u32 = 64;

/// The wavelength groups of one pass.
#[derive(Clone, Debug)]
pub struct PassWavelengths {
    groups: Vec<SampledWavelengths>,
    seed: u64,
    pass: u64,
}

impl PassWavelengths {
    /// The `groups` (clamped to 1..=[`MAX_GROUPS`]) wavelength sets of pass
    /// `pass` at pass position `u` ∈ [0, 1) (module doc).
    pub fn new(seed: u64, pass: u64, u: f64, groups: u32) -> Self {
        let g_count = groups.clamp(1, MAX_GROUPS);
        let u = if u.is_finite() {
            u.clamp(0.0, 1.0)
        } else {
            0.0
        };
        let groups = (0..g_count)
            .map(|g| {
                let k = hash_u64s(&[seed, pass, u64::from(g), 0x4845_524f]) % 4;
                let pos =
                    (u + f64::from(g) + f64::from(g_count) * k as f64) / (4.0 * f64::from(g_count));
                // Keep the offset strictly below 1 after rounding to f32.
                let pos = (pos as f32).min(1.0 - f32::EPSILON / 2.0);
                SampledWavelengths::sample_visible(pos)
            })
            .collect();
        Self { groups, seed, pass }
    }

    /// Number of groups G.
    pub fn len(&self) -> usize {
        self.groups.len()
    }

    /// True if there are no groups (never: at least one is made).
    pub fn is_empty(&self) -> bool {
        self.groups.is_empty()
    }

    /// The wavelengths of group `g`.
    pub fn group(&self, g: usize) -> &SampledWavelengths {
        &self.groups[g % self.groups.len()]
    }

    /// The group of the pixel with (scanline) index `index` in this pass.
    pub fn pixel_group(&self, index: u64) -> usize {
        if self.groups.len() == 1 {
            return 0;
        }
        let h = hash_u64s(&[self.seed, index, 0x5049_5847]);
        ((h + self.pass) % self.groups.len() as u64) as usize
    }

    /// The group of photon `i` of the pass.
    pub fn photon_group(&self, i: u64) -> usize {
        (i % self.groups.len() as u64) as usize
    }

    /// N/N_g: the factor on the power of each photon of group `g` when the
    /// pass shoots `n` photons (module doc); 0 for a group with none.
    pub fn photon_scale(&self, g: usize, n: u64) -> f32 {
        let gs = self.groups.len() as u64;
        let g = g as u64 % gs;
        let n_g = n / gs + u64::from(g < n % gs);
        if n_g == 0 {
            0.0
        } else {
            (n as f64 / n_g as f64) as f32
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spectrum::N_SPECTRUM_SAMPLES;

    /// The visible-range CDF position of a wavelength (inverse of
    /// `sample_visible_wavelength`, by bisection).
    fn cdf_position(lambda: f32) -> f64 {
        let (mut lo, mut hi) = (0.0f32, 1.0f32);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if crate::spectrum::sample_visible_wavelength(mid) < lambda {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        f64::from(0.5 * (lo + hi))
    }

    #[test]
    fn groups_fill_every_stratum_once() {
        for groups in [1u32, 3, 4, 8] {
            let pw = PassWavelengths::new(9, 17, 0.37, groups);
            let strata = 4 * groups as usize;
            let mut seen = vec![0; strata];
            for g in 0..pw.len() {
                for j in 0..N_SPECTRUM_SAMPLES {
                    let x = cdf_position(pw.group(g).lambda(j));
                    let s = ((x * strata as f64) as usize).min(strata - 1);
                    seen[s] += 1;
                    let within = x * strata as f64 - s as f64;
                    assert!(
                        (within - 0.37).abs() < 1e-3,
                        "jitter {within} in stratum {s}"
                    );
                }
            }
            assert!(seen.iter().all(|&c| c == 1), "G = {groups}: {seen:?}");
        }
    }

    #[test]
    fn photon_scales_sum_to_the_group_count() {
        let pw = PassWavelengths::new(1, 2, 0.5, 4);
        for n in [1u64, 3, 4, 10, 1001] {
            // Each group with photons carries total weight N_g·(N/N_g) = N.
            let mut total = 0.0f64;
            for i in 0..n {
                let g = pw.photon_group(i);
                total += f64::from(pw.photon_scale(g, n)) / n as f64;
            }
            let nonempty = n.min(4) as f64;
            assert!((total - nonempty).abs() < 1e-4, "n = {n}: {total}");
        }
    }

    /// Pixels spread evenly over the groups in a pass, and each visits every
    /// group once in any G consecutive passes (a group hashed per pass
    /// would revisit one within G passes for most pixels, and fail).
    #[test]
    fn pixel_groups_are_balanced_and_each_pixel_visits_every_group_in_turn() {
        for g in [3u32, 4] {
            let passes: Vec<PassWavelengths> = (5..5 + u64::from(g))
                .map(|p| PassWavelengths::new(3, p, 0.1, g))
                .collect();
            let n = 40_000u64;
            let mut count = vec![0usize; g as usize];
            for i in 0..n {
                count[passes[0].pixel_group(i)] += 1;
                let mut seen = vec![false; g as usize];
                for pw in &passes {
                    seen[pw.pixel_group(i)] = true;
                }
                assert!(seen.iter().all(|&s| s), "G = {g}, pixel {i}");
            }
            // Binomial(n, 1/G): 5σ.
            let p = 1.0 / f64::from(g);
            let five_sigma = 5.0 * (n as f64 * p * (1.0 - p)).sqrt();
            let mean = n as f64 * p;
            assert!(
                count.iter().all(|&c| (c as f64 - mean).abs() < five_sigma),
                "{count:?}"
            );
        }
    }
}
