//! Structure-aware mutations of scene text and PLY meshes.
//!
//! A case starts from one seed scene and applies one to three mutations,
//! each chosen at random from operators that know the syntax well enough
//! to reach past the tokenizer: number replacement with values at the
//! edges of every numeric type (NaN, ±∞, 1e39, 2³¹, denormals, −1, 0),
//! parameter-type swaps (`"float radius"` → `"integer radius"`), token and
//! directive duplication, deletion, swapping and splicing from other
//! scenes, bracket and encoding damage (BOM, invalid UTF-8, NUL), byte
//! flips and truncation. Meshes get header edits (element counts, property
//! types, format, dropped or repeated header lines) and body damage.
//!
//! When a case mutates an included file or a mesh, the copy is written
//! under a fixed name (`fuzz_inc.pbrt`, `fuzz_mesh.ply`) and the main
//! scene's reference to the original is rewritten to that name.

use crate::corpus::{Referenced, Seed};
use crate::ply_mutate::mutate_ply;
use crate::rng::Rng;
use crate::tokens::{directives, join, split, Kind, Piece};

/// Name under which a mutated included file is written.
pub const INCLUDE_NAME: &str = "fuzz_inc.pbrt";
/// Name under which a mutated mesh is written.
pub const MESH_NAME: &str = "fuzz_mesh.ply";

/// Values at the edges of f32, f64, i32 and u32, and a few ordinary ones.
pub const EXTREME_NUMBERS: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e39",
    "-1e39",
    "1e308",
    "1e400",
    "-1",
    "0",
    "-0",
    "2147483647",
    "2147483648",
    "-2147483649",
    "4294967296",
    "1e-45",
    "1e-39",
    "1e-300",
    "0.5",
    "1",
    "2",
    "3",
    "65536",
    "1e9",
    "1e6",
    "-1e6",
    "0x10",
    "1.",
    ".5e",
];

/// Parameter types of pbrt-v4 (and a wrong one) for type swaps.
const PARAM_TYPES: &[&str] = &[
    "float",
    "integer",
    "bool",
    "string",
    "point2",
    "vector2",
    "point3",
    "vector3",
    "normal3",
    "normal",
    "point",
    "vector",
    "rgb",
    "color",
    "blackbody",
    "spectrum",
    "texture",
    "bogus",
];

/// Strings to drop in place of a quoted string.
const ODD_STRINGS: &[&str] = &[
    "\"\"",
    "\"float\"",
    "\"float \"",
    "\" radius\"",
    "\"float radius radius\"",
    "\"plymesh\"",
    "\"sphere\"",
    "\"/dev/zero\"",
    "\"/\"",
    "\"..\"",
    "\"nonexistent.ply\"",
    "\"a\\\\\"",
    "\"\u{feff}\"",
    "\"\\n\"",
];

/// One generated input.
#[derive(Debug, Clone)]
pub struct Case {
    /// The main scene text.
    pub scene: Vec<u8>,
    /// Other files to write beside it: (name, bytes).
    pub extra: Vec<(String, Vec<u8>)>,
    /// What was done, one entry per mutation, for reports.
    pub ops: Vec<String>,
}

/// How many mutations a case gets: one (60 %), two (30 %) or three.
fn op_count(rng: &mut Rng) -> usize {
    match rng.below(10) {
        0..=5 => 1,
        6..=8 => 2,
        _ => 3,
    }
}

/// Builds a case from `seed` (and `others`, for splicing) with `rng`.
pub fn make_case(rng: &mut Rng, seed: &Seed, others: &[Seed]) -> Case {
    let mut case = Case {
        scene: seed.text.clone(),
        extra: Vec::new(),
        ops: Vec::new(),
    };
    let target = rng.unit();
    if target < 0.2 && !seed.meshes.is_empty() {
        let mesh = pick_ref(rng, &seed.meshes);
        let mut bytes = mesh.bytes.clone();
        for _ in 0..op_count(rng) {
            let op = mutate_ply(rng, &mut bytes);
            case.ops.push(format!("{}: {op}", mesh.name));
        }
        rewire(&mut case, &mesh.name, MESH_NAME, bytes);
        if rng.chance(0.3) {
            mutate_text_into(rng, &mut case, others, "scene");
        }
    } else if target < 0.3 && !seed.includes.is_empty() {
        let inc = pick_ref(rng, &seed.includes);
        let mut bytes = inc.bytes.clone();
        for _ in 0..op_count(rng) {
            let op = mutate_text(rng, &mut bytes, others);
            case.ops.push(format!("{}: {op}", inc.name));
        }
        rewire(&mut case, &inc.name, INCLUDE_NAME, bytes);
    } else {
        for _ in 0..op_count(rng) {
            mutate_text_into(rng, &mut case, others, "scene");
        }
    }
    case
}

