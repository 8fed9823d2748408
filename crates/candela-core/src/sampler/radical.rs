//! The radical inverse and its digit-permuted form, for the Halton sampler.
//!
//! Φ_b(a) = Σ_k d_k(a) b^(−k−1) with d_k the base-b digits of a, least
//! significant first [Halton 1960]; the permuted form replaces digit k by
//! π_k(d_k) for one permutation π_k per digit position [Faure & Lemieux
//! 2009], over all n digit positions a 32-bit float resolves, so the zero
//! digits above a's highest are permuted too.
//!
//! Two things make it cheap without changing one bit of the result
//! (`permuted_matches_the_digit_by_digit_definition` checks them against the
//! definition):
//! - once a has no digits left, the rest of the sum is a constant of the
//!   dimension and the digit position where a ran out (`tail`), so the loop
//!   stops at a's highest digit, not at n;
//! - a digit is split off by multiplying with ⌈2⁶⁴/b⌉ and keeping the high
//!   64 bits, exact for every a < 2³² [Lemire, Kaser & Kurz 2019, "Faster
//!   remainder by direct computation", Theorem 1 with F = 64, N = 32], which
//!   is every index below 2³² (16 spp on a 128×243 pattern reaches 2¹⁹);
//!   larger indices divide;
//! - the permuted form reads c digits at a time from a table of b^c ≤ 1024
//!   entries per group of c positions ([`DigitTable`]), split off by
//!   ⌈2⁶⁴/b^c⌉ alike: base 2 takes 3 steps for a 24-digit index instead of
//!   24, base 3 3 instead of 15. On killeroo-simple (700², `Sampler
//!   "halton"`, 1 spp, one thread, `valgrind --tool=callgrind`) the
//!   sampler's dimensions were 11.2 % of the render's instructions before
//!   this and the reciprocal of [`to_unit`], 9.9 % after (992 M → 866 M).

use crate::sampling::{hash_u64s, mix_bits, Pcg32, ONE_MINUS_EPSILON};
use std::sync::OnceLock;

/// Dimensions (primes) before the sequence wraps to dimension 2.
pub const PRIME_TABLE_SIZE: usize = 1000;

/// The first [`PRIME_TABLE_SIZE`] primes (the 1000th is 7919).
pub(super) static PRIMES: [u32; PRIME_TABLE_SIZE] = primes();

const fn primes() -> [u32; PRIME_TABLE_SIZE] {
    let mut out = [0u32; PRIME_TABLE_SIZE];
    let (mut n, mut found) = (2u32, 0usize);
    while found < PRIME_TABLE_SIZE {
        let mut d = 2;
        let mut prime = true;
        while d * d <= n {
            if n % d == 0 {
                prime = false;
                break;
            }
            d += 1;
        }
        if prime {
            out[found] = n;
            found += 1;
        }
        n += 1;
    }
    out
}

/// Digit positions a 32-bit float resolves in base `b` (pbrt-v4's count:
/// until (b − 1)·b^−n no longer changes 1 − ·).
pub(super) const fn digits(b: u32) -> u32 {
    let inv = 1.0 / b as f32;
    let (mut n, mut inv_m) = (0, 1.0f32);
    while 1.0 - (b - 1) as f32 * inv_m < 1.0 {
        n += 1;
        inv_m *= inv;
    }
    n
}

/// Division of indices below 2³² by a constant d as a multiplication by
/// ⌈2⁶⁴/d⌉ (module docs); larger indices divide.
#[derive(Clone, Copy, Debug)]
struct Divisor {
    d: u64,
    magic: u64,
}

impl Divisor {
    const fn new(d: u64) -> Self {
        Divisor {
            d,
            magic: u64::MAX / d + 1,
        }
    }

    /// (a / d, a mod d).
    #[inline]
    fn split(&self, a: u64) -> (u64, u64) {
        let q = if a >> 32 == 0 {
            ((u128::from(self.magic) * u128::from(a)) >> 64) as u64
        } else {
            a / self.d
        };
        (q, a - q * self.d)
    }
}

/// A prime base, its digit count ([`digits`]), b^−n (b^n is exact in f64,
/// below 2⁵³) and its [`Divisor`].
#[derive(Clone, Copy, Debug)]
pub(super) struct Base {
    pub b: u64,
    pub n: u32,
    pub inv_scale: f64,
    div: Divisor,
}

impl Base {
    /// Base `b` over `n` digit positions.
    const fn new(b: u64, n: u32) -> Self {
        let (mut scale, mut i) = (1.0f64, 0);
        while i < n {
            scale *= b as f64;
            i += 1;
        }
        Base {
            b,
            n,
            inv_scale: 1.0 / scale,
            div: Divisor::new(b),
        }
    }

