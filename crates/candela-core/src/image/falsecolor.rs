//! False-colour pictures of photometric layers (luminance in cd/m²,
//! illuminance in lx) with a legend, so values can be read off the image,
//! as with Radiance's `falsecolor`.
//!
//! **Mapping.** A value v goes to t ∈ [0, 1]: linearly, t = v/max, or
//! logarithmically over [`LOG_DECADES`] decades below max,
//! t = 1 + log₁₀(v/max)/[`LOG_DECADES`]; t is clipped to [0, 1] (values
//! at or below the bottom of the scale, and 0, are black; above max, the
//! top colour). The colour map runs black → blue → magenta → red →
//! orange → yellow → near-white through fixed control points, linearly
//! between them, and its luma (Rec. 709 weights) rises strictly with t, so
//! brighter always reads brighter, also in grey print.
//!
//! **Default maximum.** The smallest "nice" number 1, 2 or 5 × 10^k at or
//! above the 99th percentile of the positive values: a few very bright
//! pixels (a luminaire seen directly) do not squeeze the rest of the scale.
//!
//! **Legend.** Right of the image: the unit on top, a vertical colour bar
//! (max at the top) and its values at ticks, every decade on a log scale
//! and every fifth of the range on a linear one, in the hand-made font of
//! [`super::font`].

use super::font;
use super::ImageError;
use std::path::Path;

/// Decades below the maximum that a log scale shows.
pub const LOG_DECADES: i32 = 3;

/// How values map to colours.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FalseColorScale {
    /// t = 1 + log₁₀(v/max)/[`LOG_DECADES`].
    Log,
    /// t = v/max.
    Linear,
}

impl std::str::FromStr for FalseColorScale {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "log" => Ok(Self::Log),
            "linear" => Ok(Self::Linear),
            _ => Err(format!("expected log or linear, found {s:?}")),
        }
    }
}

/// Control points (t, sRGB) of the colour map.
const MAP: [(f64, [f64; 3]); 8] = [
    (0.0, [0.0, 0.0, 0.0]),
    (0.15, [30.0, 10.0, 110.0]),
    (0.3, [110.0, 20.0, 150.0]),
    (0.45, [190.0, 40.0, 110.0]),
    (0.6, [235.0, 80.0, 40.0]),
    (0.75, [250.0, 150.0, 20.0]),
    (0.9, [250.0, 220.0, 60.0]),
    (1.0, [255.0, 255.0, 220.0]),
];

/// The colour of t (clipped to [0, 1]) before rounding to 8 bits.
fn colour_exact(t: f64) -> [f64; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let k = MAP
        .iter()
        .rposition(|(a, _)| *a <= t)
        .unwrap_or(0)
        .min(MAP.len() - 2);
    let ((a, ca), (b, cb)) = (MAP[k], MAP[k + 1]);
    let s = (t - a) / (b - a);
    [0, 1, 2].map(|c| ca[c] + s * (cb[c] - ca[c]))
}

/// The colour of t (clipped to [0, 1]).
pub fn colour(t: f64) -> [u8; 3] {
    colour_exact(t).map(|c| c.round() as u8)
}

/// Where `v` sits on the scale ending at `max` (> 0).
pub fn position(v: f64, scale: FalseColorScale, max: f64) -> f64 {
    if v.is_nan() || v <= 0.0 {
        return 0.0;
    }
    let t = match scale {
        FalseColorScale::Linear => v / max,
        FalseColorScale::Log => 1.0 + (v / max).log10() / LOG_DECADES as f64,
    };
    t.clamp(0.0, 1.0)
}

/// The smallest of 1, 2, 5 × 10^k that is ≥ `v` (`v` > 0 and finite; else 1).
pub fn nice_ceil(v: f64) -> f64 {
    if !(v > 0.0 && v.is_finite()) {
        return 1.0;
    }
    let p = 10f64.powf(v.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|c| *c >= v * (1.0 - 1e-12))
        .unwrap_or(10.0 * p)
}

/// The default maximum: [`nice_ceil`] of the 99th percentile of the
/// positive finite values (1 if there are none).
pub fn auto_max(values: &[f32]) -> f64 {
    let mut v: Vec<f32> = values
        .iter()
        .copied()
        .filter(|x| x.is_finite() && *x > 0.0)
        .collect();
    if v.is_empty() {
        return 1.0;
    }
    let k = ((v.len() - 1) as f64 * 0.99).round() as usize;
    let (_, p, _) = v.select_nth_unstable_by(k, f32::total_cmp);
    nice_ceil(*p as f64)
}

