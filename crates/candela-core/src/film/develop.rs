//! Developing an accumulated film state into named image channels.
//!
//! The main layer is Σw·rgb/Σw + Σdirect/n in sensor RGB (n passes; pbrt-v4's
//! `rgbSum/weightSum + splatScale·splat` with splat scale 1/n), mapped to the
//! output colour space. Channel names follow the film kind: pbrt-v4's `rgb`
//! (R, G, B), `gbuffer` (`Albedo.R`, `P.X`, `dzdx`, `N.X`, `Ns.X`, `u`, `v`,
//! `Variance.R`, `RelativeVariance.R`) and `spectral` (`S0.<λ>nm`, λ the
//! bucket centre with ',' for '.'), or candela's `--aov` layers (`albedo.R`,
//! `position.X`, `normal.X`, `shading_normal.X`, `depth.Z`, `uv.U`,
//! `variance.R`).
//!
//! Variance: with v_p the pass estimates of a pixel (output RGB), the sample
//! variance is s² = (Σv² − (Σv)²/n)/(n − 1). `gbuffer`'s `Variance` is s²
//! (pbrt-v4's per-sample variance, here per pass) and `RelativeVariance`
//! s²/v̄²; candela's `variance` layer is s²/n, the variance of the pixel's
//! estimate itself.
//!
//! Photometric films (`--units photometric`) have no R, G, B: their main
//! layers are `luminance.Y` [cd/m²] (Σw·Y_v/Σw + Σdirect Y_v/n, see
//! [`super::layout`]) and `illuminance.Y` \[lx\] (Σw_E·E_v/Σw_E), each with
//! its standard error `luminance_stderr.Y`, `illuminance_stderr.Y` =
//! √(s²/n) from the per-pass values (0 before 2 passes). The units are in
//! [`Developed::units`], per layer, for the EXR header.

use super::layout::{SurfaceAov, MAIN_DIRECT, MAIN_W, MAIN_WRGB};
use super::{Film, FilmKind, FilmState};
use crate::image::RgbImage;

/// One named image channel.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Channel name as written to EXR (layer prefix included).
    pub name: String,
    /// Row-major values over the pixel bounds.
    pub data: Vec<f32>,
}

/// A developed film.
#[derive(Clone, Debug, PartialEq)]
pub struct Developed {
    /// Width of the pixel bounds.
    pub width: usize,
    /// Height of the pixel bounds.
    pub height: usize,
    /// Passes accumulated.
    pub passes: u64,
    /// R, G, B first, then every other layer's channels.
    pub channels: Vec<Channel>,
    /// BDPT strategy images in output RGB (empty unless the film records strategies).
    pub strategies: Vec<RgbImage>,
    /// (layer, unit) of the layers in physical units (photometric films).
    pub units: Vec<(String, &'static str)>,
}

impl Developed {
    /// The main layer as an RGB image (black without R, G, B channels, as
    /// for photometric films).
    pub fn rgb(&self) -> RgbImage {
        let mut img = RgbImage::new(self.width, self.height);
        let planes = ["R", "G", "B"].map(|n| self.channel(n));
        for (i, p) in img.pixels.iter_mut().enumerate() {
            *p = planes.map(|c| c.map_or(0.0, |d| d[i]));
        }
        img
    }

