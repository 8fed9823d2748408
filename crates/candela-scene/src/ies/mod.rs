//! IES LM-63 photometric files (1986, 1991, 1995, 2002 and 2019 syntax).
//!
//! A lighting engineer describes a luminaire by its luminous intensity
//! distribution: candela values measured on a web of vertical and horizontal
//! angles. This module reads such a file into a plain [`IesFile`]; turning
//! the web into a light is the core's business.
//!
//! **Layout** [LM-63-2002 §5, as reproduced in AGi32's "IESNA LM-63 Format";
//! Radiance `src/cv/ies2rad.c`, "Overview of the LM-63 file format"]:
//!
//! 1. a version line `IESNA:LM-63-1995`, `IESNA:LM-63-2002`, `IES:LM-63-2019`
//!    or `IESNA91`; 1986 files have none (their first line is a label);
//! 2. label lines: `[KEYWORD] text` (from 1991 on; `[MORE] text` continues
//!    the previous keyword), free text in 1986 files;
//! 3. `TILT=NONE`, `TILT=INCLUDE` or `TILT=<file>`; with `INCLUDE`, the
//!    lamp-to-luminaire geometry, a count n, n angles and n multipliers;
//! 4. `<# lamps> <lumens/lamp> <candela multiplier> <# vertical angles>
//!    <# horizontal angles> <photometric type> <units type> <width>
//!    <length> <height>`, then `<ballast factor> <ballast-lamp factor>
//!    <input watts>`;
//! 5. the vertical angles, the horizontal angles, and the candela values,
//!    all vertical angles of the first horizontal angle first.
//!
//! Everything after the `TILT=` line is a stream of numbers separated by any
//! whitespace or commas: the standard's records are lines, but values may be
//! broken across lines anywhere, so we read tokens and ignore line breaks.
//! Lines may end in CR LF or LF.
//!
//! **Scaling.** Stored candela values are the file's values × the candela
//! multiplier × the ballast factor, and × the ballast-lamp photometric factor
//! for 1986 and 1991 files only: LM-63-1995 and -2002 call that field
//! "future use" (always 1) and LM-63-2019 puts the file-generation type there,
//! so we keep it raw and do not apply it, as ies2rad does. `lumens/lamp` = −1
//! means absolute photometry (`lumens_per_lamp` is `None`).
//!
//! **Angles** (in degrees, strictly increasing). Vertical angles: type C in
//! [0°, 180°] (0° = nadir), types A and B in [−90°, 90°]; a range other than
//! the standard's (0–90, 0–180 or 90–180 for C, −90–90 or 0–90 for A/B) is
//! read with a warning, and the intensity is zero outside it. Horizontal
//! angles give the lateral [`Symmetry`]: for type C the first and last are
//! 0 (one plane: rotational symmetry), 0–90 (quadrants), 0–180 (bilateral
//! about the 0–180° plane), 90–270 (bilateral about the 90–270° plane,
//! LM-63-2019) or 0–360 (none); for types A and B, 0–90 (symmetric about
//! 0°) or −90–90 (none) [LM-63-2002 §5.11; Autodesk's "IES Standard File
//! Format"]. Other ranges are errors.
//!
//! **Tilt.** `TILT=INCLUDE` is read and kept ([`IesTilt::Include`]) with
//! [`IesTilt::factor`] to interpolate it; applying it needs the luminaire's
//! tilt in the scene, which is the caller's. `TILT=<file>` (a separate tilt
//! file, dropped by LM-63-2019) is reported as unsupported.
//!
//! **Errors and warnings.** Every malformed value is an error naming
//! `file:line:col`: a truncated file, counts that are negative, zero or not
//! integers, angles out of range or not increasing, negative or non-finite
//! intensities, an empty `TILT=`, a missing `TILT=` line, invalid UTF-8 in
//! the label lines. Anything but whitespace after the last candela value is
//! an **error**: it means the counts do not describe the data. The luminous
//! opening (width, length, height; negative values encode round shapes in
//! LM-63-2002) is kept as given; the core treats the luminaire as a point.

mod header;
mod numbers;

use std::path::Path;

use crate::error::{Loc, SceneError, Warning};
use header::{read_header, TiltKind};
use numbers::{read_photometry, read_tilt, Tokens};

type Result<T> = std::result::Result<T, SceneError>;

