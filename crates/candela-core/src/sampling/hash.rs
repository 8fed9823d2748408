//! Integer hashing for deterministic per-pixel / per-photon seeding.

/// 64-bit finaliser with good avalanche [Stafford's "Mix13" variant of MurmurHash3's fmix64].
#[inline]
pub fn mix_bits(mut v: u64) -> u64 {
    v ^= v >> 31;
    v = v.wrapping_mul(0x7fb5_d329_728e_a185);
    v ^= v >> 27;
    v = v.wrapping_mul(0x81da_def4_bc2d_d44d);
    v ^= v >> 33;
    v
}

/// Hash of a sequence of 64-bit values (order-dependent).
#[inline]
pub fn hash_u64s(vals: &[u64]) -> u64 {
    hash_u64s_from(0x9e37_79b9_7f4a_7c15, vals)
}

/// Continues [`hash_u64s`] from the state `h` it reached on a prefix:
/// `hash_u64s(&[a, b, c]) == hash_u64s_from(hash_u64s(&[a, b]), &[c])`.
#[inline]
pub fn hash_u64s_from(mut h: u64, vals: &[u64]) -> u64 {
    for &v in vals {
        h = mix_bits(
            h ^ v
                .wrapping_add(0x9e37_79b9_7f4a_7c15)
                .wrapping_add(h << 6)
                .wrapping_add(h >> 2),
        );
    }
    h
}

/// MurmurHash64A of a byte string [Appleby, MurmurHash2, public domain]: the
/// hash pbrt-v4's `Hash(...)` applies to the bytes of its arguments.
pub fn murmur_hash64a(key: &[u8], seed: u64) -> u64 {
    const M: u64 = 0xc6a4_a793_5bd1_e995;
    const R: u32 = 47;
    let mut h = seed ^ (key.len() as u64).wrapping_mul(M);
    let mut blocks = key.chunks_exact(8);
    for b in &mut blocks {
        let mut k = u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]);
        k = k.wrapping_mul(M);
        k ^= k >> R;
        k = k.wrapping_mul(M);
        h ^= k;
        h = h.wrapping_mul(M);
    }
    let tail = blocks.remainder();
    if !tail.is_empty() {
        for (i, &byte) in tail.iter().enumerate() {
            h ^= (byte as u64) << (8 * i);
        }
        h = h.wrapping_mul(M);
    }
    h ^= h >> R;
    h = h.wrapping_mul(M);
    h ^= h >> R;
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn continuing_from_a_prefix_equals_hashing_the_whole_sequence() {
        let v = [3u64, 1 << 40, 7, u64::MAX, 0];
        for k in 0..=v.len() {
            assert_eq!(hash_u64s_from(hash_u64s(&v[..k]), &v[k..]), hash_u64s(&v));
        }
    }
}
