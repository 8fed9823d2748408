//! Parsing of parameter lists: `"type name" value` or `"type name" [ values ]`.
//!
//! Values are converted straight into the typed vector for the declared
//! type (no intermediate token list), so a million-vertex `"point3 P"` costs
//! one `f32` parse per number. Value kinds and counts are checked here so the
//! getters in [`crate::param`] only have to check the declared type:
//! numeric types need numbers (integers must be integer literals), tuples a
//! multiple of their arity, `rgb` exactly three numbers, `blackbody` one
//! (or pbrt-v3's two: kelvin and scale),
//! `bool` `true`/`false` (bare or quoted), `string`/`texture` quoted strings,
//! and `spectrum` either (λ, value) pairs or one string (a built-in name or
//! a `.spd` file, read now).

use std::path::Path;
use std::sync::Arc;

use crate::error::{Loc, SceneError};
use crate::lexer::{Lexer, Token, TokenKind};
use crate::param::{Param, ParamType, ParamValue};
use crate::spectrum;

type Result<T> = std::result::Result<T, SceneError>;

/// Values collected for one parameter.
enum Sink {
    Floats(Vec<f32>),
    Ints(Vec<i32>),
    Bools(Vec<bool>),
    Strings(Vec<String>),
    Spectrum(Vec<f32>, Vec<String>),
}

impl Sink {
    fn new(ty: ParamType) -> Sink {
        match ty {
            ParamType::Integer => Sink::Ints(Vec::new()),
            ParamType::Bool => Sink::Bools(Vec::new()),
            ParamType::String | ParamType::Texture => Sink::Strings(Vec::new()),
            ParamType::Spectrum => Sink::Spectrum(Vec::new(), Vec::new()),
            _ => Sink::Floats(Vec::new()),
        }
    }

    /// Adds one value token, checking it has the right kind.
    fn push(&mut self, lx: &Lexer, t: &Token, name: &str) -> Result<()> {
        let is_word = t.kind == TokenKind::Word;
        let is_str = matches!(t.kind, TokenKind::Str { .. });
        let bytes = lx.bytes(t);
        let ok = match self {
            Sink::Floats(v) => is_word && push_parsed(v, bytes),
            Sink::Ints(v) => is_word && push_parsed(v, bytes),
            Sink::Bools(v) => match bytes {
                b"true" if is_word || is_str => {
                    v.push(true);
                    true
                }
                b"false" if is_word || is_str => {
                    v.push(false);
                    true
                }
                _ => false,
            },
            Sink::Strings(v) => {
                if is_str {
                    v.push(lx.string(t).into_owned());
                }
                is_str
            }
            Sink::Spectrum(nums, strs) => {
                if is_str {
                    strs.push(lx.string(t).into_owned());
                    true
                } else {
                    is_word && push_parsed(nums, bytes)
                }
            }
        };
        if ok {
            return Ok(());
        }
        Err(SceneError::at(
            &lx.loc(t),
            format!(
                "expected {} for '{name}', found {}",
                self.expected(),
                describe(lx, t)
            ),
        ))
    }

    fn expected(&self) -> &'static str {
        match self {
            Sink::Floats(_) => "a number",
            Sink::Ints(_) => "an integer",
            Sink::Bools(_) => "true or false",
            Sink::Strings(_) => "a quoted string",
            Sink::Spectrum(..) => "a number or a quoted string",
        }
    }
}

/// Parses `bytes` as a `T` and pushes it; false if it is not one.
fn push_parsed<T: std::str::FromStr>(v: &mut Vec<T>, bytes: &[u8]) -> bool {
    match std::str::from_utf8(bytes).ok().and_then(|s| s.parse().ok()) {
        Some(x) => {
            v.push(x);
            true
        }
        None => false,
    }
}

/// A short description of a token for error messages.
pub(crate) fn describe(lx: &Lexer, t: &Token) -> String {
    let text = lx.string(t);
    let short: String = text.chars().take(40).collect();
    match t.kind {
        TokenKind::Word => format!("'{short}'"),
        TokenKind::Str { .. } => format!("string \"{short}\""),
        TokenKind::Open => "'['".to_string(),
        TokenKind::Close => "']'".to_string(),
    }
}

