//! Photometric light units: lights given in candela, cd/m², lumens or lux.
//!
//! The photometric quantities follow from the radiometric ones through the
//! CIE 1931 luminous efficiency V(λ) = ȳ(λ) and K_m = 683 lm/W: e.g.
//! Φ_v = K_m ∫ Φ(λ) V(λ) dλ [CIE S 017/E:2011, 17-21-039]. A light's
//! spectrum is normalised to ∫ ȳ s dλ = 1 (pbrt-v4's `SpectrumToPhotometric`,
//! see `light::create`), so after that normalisation `scale = 1` means
//! K_m = 683 cd (or cd/m², lx) and pbrt-v4's `power` Φ means Φ·K_m lumens.
//! A photometric parameter is therefore its value ÷ K_m in pbrt-v4's units,
//! and the spectrum (`I`, `L`) only sets the colour. pbrt-v4 normalises an
//! RGB spectrum by its illuminant alone, which leaves the RGB's relative
//! luminance Y in the emission; with a photometric parameter (and always for
//! an IES file, which is in candela) [`Units::colour_only`] divides it out,
//! so `"rgb L" [0.2 0.5 0.9] "float luminance" 250` emits 250 cd/m², not
//! 250·Y. pbrt-v4's own `power`/`illuminance`/`scale` keep its meaning:
//!
//! | parameter | lights | meaning |
//! |---|---|---|
//! | `candela` | point, spot, goniometric (image), projection | intensity \[cd\]: of a point light; of a spot on its axis; where the goniometric map or projector slide is 1 |
//! | `luminance` | diffuse area, infinite | luminance [cd/m²] of the emitter (of an RGB (1,1,1) texel for images) |
//! | `lumens` | point, spot, goniometric (image or IES), projection, diffuse area | total luminous flux \[lm\]; an area light's flux is shared by its shape's triangles in proportion to their areas |
//! | `lux` | distant, infinite | illuminance \[lx\] on a surface facing a distant light, on an upward patch for an infinite light |
//!
//! Each multiplies with `scale`, as pbrt-v4's `power` does. At most one may
//! be given, and not together with `power` or `illuminance`. Distant and
//! infinite lights have no total flux of their own (it depends on the
//! scene's size), so `lumens` is refused there. An IES file is already in
//! candela, so `candela` is refused for it (use `scale` or `lumens`).
//!
//! For an image infinite light, pbrt-v4's `illuminance` normalisation
//! renders twice the requested value (see `light::create`), which candela
//! keeps for pbrt-v4 files; `lux` is exact (it asks for half as much).

use super::check::{Check, Domain};
use super::BuildError;
use crate::spectrum::{cie_xyz, inner_product, spectrum_to_photometric, Spectrum, K_M};

/// The photometric parameter names.
const NAMES: [&str; 4] = ["candela", "luminance", "lumens", "lux"];

/// Which photometric parameters a light takes, and how each applies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnitsOf {
    /// Point, spot, goniometric image, projection: `candela`, `lumens`.
    Intensity,
    /// Goniometric light from an IES file: `lumens`.
    IesWeb,
    /// Diffuse area light: `luminance`, `lumens`.
    Area,
    /// Distant light: `lux`.
    Distant,
    /// Uniform infinite light: `luminance`, `lux`.
    UniformSky,
    /// Image infinite light: `luminance`, `lux`.
    ImageSky,
}

impl UnitsOf {
    /// The photometric parameters this light accepts.
    fn accepts(self) -> &'static [&'static str] {
        match self {
            UnitsOf::Intensity => &["candela", "lumens"],
            UnitsOf::IesWeb => &["lumens"],
            UnitsOf::Area => &["luminance", "lumens"],
            UnitsOf::Distant => &["lux"],
            UnitsOf::UniformSky | UnitsOf::ImageSky => &["luminance", "lux"],
        }
    }
    /// pbrt-v4's parameter for the same target (`power` or `illuminance`).
    fn pbrt_target(self) -> &'static str {
        match self {
            UnitsOf::Distant | UnitsOf::UniformSky | UnitsOf::ImageSky => "illuminance",
            _ => "power",
        }
    }
}