/// Syntax version of an LM-63 file, from its first line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum IesVersion {
    /// LM-63-1986: no version line.
    Lm1986,
    /// LM-63-1991: `IESNA91`.
    Lm1991,
    /// `IESNA:LM-63-1995`.
    Lm1995,
    /// `IESNA:LM-63-2002`.
    Lm2002,
    /// `IES:LM-63-2019`.
    Lm2019,
}

/// Goniometer coordinate system [LM-63-2002 §3; IESNA LM-75].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhotometricType {
    /// Type C (1): vertical polar axis, vertical angle 0 at nadir.
    C,
    /// Type B (2): horizontal polar axis (floodlights).
    B,
    /// Type A (3): polar axis perpendicular to type B's (automotive).
    A,
}

/// Units of the luminous-opening dimensions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IesUnits {
    /// Units type 1.
    Feet,
    /// Units type 2.
    Meters,
}

/// Lateral symmetry encoded by the range of the horizontal angles.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Symmetry {
    /// Type C, a single plane at 0°: the same in every direction around the axis.
    Axial,
    /// Type C, 0–90°: symmetric about the 0–180° and 90–270° planes.
    Quadrant,
    /// Type C 0–180°, or types A/B 0–90°: I(−h) = I(h).
    Bilateral,
    /// Type C 90–270°: symmetric about the 90–270° plane, I(180° − h) = I(h).
    Bilateral90,
    /// Type C 0–360°, or types A/B −90–90°: no symmetry.
    Asymmetric,
}

impl Symmetry {
    /// The symmetry that horizontal angles `h` encode for photometric type
    /// `ty`, or `None` for a range the standard does not allow.
    pub fn of(ty: PhotometricType, h: &[f64]) -> Option<Symmetry> {
        let (&first, &last) = (h.first()?, h.last()?);
        match ty {
            PhotometricType::C => match (first, last) {
                (0.0, 0.0) if h.len() == 1 => Some(Symmetry::Axial),
                (0.0, 90.0) => Some(Symmetry::Quadrant),
                (0.0, 180.0) => Some(Symmetry::Bilateral),
                (90.0, 270.0) => Some(Symmetry::Bilateral90),
                (0.0, 360.0) => Some(Symmetry::Asymmetric),
                _ => None,
            },
            PhotometricType::A | PhotometricType::B => match (first, last) {
                (0.0, 90.0) => Some(Symmetry::Bilateral),
                (-90.0, 90.0) => Some(Symmetry::Asymmetric),
                _ => None,
            },
        }
    }
}

/// One `[KEYWORD] value` label line, `[MORE]` lines joined with `\n`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IesKeyword {
    /// The text between the brackets, e.g. `MANUFAC`.
    pub name: String,
    /// The rest of the line (and of its `[MORE]` lines), trimmed.
    pub value: String,
}

/// The tilt section.
#[derive(Debug, Clone, PartialEq)]
pub enum IesTilt {
    /// `TILT=NONE`: output does not depend on the luminaire's tilt.
    None,
    /// `TILT=INCLUDE`: multipliers of the candela values by tilt angle.
    Include {
        /// Lamp-to-luminaire geometry: 1 vertical, 2 horizontal along the
        /// 0° plane, 3 horizontal along the 90° plane.
        geometry: u8,
        /// Tilt angles in degrees, increasing.
        angles: Vec<f64>,
        /// Multiplier at each angle.
        factors: Vec<f64>,
    },
}

impl IesTilt {
    /// The multiplier at tilt `angle_deg`, linear between the tabulated
    /// angles and clamped to the end values; 1 for `TILT=NONE`.
    pub fn factor(&self, angle_deg: f64) -> f64 {
        let IesTilt::Include {
            angles, factors, ..
        } = self
        else {
            return 1.0;
        };
        let i = angles.partition_point(|&a| a <= angle_deg);
        match (i.checked_sub(1), angles.get(i)) {
            (None, _) => factors.first().copied().unwrap_or(1.0),
            (Some(k), None) => factors.get(k).copied().unwrap_or(1.0),
            (Some(k), Some(&a1)) => {
                let a0 = angles[k];
                let t = (angle_deg - a0) / (a1 - a0);
                factors[k] + t * (factors[k + 1] - factors[k])
            }
        }
    }
}

