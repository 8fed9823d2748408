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
    let mut h = 0x9e37_79b9_7f4a_7c15u64;
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
