//! The label section of an LM-63 file: version line, keywords, `TILT=`.

use super::{IesKeyword, IesVersion, Result};
use crate::error::{Loc, SceneError, Warning};

/// What `TILT=` said (a tilt file is an error before this is built).
pub(super) enum TiltKind {
    None,
    Include,
}

/// The label section and where the numbers start.
pub(super) struct Header {
    pub(super) version: IesVersion,
    pub(super) keywords: Vec<IesKeyword>,
    pub(super) label_lines: Vec<String>,
    pub(super) tilt: TiltKind,
    /// Byte offset and 1-based line of the first byte after the `TILT=` line.
    pub(super) data_start: usize,
    pub(super) data_line: u32,
    pub(super) warnings: Vec<Warning>,
}

/// The version a first line announces, if it is a version line.
fn version_of(line: &str) -> Option<IesVersion> {
    Some(match line {
        "IESNA91" | "IESNA:LM-63-1991" => IesVersion::Lm1991,
        "IESNA:LM-63-1995" => IesVersion::Lm1995,
        "IESNA:LM-63-2002" => IesVersion::Lm2002,
        "IES:LM-63-2019" => IesVersion::Lm2019,
        _ => return None,
    })
}

/// Reads lines up to and including `TILT=`.
pub(super) fn read_header(bytes: &[u8], at: &impl Fn(u32, u32) -> Loc) -> Result<Header> {
    let mut h = Header {
        version: IesVersion::Lm1986,
        keywords: Vec::new(),
        label_lines: Vec::new(),
        tilt: TiltKind::None,
        data_start: 0,
        data_line: 0,
        warnings: Vec::new(),
    };
    let (mut pos, mut line_no) = (0, 0u32);
    loop {
        line_no += 1;
        if pos >= bytes.len() {
            return Err(SceneError::at(
                &at(line_no.saturating_sub(1).max(1), 1),
                "no TILT= line: not an IES LM-63 photometric file",
            ));
        }
        let rest = &bytes[pos..];
        let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        let mut raw = &rest[..len];
        pos += (len + 1).min(rest.len());
        if line_no == 1 {
            raw = raw.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(raw);
        }
        let text = std::str::from_utf8(raw).map_err(|e| {
            let col = e.valid_up_to() as u32 + 1;
            SceneError::at(
                &at(line_no, col),
                format!(
                    "invalid UTF-8 (byte 0x{:02X}) in a label line",
                    raw[e.valid_up_to()]
                ),
            )
        })?;
        let line = text.trim();
        if line_no == 1 {
            if let Some(v) = version_of(line) {
                h.version = v;
                continue;
            }
            if line.starts_with("IESNA:") || line.starts_with("IES:") {
                h.version = IesVersion::Lm2019;
                h.warnings.push(Warning {
                    loc: at(1, 1),
                    message: format!("unknown version line '{line}', read as LM-63-2019"),
                });
                continue;
            }
        }
        if let Some(value) = strip_prefix_ci(line, "TILT=") {
            let col = (text.len() - text.trim_start().len()) as u32 + 6;
            h.tilt = tilt_kind(value.trim(), &at(line_no, col))?;
            h.data_start = pos;
            h.data_line = line_no + 1;
            return Ok(h);
        }
        label_line(&mut h, line, &at(line_no, 1));
    }
}

/// ASCII case-insensitive `strip_prefix`.
fn strip_prefix_ci<'a>(s: &'a str, prefix: &str) -> Option<&'a str> {
    let head = s.get(..prefix.len())?;
    head.eq_ignore_ascii_case(prefix)
        .then(|| &s[prefix.len()..])
}

/// Interprets the value of `TILT=`.
fn tilt_kind(value: &str, loc: &Loc) -> Result<TiltKind> {
    if value.eq_ignore_ascii_case("NONE") {
        Ok(TiltKind::None)
    } else if value.eq_ignore_ascii_case("INCLUDE") {
        Ok(TiltKind::Include)
    } else if value.is_empty() {
        Err(SceneError::at(
            loc,
            "TILT= needs NONE, INCLUDE or a file name",
        ))
    } else {
        Err(SceneError::unsupported(
            loc,
            format!(
                "TILT={value}: tilt data in a separate file is not supported \
                 (candela reads TILT=NONE and TILT=INCLUDE)"
            ),
        ))
    }
}

/// Files one label line as a keyword, a `[MORE]` continuation or free text.
fn label_line(h: &mut Header, line: &str, loc: &Loc) {
    if line.is_empty() {
        return;
    }
    let keyword = if h.version == IesVersion::Lm1986 {
        None
    } else {
        line.strip_prefix('[')
            .and_then(|r| r.split_once(']'))
            .filter(|(name, _)| !name.trim().is_empty())
    };
    let Some((name, value)) = keyword else {
        h.label_lines.push(line.to_string());
        return;
    };
    let (name, value) = (name.trim(), value.trim());
    match h.keywords.last_mut() {
        Some(prev) if name.eq_ignore_ascii_case("MORE") => {
            prev.value.push('\n');
            prev.value.push_str(value);
        }
        _ => {
            if name.eq_ignore_ascii_case("MORE") {
                h.warnings.push(Warning {
                    loc: loc.clone(),
                    message: "[MORE] without a keyword before it".into(),
                });
            }
            h.keywords.push(IesKeyword {
                name: name.to_string(),
                value: value.to_string(),
            });
        }
    }
}