/// Splits a `"type name"` declaration.
fn declaration(lx: &Lexer, decl: &Token, loc: &Loc) -> Result<(ParamType, String)> {
    let text = lx.string(decl);
    let mut words = text.split_whitespace();
    let (Some(ty), Some(name), None) = (words.next(), words.next(), words.next()) else {
        return Err(SceneError::at(
            loc,
            format!("expected a \"type name\" parameter declaration, found \"{text}\""),
        ));
    };
    match ParamType::from_name(ty) {
        Some(t) => Ok((t, name.to_string())),
        None => Err(SceneError::at(
            loc,
            format!("unknown parameter type '{ty}'"),
        )),
    }
}

/// Parses one parameter whose declaration token `decl` was just read.
pub(crate) fn parse_param(lx: &mut Lexer, decl: &Token, base_dir: &Arc<Path>) -> Result<Param> {
    let loc = lx.loc(decl);
    let (ty, name) = declaration(lx, decl, &loc)?;
    let mut sink = Sink::new(ty);
    let missing = |lx: &Lexer| {
        SceneError::at(
            &lx.end_loc(),
            format!("premature end of file: expected a value for '{name}'"),
        )
    };
    let first = lx.next_token()?.ok_or_else(|| missing(lx))?;
    if first.kind == TokenKind::Open {
        loop {
            let Some(t) = lx.next_token()? else {
                return Err(SceneError::at(
                    &lx.end_loc(),
                    format!("premature end of file: expected ']' to close the values of '{name}'"),
                ));
            };
            if t.kind == TokenKind::Close {
                break;
            }
            sink.push(lx, &t, &name).map_err(with_bracket_hint)?;
        }
    } else {
        sink.push(lx, &first, &name)?;
    }
    let value = finish(sink, ty, &name, &loc, base_dir)?;
    Ok(Param {
        name,
        ty,
        value,
        loc,
        used: Default::default(),
        may_be_unused: false,
    })
}

/// Inside brackets a wrong token usually means a missing `]`: say so.
fn with_bracket_hint(e: SceneError) -> SceneError {
    match e {
        SceneError::Syntax { loc, message } => SceneError::Syntax {
            loc,
            message: format!("{message} (missing ']'?)"),
        },
        other => other,
    }
}

/// Checks counts and builds the stored value.
fn finish(
    sink: Sink,
    ty: ParamType,
    name: &str,
    loc: &Loc,
    base: &Arc<Path>,
) -> Result<ParamValue> {
    let count_err = |want: &str, got: usize| {
        SceneError::at(
            loc,
            format!("'{ty} {name}' needs {want}, found {got} values"),
        )
    };
    Ok(match sink {
        Sink::Floats(v) => {
            let n = v.len();
            match ty {
                ParamType::Rgb if n != 3 => return Err(count_err("3 values", n)),
                // pbrt-v3 wrote [kelvin scale]; `upgrade` folds the scale into lights'.
                ParamType::Blackbody if n != 1 && n != 2 => {
                    return Err(count_err("1 value (kelvin)", n))
                }
                _ if n % ty.arity() != 0 => {
                    return Err(count_err(
                        &format!("a multiple of {} values", ty.arity()),
                        n,
                    ))
                }
                _ => ParamValue::Floats(v),
            }
        }
        Sink::Ints(v) => ParamValue::Ints(v),
        Sink::Bools(v) => ParamValue::Bools(v),
        Sink::Strings(v) if ty == ParamType::Texture && v.len() != 1 => {
            return Err(count_err("1 texture name", v.len()))
        }
        Sink::Strings(v) => ParamValue::Strings(v),
        Sink::Spectrum(nums, strs) => match (nums.is_empty(), strs.as_slice()) {
            (true, [s]) => ParamValue::Spectrum(spectrum::from_string(s, base, loc)?),
            (_, []) => ParamValue::Spectrum(spectrum::SpectrumValue::Sampled(spectrum::pairs(
                &nums, loc, name,
            )?)),
            _ => {
                return Err(count_err(
                    "pairs of numbers or one string",
                    nums.len() + strs.len(),
                ))
            }
        },
    })
}
