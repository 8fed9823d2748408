//! The accumulated film: fixed-point sums of every pass added so far
//! ([`super::fixed`]), which passes those are, and per-pass statistics.
//!
//! Because the sums are integers and every pass's block is a pure function
//! of its index, `FilmState`s of disjoint pass sets merge into exactly the
//! state of one run over their union, whatever the split, the order or the
//! thread count.
//!
//! **Per-pass statistics.** For each pass the state keeps the image mean of
//! the pass's own estimate in output RGB, m_p = mean over pixels of
//! v_p = Σw·rgb/Σw + Σdirect (that pass's values only). With the variance
//! layer it also keeps, per pixel, Σv_p and Σv_p² in output RGB. Passes of
//! path, light and bidirectional tracing and of PPM and photon mapping are
//! independent, identically distributed estimates of the image, so
//! s²(m)/n is the variance of the image mean and s²(v)/n that of a pixel.
//! The photometric layers keep Σv_p and Σv_p² of each pixel's per-pass
//! luminance and first-hit illuminance in the same way.

use super::fixed::{add_into, quantise};
use super::layout::{FilmLayout, MAIN_DIRECT, MAIN_W, MAIN_WRGB};
use super::{block::PassBlock, Film};
use rayon::prelude::*;

/// A set of pass indices as sorted, disjoint, non-adjacent half-open ranges.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PassSet(Vec<(u64, u64)>);

impl PassSet {
    /// The set [a, b).
    pub fn range(a: u64, b: u64) -> Self {
        Self(if a < b { vec![(a, b)] } else { Vec::new() })
    }
    /// The ranges.
    pub fn ranges(&self) -> &[(u64, u64)] {
        &self.0
    }
    /// Number of passes.
    pub fn count(&self) -> u64 {
        self.0.iter().map(|(a, b)| b - a).sum()
    }
    /// True if `p` is in the set.
    pub fn contains(&self, p: u64) -> bool {
        self.0.iter().any(|&(a, b)| a <= p && p < b)
    }
    /// True if the sets share a pass.
    pub fn overlaps(&self, other: &PassSet) -> bool {
        self.0
            .iter()
            .any(|&(a, b)| other.0.iter().any(|&(c, d)| a < d && c < b))
    }
    /// Adds pass `p`.
    pub fn insert(&mut self, p: u64) {
        self.union(&PassSet::range(p, p + 1));
    }
    /// Adds every pass of `other`.
    pub fn union(&mut self, other: &PassSet) {
        let mut all: Vec<(u64, u64)> = self.0.iter().chain(&other.0).copied().collect();
        all.sort_unstable();
        let mut out: Vec<(u64, u64)> = Vec::with_capacity(all.len());
        for (a, b) in all {
            match out.last_mut() {
                Some(last) if a <= last.1 => last.1 = last.1.max(b),
                _ => out.push((a, b)),
            }
        }
        self.0 = out;
    }
    /// The passes of [a, b) not in the set, in order.
    pub fn missing_in(&self, a: u64, b: u64) -> impl Iterator<Item = u64> + '_ {
        (a..b).filter(move |&p| !self.contains(p))
    }
}

impl std::fmt::Display for PassSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let parts: Vec<String> = self.0.iter().map(|(a, b)| format!("{a}..{b}")).collect();
        write!(
            f,
            "{}",
            if parts.is_empty() {
                "none".into()
            } else {
                parts.join(", ")
            }
        )
    }
}

/// Why two film states cannot be merged.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MergeError {
    /// Different film layouts or sizes.
    #[error("the partial results are of different films (size or layers differ)")]
    Shape,
    /// The pass sets overlap.
    #[error("pass ranges overlap: {0} and {1}")]
    Overlap(String, String),
}

/// Accumulated sums of a film over a set of passes.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmState {
    pub(crate) layout: FilmLayout,
    pub(crate) pixels: usize,
    pub(crate) sums: Vec<i128>,
    pub(crate) passes: PassSet,
    /// (pass, image mean of that pass in output RGB), sorted by pass.
    pub(crate) pass_means: Vec<(u64, [f64; 3])>,
    pub(crate) dropped: u64,
    pub(crate) saturated: u64,
}

impl FilmState {
    /// An empty state for `film`.
    pub fn new(film: &Film) -> Self {
        let layout = film.layout().clone();
        let pixels = film.pixel_count();
        Self {
            sums: vec![0; pixels * layout.state_stride()],
            layout,
            pixels,
            passes: PassSet::default(),
            pass_means: Vec::new(),
            dropped: 0,
            saturated: 0,
        }
    }

    /// The passes added.
    pub fn passes(&self) -> &PassSet {
        &self.passes
    }
    /// Non-finite samples dropped so far (should stay 0).
    pub fn dropped(&self) -> u64 {
        self.dropped
    }
    /// Fixed-point sums that saturated (exactness lost; never for physical values).
    pub fn saturated(&self) -> u64 {
        self.saturated
    }
    /// Image mean of every pass, in output RGB, sorted by pass.
    pub fn pass_means(&self) -> &[(u64, [f64; 3])] {
        &self.pass_means
    }