/// A referenced file, preferring small ones (big meshes slow every case).
fn pick_ref<'a>(rng: &mut Rng, refs: &'a [Referenced]) -> &'a Referenced {
    let small: Vec<&Referenced> = refs.iter().filter(|r| r.bytes.len() < 1 << 20).collect();
    match rng.pick(&small) {
        Some(r) if rng.chance(0.9) => r,
        _ => &refs[rng.below(refs.len())],
    }
}

/// Mutates the case's main text once and records the operation.
fn mutate_text_into(rng: &mut Rng, case: &mut Case, others: &[Seed], what: &str) {
    let op = mutate_text(rng, &mut case.scene, others);
    case.ops.push(format!("{what}: {op}"));
}

/// Points every `"old"` in the scene at `new` and adds `new` with `bytes`.
fn rewire(case: &mut Case, old: &str, new: &str, bytes: Vec<u8>) {
    let from = format!("\"{old}\"");
    let to = format!("\"{new}\"");
    let text = String::from_utf8_lossy(&case.scene).replace(&from, &to);
    case.scene = text.into_bytes();
    case.extra.push((new.to_string(), bytes));
}

/// Applies one random text mutation to `text`; returns its description.
pub fn mutate_text(rng: &mut Rng, text: &mut Vec<u8>, others: &[Seed]) -> String {
    let mut p = split(text);
    let tokens: Vec<usize> = (0..p.len()).filter(|&i| p[i].is_token()).collect();
    // Weights favour edits that keep the syntax valid (numbers, whole
    // directives, splices), so that most cases reach the scene builder and
    // the renderer rather than stopping at a syntax error.
    let op = match rng.below(20) {
        0..=6 => replace_number(rng, &mut p),
        7 | 8 => swap_param_type(rng, &mut p),
        9 => replace_string(rng, &mut p),
        10 | 11 => directive_edit(rng, &mut p),
        12 | 13 => splice(rng, &mut p, others),
        14 => bracket(rng, &mut p, &tokens),
        15 => token_edit(rng, &mut p, &tokens),
        16 => {
            *text = join(&p);
            return encoding(rng, text);
        }
        17 => {
            *text = join(&p);
            return flip_bytes(rng, text, 0);
        }
        18 => {
            *text = join(&p);
            return truncate(rng, text);
        }
        _ => directive_edit(rng, &mut p),
    };
    *text = join(&p);
    op
}

/// The 1-based line piece `i` starts on.
fn line_of(p: &[Piece], i: usize) -> usize {
    1 + p[..i]
        .iter()
        .map(|q| q.bytes.iter().filter(|&&b| b == b'\n').count())
        .sum::<usize>()
}

/// Replaces a number with an extreme value.
fn replace_number(rng: &mut Rng, p: &mut [Piece]) -> String {
    let nums: Vec<usize> = (0..p.len()).filter(|&i| p[i].is_number()).collect();
    let Some(&i) = rng.pick(&nums) else {
        return "no number to replace".into();
    };
    let v = EXTREME_NUMBERS[rng.below(EXTREME_NUMBERS.len())];
    let old = String::from_utf8_lossy(&p[i].bytes).into_owned();
    p[i].bytes = v.as_bytes().to_vec();
    format!("line {}: number {old} -> {v}", line_of(p, i))
}

/// Changes the type in a `"type name"` string.
fn swap_param_type(rng: &mut Rng, p: &mut [Piece]) -> String {
    let decls: Vec<usize> = (0..p.len())
        .filter(|&i| p[i].kind == Kind::Str && p[i].bytes.contains(&b' '))
        .collect();
    let Some(&i) = rng.pick(&decls) else {
        return "no parameter to retype".into();
    };
    let s = String::from_utf8_lossy(&p[i].bytes).into_owned();
    let inner = s.trim_matches('"');
    let name = inner.split_whitespace().last().unwrap_or("x");
    let ty = PARAM_TYPES[rng.below(PARAM_TYPES.len())];
    p[i].bytes = format!("\"{ty} {name}\"").into_bytes();
    format!("line {}: type {s} -> \"{ty} {name}\"", line_of(p, i))
}