/// `v` with 3 significant digits, plainly for 0.01 ≤ |v| < 10⁵, else as
/// `1.5e-3`; trailing zeros dropped.
pub fn label(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() {
        return "0".into();
    }
    let trim = |s: String| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    let e = a.log10().floor() as i32;
    if (0.01..1e5).contains(&a) {
        let decimals = (2 - e).max(0) as usize;
        return trim(format!("{v:.decimals$}"));
    }
    let m = v / 10f64.powi(e);
    let (m, e) = if trim(format!("{m:.2}")).trim_start_matches('-') == "10" {
        (m / 10.0, e + 1)
    } else {
        (m, e)
    };
    format!("{}e{e}", trim(format!("{m:.2}")))
}

/// Values and positions of the legend's ticks.
fn ticks(scale: FalseColorScale, max: f64) -> Vec<(f64, f64)> {
    match scale {
        FalseColorScale::Log => (0..=LOG_DECADES)
            .map(|k| (max * 10f64.powi(-k), 1.0 - k as f64 / LOG_DECADES as f64))
            .collect(),
        FalseColorScale::Linear => (0..=5)
            .map(|j| (max * j as f64 / 5.0, j as f64 / 5.0))
            .collect(),
    }
}

/// Font scale of the legend.
const FONT: usize = 2;
/// Margin around the legend's parts.
const MARGIN: usize = 6;
/// Width of the colour bar.
const BAR: usize = 14;
/// Smallest height of the picture (room for the legend).
const MIN_HEIGHT: usize = 150;
/// Legend background and text colours.
const BACKGROUND: [u8; 3] = [40, 40, 40];
const TEXT: [u8; 3] = [255, 255, 255];

/// An 8-bit RGB picture.
#[derive(Clone, Debug, PartialEq)]
pub struct Picture {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// RGB bytes, row-major, top row first.
    pub rgb: Vec<u8>,
}

impl Picture {
    fn put(&mut self, x: usize, y: usize, c: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = 3 * (y * self.width + x);
            self.rgb[i..i + 3].copy_from_slice(&c);
        }
    }
    /// The colour at (x, y).
    pub fn get(&self, x: usize, y: usize) -> [u8; 3] {
        let i = 3 * (y * self.width + x);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }
}

/// Width of the legend for the labels of `scale` up to `max` and `unit`.
pub fn legend_width(unit: &str, scale: FalseColorScale, max: f64) -> usize {
    let labels = ticks(scale, max)
        .iter()
        .map(|(v, _)| font::text_width(&label(*v), FONT))
        .max()
        .unwrap_or(0);
    let body = BAR + MARGIN + labels;
    MARGIN + body.max(font::text_width(unit, FONT)) + MARGIN
}

/// The false-colour picture of `values` (`width × height`, row-major, top
/// row first) with its legend in `unit` at the right.
pub fn render(
    values: &[f32],
    width: usize,
    height: usize,
    unit: &str,
    scale: FalseColorScale,
    max: f64,
) -> Picture {
    let lw = legend_width(unit, scale, max);
    let mut pic = Picture {
        width: width + lw,
        height: height.max(MIN_HEIGHT),
        rgb: Vec::new(),
    };
    pic.rgb = BACKGROUND
        .iter()
        .copied()
        .cycle()
        .take(3 * pic.width * pic.height)
        .collect();
    for y in 0..height {
        for x in 0..width {
            let v = values.get(y * width + x).copied().unwrap_or(0.0);
            pic.put(x, y, colour(position(v as f64, scale, max)));
        }
    }
    let th = font::text_height(FONT);
    let x0 = width + MARGIN;
    font::draw(unit, x0, MARGIN, FONT, &mut |x, y| pic.put(x, y, TEXT));
    let (top, bottom) = (
        MARGIN + th + MARGIN + th / 2,
        pic.height - MARGIN - th / 2 - 1,
    );
    for y in top..=bottom {
        let t = (bottom - y) as f64 / (bottom - top) as f64;
        for x in x0..x0 + BAR {
            pic.put(x, y, colour(t));
        }
    }
    for (v, t) in ticks(scale, max) {
        let y = bottom - (t * (bottom - top) as f64).round() as usize;
        for x in x0 + BAR..x0 + BAR + MARGIN / 2 {
            pic.put(x, y, TEXT);
        }
        let ly = y.saturating_sub(th / 2);
        font::draw(&label(v), x0 + BAR + MARGIN, ly, FONT, &mut |x, y| {
            pic.put(x, y, TEXT)
        });
    }
    pic
}

