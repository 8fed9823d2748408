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
