//! The identity of a render: a hash of everything that decides its passes,
//! so checkpoints and partial renders are only ever combined with their own
//! kind.
//!
//! It covers the bytes of the scene file and of every `Include`/`Import`
//! (hashed by the parser as it reads them), the bytes of every file a
//! parameter names (PLY meshes, images, IES files: any string parameter whose
//! value is an existing file relative to the scene), spectra read from files
//! (their samples), the command-line values that change the image (`--spp`,
//! `--integrator`, `--seed`) and the film's layers. File *names* are hashed
//! relative to the scene's directory, so a scene copied elsewhere (a cluster
//! worker's unpacked archive) has the same fingerprint. The output path, the
//! thread count and the budgets do not enter: they do not change a pass.

use crate::build::Overrides;
use crate::film::FilmLayout;
use crate::sampling::{hash_u64s, murmur_hash64a};
use candela_scene::{ParamSet, ParamValue, SceneDescription, SpectrumValue};
use std::path::Path;

/// Files at most this large are hashed whole; larger ones by size and their
/// first and last 64 MiB (a scene's meshes and images are far smaller).
const WHOLE: u64 = 1 << 30;
const EDGE: usize = 64 << 20;

/// The fingerprint of a render.
pub fn fingerprint(desc: &SceneDescription, ov: &Overrides, layout: &FilmLayout) -> u64 {
    let mut h: Vec<u64> = vec![0xC4D1_A000_0000_0001];
    for s in &desc.sources {
        h.push(name_hash(&s.path, &desc.base_dir));
        h.push(s.hash);
    }
    for_each_params(desc, |p| {
        for param in &p.params {
            match &param.value {
                ParamValue::Strings(v) => {
                    for s in v {
                        if let Some(fh) = file_hash(&desc.base_dir, s) {
                            h.push(murmur_hash64a(s.as_bytes(), 0));
                            h.push(fh);
                        }
                    }
                }
                ParamValue::Spectrum(SpectrumValue::Sampled(v)) => {
                    h.extend(
                        v.iter()
                            .map(|(l, x)| (l.to_bits() as u64) << 32 | x.to_bits() as u64),
                    );
                }
                _ => {}
            }
        }
    });
    let settings = format!(
        "spp={:?} integrator={:?} seed={:?} cropwindow={:?} layout={:?}",
        ov.spp, ov.integrator, ov.seed, ov.cropwindow, layout
    );
    h.push(murmur_hash64a(settings.as_bytes(), 0));
    hash_u64s(&h)
}

/// Hash of `path` relative to `base` (the whole path if it is not under it).
fn name_hash(path: &Path, base: &Path) -> u64 {
    let rel = path.strip_prefix(base).unwrap_or(path);
    murmur_hash64a(rel.to_string_lossy().as_bytes(), 0)
}

/// Hash of the bytes of the regular file `name` names relative to `base`, if any.
fn file_hash(base: &Path, name: &str) -> Option<u64> {
    if name.is_empty() || name.len() > 4096 {
        return None;
    }
    let path = base.join(name);
    let meta = std::fs::metadata(&path).ok()?;
    if !meta.is_file() {
        return None;
    }
    if meta.len() <= WHOLE {
        let bytes = std::fs::read(&path).ok()?;
        return Some(murmur_hash64a(&bytes, meta.len()));
    }
    use std::io::{Read, Seek, SeekFrom};
    let mut f = std::fs::File::open(&path).ok()?;
    let mut head = vec![0u8; EDGE];
    f.read_exact(&mut head).ok()?;
    f.seek(SeekFrom::End(-(EDGE as i64))).ok()?;
    let mut tail = vec![0u8; EDGE];
    f.read_exact(&mut tail).ok()?;
    Some(hash_u64s(&[
        meta.len(),
        murmur_hash64a(&head, 0),
        murmur_hash64a(&tail, 1),
    ]))
}

/// Calls `f` on the parameter list of every entity of the description.
fn for_each_params(desc: &SceneDescription, mut f: impl FnMut(&ParamSet)) {
    for e in [
        &desc.film,
        &desc.sampler,
        &desc.integrator,
        &desc.filter,
        &desc.accelerator,
    ]
    .into_iter()
    .flatten()
    {
        f(&e.params);
    }
    if let Some(c) = &desc.camera {
        f(&c.params);
    }
    desc.textures.iter().for_each(|t| f(&t.params));
    desc.named_materials.iter().for_each(|(_, m)| f(&m.params));
    desc.materials.iter().for_each(|m| f(&m.params));
    desc.lights.iter().for_each(|l| f(&l.params));
    let defs = desc.instance_definitions.iter().flat_map(|d| &d.shapes);
    for s in desc.shapes.iter().chain(defs) {
        f(&s.params);
        if let Some(a) = &s.area_light {
            f(&a.params);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::film::SurfaceAov;

    fn fp(text: &str, ov: &Overrides) -> u64 {
        let desc = candela_scene::parse_str(text, Path::new("/tmp/a/scene.pbrt")).expect("parses");
        fingerprint(&desc, ov, &FilmLayout::default())
    }

    #[test]
    fn fingerprint_changes_with_the_scene_and_the_settings_but_not_the_output() {
        let a = "WorldBegin\nShape \"sphere\"\n";
        let base = fp(a, &Overrides::default());
        assert_eq!(base, fp(a, &Overrides::default()));
        assert_ne!(
            base,
            fp(
                "WorldBegin\nShape \"sphere\" \"float radius\" 2\n",
                &Overrides::default()
            )
        );
        let spp = Overrides {
            spp: Some(4),
            ..Overrides::default()
        };
        assert_ne!(base, fp(a, &spp));
        let out = Overrides {
            outfile: Some("x.exr".into()),
            ..Overrides::default()
        };
        assert_eq!(base, fp(a, &out));
        let desc = candela_scene::parse_str(a, Path::new("/tmp/a/scene.pbrt")).expect("parses");
        let layered = FilmLayout {
            surface: vec![SurfaceAov::Albedo],
            ..FilmLayout::default()
        };
        assert_ne!(base, fingerprint(&desc, &Overrides::default(), &layered));
    }
}
