//! Which layers a film accumulates and where their channels sit.
//!
//! Every pixel of a pass block (f64) and of the accumulated film state
//! (i128, see [`super::fixed`]) is a row of channels:
//!
//! | group | channels | developed as |
//! |---|---|---|
//! | main | Σw·rgb (3), Σw, Σdirect rgb (3) | Σw·rgb/Σw + Σdirect/passes, sensor RGB → output RGB |
//! | spectral | Σw·L̄_b, then Σdirect L̄_b, per bucket | Σw·L̄_b/Σw + Σdirect L̄_b/passes |
//! | surface | Σw, then Σw·x for each requested first-hit value | Σw·x/Σw (normals normalised) |
//! | strategies | Σdirect rgb (3) per BDPT strategy | Σ/passes |
//! | photometric | Σw·Y_v, Σdirect Y_v, Σw_E, Σw_E·E_v | Σw·Y_v/Σw + Σdirect/passes [cd/m²]; Σw_E·E_v/Σw_E \[lx\] |
//! | variance (state only) | Σv (3), Σv² (3) of per-pass pixel values v | see `super::state` |
//! | photometric variance (state only) | Σv, Σv² of per-pass luminance, then of illuminance | √(s²/n) |
//!
//! "Weighted" channels hold filtered camera samples (pbrt-v4's
//! `rgbSum`/`weightSum`); "direct" channels hold values that are already
//! estimates of the pixel (light-tracing splats, PPM's per-pass estimates),
//! which the film averages over passes.
//!
//! A spectral bucket b of width Δ_b holds, per camera sample, the estimate
//! L̄_b = Σ_i 1_b(λ_i)·L(λ_i)/(p(λ_i)·n·Δ_b) of the radiance averaged over
//! the bucket (n wavelengths λ_i of density p per sample): its expectation
//! is (1/Δ_b)∫_b L dλ whatever the wavelength density, so the buckets share
//! the main layer's weight Σw. (pbrt-v4's `SpectralFilm` samples λ
//! uniformly and averages L per bucket with per-bucket weights; candela's
//! integrators sample the visible-light density, hence the division by p.)
//!
//! The photometric group (`--units photometric`) holds the luminance
//! Y_v = K_m·(1/N) Σ_i ȳ(λ_i)·L(λ_i)/p(λ_i) of each camera sample or splat
//! (weighted like the main layer, sharing its Σw), and the illuminance E_v
//! at the first visible surface of the pass's camera ray with that ray's
//! filter weight w_E (the first-hit pass, [`crate::render::surface`]; rays
//! that escape add w_E and no E_v). Its per-pass variance sums are always
//! kept: every photometric value has its standard error.
//!
//! The surface group's weight Σw counts every camera sample of the
//! first-hit pass, hits or not: a sample that escapes adds zeros, so, as
//! in pbrt-v4's `GBufferFilm`, a pixel half covered by an object reads half
//! its albedo.

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

/// A layer `--aov` can ask for: a first-hit value, or the per-pixel variance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Aov {
    /// A first-hit value.
    Surface(SurfaceAov),
    /// Variance of the pixel estimate (from the spread of the passes).
    Variance,
}

