//! One pass's contribution to the film, before it is quantised.
//!
//! A pass writes filtered camera samples tile by tile ([`FilmTile`]) and
//! direct values into splat buffers ([`SplatBuffer`]); the block gathers them
//! over the film's pixel bounds in f64. Tiles cover disjoint pixels, and the
//! caller adds splat buffers in a fixed order, so a block is a pure function
//! of the pass index whatever the thread count. The film state then adds the
//! block in fixed point ([`super::state::FilmState::add_pass`]).

use super::layout::FilmLayout;
use super::tile::{FilmTile, SplatBuffer};
use crate::math::UVec2;

/// The f64 sums of one pass over the pixel bounds (rows of `layout.pass_stride()`).
pub struct PassBlock {
    pub(crate) lo: UVec2,
    pub(crate) hi: UVec2,
    pub(crate) stride: usize,
    pub(crate) rows: Vec<f64>,
    pub(crate) layout: FilmLayout,
    /// Non-finite samples dropped in this pass.
    pub(crate) dropped: u64,
}

impl PassBlock {
    pub(crate) fn new(lo: UVec2, hi: UVec2, layout: &FilmLayout) -> Self {
        let stride = layout.pass_stride();
        let n = ((hi.x - lo.x) * (hi.y - lo.y)) as usize;
        Self {
            lo,
            hi,
            stride,
            rows: vec![0.0; n * stride],
            layout: layout.clone(),
            dropped: 0,
        }
    }

    /// Clears the block for the next pass (keeps its allocation).
    pub fn clear(&mut self) {
        self.rows.iter_mut().for_each(|v| *v = 0.0);
        self.dropped = 0;
    }

    /// Pixels in the block.
    pub fn pixel_count(&self) -> usize {
        self.rows.len() / self.stride
    }

    /// Non-finite samples dropped in this pass.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    #[inline]
    fn index(&self, x: u32, y: u32) -> usize {
        ((y - self.lo.y) * (self.hi.x - self.lo.x) + (x - self.lo.x)) as usize
    }

    /// Adds a finished tile (tiles of one pass cover disjoint pixels).
    pub fn add_tile(&mut self, tile: &FilmTile) {
        let w = (tile.hi.x - tile.lo.x) as usize;
        debug_assert_eq!(tile.stride, self.stride);
        for y in tile.lo.y..tile.hi.y {
            let src0 = (y - tile.lo.y) as usize * w * self.stride;
            let dst0 = self.index(tile.lo.x, y) * self.stride;
            let n = w * self.stride;
            for (d, s) in self.rows[dst0..dst0 + n]
                .iter_mut()
                .zip(&tile.rows[src0..src0 + n])
            {
                *d += s;
            }
        }
        self.dropped += tile.dropped;
    }

    /// Block pixel indices of the pixels `lo..hi` (within the block), row by row.
    fn pixels_of(&self, lo: UVec2, hi: UVec2) -> impl Iterator<Item = usize> {
        debug_assert!(lo.cmpge(self.lo).all() && hi.cmple(self.hi).all());
        let (origin, width) = (self.lo, (self.hi.x - self.lo.x) as usize);
        (lo.y..hi.y).flat_map(move |y| {
            let i0 = (y - origin.y) as usize * width + (lo.x - origin.x) as usize;
            i0..i0 + (hi.x - lo.x) as usize
        })
    }

    /// Adds a splat buffer (over the block's pixels or a part of them) to
    /// the direct channels of the main (spectral, photometric) layers.
    pub fn add_splats(&mut self, buf: &SplatBuffer) {
        let nb = self.layout.n_buckets();
        let (direct, spectral) = (
            super::layout::MAIN_DIRECT,
            self.layout.spectral_direct_offset(),
        );
        let luminance = buf.luminance.filter(|_| self.layout.photometric);
        let dy = self.layout.photometric_offset() + super::layout::photo::DY;
        for (j, i) in self.pixels_of(buf.lo, buf.hi).enumerate() {
            let (row, src) = (i * self.stride, j * buf.stride);
            for k in 0..3 {
                self.rows[row + direct + k] += buf.sums[src + k];
            }
            for k in 0..nb.min(buf.stride - 3) {
                self.rows[row + spectral + k] += buf.sums[src + 3 + k];
            }
            if let Some(o) = luminance {
                self.rows[row + dy] += buf.sums[src + o];
            }
        }
        self.dropped += buf.dropped;
    }

    /// Adds a splat buffer to BDPT strategy layer `k`.
    pub fn add_strategy(&mut self, k: usize, buf: &SplatBuffer) {
        let o = self.layout.strategy_offset() + 3 * k;
        for i in 0..self.pixel_count() {
            let (row, src) = (i * self.stride, i * buf.stride);
            for c in 0..3 {
                self.rows[row + o + c] += buf.sums[src + c];
            }
        }
    }
}
