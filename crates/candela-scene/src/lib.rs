//! candela-scene: reads pbrt-v4 scene files into a plain description.
//!
//! The crate turns scene text into a [`SceneDescription`]: entity names,
//! typed parameter lists and the graphics state (transforms, materials,
//! area lights...) each entity was declared with. It knows nothing about
//! rendering; the core crate interprets the description.
//!
//! Layout:
//! - `error`: [`Loc`], [`SceneError`], [`Warning`].
//! - `input`: bounded reads of regular files only (no devices, FIFOs, bombs).
//! - `lexer`: byte tokenizer with line/column tracking.
//! - `paramlist`: `"type name" [values]` lists -> [`ParamSet`].
//! - `param`: [`ParamSet`] and its typed getters; `spectrum`: spectra.
//! - `parser`: directive loop over a stack of included files.
//! - `builder`, `world`: pbrt-v4 directive semantics and graphics state.
//! - `upgrade`: pbrt-v3 syntax rewritten as pbrt-v4's `--upgrade` does.
//! - `desc`: the output types; `math`: [`Mat4d`]; `ply`: PLY mesh reader.
//! - `ies`: IES LM-63 photometric files ([`read_ies`]).

mod builder;
mod desc;
mod error;
pub mod ies;
mod input;
mod lexer;
mod math;
mod param;
mod paramlist;
mod parser;
pub mod ply;
mod spectrum;
mod upgrade;
mod world;

use std::path::Path;

pub use builder::{MAX_BLOCK_DEPTH, MAX_COPIED_VALUES};
pub use desc::{
    fnv1a64, CameraDesc, Entity, InstanceDefinition, InstanceUse, LightDesc, MaterialDesc,
    MaterialRef, SceneDescription, ShapeDesc, SourceFile, TextureDesc, TextureKind,
};
pub use error::{Loc, SceneError, Warning};
pub use ies::{read_ies, IesFile};
pub use input::{MAX_PLY_FILE_BYTES, MAX_SCENE_FILE_BYTES, MAX_SPECTRUM_FILE_BYTES};
pub use math::Mat4d;
pub use param::{Param, ParamSet, ParamType, ParamValue};
pub use parser::{MAX_INCLUDED_FILES, MAX_INCLUDE_DEPTH};
pub use ply::{read_ply, MeshData};
pub use spectrum::{ParamSpectrum, SpectrumValue};

/// Parses the scene file at `path` (gzipped if it ends in `.gz`) and the
/// files it includes. Relative paths resolve against `path`'s directory.
pub fn parse_file(path: &Path) -> Result<SceneDescription, SceneError> {
    let text = parser::read_scene_file(path, &Loc::file_only(path))?;
    parser::parse_bytes(text, path)
}

/// Parses scene `text` as if it were the file `virtual_path` (used for
/// locations and to resolve relative file names).
pub fn parse_str(text: &str, virtual_path: &Path) -> Result<SceneDescription, SceneError> {
    parser::parse_bytes(text.as_bytes().to_vec(), virtual_path)
}

/// Like [`parse_str`] for raw bytes (scene files need not be valid UTF-8).
pub fn parse_bytes(bytes: &[u8], virtual_path: &Path) -> Result<SceneDescription, SceneError> {
    parser::parse_bytes(bytes.to_vec(), virtual_path)
}