/// Replaces a quoted string by another from the text or an odd one.
fn replace_string(rng: &mut Rng, p: &mut [Piece]) -> String {
    let strs: Vec<usize> = (0..p.len()).filter(|&i| p[i].kind == Kind::Str).collect();
    let (Some(&i), Some(&j)) = (rng.pick(&strs), rng.pick(&strs)) else {
        return "no string to replace".into();
    };
    let new = if rng.chance(0.5) {
        p[j].bytes.clone()
    } else {
        ODD_STRINGS[rng.below(ODD_STRINGS.len())]
            .as_bytes()
            .to_vec()
    };
    let desc = format!(
        "line {}: string {} -> {}",
        line_of(p, i),
        String::from_utf8_lossy(&p[i].bytes),
        String::from_utf8_lossy(&new)
    );
    p[i].bytes = new;
    desc
}

/// Deletes, duplicates or swaps tokens.
fn token_edit(rng: &mut Rng, p: &mut Vec<Piece>, tokens: &[usize]) -> String {
    let (Some(&i), Some(&j)) = (rng.pick(tokens), rng.pick(tokens)) else {
        return "no token".into();
    };
    let show = |q: &Piece| String::from_utf8_lossy(&q.bytes).into_owned();
    match rng.below(3) {
        0 => {
            let gone = p.remove(i);
            format!("delete token {}", show(&gone))
        }
        1 => {
            let copy = p[i].clone();
            let n = 1 + rng.below(3);
            for _ in 0..n {
                p.insert(i + 1, Piece::new(Kind::Space, b" "));
                p.insert(i + 2, copy.clone());
            }
            format!("duplicate token {} x{n}", show(&copy))
        }
        _ => {
            p.swap(i, j);
            format!("swap tokens {} <-> {}", show(&p[j]), show(&p[i]))
        }
    }
}

/// Duplicates, deletes or moves a whole directive.
fn directive_edit(rng: &mut Rng, p: &mut Vec<Piece>) -> String {
    let ds = directives(p);
    let (Some(d), Some(to)) = (rng.pick(&ds).cloned(), rng.pick(&ds).cloned()) else {
        return "no directive".into();
    };
    let name = String::from_utf8_lossy(&p[d.start].bytes).into_owned();
    let body: Vec<Piece> = p[d.clone()].to_vec();
    match rng.below(3) {
        0 => {
            let n = 1 + rng.below(3);
            for _ in 0..n {
                let at = d.end;
                p.splice(at..at, body.iter().cloned());
            }
            format!("duplicate directive {name} x{n}")
        }
        1 => {
            p.drain(d);
            format!("delete directive {name}")
        }
        _ => {
            p.drain(d.clone());
            let at = if to.start > d.start {
                to.start - d.len().min(to.start - d.start)
            } else {
                to.start
            };
            let at = at.min(p.len());
            p.splice(at..at, body);
            format!("move directive {name}")
        }
    }
}

/// Inserts a directive taken from another seed scene.
fn splice(rng: &mut Rng, p: &mut Vec<Piece>, others: &[Seed]) -> String {
    let Some(other) = rng.pick(others) else {
        return "no scene to splice from".into();
    };
    let q = split(&other.text);
    let (Some(d), ds) = (rng.pick(&directives(&q)).cloned(), directives(p)) else {
        return "nothing to splice".into();
    };
    let at = rng.pick(&ds).map_or(p.len(), |r| r.start);
    let name = String::from_utf8_lossy(&q[d.start].bytes).into_owned();
    let mut body = q[d].to_vec();
    body.push(Piece::new(Kind::Space, b"\n"));
    p.splice(at..at, body);
    format!("splice {name} from {}", other.label)
}

/// Inserts or deletes a bracket.
fn bracket(rng: &mut Rng, p: &mut Vec<Piece>, tokens: &[usize]) -> String {
    let brackets: Vec<usize> = tokens
        .iter()
        .copied()
        .filter(|&i| p[i].kind == Kind::Bracket)
        .collect();
    if rng.chance(0.5) {
        if let Some(&i) = rng.pick(&brackets) {
            let b = p.remove(i);
            return format!("delete bracket {}", String::from_utf8_lossy(&b.bytes));
        }
    }
    let at = rng.pick(tokens).copied().unwrap_or(0);
    let b: &[u8] = if rng.chance(0.5) { b"[" } else { b"]" };
    p.insert(at, Piece::new(Kind::Bracket, b));
    p.insert(at + 1, Piece::new(Kind::Space, b" "));
    format!("insert bracket {}", String::from_utf8_lossy(b))
}

