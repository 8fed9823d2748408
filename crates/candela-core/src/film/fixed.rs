//! Exact, order-independent sums for the film: every per-pass value is
//! quantised to fixed point in an `i128`, and integer addition is
//! associative and commutative, so a render split into pass ranges, threads,
//! resumed runs or cluster tasks adds up to the same bits as one run
//! (candela's PPM partial sums introduced the scheme; it now sits under every
//! film layer).
//!
//! A value v is stored as round(v·2^k). With k = 64 (radiance-like channels)
//! the step is 5.4e-20 and the range ±9.2e18: a pixel can sum a million
//! passes of values up to 1e12 before it saturates. Squares (variance
//! layers) use k = 32. Sums saturate instead of wrapping; saturation (never
//! reached by physical values) is the one case in which exactness is lost,
//! and it is counted.

/// Fractional bits of radiance-like channels.
pub const VALUE_BITS: i32 = 64;
/// Fractional bits of squared values (variance layers).
pub const SQUARE_BITS: i32 = 32;

/// Largest magnitude one quantised value may have (leaves headroom for sums).
const LIMIT: f64 = 1.7e37;

/// 2^e exactly, for |e| ≤ 1022, built from its exponent bits: the same value
/// as `2f64.powi(e)`, which with a run-time exponent is a call into the
/// compiler's runtime (~1 % of a path-tracing pass's instructions when the
/// film quantises every channel of every pixel).
#[inline]
fn exp2i(e: i32) -> f64 {
    debug_assert!(e.abs() <= 1022);
    f64::from_bits(((1023 + e) as u64) << 52)
}

/// 2^53: every f64 of at least this magnitude is an integer.
const INTEGRAL: f64 = 9_007_199_254_740_992.0;

/// round(v·2^bits) (halves away from zero), clamped to ±`LIMIT`;
/// non-finite values give 0 (the film drops and counts them before they
/// get here).
///
/// The film quantises every channel of every pixel of every pass, so this
/// avoids the runtime's `round` and f64 → i128 conversion calls: below
/// 2^53 the rounding goes through i64 (exact there), above it the value is
/// already an integer and its bits are shifted into place. Either way the
/// result is that of `(v·2^bits).round().clamp(−LIMIT, LIMIT) as i128`.
#[inline]
pub fn quantise(v: f64, bits: i32) -> i128 {
    if !v.is_finite() {
        return 0;
    }
    let s = v * exp2i(bits);
    if s.abs() < INTEGRAL {
        let t = s as i64;
        // s − trunc(s) is exact: it keeps s's fraction bits.
        let frac = s - t as f64;
        let r = if frac >= 0.5 {
            t + 1
        } else if frac <= -0.5 {
            t - 1
        } else {
            t
        };
        return i128::from(r);
    }
    integral_to_i128(s.clamp(-LIMIT, LIMIT))
}

/// An integer-valued f64 of magnitude in [2^53, 2^127) as i128: its 53-bit
/// significand shifted left by its exponent.
#[inline]
fn integral_to_i128(s: f64) -> i128 {
    let bits = s.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i32 - 1075;
    debug_assert!((1..=74).contains(&exponent));
    let significand = (bits & ((1 << 52) - 1)) | (1 << 52);
    let m = i128::from(significand) << exponent;
    if s < 0.0 {
        -m
    } else {
        m
    }
}

/// The value of a fixed-point sum.
#[inline]
pub fn dequantise(s: i128, bits: i32) -> f64 {
    s as f64 * exp2i(-bits)
}

/// Adds `b` into `a` element by element, saturating; returns the number of
/// elements that saturated.
pub fn add_into(a: &mut [i128], b: &[i128]) -> u64 {
    let mut saturated = 0;
    for (x, y) in a.iter_mut().zip(b) {
        let (s, overflow) = x.overflowing_add(*y);
        *x = if overflow {
            saturated += 1;
            x.saturating_add(*y)
        } else {
            s
        };
    }
    saturated
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantised_sums_do_not_depend_on_order() {
        // Floating-point sums of these values differ by order; fixed-point ones do not.
        let vals = [1e-9, 3.7, -2.5e3, 1e12, 7.25e-17, -1e12, 0.1, 0.2];
        let fwd: i128 = vals.iter().map(|&v| quantise(v, VALUE_BITS)).sum();
        let rev: i128 = vals.iter().rev().map(|&v| quantise(v, VALUE_BITS)).sum();
        assert_eq!(fwd, rev);
        let f: f64 = vals.iter().sum();
        assert!((dequantise(fwd, VALUE_BITS) - f).abs() < 1e-12 * 1e12);
    }

    #[test]
    fn round_trip_keeps_small_and_large_values() {
        for v in [5.4e-19, 1.0, 123.456, 1e15, -7.0] {
            let r = dequantise(quantise(v, VALUE_BITS), VALUE_BITS);
            assert!((r - v).abs() <= 6e-20 + 1e-15 * v.abs(), "{v} -> {r}");
        }
        assert_eq!(quantise(f64::NAN, VALUE_BITS), 0);
        assert_eq!(quantise(f64::INFINITY, VALUE_BITS), 0);
    }

    /// The fast paths of `quantise` against its definition, on values
    /// around every boundary: halves, the 2^53 switch, the clamp, signs,
    /// subnormals and random magnitudes over the whole range.
    #[test]
    fn quantise_matches_its_definition() {
        let reference = |v: f64, bits: i32| -> i128 {
            if !v.is_finite() {
                return 0;
            }
            (v * exp2i(bits)).round().clamp(-LIMIT, LIMIT) as i128
        };
        let mut vals = vec![
            0.0, -0.0, 5e-324, 1e-300, 0.5, 1.5, 2.5, -0.5, -2.5, 1e30, 1e300,
        ];
        for k in 40..=60 {
            let p = exp2i(k);
            for d in [-1.0, -0.5, 0.0, 0.5, 1.0] {
                vals.push(p + d);
            }
        }
        for e in [LIMIT, LIMIT * 0.999_999, 1.7e38] {
            vals.push(e);
        }
        let mut x = 0x1234_5678_9abc_def0u64;
        for _ in 0..200_000 {
            // xorshift64: random bit patterns give every exponent and fraction.
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            vals.push(f64::from_bits(x));
        }
        for &v in &vals {
            for v in [v, -v] {
                for bits in [0, SQUARE_BITS, VALUE_BITS] {
                    assert_eq!(
                        quantise(v, bits),
                        reference(v, bits),
                        "{v:e} at {bits} bits"
                    );
                }
            }
        }
    }

    #[test]
    fn exp2i_is_powi() {
        for e in -1022..=1022 {
            assert_eq!(exp2i(e), 2f64.powi(e), "2^{e}");
        }
    }

    #[test]
    fn sums_saturate_and_count() {
        let mut a = [i128::MAX - 1, 5];
        let n = add_into(&mut a, &[10, 1]);
        assert_eq!(n, 1);
        assert_eq!(a, [i128::MAX, 6]);
    }
}
