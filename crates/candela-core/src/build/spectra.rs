//! Spectrum-valued parameters: RGB (lifted by kind), blackbody, named and
//! sampled spectra, with pbrt-v4's meaning of each.

use super::BuildError;
use crate::spectrum::{named_spectrum, ColorSpace, Rgb, Spectrum};
use candela_scene::{ParamSet, ParamSpectrum, SpectrumValue};

pub use crate::spectrum::SpectrumKind;

/// Reads spectrum parameter `name` of `params`, if present.
pub fn spectrum_param(
    params: &ParamSet,
    name: &str,
    kind: SpectrumKind,
    cs: &'static ColorSpace,
) -> Result<Option<Spectrum>, BuildError> {
    let Some(v) = params.get_spectrum(name)? else {
        return Ok(None);
    };
    let loc = params
        .param_loc(name)
        .cloned()
        .unwrap_or_else(|| candela_scene::Loc::file_only(std::path::Path::new("<parameter>")));
    let s = match v {
        ParamSpectrum::Rgb(rgb) => {
            if rgb.iter().any(|c| *c < 0.0 || !c.is_finite()) {
                return Err(BuildError::at(
                    &loc,
                    format!(
                        "\"{name}\": RGB values must be finite and non-negative, found {} {} {}",
                        rgb[0], rgb[1], rgb[2]
                    ),
                ));
            }
            let rgb = Rgb::new(rgb[0], rgb[1], rgb[2]);
            match kind {
                SpectrumKind::Albedo => {
                    if rgb.r > 1.0 || rgb.g > 1.0 || rgb.b > 1.0 {
                        return Err(BuildError::at(
                            &loc,
                            format!(
                                "\"{name}\": a reflectance RGB must be at most 1 in each channel, found {} {} {}",
                                rgb.r, rgb.g, rgb.b
                            ),
                        ));
                    }
                    Spectrum::rgb_albedo(cs, rgb)
                }
                SpectrumKind::Unbounded => Spectrum::rgb_unbounded(cs, rgb),
                SpectrumKind::Illuminant => Spectrum::rgb_illuminant(cs, rgb),
            }
        }
        ParamSpectrum::Value(SpectrumValue::Blackbody(t)) => {
            if t.is_nan() || t <= 0.0 {
                return Err(BuildError::at(
                    &loc,
                    format!("\"{name}\": blackbody temperature must be positive, found {t}"),
                ));
            }
            Spectrum::blackbody(t)
        }
        ParamSpectrum::Value(SpectrumValue::Named(n)) => named_spectrum(&n).ok_or_else(|| {
            BuildError::at(&loc, format!("\"{name}\": unknown named spectrum \"{n}\""))
        })?,
        ParamSpectrum::Value(SpectrumValue::Sampled(pairs)) => {
            if pairs.is_empty() || pairs.windows(2).any(|w| w[1].0 <= w[0].0) {
                return Err(BuildError::at(
                    &loc,
                    format!("\"{name}\": sampled spectrum needs increasing wavelengths"),
                ));
            }
            Spectrum::piecewise_linear(&pairs)
        }
    };
    Ok(Some(s))
}