    /// The samples of the channel named `name`.
    pub fn channel(&self, name: &str) -> Option<&[f32]> {
        let c = self.channels.iter().find(|c| c.name == name)?;
        Some(&c.data)
    }
}

/// Unit of the luminance layers.
pub const LUMINANCE_UNIT: &str = "cd/m^2";
/// Unit of the illuminance layers.
pub const ILLUMINANCE_UNIT: &str = "lx";

/// Develops `state`; `overlay`, if given, replaces the main layer's sensor
/// RGB per pixel (SPPM, whose estimate is not a sum over passes).
pub fn develop(film: &Film, state: &FilmState, overlay: Option<&[[f64; 3]]>) -> Developed {
    let (lo, hi) = film.pixel_bounds();
    let (width, height) = ((hi.x - lo.x) as usize, (hi.y - lo.y) as usize);
    let n = state.passes.count();
    let inv_n = if n > 0 { 1.0 / n as f64 } else { 0.0 };
    let m = film.output_from_sensor_f64();
    let mut rgb: Vec<Vec<f32>> = (0..3).map(|_| Vec::with_capacity(state.pixels)).collect();
    for i in 0..state.pixels {
        let sensor = match overlay {
            Some(o) => o[i],
            None => {
                let w = state.value(i, MAIN_W);
                [0, 1, 2].map(|c| {
                    let avg = if w != 0.0 {
                        state.value(i, MAIN_WRGB + c) / w
                    } else {
                        0.0
                    };
                    avg + state.value(i, MAIN_DIRECT + c) * inv_n
                })
            }
        };
        for (r, out) in rgb.iter_mut().enumerate() {
            out.push((0..3).map(|c| m[r][c] * sensor[c]).sum::<f64>() as f32);
        }
    }
    let mut channels: Vec<Channel> = Vec::new();
    let mut units = Vec::new();
    if film.layout().photometric {
        units = photometric_channels(film, state, inv_n, &mut channels);
    } else {
        channels.extend(["R", "G", "B"].iter().zip(rgb).map(|(name, data)| Channel {
            name: name.to_string(),
            data,
        }));
    }
    spectral_channels(film, state, inv_n, &mut channels);
    surface_channels(film, state, &mut channels);
    variance_channels(film, state, &mut channels);
    Developed {
        width,
        height,
        passes: n,
        channels,
        strategies: strategy_images(film, state, width, height, inv_n),
        units,
    }
}

/// Luminance, illuminance and their standard errors; returns their units.
fn photometric_channels(
    film: &Film,
    state: &FilmState,
    inv_n: f64,
    out: &mut Vec<Channel>,
) -> Vec<(String, &'static str)> {
    use super::layout::photo;
    let layout = film.layout();
    let (o, vo) = (
        layout.photometric_offset(),
        layout.photometric_variance_offset(),
    );
    let ratio = |a: f64, w: f64| if w != 0.0 { a / w } else { 0.0 };
    let stderr = |i: usize, k: usize| {
        let n = state.passes.count().max(1) as f64;
        (pass_stats(state, i, vo + 2 * k, vo + 2 * k + 1).1 / n).sqrt()
    };
    out.push(per_pixel(state, "luminance.Y".into(), |i| {
        ratio(state.value(i, o + photo::WY), state.value(i, MAIN_W))
            + state.value(i, o + photo::DY) * inv_n
    }));
    out.push(per_pixel(state, "luminance_stderr.Y".into(), |i| {
        stderr(i, 0)
    }));
    out.push(per_pixel(state, "illuminance.Y".into(), |i| {
        ratio(
            state.value(i, o + photo::WEE),
            state.value(i, o + photo::WE),
        )
    }));
    out.push(per_pixel(state, "illuminance_stderr.Y".into(), |i| {
        stderr(i, 1)
    }));
    [
        ("luminance", LUMINANCE_UNIT),
        ("luminance_stderr", LUMINANCE_UNIT),
        ("illuminance", ILLUMINANCE_UNIT),
        ("illuminance_stderr", ILLUMINANCE_UNIT),
    ]
    .map(|(l, u)| (l.to_string(), u))
    .to_vec()
}

/// Channels computed pixel by pixel from the state.
fn per_pixel(state: &FilmState, name: String, f: impl Fn(usize) -> f64) -> Channel {
    Channel {
        name,
        data: (0..state.pixels).map(|i| f(i) as f32).collect(),
    }
}

fn spectral_channels(film: &Film, state: &FilmState, inv_n: f64, out: &mut Vec<Channel>) {
    let Some(b) = film.layout().spectral else {
        return;
    };
    let o = film.layout().spectral_offset();
    for k in 0..b.n {
        let name = format!("S0.{:.3}nm", b.centre(k))
            .replace('.', ",")
            .replacen(',', ".", 1);
        out.push(per_pixel(state, name, |i| {
            let w = state.value(i, MAIN_W);
            let avg = if w != 0.0 {
                state.value(i, o + k) / w
            } else {
                0.0
            };
            avg + state.value(i, o + b.n + k) * inv_n
        }));
    }
}

/// Channel names of a first-hit value for the film kind.
fn surface_names(aov: SurfaceAov, kind: FilmKind) -> Vec<String> {
    let pbrt = kind == FilmKind::GBuffer;
    let names: &[&str] = match (aov, pbrt) {
        (SurfaceAov::Albedo, true) => &["Albedo.R", "Albedo.G", "Albedo.B"],
        (SurfaceAov::Albedo, false) => &["albedo.R", "albedo.G", "albedo.B"],
        (SurfaceAov::Position, true) => &["P.X", "P.Y", "P.Z"],
        (SurfaceAov::Position, false) => &["position.X", "position.Y", "position.Z"],
        (SurfaceAov::Normal, true) => &["N.X", "N.Y", "N.Z"],
        (SurfaceAov::Normal, false) => &["normal.X", "normal.Y", "normal.Z"],
        (SurfaceAov::ShadingNormal, true) => &["Ns.X", "Ns.Y", "Ns.Z"],
        (SurfaceAov::ShadingNormal, false) => {
            &["shading_normal.X", "shading_normal.Y", "shading_normal.Z"]
        }
        (SurfaceAov::Depth, _) => &["depth.Z"],
        (SurfaceAov::Uv, true) => &["u", "v"],
        (SurfaceAov::Uv, false) => &["uv.U", "uv.V"],
        (SurfaceAov::DepthGradient, _) => &["dzdx", "dzdy"],
    };
    names.iter().map(|s| s.to_string()).collect()
}

fn surface_channels(film: &Film, state: &FilmState, out: &mut Vec<Channel>) {
    let layout = film.layout();
    let wo = layout.surface_offset();
    for &aov in &layout.surface {
        let Some(o) = layout.surface_channel(aov) else {
            continue;
        };
        let normal = matches!(aov, SurfaceAov::Normal | SurfaceAov::ShadingNormal);
        for (k, name) in surface_names(aov, film.kind()).into_iter().enumerate() {
            out.push(per_pixel(state, name, |i| {
                let w = state.value(i, wo);
                if w == 0.0 {
                    return 0.0;
                }
                if normal {
                    let v = [0, 1, 2].map(|c| state.value(i, o + c));
                    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                    return if len > 0.0 { v[k] / len } else { 0.0 };
                }
                let v = state.value(i, o + k) / w;
                if aov == SurfaceAov::DepthGradient {
                    v.abs()
                } else {
                    v
                }
            }));
        }
    }
}

/// (mean, sample variance) of the pass estimates of pixel `i` whose sum
/// and sum of squares are state channels `c1` and `c2`.
fn pass_stats(state: &FilmState, i: usize, c1: usize, c2: usize) -> (f64, f64) {
    let n = state.passes.count() as f64;
    let (s1, s2) = (state.value(i, c1), state.value(i, c2));
    if n < 2.0 {
        return (s1 / n.max(1.0), 0.0);
    }
    let mean = s1 / n;
    (mean, ((s2 - s1 * mean) / (n - 1.0)).max(0.0))
}

fn variance_channels(film: &Film, state: &FilmState, out: &mut Vec<Channel>) {
    if !film.layout().variance {
        return;
    }
    let n = state.passes.count().max(1) as f64;
    let o = film.layout().variance_offset();
    let rgb_stats = |i: usize, c: usize| pass_stats(state, i, o + c, o + 3 + c);
    for (c, ch) in ["R", "G", "B"].iter().enumerate() {
        if film.kind() == FilmKind::GBuffer {
            out.push(per_pixel(state, format!("Variance.{ch}"), |i| {
                rgb_stats(i, c).1
            }));
        } else {
            out.push(per_pixel(state, format!("variance.{ch}"), |i| {
                rgb_stats(i, c).1 / n
            }));
        }
    }
    if film.kind() == FilmKind::GBuffer {
        for (c, ch) in ["R", "G", "B"].iter().enumerate() {
            out.push(per_pixel(state, format!("RelativeVariance.{ch}"), |i| {
                let (mean, var) = rgb_stats(i, c);
                if mean != 0.0 {
                    var / (mean * mean)
                } else {
                    0.0
                }
            }));
        }
    }
}

fn strategy_images(
    film: &Film,
    state: &FilmState,
    width: usize,
    height: usize,
    inv_n: f64,
) -> Vec<RgbImage> {
    let layout = film.layout();
    let m = film.output_from_sensor_f64();
    (0..layout.strategies)
        .map(|k| {
            let o = layout.strategy_offset() + 3 * k;
            let mut img = RgbImage::new(width, height);
            for (i, p) in img.pixels.iter_mut().enumerate() {
                let s = [0, 1, 2].map(|c| state.value(i, o + c) * inv_n);
                *p = [0, 1, 2].map(|r| (0..3).map(|c| m[r][c] * s[c]).sum::<f64>() as f32);
            }
            img
        })
        .collect()
}
