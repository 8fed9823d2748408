//! The `mix` material's per-hit choice.
//!
//! pbrt-v4's `MixMaterial` does not blend BSDFs: at each hit it picks one of
//! its two materials, the second with probability `amount`, so the expected
//! reflection is the blend (`MixMaterial::ChooseMaterial`, book §10.5.2). The
//! "random" number is a hash of the hit point and the outgoing direction,
//! so the choice is deterministic for a given hit and needs no sampler
//! dimension: u = low 32 bits of MurmurHash64A(p, wo) / 2³², and the first
//! material is taken when amount < u.

use crate::math::Vec3;
use crate::sampling::murmur_hash64a;

/// Index (0 or 1) of the material a mix with weight `amount` uses at `p` seen from `wo`.
pub fn mix_choice(amount: f32, p: Vec3, wo: Vec3) -> usize {
    if amount <= 0.0 {
        return 0;
    }
    if amount >= 1.0 {
        return 1;
    }
    if amount < hash_uniform(p, wo) {
        0
    } else {
        1
    }
}

/// A number in [0, 1] hashed from the bytes of `p` and `wo` (pbrt-v4 `HashFloat`).
fn hash_uniform(p: Vec3, wo: Vec3) -> f32 {
    let mut bytes = [0u8; 24];
    for (i, v) in [p.x, p.y, p.z, wo.x, wo.y, wo.z].iter().enumerate() {
        bytes[4 * i..4 * i + 4].copy_from_slice(&v.to_le_bytes());
    }
    (murmur_hash64a(&bytes, 0) as u32) as f32 * (1.0 / 4_294_967_296.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    #[test]
    fn first_material_fraction_is_one_minus_amount() {
        // Over n hits with independent uniform hashes, the count choosing the
        // first material is Binomial(n, 1 − a): mean n(1 − a), standard
        // deviation σ = √(n a (1 − a)). Accept within 5σ.
        let mut rng = Pcg32::new(11, 2);
        let n = 200_000;
        for a in [0.1f32, 0.3, 0.5, 0.85] {
            let mut first = 0u32;
            for _ in 0..n {
                let p = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 10.0;
                let wo = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32())
                    .normalize_or_zero();
                if mix_choice(a, p, wo) == 0 {
                    first += 1;
                }
            }
            let (nf, af) = (n as f64, a as f64);
            let sigma = (nf * af * (1.0 - af)).sqrt();
            let dev = (first as f64 - nf * (1.0 - af)).abs();
            assert!(
                dev <= 5.0 * sigma,
                "amount {a}: {first} of {n} chose the first material"
            );
        }
    }

    #[test]
    fn choice_is_deterministic_and_saturates() {
        let (p, wo) = (Vec3::new(0.1, 2.0, -3.0), Vec3::new(0.0, 0.6, 0.8));
        assert_eq!(mix_choice(0.4, p, wo), mix_choice(0.4, p, wo));
        assert_eq!(mix_choice(0.0, p, wo), 0);
        assert_eq!(mix_choice(-1.0, p, wo), 0);
        assert_eq!(mix_choice(1.0, p, wo), 1);
    }
}