    /// (a / b, a mod b): the lowest base-b digit of `a` and what is left.
    #[inline]
    fn split(&self, a: u64) -> (u64, u64) {
        self.div.split(a)
    }
}

/// The bases of all dimensions, made at compile time (a static, not a
/// lazily made table: no initialisation check on every sample).
static BASES: [Base; PRIME_TABLE_SIZE] = {
    let mut out = [Base::new(2, 1); PRIME_TABLE_SIZE];
    let mut i = 0;
    while i < PRIME_TABLE_SIZE {
        out[i] = Base::new(PRIMES[i] as u64, digits(PRIMES[i]));
        i += 1;
    }
    out
};

/// The bases of all dimensions.
#[inline]
pub(super) fn bases() -> &'static [Base] {
    &BASES
}

/// `v · inv_scale` as a sample in [0, 1). `v` below 2⁶³ (always for the
/// permuted digits, below 2⁵³) converts as a signed integer: one
/// instruction, where the unsigned conversion takes a dozen without
/// AVX-512. A product, not a quotient by b^n: the division's latency was
/// the sampler's largest single cost (`perf annotate` on killeroo-simple);
/// the two differ by at most an ulp of the f64 before rounding to f32.
pub(super) fn to_unit(v: u64, inv_scale: f64) -> f32 {
    let v = if v >> 63 == 0 {
        v as i64 as f64
    } else {
        v as f64
    };
    ((v * inv_scale) as f32).min(ONE_MINUS_EPSILON)
}

/// The radical inverse of `a` in base `b`, unrandomised.
pub(super) fn radical_inverse(b: u32, mut a: u64) -> f32 {
    let b = u64::from(b);
    let (mut reversed, mut scale) = (0u64, 1.0f64);
    while a != 0 {
        let q = a / b;
        reversed = reversed * b + (a - q * b);
        a = q;
        scale *= b as f64;
    }
    to_unit(reversed, 1.0 / scale)
}

/// The digits of `a` in `base`, least significant first, each handed to
/// `f`, over all `base.n` positions (zeros above a's highest digit), by
/// [`Base::split`].
pub(super) fn for_each_digit(base: &Base, mut a: u64, mut f: impl FnMut(u64)) {
    for _ in 0..base.n {
        let (q, v) = base.split(a);
        a = q;
        f(v);
    }
}

/// A uniformly random permutation of `0..n` (Fisher–Yates from a PCG32
/// stream seeded by `h`).
fn shuffled(n: u32, h: u64) -> Vec<u16> {
    let mut rng = Pcg32::new(h, mix_bits(h));
    let mut p: Vec<u16> = (0..n as u16).collect();
    for i in (1..n as usize).rev() {
        let j = (rng.uniform_f64() * (i + 1) as f64) as usize;
        p.swap(i, j.min(i));
    }
    p
}

/// Digit positions are looked up together while b^c stays within this many
/// table entries (module docs).
const CHUNK_ENTRIES: u64 = 1024;

/// One dimension's digit permutations: position k's image of digit v at
/// `perm[k·b + v]`, and `tail[k]`, the permuted zeros of positions k..n
/// read as the low n − k digits of the reversed number, with `pow[j]` = b^j.
///
/// [`DigitTable::reversed`] reads `c` positions at once (b^c ≤
/// [`CHUNK_ENTRIES`]): `chunks[g·b^c + v]` is positions gc..gc+c−1 of the
/// reversed number for their digits v (least significant first), so a
/// 24-digit base-2 index takes 3 lookups, not 24; the last group, of
/// fewer positions where c does not divide n, ignores the digits of v
/// above n.
#[derive(Debug)]
pub(super) struct DigitTable {
    /// Read only by the tests' digit-by-digit definition.
    #[cfg(test)]
    perm: Box<[u16]>,
    tail: Box<[u64]>,
    pow: Box<[u64]>,
    /// Positions per lookup.
    c: usize,
    /// b^c, to split c digits off an index.
    chunk: Divisor,
    chunks: Box<[u16]>,
}

