//! PLY mutations: header edits (element counts set to neighbours, zero or
//! values past `u32`/`u64`, property and list-count types, the format
//! line, dropped or repeated header lines) and body damage (bit and byte
//! flips, inserted or deleted runs that shift every later record,
//! truncation). Header edits re-join the header's lines and keep the body's
//! bytes as they were, so binary bodies survive an edited header.

use crate::mutate::{flip_bytes, truncate};
use crate::rng::Rng;

/// Applies one random PLY mutation; returns its description.
pub fn mutate_ply(rng: &mut Rng, bytes: &mut Vec<u8>) -> String {
    let header_end = find(bytes, b"end_header\n").map_or(bytes.len(), |i| i + 11);
    let header = String::from_utf8_lossy(&bytes[..header_end]).into_owned();
    let mut lines: Vec<String> = header.lines().map(str::to_string).collect();
    let body = bytes[header_end..].to_vec();
    let op = match rng.below(8) {
        0 | 1 => edit_count(rng, &mut lines),
        2 => edit_type(rng, &mut lines),
        3 => edit_lines(rng, &mut lines),
        4 => edit_format(rng, &mut lines),
        5 => {
            return flip_bytes(rng, bytes, header_end);
        }
        6 => {
            return truncate(rng, bytes);
        }
        _ => {
            return body_splice(rng, bytes, header_end);
        }
    };
    let mut out = lines.join("\n").into_bytes();
    out.push(b'\n');
    out.extend(body);
    *bytes = out;
    op
}

/// Sets an element count to a neighbour, zero or a huge value.
fn edit_count(rng: &mut Rng, lines: &mut [String]) -> String {
    let els: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].starts_with("element "))
        .collect();
    let Some(&i) = rng.pick(&els) else {
        return "no element line".into();
    };
    let w: Vec<String> = lines[i].split_whitespace().map(str::to_string).collect();
    let n: i128 = w.get(2).and_then(|s| s.parse().ok()).unwrap_or(0);
    let choices = [
        (n - 1).to_string(),
        (n + 1).to_string(),
        "0".into(),
        "1".into(),
        (2 * n).to_string(),
        "2147483648".into(),
        "4294967296".into(),
        "18446744073709551615".into(),
        "18446744073709551616".into(),
        "-1".into(),
        "1e9".into(),
        "x".into(),
    ];
    let v = &choices[rng.below(choices.len())];
    let old = lines[i].clone();
    lines[i] = format!("element {} {v}", w.get(1).map_or("vertex", |s| s.as_str()));
    format!("header {old} -> {}", lines[i])
}

/// Changes a property's (or list count's) type.
fn edit_type(rng: &mut Rng, lines: &mut [String]) -> String {
    const TYPES: &[&str] = &[
        "char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8",
        "float32", "float64", "float128", "list",
    ];
    let props: Vec<usize> = (0..lines.len())
        .filter(|&i| lines[i].starts_with("property "))
        .collect();
    let Some(&i) = rng.pick(&props) else {
        return "no property line".into();
    };
    let mut w: Vec<String> = lines[i].split_whitespace().map(str::to_string).collect();
    let slot = 1 + rng.below(w.len().saturating_sub(2).max(1));
    if let Some(x) = w.get_mut(slot) {
        *x = TYPES[rng.below(TYPES.len())].to_string();
    }
    let old = std::mem::replace(&mut lines[i], w.join(" "));
    format!("header {old} -> {}", lines[i])
}

/// Deletes or repeats a header line (never the `ply` magic).
fn edit_lines(rng: &mut Rng, lines: &mut Vec<String>) -> String {
    if lines.len() < 2 {
        return "header too short".into();
    }
    let i = 1 + rng.below(lines.len() - 1);
    if rng.chance(0.5) {
        let gone = lines.remove(i);
        format!("header delete {gone}")
    } else {
        let l = lines[i].clone();
        lines.insert(i, l.clone());
        format!("header repeat {l}")
    }
}

/// Changes the format line.
fn edit_format(rng: &mut Rng, lines: &mut [String]) -> String {
    const FORMATS: &[&str] = &[
        "ascii",
        "binary_little_endian",
        "binary_big_endian",
        "binary",
    ];
    let Some(i) = lines.iter().position(|l| l.starts_with("format ")) else {
        return "no format line".into();
    };
    let f = FORMATS[rng.below(FORMATS.len())];
    lines[i] = format!("format {f} 1.0");
    format!("header format -> {f}")
}

/// Inserts or deletes a run of body bytes (shifting everything after it).
fn body_splice(rng: &mut Rng, bytes: &mut Vec<u8>, from: usize) -> String {
    let len = bytes.len().saturating_sub(from);
    let at = from + rng.below(len + 1);
    let n = 1 + rng.below(16);
    if rng.chance(0.5) {
        let end = (at + n).min(bytes.len());
        bytes.drain(at..end);
        format!("body delete {} bytes at {at}", end - at)
    } else {
        let ins: Vec<u8> = (0..n).map(|_| rng.next_u64() as u8).collect();
        bytes.splice(at..at, ins);
        format!("body insert {n} bytes at {at}")
    }
}

/// The first position of `needle` in `hay`.
fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    hay.windows(needle.len()).position(|w| w == needle)
}
