//! A pass's splats summed by horizontal bands of the film, in parallel and
//! in a fixed order.
//!
//! Estimators that splat record their splats tile by tile. The film's rows
//! are cut into bands of equal height, each a [`SplatBuffer`] of its own;
//! every tile's records are sorted out by the bands whose rows the filter
//! reaches from them ([`BandRows::split`], on the thread that rendered the
//! tile), and every band replays its share of each tile in tile order (the
//! bands in parallel). So every pixel receives its splats in tile order,
//! whatever the thread count, and a pass's buffers together cover the film
//! once.

use super::tile::{SplatBuffer, SplatRecord};
use super::{Film, PassBlock};
use crate::math::UVec2;
use rayon::prelude::*;

/// The rows of the bands: what [`BandRows::split`] needs.
#[derive(Clone, Copy, Debug)]
pub struct BandRows {
    /// First row of the pixel bounds.
    lo_y: u32,
    /// Rows per band (the last may have fewer).
    step: u32,
    /// Number of bands.
    n: usize,
    /// The filter's radius in y.
    radius_y: f32,
}

impl BandRows {
    /// `n` bands (fewer when the film has fewer rows) of `film`.
    pub fn new(film: &Film, n: usize) -> Self {
        let (lo, hi) = film.pixel_bounds();
        Self::over(lo.y, hi.y, film.filter().radius().y, n)
    }

    /// `n` bands (fewer when there are fewer rows) of rows `lo_y..hi_y`
    /// for a filter of radius `radius_y`.
    fn over(lo_y: u32, hi_y: u32, radius_y: f32, n: usize) -> Self {
        let rows = hi_y.saturating_sub(lo_y).max(1);
        let step = rows.div_ceil(n.max(1) as u32);
        Self {
            lo_y,
            step,
            n: rows.div_ceil(step) as usize,
            radius_y,
        }
    }

    /// Pixels `lo..hi` of band `b` of the film's pixel bounds `bounds`.
    fn band(&self, b: usize, (lo, hi): (UVec2, UVec2)) -> (UVec2, UVec2) {
        let y0 = lo.y + b as u32 * self.step;
        (
            UVec2::new(lo.x, y0),
            UVec2::new(hi.x, (y0 + self.step).min(hi.y)),
        )
    }

    /// Sorts `records` out by band, keeping their order: a record goes to
    /// every band holding a row whose pixel centres its filter reaches (to
    /// none when those rows are off the film; to every band if its position
    /// is not finite); one with a non-finite value goes to the first band
    /// alone, which drops and counts it ([`SplatBuffer::add`]).
    pub fn split(&self, records: &[SplatRecord]) -> Vec<Vec<SplatRecord>> {
        let mut out: Vec<Vec<SplatRecord>> = vec![Vec::new(); self.n];
        if self.n == 1 {
            out[0] = records.to_vec();
            return out;
        }
        let last = (self.n - 1) as f32;
        for &r in records {
            let p = r.position();
            if r.is_dropped() {
                out[0].push(r);
                continue;
            }
            // Rows y with |p.y − (y + ½)| ≤ r, as band indices.
            let band = |y: f32| ((y - self.lo_y as f32) / self.step as f32).floor();
            let (b0, b1) = if p.y.is_finite() {
                (
                    band((p.y - 0.5 - self.radius_y).ceil()).max(0.0),
                    band((p.y - 0.5 + self.radius_y).floor()).min(last),
                )
            } else {
                (0.0, last)
            };
            if b0 <= b1 {
                for band in &mut out[b0 as usize..=b1 as usize] {
                    band.push(r);
                }
            }
        }
        out
    }
}

/// A pass's splats by band: the rows, and the band buffers once a splat
/// comes (estimators that never splat allocate nothing).
pub struct PassSplats {
    rows: BandRows,
    bands: Option<SplatBands>,
}

impl PassSplats {
    /// No splats yet, over `n` bands of `film`.
    pub fn new(film: &Film, n: usize) -> Self {
        Self {
            rows: BandRows::new(film, n),
            bands: None,
        }
    }

    /// The bands' rows, to split records by ([`BandRows::split`]).
    pub fn rows(&self) -> &BandRows {
        &self.rows
    }

    /// Adds tasks' records, each task's split by band, in the order of `tasks`.
    pub fn add<'a>(
        &mut self,
        film: &Film,
        tasks: impl Iterator<Item = &'a [Vec<SplatRecord>]> + Clone + Send + Sync,
    ) {
        if tasks
            .clone()
            .all(|split| split.iter().all(|r| r.is_empty()))
        {
            return;
        }
        let rows = &self.rows;
        self.bands
            .get_or_insert_with(|| SplatBands::new(film, rows))
            .replay(tasks);
    }

    /// Adds the sums to `block`'s direct channels.
    pub fn add_to(&self, block: &mut PassBlock) {
        for buf in self.bands.iter().flat_map(|b| b.buffers()) {
            block.add_splats(buf);
        }
    }
}