/// Inserts a byte-order mark, invalid UTF-8 or a NUL somewhere.
fn encoding(rng: &mut Rng, text: &mut Vec<u8>) -> String {
    let (what, bytes): (&str, &[u8]) = match rng.below(5) {
        0 => ("UTF-8 BOM", b"\xef\xbb\xbf"),
        1 => ("invalid UTF-8", b"\xff\xfe"),
        2 => ("NUL", b"\0"),
        3 => ("lone continuation byte", b"\x80"),
        _ => ("CR", b"\r"),
    };
    let at = if rng.chance(0.4) {
        0
    } else {
        rng.below(text.len() + 1)
    };
    text.splice(at..at, bytes.iter().copied());
    format!("insert {what} at byte {at}")
}

/// Flips one to four random bits or bytes at or after `from`.
pub fn flip_bytes(rng: &mut Rng, bytes: &mut [u8], from: usize) -> String {
    if bytes.len() <= from {
        return "nothing to flip".into();
    }
    let n = 1 + rng.below(4);
    let mut at = Vec::new();
    for _ in 0..n {
        let i = from + rng.below(bytes.len() - from);
        if rng.chance(0.5) {
            bytes[i] ^= 1 << rng.below(8);
        } else {
            bytes[i] = rng.next_u64() as u8;
        }
        at.push(i);
    }
    format!("flip bytes at {at:?}")
}

/// Cuts `bytes` at a random length.
pub fn truncate(rng: &mut Rng, bytes: &mut Vec<u8>) -> String {
    let n = rng.below(bytes.len() + 1);
    bytes.truncate(n);
    format!("truncate to {n} bytes")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seed() -> Seed {
        Seed {
            label: "t/t.pbrt".into(),
            dir: std::env::temp_dir(),
            text: b"LookAt 0 0 5 0 0 0 0 1 0\nCamera \"perspective\" \"float fov\" [45]\n\
                    WorldBegin\nShape \"plymesh\" \"string filename\" \"m.ply\"\n"
                .to_vec(),
            includes: Vec::new(),
            meshes: vec![Referenced {
                name: "m.ply".into(),
                bytes: b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1 2 3\n"
                    .to_vec(),
            }],
        }
    }

    #[test]
    fn cases_are_deterministic_and_change_something() {
        let s = seed();
        let others = [s.clone()];
        let mut changed = 0;
        for i in 0..300 {
            let a = make_case(&mut Rng::for_case(5, i), &s, &others);
            let b = make_case(&mut Rng::for_case(5, i), &s, &others);
            assert_eq!((&a.scene, &a.extra, &a.ops), (&b.scene, &b.extra, &b.ops));
            assert!(!a.ops.is_empty());
            let mesh_changed = a.extra.iter().any(|(_, m)| *m != s.meshes[0].bytes);
            changed += usize::from(a.scene != s.text || mesh_changed);
        }
        // Some mutations are no-ops (swapping equal tokens, replacing a
        // number by itself), but most change the input.
        assert!(changed > 250, "{changed}");
    }

    #[test]
    fn mesh_cases_point_the_scene_at_the_mutated_copy() {
        let s = seed();
        for i in 0..200 {
            let c = make_case(&mut Rng::for_case(9, i), &s, &[]);
            if c.extra.iter().any(|(n, _)| n == MESH_NAME) {
                let text = String::from_utf8_lossy(&c.scene);
                assert!(!text.contains("\"m.ply\""), "{text}");
                return;
            }
        }
        panic!("no mesh case in 200");
    }

    #[test]
    fn number_replacement_uses_the_extreme_values() {
        let mut p = split(b"Translate 7 8 9");
        let op = replace_number(&mut Rng::for_case(1, 2), &mut p);
        let t = String::from_utf8_lossy(&join(&p)).into_owned();
        assert!(
            EXTREME_NUMBERS
                .iter()
                .any(|v| t.split(' ').any(|w| w == *v)),
            "{op}: {t}"
        );
    }
}