impl DigitTable {
    /// Uniformly random permutations, position k's seeded by `hash(k)`.
    pub fn new(base: &Base, hash: impl Fn(u32) -> u64) -> Self {
        let (b, n) = (base.b, base.n as usize);
        let perm: Box<[u16]> = (0..base.n)
            .flat_map(|k| shuffled(b as u32, hash(k)))
            .collect();
        let pow: Box<[u64]> = std::iter::successors(Some(1u64), |p| Some(p * b))
            .take(n + 1)
            .collect();
        let mut tail = vec![0u64; n + 1];
        for k in (0..n).rev() {
            // Position k's zero comes first, then positions k+1.. below it.
            tail[k] = u64::from(perm[k * b as usize]) * pow[n - 1 - k] + tail[k + 1];
        }
        let c = (1..=n)
            .take_while(|&c| pow[c] <= CHUNK_ENTRIES)
            .last()
            .unwrap_or(1);
        let entries = pow[c] as usize;
        let mut chunks = Vec::with_capacity(n.div_ceil(c) * entries);
        for k0 in (0..n).step_by(c) {
            for v in 0..entries as u64 {
                let mut digits = v;
                let mut r = 0u64;
                for k in k0..(k0 + c).min(n) {
                    r = r * b + u64::from(perm[k * b as usize + (digits % b) as usize]);
                    digits /= b;
                }
                chunks.push(r as u16);
            }
        }
        Self {
            #[cfg(test)]
            perm,
            tail: tail.into(),
            chunk: Divisor::new(pow[c]),
            pow,
            c,
            chunks: chunks.into(),
        }
    }

    /// The permuted radical inverse of `a` as an integer over b^n.
    #[inline]
    pub fn reversed(&self, base: &Base, mut a: u64) -> u64 {
        let n = base.n as usize;
        let entries = self.chunk.d as usize;
        let (mut reversed, mut k, mut g) = (0u64, 0usize, 0usize);
        while a != 0 && k < n {
            let (q, v) = self.chunk.split(a);
            let w = self.c.min(n - k);
            reversed = reversed * self.pow[w] + u64::from(self.chunks[g * entries + v as usize]);
            a = q;
            k += w;
            g += 1;
        }
        reversed * self.pow[n - k] + self.tail[k]
    }
}

/// The digit-permuted Halton sequence over all [`PRIME_TABLE_SIZE`]
/// dimensions for one seed: position k of dimension d permuted by a
/// uniformly random permutation seeded by (base, k, seed), made on first
/// use and shared by every thread.
#[derive(Debug)]
pub(super) struct ScrambledHalton {
    seed: u64,
    tables: Vec<OnceLock<DigitTable>>,
}

impl ScrambledHalton {
    /// The sequence of `seed`.
    pub(super) fn new(seed: u64) -> Self {
        Self {
            seed,
            tables: (0..PRIME_TABLE_SIZE).map(|_| OnceLock::new()).collect(),
        }
    }

    /// Dimension `d`'s permutations.
    pub(super) fn table(&self, d: usize) -> &DigitTable {
        self.tables[d].get_or_init(|| {
            let base = &bases()[d];
            DigitTable::new(base, |k| hash_u64s(&[base.b, u64::from(k), self.seed]))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    /// [`DigitTable::reversed`] against the definition (every position's
    /// digit by division, then permuted), for small, large (> 2³², where the
    /// split divides) and boundary indices in many bases; and the split by
    /// multiplication against division for every base at its worst 32-bit
    /// numerators.
    #[test]
    fn permuted_matches_the_digit_by_digit_definition() {
        let mut rng = Pcg32::new(3, 7);
        for d in (0..PRIME_TABLE_SIZE).step_by(7).chain([0, 1, 2, 3, 999]) {
            let base = &bases()[d];
            let table = DigitTable::new(base, |k| u64::from(k) * 31 + d as u64);
            let mut indices = vec![
                0u64,
                1,
                base.b - 1,
                base.b,
                u64::from(u32::MAX),
                1 << 32,
                u64::MAX,
            ];
            indices.extend((0..200).map(|_| u64::from(rng.next_u32()) >> (rng.next_u32() % 32)));
            indices.extend(
                (0..50).map(|_| (u64::from(rng.next_u32()) << 32) | u64::from(rng.next_u32())),
            );
            for a in indices {
                let (mut rest, mut want) = (a, 0u64);
                for k in 0..base.n as usize {
                    let v = rest % base.b;
                    rest /= base.b;
                    want = want * base.b + u64::from(table.perm[k * base.b as usize + v as usize]);
                }
                assert_eq!(table.reversed(base, a), want, "base {} index {a}", base.b);
            }
            for a in [
                u64::from(u32::MAX),
                u64::from(u32::MAX) - 1,
                (1 << 32) - base.b,
            ] {
                assert_eq!(
                    base.split(a),
                    (a / base.b, a % base.b),
                    "base {} a {a}",
                    base.b
                );
                let d = table.chunk.d;
                for a in [a, (1 << 32) - d, (1 << 32) - d - 1] {
                    assert_eq!(table.chunk.split(a), (a / d, a % d), "b^c {d} a {a}");
                }
            }
        }
    }
}