impl Aov {
    /// Every layer with its `--aov` name, in the canonical order.
    pub const ALL: [(&'static str, Aov); 8] = [
        ("albedo", Aov::Surface(SurfaceAov::Albedo)),
        ("position", Aov::Surface(SurfaceAov::Position)),
        ("normal", Aov::Surface(SurfaceAov::Normal)),
        ("shading_normal", Aov::Surface(SurfaceAov::ShadingNormal)),
        ("depth", Aov::Surface(SurfaceAov::Depth)),
        ("uv", Aov::Surface(SurfaceAov::Uv)),
        ("dzdxy", Aov::Surface(SurfaceAov::DepthGradient)),
        ("variance", Aov::Variance),
    ];

    /// The `--aov` name.
    pub fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, a)| *a == self)
            .map_or("?", |(n, _)| n)
    }

    /// Parses a comma-separated list of names into a sorted list without repeats.
    pub fn parse_list(s: &str) -> Result<Vec<Aov>, String> {
        let mut out = Vec::new();
        for t in s.split(',').map(str::trim) {
            let Some((_, a)) = Self::ALL.iter().find(|(n, _)| *n == t) else {
                let names: Vec<&str> = Self::ALL.iter().map(|(n, _)| *n).collect();
                return Err(format!(
                    "unknown layer \"{t}\" (known: {})",
                    names.join(", ")
                ));
            };
            out.push(*a);
        }
        out.sort_unstable();
        out.dedup();
        Ok(out)
    }

    /// The canonical text of a list, as [`Aov::parse_list`] reads it.
    pub fn list_text(list: &[Aov]) -> String {
        let mut v = list.to_vec();
        v.sort_unstable();
        v.dedup();
        v.iter().map(|a| a.name()).collect::<Vec<_>>().join(",")
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

    /// Width of every bucket (nm).
    pub fn width(&self) -> f32 {
        (self.lambda_max - self.lambda_min) / self.n as f32
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
    /// Luminance and illuminance layers with their variance (`--units photometric`).
    pub photometric: bool,
}

/// Offsets within the photometric group.
pub mod photo {
    /// Σw·Y_v of camera samples (weights are the main layer's Σw).
    pub const WY: usize = 0;
    /// Σ Y_v of direct values (splats, per-pass pixel estimates).
    pub const DY: usize = 1;
    /// Σw_E: filter weights of the first-hit rays.
    pub const WE: usize = 2;
    /// Σw_E·E_v.
    pub const WEE: usize = 3;
    /// Channels of the group in a pass block.
    pub const WIDTH: usize = 4;
    /// Channels of its variance sums in the state (Σv, Σv² of Y_v, then of E_v).
    pub const VARIANCE_WIDTH: usize = 4;
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
    /// The same layout also recording `aovs`: first-hit values it lacks are
    /// appended in the canonical order (those it has keep their place).
    pub fn with_aovs(mut self, aovs: &[Aov]) -> Self {
        let mut aovs = aovs.to_vec();
        aovs.sort_unstable();
        for a in aovs {
            match a {
                Aov::Surface(s) if !self.surface.contains(&s) => self.surface.push(s),
                Aov::Surface(_) => {}
                Aov::Variance => self.variance = true,
            }
        }
        self
    }

    /// Number of spectral buckets (0 without a spectral layer).
    pub fn n_buckets(&self) -> usize {
        self.spectral.map_or(0, |b| b.n)
    }
    /// Offset of the spectral group.
    pub fn spectral_offset(&self) -> usize {
        MAIN
    }
    /// Offset of the spectral direct sums.
    pub fn spectral_direct_offset(&self) -> usize {
        MAIN + self.n_buckets()
    }
    /// Offset of the surface group (its weight first).
    pub fn surface_offset(&self) -> usize {
        MAIN + 2 * self.n_buckets()
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
    /// Offset of the photometric group.
    pub fn photometric_offset(&self) -> usize {
        self.strategy_offset() + 3 * self.strategies
    }
    /// Channels of one pass-block pixel.
    pub fn pass_stride(&self) -> usize {
        self.photometric_offset() + if self.photometric { photo::WIDTH } else { 0 }
    }
    /// Offset of the variance sums in a state pixel.
    pub fn variance_offset(&self) -> usize {
        self.pass_stride()
    }
    /// Offset of the photometric variance sums in a state pixel.
    pub fn photometric_variance_offset(&self) -> usize {
        self.variance_offset() + if self.variance { 6 } else { 0 }
    }
    /// Channels of one state pixel.
    pub fn state_stride(&self) -> usize {
        self.photometric_variance_offset()
            + if self.photometric {
                photo::VARIANCE_WIDTH
            } else {
                0
            }
    }
    /// True when the first-hit pass must run (surface values or illuminance).
    pub fn needs_first_hit(&self) -> bool {
        !self.surface.is_empty() || self.photometric
    }
    /// Fixed-point fraction bits of state channel `c`.
    pub fn bits(&self, c: usize) -> i32 {
        let v = self.variance_offset();
        let pv = self.photometric_variance_offset();
        let square = (self.variance && (v + 3..v + 6).contains(&c))
            || (self.photometric && (c == pv + 1 || c == pv + 3));
        if square {
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
            photometric: false,
        };
        assert_eq!(l.spectral_direct_offset(), 7 + 4);
        assert_eq!(l.surface_offset(), 7 + 8);
        assert_eq!(l.surface_channel(SurfaceAov::Albedo), Some(16));
        assert_eq!(l.surface_channel(SurfaceAov::Depth), Some(19));
        assert_eq!(l.surface_channel(SurfaceAov::Uv), None);
        assert_eq!(l.strategy_offset(), 20);
        assert_eq!(l.pass_stride(), 26);
        assert_eq!(l.state_stride(), 32);
        assert_eq!(l.bits(28), super::super::fixed::VALUE_BITS);
        assert_eq!(l.bits(29), super::super::fixed::SQUARE_BITS);
        let p = FilmLayout {
            photometric: true,
            ..l.clone()
        };
        assert_eq!(p.photometric_offset(), 26);
        assert_eq!(p.pass_stride(), 30);
        assert_eq!(p.variance_offset(), 30);
        assert_eq!(p.photometric_variance_offset(), 36);
        assert_eq!(p.state_stride(), 40);
        let bits: Vec<i32> = (30..40).map(|c| p.bits(c)).collect();
        let (v, s) = (
            super::super::fixed::VALUE_BITS,
            super::super::fixed::SQUARE_BITS,
        );
        assert_eq!(bits, [v, v, v, s, s, s, v, s, v, s]);
        assert!(p.needs_first_hit() && !FilmLayout::default().needs_first_hit());
        let b = l.spectral.unwrap();
        assert_eq!(b.bucket(400.0), Some(0));
        assert_eq!(b.bucket(799.9), Some(3));
        assert_eq!(b.bucket(800.0), Some(3));
        assert_eq!(b.bucket(300.0), None);
        assert_eq!(b.centre(0), 450.0);
        assert_eq!(b.width(), 100.0);
    }

    #[test]
    fn aov_lists_parse_into_one_canonical_layout() {
        let a = Aov::parse_list("depth, albedo,variance,depth").unwrap();
        let b = Aov::parse_list("variance,albedo,depth").unwrap();
        let (la, lb) = (
            FilmLayout::default().with_aovs(&a),
            FilmLayout::default().with_aovs(&b),
        );
        assert_eq!(la, lb);
        assert_eq!(la.surface, vec![SurfaceAov::Albedo, SurfaceAov::Depth]);
        assert!(la.variance);
        assert_eq!(Aov::list_text(&a), "albedo,depth,variance");
        assert_eq!(
            Aov::parse_list(&Aov::list_text(&a)).unwrap(),
            Aov::parse_list("albedo,depth,variance").unwrap()
        );
        let e = Aov::parse_list("albedo,colour").unwrap_err();
        assert!(
            e.contains("\"colour\"") && e.contains("shading_normal"),
            "{e}"
        );
        assert!(Aov::parse_list("").is_err());
    }
}
