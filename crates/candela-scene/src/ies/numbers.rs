//! The numeric section of an LM-63 file: tilt data, photometric header,
//! angles and candela values, as located tokens.

use super::{IesTilt, IesUnits, IesVersion, PhotometricType, Result, Symmetry};
use crate::error::{Loc, SceneError, Warning};

/// One whitespace- or comma-separated token of the numeric section.
#[derive(Clone, Copy)]
pub(super) struct Tok<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) line: u32,
    pub(super) col: u32,
}

impl Tok<'_> {
    /// The token as text (lossy, for messages).
    pub(super) fn text(&self) -> String {
        String::from_utf8_lossy(self.bytes).into_owned()
    }
}

/// The numeric section as a token stream with locations.
pub(super) struct Tokens<'a, F> {
    toks: Vec<Tok<'a>>,
    next: usize,
    /// Line and column just past the last byte (for "file ends" errors).
    end: (u32, u32),
    at: &'a F,
}

/// Separators: any whitespace, commas, and the DOS end-of-file mark.
fn is_separator(b: u8) -> bool {
    b.is_ascii_whitespace() || b == b',' || b == 0x0B || b == 0x1A
}

impl<'a, F: Fn(u32, u32) -> Loc> Tokens<'a, F> {
    /// Splits `bytes[start..]`, whose first line is `line`.
    pub(super) fn new(bytes: &'a [u8], start: usize, line: u32, at: &'a F) -> Self {
        let (mut line, mut col) = (line, 1u32);
        let mut toks = Vec::new();
        let mut i = start;
        while i < bytes.len() {
            let b = bytes[i];
            if is_separator(b) {
                if b == b'\n' {
                    line += 1;
                    col = 1;
                } else {
                    col += 1;
                }
                i += 1;
                continue;
            }
            let len = bytes[i..]
                .iter()
                .position(|&c| is_separator(c))
                .unwrap_or(bytes.len() - i);
            toks.push(Tok {
                bytes: &bytes[i..i + len],
                line,
                col,
            });
            i += len;
            col += len as u32;
        }
        Tokens {
            toks,
            next: 0,
            end: (line, col),
            at,
        }
    }

    /// The next token, not consumed.
    pub(super) fn peek(&self) -> Option<Tok<'a>> {
        self.toks.get(self.next).copied()
    }

    /// Tokens not yet read.
    fn remaining(&self) -> usize {
        self.toks.len() - self.next
    }

    /// The location of a token.
    fn loc(&self, t: &Tok) -> Loc {
        (self.at)(t.line, t.col)
    }

    /// The error for a file that ends while reading `what`.
    fn truncated(&self, what: &str) -> SceneError {
        SceneError::at(
            &(self.at)(self.end.0, self.end.1),
            format!("file ends before the {what} (truncated file or wrong counts?)"),
        )
    }

    /// The next value as a finite number, with its token.
    fn number(&mut self, what: &str) -> Result<(f64, Tok<'a>)> {
        let t = self.peek().ok_or_else(|| self.truncated(what))?;
        self.next += 1;
        let v: f64 = std::str::from_utf8(t.bytes)
            .ok()
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| {
                SceneError::at(
                    &self.loc(&t),
                    format!("expected a number for the {what}, found '{}'", t.text()),
                )
            })?;
        if !v.is_finite() {
            return Err(SceneError::at(
                &self.loc(&t),
                format!("the {what} is '{}', not a finite number", t.text()),
            ));
        }
        Ok((v, t))
    }

    /// The next value as a number satisfying `ok`, else `need` in the error.
    fn number_where(&mut self, what: &str, need: &str, ok: impl Fn(f64) -> bool) -> Result<f64> {
        let (v, t) = self.number(what)?;
        if !ok(v) {
            return Err(SceneError::at(
                &self.loc(&t),
                format!("the {what} must be {need}, found {}", t.text()),
            ));
        }
        Ok(v)
    }

    /// The next value as an integer in `min..=max` (1986 files may write
    /// integers with a decimal point, so `3.0` is accepted).
    fn integer(&mut self, what: &str, min: i64, max: i64) -> Result<i64> {
        let (v, t) = self.number(what)?;
        if v.fract() != 0.0 {
            return Err(SceneError::at(
                &self.loc(&t),
                format!("the {what} must be an integer, found {}", t.text()),
            ));
        }
        if v < min as f64 || v > max as f64 {
            let range = if max >= u32::MAX as i64 {
                format!("at least {min}")
            } else {
                format!("in {min}..={max}")
            };
            return Err(SceneError::at(
                &self.loc(&t),
                format!("the {what} must be {range}, found {}", t.text()),
            ));
        }
        Ok(v as i64)
    }

    /// `n` strictly increasing angles within `[lo, hi]`.
    fn angles(&mut self, n: usize, what: &str, lo: f64, hi: f64) -> Result<Vec<f64>> {
        let mut out: Vec<f64> = Vec::with_capacity(n.min(self.remaining()));
        for k in 0..n {
            let (a, t) = self.number(&format!("{what} #{}", k + 1))?;
            if a < lo || a > hi {
                return Err(SceneError::at(
                    &self.loc(&t),
                    format!("{what} {} is outside [{lo}, {hi}]", t.text()),
                ));
            }
            if let Some(&prev) = out.last() {
                if a <= prev {
                    return Err(SceneError::at(
                        &self.loc(&t),
                        format!("{what} must increase: {} follows {prev}", t.text()),
                    ));
                }
            }
            out.push(a);
        }
        Ok(out)
    }
}

