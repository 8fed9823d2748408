//! One candidate out of a stream, drawn with probability proportional to a
//! non-negative weight from a single uniform number: weighted reservoir
//! sampling of one item [Chao 1982, "A general purpose unequal probability
//! sampling plan"; the one-item reservoir of Bitterli et al. 2020,
//! "Spatiotemporal reservoir resampling", Alg. 2].
//!
//! Candidate k (weight w_k, running total W_k = w_1 + … + w_k) replaces the
//! current choice with probability w_k / W_k, so after n candidates item j
//! is the choice with probability w_j / W_n. Instead of one random number
//! per candidate, the uniform u is rescaled after each decision: given
//! u < p it is uniform on [0, p), given u ≥ p on [p, 1), so u/p and
//! (u − p)/(1 − p) are again uniform on [0, 1) and independent of the
//! decisions taken. Exact in real arithmetic; in f32 each rescaling loses
//! about one ulp of u, far below any estimator's noise for the few
//! candidates of a subpath.
//!
//! # In VCM
//!
//! **Resampled connections** (`"string connections"`, `one` by default,
//! `all` for BDPT's estimator). A camera vertex z could join every vertex
//! y_j of its pixel's light subpath, each with a shadow ray; let X_j be the
//! MIS-weighted contribution of that join if nothing lies between (eqs.
//! 40–41) and V_j ∈ {0, 1} its visibility. `all` adds Σ_j V_j X_j. `one`
//! evaluates every X_j (BSDFs and weights, no ray), draws one index J with
//! P(J = j) = m(X_j) / Σ_k m(X_k), m the mean over the wavelengths
//! (the reservoir above), and adds V_J X_J / P(J) after one shadow ray. J is drawn
//! independently of the visibilities and P(j) > 0 wherever X_j ≠ 0, so
//! E[V_J X_J / P(J)] = Σ_j V_j X_j given everything else: every connection
//! technique keeps its expected weighted contribution, and the MIS weights,
//! functions of the path's sampling densities alone, still sum to one over
//! the techniques that can make a path, which is all unbiasedness needs
//! [Veach 1997, §9.2; on choosing one of many candidates by their
//! contribution: Talbot, Cline & Egbert 2005, "Importance resampling for
//! global illumination"]. The weights stay the power heuristic of the
//! techniques' densities, not of the thinned connections' effective ones:
//! valid, if no longer the heuristic's optimum. When every join is visible
//! and their spectra proportional, `one` equals `all`; the variance it adds
//! comes from joins of unequal visibility or colour. Measured at 128²,
//! 4 seeds (relMSE against long references; instructions by callgrind, 1
//! thread): on the Cornell box (16 iterations) `one` gave relMSE 0.008170
//! against `all`'s 0.008142 (+0.3 %) with 5.3 shadow rays per camera path
//! down to 3.1 and 5 % fewer instructions, while a uniform choice (weight
//! n) cost 13 % more relMSE for 12 % fewer instructions; on caustic-glass
//! (8 iterations, 0.2717 against 0.2722) and the pool (32 iterations,
//! 0.1463 against 0.1464) the two are equal in error and within 0.4 % in
//! instructions. So `one` is the default; shadow rays are cheap in these
//! small scenes, and the saving grows with the cost of a ray.
//!
//! **Join roulette** (`"float joinroulette"` τ, 0.1 by default, 0 off).
//! A join (a light-tracing splat, or with `connections all` a camera
//! vertex's connection) whose
//! MIS weight w is below τ is made with probability w/τ and then counts
//! with weight τ ([`super::mis::thin`]): the same expectation, without the
//! shadow ray of most joins that would count little. On the Cornell box
//! 61 % of the camera's connections and 68 % of the light-tracing joins
//! have w < 0.1 (31 iterations at 128²). Measured at 128² (relMSE against
//! long references, equal iterations; instructions by callgrind, 8
//! iterations, 1 thread): the Cornell box, 36 iterations, seeds 1–3,
//! 0.001631/0.001548/0.001584 with τ = 0 against 0.001654/0.001532/
//! 0.001616 with 0.1 (+0.8 %) and 0.001693/0.001620/0.001716 with 0.2
//! (+5.5 %), for 4.4 % fewer instructions at 0.1 (7.90 G → 7.55 G);
//! caustic-glass (32 iterations, seeds 1–2) 0.02126/0.01466 against
//! 0.02126/0.01470, the pool (64) 0.01852/0.02931 against 0.01861/0.02949.
//! Next-event estimation keeps every shadow ray (its weights are mostly
//! large, and its ray is traced inside the light sampling), and so does
//! the one resampled connection of `connections one`: its pick J was drawn
//! in proportion to X_J, which already holds w_J, so thinning it by w_J as
//! well made a join of weight w count Σ_k m(X_k)·τ/w with probability
//! ∝ w²: rare, unbounded splats (a camera vertex with w = 1.5·10⁻⁴ and
//! P(J) = 1/124 put 45 into one pixel of one pass, a red spot at 5× the
//! pixel's value after 90 passes; 2 of 13 Cornell renders had one). Without
//! it, 90 iterations at 128², seeds 1–11, 101, 301: relMSE mean 0.000842
//! (largest 0.000860) against 0.000878 (largest 0.001031), in the same
//! time (150 iterations 6.54 s against 6.51–6.53 s).

