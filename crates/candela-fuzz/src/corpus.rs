//! The seed corpus: the bundled scenes and the files they reference.
//!
//! Every `.pbrt` file directly inside a directory of `scenes/` is a seed.
//! Quoted names in it that end in `.pbrt` or `.ply` (optionally `.gz`) and
//! exist relative to the scene's directory are loaded too, so a case can
//! mutate an included file or a mesh instead of the main file. Nothing is
//! parsed here: the fuzzer only needs bytes and where they came from.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

/// A file referenced by a seed scene.
#[derive(Debug, Clone)]
pub struct Referenced {
    /// The name exactly as quoted in the scene (e.g. `geometry/a.ply`).
    pub name: String,
    /// The file's bytes.
    pub bytes: Vec<u8>,
}

/// One seed scene.
#[derive(Debug, Clone)]
pub struct Seed {
    /// `directory/file.pbrt`, for reports.
    pub label: String,
    /// The scene's directory (absolute), whose entries cases link to.
    pub dir: PathBuf,
    /// The main file's text.
    pub text: Vec<u8>,
    /// Included scene files.
    pub includes: Vec<Referenced>,
    /// PLY meshes.
    pub meshes: Vec<Referenced>,
}

/// Loads every seed under `scenes` (sorted, so the corpus is deterministic).
pub fn load(scenes: &Path) -> Result<Vec<Seed>> {
    let scenes = std::fs::canonicalize(scenes)
        .with_context(|| format!("scene directory {}", scenes.display()))?;
    let mut seeds = Vec::new();
    for dir in sorted_entries(&scenes)? {
        if !dir.is_dir() {
            continue;
        }
        for file in sorted_entries(&dir)? {
            if file.extension().is_some_and(|e| e == "pbrt") && file.is_file() {
                seeds.push(load_seed(&dir, &file)?);
            }
        }
    }
    anyhow::ensure!(
        !seeds.is_empty(),
        "no .pbrt scenes under {}",
        scenes.display()
    );
    Ok(seeds)
}

/// The entries of `dir`, sorted by name.
fn sorted_entries(dir: &Path) -> Result<Vec<PathBuf>> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    v.sort();
    Ok(v)
}

/// Loads one scene and the files it names.
fn load_seed(dir: &Path, file: &Path) -> Result<Seed> {
    let text = std::fs::read(file).with_context(|| format!("reading {}", file.display()))?;
    let mut includes = Vec::new();
    let mut meshes = Vec::new();
    for name in quoted_names(&text) {
        let base = name.strip_suffix(".gz").unwrap_or(&name);
        let list = if base.ends_with(".pbrt") {
            &mut includes
        } else if base.ends_with(".ply") {
            &mut meshes
        } else {
            continue;
        };
        let path = dir.join(&name);
        if list.iter().any(|r: &Referenced| r.name == name) || !path.is_file() {
            continue;
        }
        let bytes = std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
        list.push(Referenced { name, bytes });
    }
    let dir_name = dir.file_name().unwrap_or_default().to_string_lossy();
    let file_name = file.file_name().unwrap_or_default().to_string_lossy();
    Ok(Seed {
        label: format!("{dir_name}/{file_name}"),
        dir: dir.to_path_buf(),
        text,
        includes,
        meshes,
    })
}

/// The contents of every `"..."` in `text` (no escapes: file names only).
pub fn quoted_names(text: &[u8]) -> Vec<String> {
    let s = String::from_utf8_lossy(text);
    s.split('"')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quoted_names_are_the_odd_fields() {
        let v = quoted_names(b"Include \"a.pbrt\" Shape \"plymesh\" \"string filename\" \"m.ply\"");
        assert_eq!(v, ["a.pbrt", "plymesh", "string filename", "m.ply"]);
    }

    #[test]
    fn bundled_scenes_load_with_their_meshes_and_includes() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
        let seeds = load(&root).unwrap();
        assert!(seeds.len() >= 5);
        assert!(seeds.iter().any(|s| !s.meshes.is_empty()));
        assert!(seeds.iter().any(|s| !s.includes.is_empty()));
    }
}