/// Reads the `TILT=INCLUDE` records.
pub(super) fn read_tilt<F: Fn(u32, u32) -> Loc>(toks: &mut Tokens<F>) -> Result<IesTilt> {
    let geometry = toks.integer("lamp-to-luminaire geometry", 1, 3)? as u8;
    let n = toks.integer("number of tilt angles", 1, i64::MAX)? as usize;
    if n > toks.remaining() {
        return Err(toks.truncated(&format!("{n} tilt angles and factors")));
    }
    let angles = toks.angles(n, "tilt angle", 0.0, 180.0)?;
    let mut factors = Vec::with_capacity(n);
    for k in 0..n {
        let what = format!("tilt multiplier #{}", k + 1);
        factors.push(toks.number_where(&what, "non-negative", |v| v >= 0.0)?);
    }
    Ok(IesTilt::Include {
        geometry,
        angles,
        factors,
    })
}

/// The photometric records, decoded.
pub(super) struct Photometry {
    pub(super) lamp_count: u32,
    pub(super) lumens_per_lamp: Option<f64>,
    pub(super) multiplier: f64,
    pub(super) ty: PhotometricType,
    pub(super) units: IesUnits,
    pub(super) opening: [f64; 3],
    pub(super) ballast_factor: f64,
    pub(super) ballast_lamp_factor: f64,
    pub(super) input_watts: f64,
    pub(super) vertical: Vec<f64>,
    pub(super) horizontal: Vec<f64>,
    pub(super) candela: Vec<f64>,
}

/// Reads the photometric header, the angles and the candela values.
pub(super) fn read_photometry<F: Fn(u32, u32) -> Loc>(
    toks: &mut Tokens<F>,
    version: IesVersion,
    warnings: &mut Vec<Warning>,
) -> Result<Photometry> {
    let lamp_count = toks.integer("number of lamps", 1, u32::MAX as i64)? as u32;
    let lumens = toks.number_where("lumens per lamp", "positive or -1", |v| {
        v > 0.0 || v == -1.0
    })?;
    let multiplier = toks.number_where("candela multiplier", "positive", |v| v > 0.0)?;
    let nv = toks.integer("number of vertical angles", 2, i64::MAX)? as usize;
    let nh_tok = toks.peek();
    let nh = toks.integer("number of horizontal angles", 1, i64::MAX)? as usize;
    let ty = match toks.integer("photometric type", 1, 3)? {
        1 => PhotometricType::C,
        2 => PhotometricType::B,
        _ => PhotometricType::A,
    };
    let units = match toks.integer("units type", 1, 2)? {
        1 => IesUnits::Feet,
        _ => IesUnits::Meters,
    };
    let mut opening = [0.0; 3];
    for (d, what) in opening.iter_mut().zip(["width", "length", "height"]) {
        *d = toks.number(&format!("luminous opening {what}"))?.0;
    }
    let ballast_factor = toks.number_where("ballast factor", "positive", |v| v > 0.0)?;
    let ballast_lamp_factor = if version <= IesVersion::Lm1991 {
        toks.number_where("ballast-lamp photometric factor", "positive", |v| v > 0.0)?
    } else {
        toks.number("ballast-lamp factor (future use / file generation type)")?
            .0
    };
    let input_watts = toks.number("input watts")?.0;
    let scale = multiplier
        * ballast_factor
        * if version <= IesVersion::Lm1991 {
            ballast_lamp_factor
        } else {
            1.0
        };
    let (vertical, horizontal, candela) = read_web(toks, [nv, nh], nh_tok, ty, scale, warnings)?;
    Ok(Photometry {
        lamp_count,
        lumens_per_lamp: (lumens > 0.0).then_some(lumens),
        multiplier,
        ty,
        units,
        opening,
        ballast_factor,
        ballast_lamp_factor,
        input_watts,
        vertical,
        horizontal,
        candela,
    })
}