/// A running one-item reservoir over candidates of type `T`.
#[derive(Clone, Copy, Debug)]
pub struct Resampler<T> {
    u: f32,
    total: f32,
    chosen: Option<(T, f32)>,
}

/// The largest f32 below 1.
const ONE_MINUS_EPSILON: f32 = 1.0 - f32::EPSILON / 2.0;

impl<T> Resampler<T> {
    /// An empty reservoir driven by the uniform number `u` in [0, 1).
    pub fn new(u: f32) -> Self {
        Self {
            u: u.clamp(0.0, ONE_MINUS_EPSILON),
            total: 0.0,
            chosen: None,
        }
    }

    /// Offers `item` with weight `w`; a weight that is not positive and
    /// finite is never chosen.
    pub fn offer(&mut self, item: T, w: f32) {
        if !(w > 0.0 && w.is_finite()) {
            return;
        }
        self.total += w;
        let p = w / self.total;
        if self.u < p {
            self.chosen = Some((item, w));
            self.u /= p;
        } else {
            self.u = ((self.u - p) / (1.0 - p)).min(ONE_MINUS_EPSILON);
        }
    }

    /// The chosen item and the reciprocal of the probability that it was
    /// chosen, W_n / w_j; `None` when no candidate had a positive weight.
    pub fn pick(self) -> Option<(T, f32)> {
        let total = self.total;
        self.chosen.map(|(item, w)| (item, total / w))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For weights w and values x, drives the reservoir with M stratified
    /// uniforms. Item j is picked on a union of at most 2^(n − 1) intervals
    /// of u (one per sequence of the n − 1 later decisions), so its share of
    /// picks is w_j / Σw to within 2^(n − 1) strata, and the mean of
    /// x_J · Σw / w_J is the full sum Σx to within that many strata of
    /// every item's x_j Σw / w_j: a wrong reciprocal probability (n, or 1)
    /// misses it by far more.
    #[test]
    fn picks_in_proportion_and_the_weighted_pick_is_unbiased() {
        let w = [0.5f32, 0.0, 3.0, 1e-3, 1.25, 0.7, f32::NAN, 2.0];
        let x = [4.0f32, 0.0, 1.0, 0.004, 0.3, 2.0, 0.0, 0.9];
        let valid = |wj: f32| wj > 0.0 && wj.is_finite();
        let total: f32 = w.iter().filter(|v| valid(**v)).sum();
        let n = w.iter().filter(|v| valid(**v)).count();
        let m = 1 << 20;
        let mut picks = [0u32; 8];
        let mut mean = 0.0f64;
        for k in 0..m {
            let mut r = Resampler::new((k as f32 + 0.5) / m as f32);
            for (j, &wj) in w.iter().enumerate() {
                r.offer(j, wj);
            }
            let (j, inv_p) = r.pick().expect("a positive weight");
            picks[j] += 1;
            mean += f64::from(x[j] * inv_p) / m as f64;
        }
        let strata = f64::from(1u32 << (n - 1)) / m as f64;
        let mut bound = 0.0;
        for (j, &wj) in w.iter().enumerate() {
            let share = f64::from(picks[j]) / m as f64;
            let expect = if valid(wj) {
                f64::from(wj / total)
            } else {
                0.0
            };
            assert!(
                (share - expect).abs() <= strata,
                "item {j}: {share} vs {expect}"
            );
            if valid(wj) {
                bound += strata * f64::from(x[j] * total / wj);
            }
        }
        let full: f64 = x.iter().map(|&xj| f64::from(xj)).sum();
        assert!(bound < 0.01 * full, "the test resolves a 1 % error");
        assert!((mean - full).abs() <= bound, "{mean} vs {full} ± {bound}");
    }

    #[test]
    fn a_single_candidate_is_taken_with_probability_one() {
        for u in [0.0, 0.3, ONE_MINUS_EPSILON, 1.0] {
            let mut r = Resampler::new(u);
            r.offer("only", 0.25);
            assert_eq!(r.pick(), Some(("only", 1.0)));
        }
        let mut r = Resampler::<u8>::new(0.5);
        r.offer(1, 0.0);
        r.offer(2, -1.0);
        assert_eq!(r.pick(), None);
    }
}
