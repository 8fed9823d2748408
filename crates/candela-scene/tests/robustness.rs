//! No input makes the parser panic: truncations and garbled variants of the
//! shared scenes must give `Ok` or `Err`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use candela_scene::*;

const SCENES: [&str; 4] = [
    "cornell-box/scene.pbrt",
    "caustic-glass/scene.pbrt",
    "killeroo-simple/killeroo-simple.pbrt",
    "killeroo-simple/geometry/killeroo.pbrt",
];

/// Deterministic xorshift64* generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

fn load(rel: &str) -> (PathBuf, Vec<u8>) {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(rel);
    let bytes = std::fs::read(&p).unwrap();
    (p, bytes)
}

/// Parses `bytes` as the file `path` (so Includes resolve), touching every
/// parameter through the getters too.
fn exercise(bytes: &[u8], path: &Path) {
    if let Ok(d) = parse_bytes(bytes, path) {
        for s in &d.shapes {
            for p in &s.params.params {
                let _ = s.params.get_float(&p.name, 0.0);
                let _ = s.params.get_point3s(&p.name);
                let _ = s.params.get_spectrum(&p.name);
                let _ = s.params.get_filename(&p.name);
            }
        }
    }
}

#[test]
fn every_prefix_truncation() {
    let t = Instant::now();
    for rel in SCENES {
        let (path, bytes) = load(rel);
        let step = (bytes.len() / 1500).max(3);
        for n in (0..=bytes.len()).step_by(step) {
            exercise(&bytes[..n], &path);
        }
    }
    eprintln!("truncations: {:.2} s", t.elapsed().as_secs_f64());
}

/// Replaces, deletes or duplicates a few random bytes; some replacements
/// are syntax characters to stress the tokenizer.
fn garble(rng: &mut Rng, src: &[u8]) -> Vec<u8> {
    const SPECIAL: &[u8] = b"\"[]#\\\n 0.-eE\xff";
    let mut v = src.to_vec();
    for _ in 0..1 + rng.below(6) {
        let i = rng.below(v.len());
        match rng.below(4) {
            0 => v[i] = SPECIAL[rng.below(SPECIAL.len())],
            1 => v[i] = rng.next() as u8,
            2 => {
                v.remove(i);
            }
            _ => {
                let len = rng.below(40).min(v.len() - i);
                let chunk = v[i..i + len].to_vec();
                v.splice(i..i, chunk);
            }
        }
        if v.is_empty() {
            v.push(b'#');
        }
    }
    v
}

#[test]
fn garbled_variants() {
    let t = Instant::now();
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let counts = [900, 700, 300, 100];
    let mut errors = 0;
    for (rel, count) in SCENES.iter().zip(counts) {
        let (path, bytes) = load(rel);
        for _ in 0..count {
            let g = garble(&mut rng, &bytes);
            errors += usize::from(parse_bytes(&g, &path).is_err());
            exercise(&g, &path);
        }
    }
    eprintln!(
        "garbled: {errors} errors in 2000 variants, {:.2} s",
        t.elapsed().as_secs_f64()
    );
    assert!(errors > 0, "garbling should break some scenes");
}