/// A parsed IES LM-63 file.
#[derive(Debug, Clone, PartialEq)]
pub struct IesFile {
    /// Syntax version.
    pub version: IesVersion,
    /// `[KEYWORD]` label lines, in file order.
    pub keywords: Vec<IesKeyword>,
    /// Label lines that are not keywords (all of them in 1986 files).
    pub label_lines: Vec<String>,
    /// The tilt section.
    pub tilt: IesTilt,
    /// Number of lamps.
    pub lamp_count: u32,
    /// Rated lumens per lamp; `None` for absolute photometry (−1 in the file).
    pub lumens_per_lamp: Option<f64>,
    /// Candela multiplier (already applied to `candela`).
    pub candela_multiplier: f64,
    /// Goniometer type.
    pub photometric_type: PhotometricType,
    /// Units of `opening`.
    pub units: IesUnits,
    /// Luminous opening width, length and height, in `units`, as given.
    pub opening: [f64; 3],
    /// Ballast factor (already applied to `candela`).
    pub ballast_factor: f64,
    /// The field after the ballast factor, raw: the ballast-lamp photometric
    /// factor in 1986/1991 files (then applied to `candela`), "future use"
    /// in 1995/2002, the file-generation type in 2019 (not applied).
    pub ballast_lamp_factor: f64,
    /// Input watts.
    pub input_watts: f64,
    /// Vertical angles in degrees, strictly increasing.
    pub vertical_angles: Vec<f64>,
    /// Horizontal angles in degrees, strictly increasing.
    pub horizontal_angles: Vec<f64>,
    /// Candela values after the multipliers, `candela[h * nv + v]`.
    pub candela: Vec<f64>,
    /// Non-fatal problems found while reading.
    pub warnings: Vec<Warning>,
}

impl IesFile {
    /// Candela value at horizontal index `h`, vertical index `v`.
    pub fn value(&self, h: usize, v: usize) -> f64 {
        self.candela[h * self.vertical_angles.len() + v]
    }

    /// The lateral symmetry of the horizontal angles (always `Some` for a
    /// parsed file).
    pub fn symmetry(&self) -> Option<Symmetry> {
        Symmetry::of(self.photometric_type, &self.horizontal_angles)
    }

    /// Total rated lamp lumens (lamps × lumens per lamp); `None` for
    /// absolute photometry.
    pub fn lamp_lumens(&self) -> Option<f64> {
        self.lumens_per_lamp.map(|l| l * self.lamp_count as f64)
    }

    /// Luminous-opening width, length and height in metres.
    pub fn opening_meters(&self) -> [f64; 3] {
        let k = match self.units {
            IesUnits::Feet => 0.3048,
            IesUnits::Meters => 1.0,
        };
        self.opening.map(|d| d * k)
    }
}

/// Reads the IES file at `path` (a regular file of at most
/// [`crate::input::MAX_SPECTRUM_FILE_BYTES`]: photometric files are a few kB).
pub fn read_ies(path: &Path) -> Result<IesFile> {
    let bytes = crate::input::read_file(
        path,
        &Loc::file_only(path),
        crate::input::MAX_SPECTRUM_FILE_BYTES,
    )?;
    parse_ies(&bytes, path)
}

/// Parses IES `bytes`; `path` names the file in errors and warnings.
pub fn parse_ies(bytes: &[u8], path: &Path) -> Result<IesFile> {
    let file: std::sync::Arc<Path> = path.into();
    let at = |line: u32, col: u32| Loc {
        file: file.clone(),
        line,
        col,
    };
    let header = read_header(bytes, &at)?;
    let mut warnings = header.warnings;
    let mut toks = Tokens::new(bytes, header.data_start, header.data_line, &at);
    let tilt = match header.tilt {
        TiltKind::None => IesTilt::None,
        TiltKind::Include => read_tilt(&mut toks)?,
    };
    let p = read_photometry(&mut toks, header.version, &mut warnings)?;
    if let Some(t) = toks.peek() {
        return Err(SceneError::at(
            &at(t.line, t.col),
            format!(
                "unexpected '{}' after the last of the {} candela values (do the counts match the data?)",
                t.text(),
                p.candela.len()
            ),
        ));
    }
    Ok(IesFile {
        version: header.version,
        keywords: header.keywords,
        label_lines: header.label_lines,
        tilt,
        lamp_count: p.lamp_count,
        lumens_per_lamp: p.lumens_per_lamp,
        candela_multiplier: p.multiplier,
        photometric_type: p.ty,
        units: p.units,
        opening: p.opening,
        ballast_factor: p.ballast_factor,
        ballast_lamp_factor: p.ballast_lamp_factor,
        input_watts: p.input_watts,
        vertical_angles: p.vertical,
        horizontal_angles: p.horizontal,
        candela: p.candela,
        warnings,
    })
}
