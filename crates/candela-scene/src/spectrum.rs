//! Spectrum-valued parameters.
//!
//! pbrt-v4 accepts a spectrum as an `rgb` triple, a `blackbody` temperature,
//! or a `spectrum` parameter that is either inline (λ, value) pairs, the
//! name of a built-in spectrum (`"stdillum-D65"`, `"metal-Cu-eta"`,
//! `"glass-BK7"`...) or the name of a `.spd` file of whitespace-separated
//! pairs with `#` comments. Files are read while parsing, relative to the
//! main scene file's directory, so renderers only see [`SpectrumValue`]s.

use std::path::Path;

use crate::error::{Loc, SceneError};

/// A non-RGB spectrum as written in the scene.
#[derive(Debug, Clone, PartialEq)]
pub enum SpectrumValue {
    /// A built-in spectrum named by pbrt-v4 (validated by the renderer).
    Named(String),
    /// Piecewise-linear samples: (wavelength in nm, value), in file order.
    Sampled(Vec<(f32, f32)>),
    /// A normalized blackbody emitter at this temperature in kelvin.
    Blackbody(f32),
}

/// What [`ParamSet::get_spectrum`](crate::ParamSet::get_spectrum) returns.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamSpectrum {
    /// An RGB triple, to be interpreted in the entity's color space.
    Rgb([f32; 3]),
    /// A spectral value.
    Value(SpectrumValue),
}

/// Turns a flat list of numbers into (λ, value) pairs.
pub(crate) fn pairs(values: &[f32], loc: &Loc, what: &str) -> Result<Vec<(f32, f32)>, SceneError> {
    if values.is_empty() || values.len() % 2 == 1 {
        return Err(SceneError::at(
            loc,
            format!(
                "{what}: expected an even, non-zero number of values (wavelength/value pairs), found {}",
                values.len()
            ),
        ));
    }
    Ok(values.chunks_exact(2).map(|c| (c[0], c[1])).collect())
}

/// Resolves the string form of a `spectrum` parameter: an existing file is
/// read as `.spd`; a name ending in `.spd` that does not exist is an error;
/// anything else is taken as a built-in spectrum name.
pub(crate) fn from_string(
    s: &str,
    base_dir: &Path,
    loc: &Loc,
) -> Result<SpectrumValue, SceneError> {
    let path = crate::param::resolve_path(base_dir, s);
    if path.is_file() {
        return read_spd(&path, loc).map(SpectrumValue::Sampled);
    }
    if s.ends_with(".spd") || s.ends_with(".txt") || s.contains('/') {
        let err = std::io::Error::new(std::io::ErrorKind::NotFound, "spectrum file not found");
        return Err(SceneError::io(loc, &path, err));
    }
    Ok(SpectrumValue::Named(s.to_string()))
}

/// Reads a `.spd` file: whitespace-separated (λ, value) pairs, `#` comments.
pub(crate) fn read_spd(path: &Path, loc: &Loc) -> Result<Vec<(f32, f32)>, SceneError> {
    let bytes = crate::input::read_file(path, loc, crate::input::MAX_SPECTRUM_FILE_BYTES)?;
    let text = String::from_utf8_lossy(&bytes);
    let mut values = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("");
        for word in content.split_whitespace() {
            let v = word.parse::<f32>().map_err(|_| {
                let at = Loc {
                    file: path.into(),
                    line: u32::try_from(i + 1).unwrap_or(u32::MAX),
                    col: 1,
                };
                SceneError::at(
                    &at,
                    format!("expected a number in spectrum file, found '{word}'"),
                )
            })?;
            values.push(v);
        }
    }
    pairs(&values, &Loc::file_only(path), "spectrum file")
}