    /// Adds the block of pass `pass` (which must not be in the state yet).
    pub fn add_pass(&mut self, film: &Film, pass: u64, block: &PassBlock) {
        debug_assert!(!self.passes.contains(pass));
        let (stride, pstride) = (self.layout.state_stride(), self.layout.pass_stride());
        let layout = &self.layout;
        let m = film.output_from_sensor_f64();
        let saturated: u64 = self
            .sums
            .par_chunks_mut(stride * 1024)
            .zip(block.rows.par_chunks(pstride * 1024))
            .map(|(dst, src)| {
                let mut sat = 0;
                let mut q = vec![0i128; stride];
                let bits: Vec<i32> = (0..pstride).map(|c| layout.bits(c)).collect();
                for (d, s) in dst.chunks_mut(stride).zip(src.chunks(pstride)) {
                    for ((q, &v), &b) in q.iter_mut().zip(s).zip(&bits) {
                        *q = quantise(v, b);
                    }
                    if layout.variance {
                        let v = pass_value(s, &m);
                        let o = layout.variance_offset();
                        for k in 0..3 {
                            q[o + k] = quantise(v[k], layout.bits(o + k));
                            q[o + 3 + k] = quantise(v[k] * v[k], layout.bits(o + 3 + k));
                        }
                    }
                    if layout.photometric {
                        let o = layout.photometric_variance_offset();
                        for (k, v) in photometric_pass_values(s, layout).iter().enumerate() {
                            q[o + 2 * k] = quantise(*v, layout.bits(o + 2 * k));
                            q[o + 2 * k + 1] = quantise(v * v, layout.bits(o + 2 * k + 1));
                        }
                    }
                    sat += add_into(d, &q);
                }
                sat
            })
            .sum();
        let mean = block_mean(block, &m);
        let at = self.pass_means.partition_point(|(p, _)| *p < pass);
        self.pass_means.insert(at, (pass, mean));
        self.passes.insert(pass);
        self.dropped += block.dropped;
        self.saturated += saturated;
    }

    /// Adds the sums of `other`, a state of the same film over disjoint passes.
    pub fn merge(&mut self, other: &FilmState) -> Result<(), MergeError> {
        if other.layout != self.layout || other.pixels != self.pixels {
            return Err(MergeError::Shape);
        }
        if self.passes.overlaps(&other.passes) {
            return Err(MergeError::Overlap(
                self.passes.to_string(),
                other.passes.to_string(),
            ));
        }
        self.saturated += add_into(&mut self.sums, &other.sums);
        self.passes.union(&other.passes);
        self.pass_means.extend_from_slice(&other.pass_means);
        self.pass_means.sort_by_key(|(p, _)| *p);
        self.dropped += other.dropped;
        self.saturated += other.saturated;
        Ok(())
    }

    /// Sum of channel `c` of pixel `i`, as a float.
    #[inline]
    pub(crate) fn value(&self, i: usize, c: usize) -> f64 {
        super::fixed::dequantise(
            self.sums[i * self.layout.state_stride() + c],
            self.layout.bits(c),
        )
    }

    /// The relative standard error of the image mean, per output channel,
    /// from the spread of the per-pass image means (`None` before 2 passes).
    pub fn relative_error(&self) -> Option<[f64; 3]> {
        let n = self.pass_means.len();
        if n < 2 {
            return None;
        }
        Some([0, 1, 2].map(|c| {
            let vals = self.pass_means.iter().map(|(_, m)| m[c]);
            let mean = vals.clone().sum::<f64>() / n as f64;
            let var = vals.map(|v| (v - mean) * (v - mean)).sum::<f64>() / (n - 1) as f64;
            let se = (var / n as f64).sqrt();
            if mean.abs() > 0.0 {
                se / mean.abs()
            } else if se == 0.0 {
                0.0
            } else {
                f64::INFINITY
            }
        }))
    }
}

/// The pass's own estimate of one pixel, in output RGB.
fn pass_value(s: &[f64], m: &[[f64; 3]; 3]) -> [f64; 3] {
    let w = s[MAIN_W];
    let sensor = [0, 1, 2].map(|c| {
        let avg = if w != 0.0 { s[MAIN_WRGB + c] / w } else { 0.0 };
        avg + s[MAIN_DIRECT + c]
    });
    [0, 1, 2].map(|r| (0..3).map(|c| m[r][c] * sensor[c]).sum())
}

/// The pass's own luminance [cd/m²] and first-hit illuminance \[lx\] of one pixel.
fn photometric_pass_values(s: &[f64], layout: &FilmLayout) -> [f64; 2] {
    use super::layout::photo;
    let o = layout.photometric_offset();
    let ratio = |a: f64, w: f64| if w != 0.0 { a / w } else { 0.0 };
    [
        ratio(s[o + photo::WY], s[MAIN_W]) + s[o + photo::DY],
        ratio(s[o + photo::WEE], s[o + photo::WE]),
    ]
}

/// Mean of [`pass_value`] over the block.
fn block_mean(block: &PassBlock, m: &[[f64; 3]; 3]) -> [f64; 3] {
    let n = block.pixel_count().max(1) as f64;
    let sum = block
        .rows
        .chunks(block.stride)
        .map(|s| pass_value(s, m))
        .fold([0.0; 3], |a, v| [a[0] + v[0], a[1] + v[1], a[2] + v[2]]);
    sum.map(|v| v / n)
}

#[cfg(test)]
mod tests {
    use super::PassSet;

    #[test]
    fn pass_sets_merge_ranges() {
        let mut s = PassSet::range(4, 6);
        s.insert(6);
        s.union(&PassSet::range(0, 2));
        assert_eq!(s.ranges(), &[(0, 2), (4, 7)]);
        assert_eq!(s.count(), 5);
        assert!(s.overlaps(&PassSet::range(6, 9)));
        assert!(!s.overlaps(&PassSet::range(2, 4)));
        assert_eq!(s.missing_in(0, 8).collect::<Vec<_>>(), vec![2, 3, 7]);
        assert_eq!(s.to_string(), "0..2, 4..7");
    }
}
