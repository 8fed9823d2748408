//! Which layers a film accumulates and where their channels sit.
//!
//! Every pixel of a pass block (f64) and of the accumulated film state
//! (i128, see [`super::fixed`]) is a row of channels:
//!
//! | group | channels | developed as |
//! |---|---|---|
//! | main | Σw·rgb (3), Σw, Σdirect rgb (3) | Σw·rgb/Σw + Σdirect/passes, sensor RGB → output RGB |
//! | spectral | Σw·L_b, Σw_b, Σdirect L_b per bucket | Σw·L_b/Σw_b + Σdirect L_b/passes |
//! | surface | Σw, then Σw·x for each requested first-hit value | Σw·x/Σw (normals normalised) |
//! | strategies | Σdirect rgb (3) per BDPT strategy | Σ/passes |
//! | variance (state only) | Σv (3), Σv² (3) of per-pass pixel values v | see [`super::state`] |
//!
//! "Weighted" channels hold filtered camera samples (pbrt-v4's
//! `rgbSum`/`weightSum`); "direct" channels hold values that are already
//! estimates of the pixel (light-tracing splats, PPM's per-pass estimates),
//! which the film averages over passes.

/// First-hit values a film can record (pbrt-v4's `VisibleSurface`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SurfaceAov {
    /// Hemispherical reflectance of the first surface, in output RGB.
    Albedo,
    /// Position of the first hit (camera space for `gbuffer`, world space for `--aov position`).
    Position,
    /// Geometric normal.
    Normal,
    /// Shading normal.
    ShadingNormal,
    /// Distance from the lens point to the first hit.
    Depth,
    /// Surface (u, v).
    Uv,
    /// |∂z/∂x|, |∂z/∂y| of camera-space depth per pixel (pbrt-v4's `dzdx`, `dzdy`).
    DepthGradient,
}

impl SurfaceAov {
    /// Channels it needs.
    pub fn width(self) -> usize {
        match self {
            SurfaceAov::Albedo
            | SurfaceAov::Position
            | SurfaceAov::Normal
            | SurfaceAov::ShadingNormal => 3,
            SurfaceAov::Uv | SurfaceAov::DepthGradient => 2,
            SurfaceAov::Depth => 1,
        }
    }
}

/// Spectral buckets of a `spectral` film (pbrt-v4's `SpectralFilm`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Buckets {
    /// Number of buckets.
    pub n: usize,
    /// Lower end of the first bucket (nm).
    pub lambda_min: f32,
    /// Upper end of the last bucket (nm).
    pub lambda_max: f32,
}

impl Buckets {
    /// Bucket of wavelength `lambda`, if inside the range.
    #[inline]
    pub fn bucket(&self, lambda: f32) -> Option<usize> {
        let t = (lambda - self.lambda_min) / (self.lambda_max - self.lambda_min);
        if !(0.0..=1.0).contains(&t) {
            return None;
        }
        Some(((t * self.n as f32) as usize).min(self.n - 1))
    }

    /// Centre wavelength of bucket `i` (nm).
    pub fn centre(&self, i: usize) -> f32 {
        self.lambda_min + (i as f32 + 0.5) / self.n as f32 * (self.lambda_max - self.lambda_min)
    }
}

/// The layers of a film and the channel offsets that follow from them.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct FilmLayout {
    /// Spectral buckets, if the film records spectra.
    pub spectral: Option<Buckets>,
    /// First-hit values recorded, in a fixed order.
    pub surface: Vec<SurfaceAov>,
    /// Per-pixel variance of the pass estimates.
    pub variance: bool,
    /// Number of BDPT strategy layers (`visualizestrategies`/`visualizeweights`).
    pub strategies: usize,
}

/// Offsets of the main channels.
pub const MAIN_WRGB: usize = 0;
/// Offset of the weight sum.
pub const MAIN_W: usize = 3;
/// Offset of the direct sums.
pub const MAIN_DIRECT: usize = 4;
/// Channels of the main group.
const MAIN: usize = 7;

impl FilmLayout {
    /// Number of spectral buckets (0 without a spectral layer).
    pub fn n_buckets(&self) -> usize {
        self.spectral.map_or(0, |b| b.n)
    }
    /// Offset of the spectral group.
    pub fn spectral_offset(&self) -> usize {
        MAIN
    }
    /// Offset of the surface group (its weight first).
    pub fn surface_offset(&self) -> usize {
        MAIN + 3 * self.n_buckets()
    }
    /// Channels of the surface group, weight included (0 when none is recorded).
    pub fn surface_width(&self) -> usize {
        if self.surface.is_empty() {
            0
        } else {
            1 + self.surface.iter().map(|a| a.width()).sum::<usize>()
        }
    }
    /// Offset of one surface value within the pixel row.
    pub fn surface_channel(&self, aov: SurfaceAov) -> Option<usize> {
        let mut o = self.surface_offset() + 1;
        for &a in &self.surface {
            if a == aov {
                return Some(o);
            }
            o += a.width();
        }
        None
    }
    /// Offset of the strategy group.
    pub fn strategy_offset(&self) -> usize {
        self.surface_offset() + self.surface_width()
    }
    /// Channels of one pass-block pixel.
    pub fn pass_stride(&self) -> usize {
        self.strategy_offset() + 3 * self.strategies
    }
    /// Offset of the variance sums in a state pixel.
    pub fn variance_offset(&self) -> usize {
        self.pass_stride()
    }
    /// Channels of one state pixel.
    pub fn state_stride(&self) -> usize {
        self.pass_stride() + if self.variance { 6 } else { 0 }
    }
    /// Fixed-point fraction bits of state channel `c`.
    pub fn bits(&self, c: usize) -> i32 {
        if self.variance && c >= self.variance_offset() + 3 {
            super::fixed::SQUARE_BITS
        } else {
            super::fixed::VALUE_BITS
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_follow_the_groups() {
        let l = FilmLayout {
            spectral: Some(Buckets {
                n: 4,
                lambda_min: 400.0,
                lambda_max: 800.0,
            }),
            surface: vec![SurfaceAov::Albedo, SurfaceAov::Depth],
            variance: true,
            strategies: 2,
        };
        assert_eq!(l.surface_offset(), 7 + 12);
        assert_eq!(l.surface_channel(SurfaceAov::Albedo), Some(20));
        assert_eq!(l.surface_channel(SurfaceAov::Depth), Some(23));
        assert_eq!(l.surface_channel(SurfaceAov::Uv), None);
        assert_eq!(l.strategy_offset(), 24);
        assert_eq!(l.pass_stride(), 30);
        assert_eq!(l.state_stride(), 36);
        assert_eq!(l.bits(32), super::super::fixed::VALUE_BITS);
        assert_eq!(l.bits(33), super::super::fixed::SQUARE_BITS);
        let b = l.spectral.unwrap();
        assert_eq!(b.bucket(400.0), Some(0));
        assert_eq!(b.bucket(799.9), Some(3));
        assert_eq!(b.bucket(800.0), Some(3));
        assert_eq!(b.bucket(300.0), None);
        assert_eq!(b.centre(0), 450.0);
    }
}