/// Writes [`render`]'s picture as a PNG at `path`, atomically.
pub fn write_png(pic: &Picture, path: &Path) -> Result<(), ImageError> {
    super::write_rgb8_png(path, &pic.rgb, pic.width, pic.height)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn luma(c: [u8; 3]) -> f64 {
        luma_f(c.map(|v| v as f64))
    }
    fn luma_f(c: [f64; 3]) -> f64 {
        0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
    }

    #[test]
    fn the_colour_map_is_monotone_in_luma() {
        let mut last = -1.0;
        for i in 0..=10_000 {
            let l = luma_f(colour_exact(i as f64 / 10_000.0));
            assert!(l > last, "luma falls at t = {}", i as f64 / 10_000.0);
            last = l;
        }
        // Strictly at the resolution of the legend bar.
        for i in 0..100 {
            let (a, b) = (colour(i as f64 / 100.0), colour((i + 1) as f64 / 100.0));
            assert!(luma(b) > luma(a), "flat at {i}");
        }
        assert_eq!(colour(-1.0), [0, 0, 0]);
        assert_eq!(colour(f64::NAN), [0, 0, 0]);
        assert_eq!(colour(2.0), colour(1.0));
    }

    #[test]
    fn positions_follow_the_scale() {
        use FalseColorScale::*;
        assert_eq!(position(50.0, Linear, 100.0), 0.5);
        assert!((position(10.0, Log, 1000.0) - 1.0 / 3.0).abs() < 1e-12);
        assert_eq!(position(0.0, Log, 1.0), 0.0);
        assert_eq!(position(1e-9, Log, 1.0), 0.0);
        assert_eq!(position(5.0, Log, 1.0), 1.0);
        assert_eq!(position(f64::NAN, Linear, 1.0), 0.0);
        assert_eq!("log".parse::<FalseColorScale>(), Ok(Log));
        assert!("cubic".parse::<FalseColorScale>().is_err());
    }

    #[test]
    fn nice_maxima_sit_above_the_99th_percentile() {
        assert_eq!(nice_ceil(130.2), 200.0);
        assert_eq!(nice_ceil(500.0), 500.0);
        assert_eq!(nice_ceil(0.0031), 0.005);
        assert_eq!(nice_ceil(7.0), 10.0);
        assert_eq!(nice_ceil(0.0), 1.0);
        // 1000 values 1..=1000 and one huge outlier: the outlier is ignored.
        let mut v: Vec<f32> = (1..=1000).map(|i| i as f32).collect();
        v.push(1e9);
        assert_eq!(auto_max(&v), 1000.0);
        assert_eq!(auto_max(&[0.0, f32::NAN]), 1.0);
    }

    #[test]
    fn labels_are_short_and_drawable() {
        let cases = [
            (500.0, "500"),
            (0.05, "0.05"),
            (0.4, "0.4"),
            (12.5, "12.5"),
            (20000.0, "20000"),
            (0.0, "0"),
            (2e5, "2e5"),
            (1.5e-3, "1.5e-3"),
            (9.999e5, "1e6"),
        ];
        for (v, want) in cases {
            assert_eq!(label(v), want);
            assert!(font::can_draw(&label(v)));
        }
    }

    #[test]
    fn the_picture_has_an_image_and_a_legend() {
        let (w, h) = (40, 30);
        let values: Vec<f32> = (0..w * h).map(|i| (i % w) as f32 * 10.0).collect();
        let pic = render(&values, w, h, "cd/m²", FalseColorScale::Linear, 400.0);
        assert_eq!(pic.height, MIN_HEIGHT);
        assert_eq!(
            pic.width,
            w + legend_width("cd/m²", FalseColorScale::Linear, 400.0)
        );
        // The image ramps left to right.
        assert!(luma(pic.get(w - 1, 0)) > luma(pic.get(1, 0)));
        // The legend holds text, a bar and background.
        let legend: Vec<[u8; 3]> = (0..pic.height)
            .flat_map(|y| (w..pic.width).map(move |x| (x, y)))
            .map(|(x, y)| pic.get(x, y))
            .collect();
        assert!(legend.contains(&TEXT) && legend.contains(&BACKGROUND));
        assert!(legend.contains(&colour(1.0)) && legend.contains(&colour(0.0)));
    }
}