/// The band buffers of a pass.
pub struct SplatBands {
    buffers: Vec<SplatBuffer>,
}

impl SplatBands {
    /// Empty buffers over the bands of `rows`.
    pub fn new(film: &Film, rows: &BandRows) -> Self {
        let buffers = (0..rows.n)
            .map(|b| {
                let (lo, hi) = rows.band(b, film.pixel_bounds());
                film.splat_buffer_over(lo, hi)
            })
            .collect();
        Self { buffers }
    }

    /// Adds the tiles' records, each tile's already split by band
    /// ([`BandRows::split`]), in the order of `tiles`.
    pub fn replay<'a>(
        &mut self,
        tiles: impl Iterator<Item = &'a [Vec<SplatRecord>]> + Clone + Send + Sync,
    ) {
        self.buffers
            .par_iter_mut()
            .enumerate()
            .for_each(|(b, buf)| {
                for split in tiles.clone() {
                    buf.replay(&split[b]);
                }
            });
    }

    /// The band buffers, top to bottom.
    pub fn buffers(&self) -> &[SplatBuffer] {
        &self.buffers
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::filter::Filter;
    use crate::film::tile::Encoder;
    use crate::math::Vec2;
    use crate::spectrum::{PixelSensor, SampledSpectrum, SampledWavelengths};

    fn buffer((lo, hi): (UVec2, UVec2), filter: &Filter) -> SplatBuffer {
        let enc = Encoder {
            sensor: PixelSensor::cie1931(1.0),
            max_component_value: f32::INFINITY,
            buckets: None,
            luminance: false,
        };
        SplatBuffer::new(lo, hi, filter.clone(), enc)
    }

    /// Splats split by band and replayed band by band sum to the bits of
    /// one buffer over the whole film replaying them all, non-finite ones
    /// dropped and counted once; records whose filter crosses a band edge,
    /// or lies off the film, included. Seen to fail with the band index
    /// rounded up instead of down.
    #[test]
    fn bands_sum_to_the_bits_of_one_buffer() {
        let film = (UVec2::new(3, 2), UVec2::new(21, 25));
        let mut u = 0.291f32;
        let mut next = || {
            u = (u * 89.77 + 0.313).fract();
            u
        };
        let records: Vec<SplatRecord> = (0..3000)
            .map(|i| {
                // Off the film by up to 3 pixels on every side.
                let p = Vec2::new(24.0 * next(), 29.0 * next());
                let lambda = SampledWavelengths::sample_visible(next());
                let v = if i % 211 == 0 {
                    f32::INFINITY
                } else {
                    10f32.powi(i % 12 - 6) * next()
                };
                SplatRecord::new(
                    p,
                    SampledSpectrum::from_fn(|k| v * (k as f32 + next())),
                    lambda,
                )
            })
            .collect();
        for (filter, n) in [
            (Filter::default(), 8),
            (Filter::default(), 3),
            (
                Filter::Box {
                    radius: Vec2::splat(2.5),
                },
                5,
            ),
        ] {
            let mut whole = buffer(film, &filter);
            whole.replay(&records);
            let rows = BandRows::over(film.0.y, film.1.y, filter.radius().y, n);
            let mut bands: Vec<SplatBuffer> = (0..rows.n)
                .map(|b| buffer(rows.band(b, film), &filter))
                .collect();
            // Two "tiles" of records, split on their own.
            let (a, b) = records.split_at(1234);
            for part in [a, b] {
                for (buf, share) in bands.iter_mut().zip(rows.split(part)) {
                    buf.replay(&share);
                }
            }
            let joined: Vec<u64> = bands
                .iter()
                .flat_map(|b| b.sums.iter().map(|v| v.to_bits()))
                .collect();
            let whole_bits: Vec<u64> = whole.sums.iter().map(|v| v.to_bits()).collect();
            assert_eq!(rows.n, n);
            assert!(whole.sums.iter().filter(|&&v| v > 0.0).count() > whole.sums.len() / 2);
            assert_eq!(joined, whole_bits, "{n} bands");
            assert_eq!(bands.iter().map(|b| b.dropped).sum::<u64>(), whole.dropped);
            assert_eq!(whole.dropped, 15);
        }
    }
}
