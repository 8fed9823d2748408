//! The plain scene description produced by the parser.
//!
//! These types mirror what a pbrt-v4 file says, after applying the graphics
//! state (transforms, current material, area light, reverse orientation,
//! color space, `Attribute` defaults) but before any interpretation: entity
//! names and parameters are kept as written, so the rendering core decides
//! what a "diffuse" material or a "plymesh" shape means. Render space is
//! world space. Entities whose directive is absent (film, sampler...) are
//! `None`; renderers apply pbrt-v4's defaults.

use std::path::PathBuf;

use crate::error::{Loc, Warning};
use crate::math::Mat4d;
use crate::param::{Param, ParamSet};

/// A named entity with parameters (film, sampler, area light...).
#[derive(Debug, Clone)]
pub struct Entity {
    /// The implementation name, e.g. `"rgb"` for `Film "rgb"`.
    pub name: String,
    /// The parameters.
    pub params: ParamSet,
    /// The color space in effect (`ColorSpace`), default `"srgb"`.
    pub color_space: String,
    /// Where the directive is.
    pub loc: Loc,
}

/// The `Camera` directive.
#[derive(Debug, Clone)]
pub struct CameraDesc {
    /// Camera type, e.g. `"perspective"`.
    pub name: String,
    /// The parameters.
    pub params: ParamSet,
    /// The CTM when `Camera` appeared (camera-from-world).
    pub camera_from_world: Mat4d,
    /// The color space in effect.
    pub color_space: String,
    /// Where the directive is.
    pub loc: Loc,
}

/// Whether a texture produces floats or spectra.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextureKind {
    /// `Texture "name" "float" ...`
    Float,
    /// `Texture "name" "spectrum" ...` (`"color"` accepted as an alias)
    Spectrum,
}

/// A `Texture` directive.
#[derive(Debug, Clone)]
pub struct TextureDesc {
    /// The texture's name, referenced by `"texture ..."` parameters.
    pub name: String,
    /// Float or spectrum texture.
    pub kind: TextureKind,
    /// Implementation, e.g. `"imagemap"`, `"checkerboard"`.
    pub class: String,
    /// The parameters (with `Attribute "texture"` defaults).
    pub params: ParamSet,
    /// The CTM at the directive.
    pub render_from_texture: Mat4d,
    /// The color space in effect.
    pub color_space: String,
    /// Where the directive is.
    pub loc: Loc,
}

/// A `Material` or `MakeNamedMaterial` directive.
#[derive(Debug, Clone)]
pub struct MaterialDesc {
    /// Material type, e.g. `"diffuse"` (from `"string type"` for named ones).
    pub ty: String,
    /// The parameters (with `Attribute "material"` defaults).
    pub params: ParamSet,
    /// The color space in effect.
    pub color_space: String,
    /// Where the directive is.
    pub loc: Loc,
}

/// Which material a shape uses.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MaterialRef {
    /// An index into [`SceneDescription::materials`].
    Index(usize),
    /// A name in [`SceneDescription::named_materials`].
    Named(String),
    /// No material was set: renderers use pbrt-v4's default (`diffuse`).
    None,
}

/// A `LightSource` directive.
#[derive(Debug, Clone)]
pub struct LightDesc {
    /// Light type, e.g. `"point"`, `"infinite"`.
    pub name: String,
    /// The parameters (with `Attribute "light"` defaults).
    pub params: ParamSet,
    /// The CTM at the directive.
    pub render_from_light: Mat4d,
    /// Whether `ReverseOrientation` was in effect.
    pub reverse_orientation: bool,
    /// The color space in effect.
    pub color_space: String,
    /// Where the directive is.
    pub loc: Loc,
}

/// A `Shape` directive with its graphics state.
#[derive(Debug, Clone)]
pub struct ShapeDesc {
    /// Shape type, e.g. `"trianglemesh"`, `"plymesh"`, `"sphere"`.
    pub name: String,
    /// The parameters (with `Attribute "shape"` defaults).
    pub params: ParamSet,
    /// The CTM at the directive (relative to the instance inside
    /// `ObjectBegin`/`ObjectEnd`).
    pub render_from_object: Mat4d,
    /// The CTM at `TransformTimes`' end time when it differs from the start
    /// (`ActiveTransform EndTime`): the shape moves during the shutter.
    pub render_from_object_end: Option<Mat4d>,
    /// Whether `ReverseOrientation` was in effect.
    pub reverse_orientation: bool,
    /// The current material.
    pub material: MaterialRef,
    /// The current `AreaLightSource`, if any.
    pub area_light: Option<Entity>,
    /// The color space in effect.
    pub color_space: String,
    /// Where the directive is.
    pub loc: Loc,
}

/// An `ObjectBegin ... ObjectEnd` block.
#[derive(Debug, Clone)]
pub struct InstanceDefinition {
    /// The object's name.
    pub name: String,
    /// Its shapes.
    pub shapes: Vec<ShapeDesc>,
    /// Where `ObjectBegin` is.
    pub loc: Loc,
}

/// An `ObjectInstance` directive.
#[derive(Debug, Clone)]
pub struct InstanceUse {
    /// The instanced object's name.
    pub name: String,
    /// The CTM at the directive.
    pub render_from_instance: Mat4d,
    /// The CTM at the end time when it differs (a moving instance).
    pub render_from_instance_end: Option<Mat4d>,
    /// Where the directive is.
    pub loc: Loc,
}

/// Everything a scene file describes.
#[derive(Debug, Clone, Default)]
pub struct SceneDescription {
    /// The camera, if any.
    pub camera: Option<CameraDesc>,
    /// `Film`.
    pub film: Option<Entity>,
    /// `Sampler`.
    pub sampler: Option<Entity>,
    /// `Integrator`.
    pub integrator: Option<Entity>,
    /// `PixelFilter`.
    pub filter: Option<Entity>,
    /// `Accelerator`.
    pub accelerator: Option<Entity>,
    /// `Option` directives: (name, value).
    pub options: Vec<(String, Param)>,
    /// `Texture` directives in order.
    pub textures: Vec<TextureDesc>,
    /// `MakeNamedMaterial` directives.
    pub named_materials: Vec<(String, MaterialDesc)>,
    /// Anonymous `Material` directives, referenced by [`MaterialRef::Index`].
    pub materials: Vec<MaterialDesc>,
    /// `LightSource` directives.
    pub lights: Vec<LightDesc>,
    /// Shapes outside object definitions.
    pub shapes: Vec<ShapeDesc>,
    /// `ObjectBegin`/`ObjectEnd` blocks.
    pub instance_definitions: Vec<InstanceDefinition>,
    /// `ObjectInstance` directives.
    pub instances: Vec<InstanceUse>,
    /// `TransformTimes` (default 0 1).
    pub transform_times: [f32; 2],
    /// Non-fatal problems found while parsing.
    pub warnings: Vec<Warning>,
    /// The main scene file's directory; relative file names resolve here.
    pub base_dir: PathBuf,
    /// The scene files read, main file first, then every `Include`/`Import`
    /// in reading order, each with a hash of its bytes (for checkpoints and
    /// partial renders, which must come from the same scene, and for packing
    /// a scene with its files).
    pub sources: Vec<SourceFile>,
}

/// A scene file that was read and the FNV-1a hash of its (decompressed) bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SourceFile {
    /// The path as resolved when it was read.
    pub path: PathBuf,
    /// FNV-1a 64 of its bytes.
    pub hash: u64,
}

/// FNV-1a 64-bit hash of `bytes` [Fowler, Noll, Vo].
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}
