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

/// round(v·2^bits), clamped to ±[`LIMIT`]; non-finite values give 0 (the
/// film drops and counts them before they get here).
#[inline]
pub fn quantise(v: f64, bits: i32) -> i128 {
    if !v.is_finite() {
        return 0;
    }
    let s = (v * exp2i(bits)).round();
    s.clamp(-LIMIT, LIMIT) as i128
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