/// Reads the `nv` vertical angles, `nh` horizontal angles and `nv·nh`
/// candela values (× `scale`) that the counts at `nh_tok` declare.
fn read_web<F: Fn(u32, u32) -> Loc>(
    toks: &mut Tokens<F>,
    [nv, nh]: [usize; 2],
    nh_tok: Option<Tok>,
    ty: PhotometricType,
    scale: f64,
    warnings: &mut Vec<Warning>,
) -> Result<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    let values = nv.checked_mul(nh).and_then(|c| c.checked_add(nv + nh));
    if values.is_none_or(|c| c > toks.remaining()) {
        let t = nh_tok.map_or((0, 0), |t| (t.line, t.col));
        return Err(SceneError::at(
            &(toks.at)(t.0, t.1),
            format!(
                "the counts ({nv} vertical × {nh} horizontal angles) need {} more values, \
                 but the file has {} (truncated file or wrong counts?)",
                values.map_or("too many".into(), |c| c.to_string()),
                toks.remaining()
            ),
        ));
    }
    let (vlo, vhi) = match ty {
        PhotometricType::C => (0.0, 180.0),
        _ => (-90.0, 90.0),
    };
    let v_loc = toks.peek().map(|t| toks.loc(&t));
    let vertical = toks.angles(nv, "vertical angle", vlo, vhi)?;
    if let Some(loc) = v_loc {
        check_vertical_range(ty, &vertical, loc, warnings);
    }
    let h_loc = toks.peek().map(|t| toks.loc(&t));
    let (hlo, hhi) = match ty {
        PhotometricType::C => (0.0, 360.0),
        _ => (-90.0, 90.0),
    };
    let horizontal = toks.angles(nh, "horizontal angle", hlo, hhi)?;
    if Symmetry::of(ty, &horizontal).is_none() {
        let allowed = match ty {
            PhotometricType::C => "0 (one plane), 0..90, 0..180, 90..270 or 0..360",
            _ => "0..90 or -90..90",
        };
        return Err(SceneError::at(
            &h_loc.unwrap_or_else(|| (toks.at)(0, 0)),
            format!(
                "horizontal angles {}..{} are not a range LM-63 allows for type {ty:?} \
                 photometry: {allowed}",
                horizontal[0],
                horizontal[nh - 1]
            ),
        ));
    }
    let mut candela = Vec::with_capacity(nv * nh);
    for h in &horizontal {
        for v in &vertical {
            let what = format!("candela value at horizontal {h}°, vertical {v}°");
            candela.push(scale * toks.number_where(&what, "non-negative", |c| c >= 0.0)?);
        }
    }
    Ok((vertical, horizontal, candela))
}

/// Warns when the vertical angles do not span one of the standard's ranges.
fn check_vertical_range(ty: PhotometricType, v: &[f64], loc: Loc, warnings: &mut Vec<Warning>) {
    let (first, last) = (v[0], v[v.len() - 1]);
    let standard = match ty {
        PhotometricType::C => matches!((first, last), (0.0, 90.0) | (0.0, 180.0) | (90.0, 180.0)),
        _ => matches!((first, last), (-90.0, 90.0) | (0.0, 90.0)),
    };
    if !standard {
        warnings.push(Warning {
            loc,
            message: format!(
                "vertical angles span {first}..{last}, not a range LM-63 names; \
                 the intensity is zero outside it"
            ),
        });
    }
}