/// A light's emission scale after its photometric parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Units {
    /// `scale` times the photometric factor.
    pub scale: f32,
    /// pbrt-v4's `power` or `illuminance` (> 0), given or from `lumens`/`lux`.
    pub target: Option<f32>,
    /// True when `target` came from `lumens` (an area light then shares it).
    pub from_lumens: bool,
    /// True when a photometric parameter was given (see [`Units::colour_only`]).
    pub photometric: bool,
}

impl Units {
    /// The units for a light of spectrum `s` when its photometric value must
    /// hold exactly, the spectrum setting only the colour. pbrt-v4's
    /// normalisation divides by the photometric value of an RGB spectrum's
    /// illuminant alone, so an `"rgb L"` of luminance Y (relative to the
    /// illuminant) would emit Y times the requested cd/m²; this divides that
    /// Y out. Other spectra are already exact (factor 1), and without a
    /// photometric parameter pbrt-v4's meaning stays.
    pub fn colour_only(self, s: &Spectrum) -> Units {
        if !self.photometric {
            return self;
        }
        let (full, norm) = (
            inner_product(|l| cie_xyz(l)[1], |l| s.eval(l)),
            spectrum_to_photometric(s),
        );
        if !(full > 0.0 && norm > 0.0) {
            return self;
        }
        let y = full / norm;
        Units {
            scale: self.scale / y,
            ..self
        }
    }
}

/// Reads `scale`, pbrt-v4's target and the photometric parameters of a light.
pub fn units(ck: &Check<'_>, of: UnitsOf) -> Result<Units, BuildError> {
    let scale = ck.float("scale", 1.0, Domain::NonNegative)?;
    let target_name = of.pbrt_target();
    let pbrt = ck.params.get_float(target_name, -1.0)?;
    let pbrt = (pbrt > 0.0).then_some(pbrt);
    let mut given = None;
    for name in NAMES {
        let Some(v) = ck.float_opt(name, Domain::Positive)? else {
            continue;
        };
        if !of.accepts().contains(&name) {
            return Err(ck.error(name, refusal(of, name)));
        }
        if let Some((other, _)) = given {
            return Err(ck.error(name, format!("and \"{other}\" both given: use one")));
        }
        given = Some((name, v));
    }
    let Some((name, v)) = given else {
        return Ok(Units {
            scale,
            target: pbrt,
            from_lumens: false,
            photometric: false,
        });
    };
    if pbrt.is_some() {
        return Err(ck.error(name, format!("and \"{target_name}\" both given: use one")));
    }
    let k = v / K_M;
    Ok(match (name, of) {
        ("lumens", _) => Units {
            scale,
            target: Some(k),
            from_lumens: true,
            photometric: true,
        },
        ("lux", UnitsOf::UniformSky) => Units {
            scale,
            target: Some(k),
            from_lumens: false,
            photometric: true,
        },
        ("lux", UnitsOf::ImageSky) => Units {
            scale,
            target: Some(k / 2.0),
            from_lumens: false,
            photometric: true,
        },
        _ => Units {
            scale: scale * k,
            target: None,
            from_lumens: false,
            photometric: true,
        },
    })
}

/// Why a light refuses photometric parameter `name`.
fn refusal(of: UnitsOf, name: &str) -> String {
    let why = match (of, name) {
        (UnitsOf::Distant | UnitsOf::UniformSky | UnitsOf::ImageSky, "lumens") => {
            "is not defined for a light at infinity (its flux depends on the scene's size)"
        }
        (UnitsOf::IesWeb, "candela") => {
            "is not needed: the IES file gives candela (use \"scale\" or \"lumens\")"
        }
        _ => "does not apply to this light",
    };
    format!("{why}; it takes {}", quoted(of.accepts()))
}

/// `"a", "b"`.
fn quoted(names: &[&str]) -> String {
    let q: Vec<String> = names.iter().map(|n| format!("\"{n}\"")).collect();
    q.join(", ")
}
