//! Typed parameter lists (`"float fov" [ 45 ]`) and their getters.
//!
//! A [`ParamSet`] is the parameter list of one entity (shape, light, ...),
//! already checked for value kinds and counts by the parser. Renderers read
//! it through typed getters that mark each parameter as used and return a
//! [`SceneError`] at the parameter's own location on a type mismatch; after
//! building an entity, [`ParamSet::unused`] lists what it never looked at so
//! typos can be reported. When a name appears more than once the last one
//! wins, which also gives entity parameters precedence over `Attribute`
//! defaults (those are placed first).

use std::cell::Cell;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::error::{Loc, SceneError};
use crate::spectrum::{ParamSpectrum, SpectrumValue};

/// The declared type of a parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamType {
    /// `float`
    Float,
    /// `integer`
    Integer,
    /// `bool`
    Bool,
    /// `string`
    String,
    /// `point2`
    Point2,
    /// `vector2`
    Vector2,
    /// `point3` (alias `point`)
    Point3,
    /// `vector3` (alias `vector`)
    Vector3,
    /// `normal3` (alias `normal`)
    Normal3,
    /// `rgb` (alias `color`)
    Rgb,
    /// `blackbody`
    Blackbody,
    /// `spectrum`
    Spectrum,
    /// `texture` (the value is a texture name)
    Texture,
}

impl ParamType {
    /// Parses a type name as written in a scene file, including aliases.
    pub fn from_name(s: &str) -> Option<ParamType> {
        Some(match s {
            "float" => ParamType::Float,
            "integer" => ParamType::Integer,
            "bool" => ParamType::Bool,
            "string" => ParamType::String,
            "point2" => ParamType::Point2,
            "vector2" => ParamType::Vector2,
            "point3" | "point" => ParamType::Point3,
            "vector3" | "vector" => ParamType::Vector3,
            "normal3" | "normal" => ParamType::Normal3,
            "rgb" | "color" => ParamType::Rgb,
            "blackbody" => ParamType::Blackbody,
            "spectrum" => ParamType::Spectrum,
            "texture" => ParamType::Texture,
            _ => return None,
        })
    }

    /// The canonical name (as used in messages).
    pub fn name(self) -> &'static str {
        match self {
            ParamType::Float => "float",
            ParamType::Integer => "integer",
            ParamType::Bool => "bool",
            ParamType::String => "string",
            ParamType::Point2 => "point2",
            ParamType::Vector2 => "vector2",
            ParamType::Point3 => "point3",
            ParamType::Vector3 => "vector3",
            ParamType::Normal3 => "normal3",
            ParamType::Rgb => "rgb",
            ParamType::Blackbody => "blackbody",
            ParamType::Spectrum => "spectrum",
            ParamType::Texture => "texture",
        }
    }

    /// How many numbers make one element (1 for scalars and non-numbers).
    pub fn arity(self) -> usize {
        match self {
            ParamType::Point2 | ParamType::Vector2 => 2,
            ParamType::Point3 | ParamType::Vector3 | ParamType::Normal3 | ParamType::Rgb => 3,
            _ => 1,
        }
    }
}

impl fmt::Display for ParamType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The values of a parameter, stored by kind.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamValue {
    /// float, point*, vector*, normal3, rgb and blackbody values, flattened.
    Floats(Vec<f32>),
    /// integer values.
    Ints(Vec<i32>),
    /// bool values.
    Bools(Vec<bool>),
    /// string values and texture names.
    Strings(Vec<String>),
    /// A `spectrum` value (inline pairs, named, or read from a file).
    Spectrum(SpectrumValue),
}

/// One parameter of an entity.
#[derive(Debug, Clone)]
pub struct Param {
    /// Parameter name, e.g. `fov`.
    pub name: String,
    /// Declared type (aliases resolved).
    pub ty: ParamType,
    /// The values.
    pub value: ParamValue,
    /// Where the parameter's `"type name"` string starts.
    pub loc: Loc,
    /// Set when a getter reads the parameter.
    pub used: Cell<bool>,
    /// True for defaults inherited from `Attribute`: never reported unused.
    pub may_be_unused: bool,
}

/// The parameter list of one entity. Lookups find the last parameter with
/// a given name.
#[derive(Debug, Clone)]
pub struct ParamSet {
    /// The parameters in file order (attribute defaults first).
    pub params: Vec<Param>,
    /// Directory that relative file names resolve against (the main scene
    /// file's directory, as in pbrt-v4).
    pub base_dir: Arc<Path>,
}

impl Default for ParamSet {
    fn default() -> Self {
        ParamSet {
            params: Vec::new(),
            base_dir: Arc::from(Path::new("")),
        }
    }
}

/// Resolves a file name like pbrt-v4's `ResolveFilename`: absolute paths
/// are kept, relative ones are joined to `base_dir`.
pub(crate) fn resolve_path(base_dir: &Path, name: &str) -> PathBuf {
    let p = Path::new(name);
    if p.is_absolute() || base_dir.as_os_str().is_empty() {
        p.to_path_buf()
    } else {
        base_dir.join(p)
    }
}

impl ParamSet {
    /// An empty set resolving files against `base_dir`.
    pub fn new(base_dir: Arc<Path>) -> ParamSet {
        ParamSet {
            params: Vec::new(),
            base_dir,
        }
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.params.len()
    }

    /// Whether there are no parameters.
    pub fn is_empty(&self) -> bool {
        self.params.is_empty()
    }

    /// The last parameter called `name`, without marking it used.
    pub fn get(&self, name: &str) -> Option<&Param> {
        self.params.iter().rev().find(|p| p.name == name)
    }

    /// Where parameter `name` was written, for callers reporting errors.
    pub fn param_loc(&self, name: &str) -> Option<&Loc> {
        self.get(name).map(|p| &p.loc)
    }

    /// An error at parameter `name`'s location, or at `fallback` when the
    /// parameter is absent.
    pub fn error_at(&self, name: &str, fallback: &Loc, message: impl Into<String>) -> SceneError {
        SceneError::at(self.param_loc(name).unwrap_or(fallback), message)
    }

    /// Marks every parameter read, for an entity that is deliberately left
    /// out (its parameters are then not "unused").
    pub fn mark_all_used(&self) {
        for p in &self.params {
            p.used.set(true);
        }
    }

    /// Parameters never read by a getter (and not inherited defaults).
    pub fn unused(&self) -> Vec<(&str, &Loc)> {
        self.params
            .iter()
            .filter(|p| !p.used.get() && !p.may_be_unused)
            .map(|p| (p.name.as_str(), &p.loc))
            .collect()
    }

    /// Finds `name`, checks its type is one of `types`, and marks it used.
    fn lookup(
        &self,
        name: &str,
        types: &[ParamType],
        what: &str,
    ) -> Result<Option<&Param>, SceneError> {
        let Some(p) = self.get(name) else {
            return Ok(None);
        };
        if !types.contains(&p.ty) {
            return Err(SceneError::at(
                &p.loc,
                format!("expected {what} for '{name}', found {}", p.ty),
            ));
        }
        p.used.set(true);
        Ok(Some(p))
    }

    /// The numbers of a float-like parameter of type `ty`, if present.
    fn floats_of(
        &self,
        name: &str,
        ty: ParamType,
        what: &str,
    ) -> Result<Option<&[f32]>, SceneError> {
        match self.lookup(name, &[ty], what)? {
            Some(Param {
                value: ParamValue::Floats(v),
                ..
            }) => Ok(Some(v)),
            Some(p) => Err(kind_error(p, what)),
            None => Ok(None),
        }
    }

    /// The single element (of `N` numbers) of a float-like parameter.
    fn one_of<const N: usize>(
        &self,
        name: &str,
        ty: ParamType,
        what: &str,
    ) -> Result<Option<[f32; N]>, SceneError> {
        let Some(v) = self.floats_of(name, ty, what)? else {
            return Ok(None);
        };
        let arr: Option<[f32; N]> = v.try_into().ok();
        match arr {
            Some(a) => Ok(Some(a)),
            None => Err(count_error(self, name, what, N, v.len())),
        }
    }

    /// A single float, or `default` when absent.
    pub fn get_float(&self, name: &str, default: f32) -> Result<f32, SceneError> {
        Ok(self
            .one_of::<1>(name, ParamType::Float, "a float")?
            .map_or(default, |[v]| v))
    }

    /// A single integer, or `default` when absent.
    pub fn get_int(&self, name: &str, default: i32) -> Result<i32, SceneError> {
        match self.get_ints(name)? {
            None => Ok(default),
            Some(v) if v.len() == 1 => Ok(v[0]),
            Some(v) => Err(count_error(self, name, "an integer", 1, v.len())),
        }
    }

    /// A single bool, or `default` when absent.
    pub fn get_bool(&self, name: &str, default: bool) -> Result<bool, SceneError> {
        match self.lookup(name, &[ParamType::Bool], "a bool")? {
            None => Ok(default),
            Some(Param {
                value: ParamValue::Bools(v),
                ..
            }) if v.len() == 1 => Ok(v[0]),
            Some(Param {
                value: ParamValue::Bools(v),
                ..
            }) => Err(count_error(self, name, "a bool", 1, v.len())),
            Some(p) => Err(kind_error(p, "a bool")),
        }
    }

    /// A single string, or `default` when absent.
    pub fn get_string(&self, name: &str, default: &str) -> Result<String, SceneError> {
        match self.lookup(name, &[ParamType::String], "a string")? {
            None => Ok(default.to_string()),
            Some(p) => one_string(p, "a string"),
        }
    }

    /// All values of a string parameter, if present.
    pub fn get_strings(&self, name: &str) -> Result<Option<Vec<String>>, SceneError> {
        match self.lookup(name, &[ParamType::String], "strings")? {
            None => Ok(None),
            Some(Param {
                value: ParamValue::Strings(v),
                ..
            }) => Ok(Some(v.clone())),
            Some(p) => Err(kind_error(p, "strings")),
        }
    }

    /// A single point3, or `default` when absent.
    pub fn get_point3(&self, name: &str, default: [f32; 3]) -> Result<[f32; 3], SceneError> {
        Ok(self
            .one_of::<3>(name, ParamType::Point3, "a point3")?
            .unwrap_or(default))
    }

    /// A single vector3, or `default` when absent.
    pub fn get_vector3(&self, name: &str, default: [f32; 3]) -> Result<[f32; 3], SceneError> {
        Ok(self
            .one_of::<3>(name, ParamType::Vector3, "a vector3")?
            .unwrap_or(default))
    }

    /// An rgb triple, if present.
    pub fn get_rgb(&self, name: &str) -> Result<Option<[f32; 3]>, SceneError> {
        self.one_of::<3>(name, ParamType::Rgb, "an rgb")
    }

    /// All values of a float parameter.
    pub fn get_floats(&self, name: &str) -> Result<Option<Vec<f32>>, SceneError> {
        Ok(self
            .floats_of(name, ParamType::Float, "floats")?
            .map(<[f32]>::to_vec))
    }

    /// All values of an integer parameter.
    pub fn get_ints(&self, name: &str) -> Result<Option<Vec<i32>>, SceneError> {
        match self.lookup(name, &[ParamType::Integer], "an integer")? {
            Some(Param {
                value: ParamValue::Ints(v),
                ..
            }) => Ok(Some(v.clone())),
            Some(p) => Err(kind_error(p, "an integer")),
            None => Ok(None),
        }
    }

    /// All values of a point3 parameter.
    pub fn get_point3s(&self, name: &str) -> Result<Option<Vec<[f32; 3]>>, SceneError> {
        self.tuples::<3>(name, ParamType::Point3, "point3s")
    }

    /// All values of a point2 parameter.
    pub fn get_point2s(&self, name: &str) -> Result<Option<Vec<[f32; 2]>>, SceneError> {
        self.tuples::<2>(name, ParamType::Point2, "point2s")
    }

    /// All values of a normal3 parameter.
    pub fn get_normals(&self, name: &str) -> Result<Option<Vec<[f32; 3]>>, SceneError> {
        self.tuples::<3>(name, ParamType::Normal3, "normals")
    }

    /// Float-like values grouped into `N`-tuples (counts checked at parse).
    fn tuples<const N: usize>(
        &self,
        name: &str,
        ty: ParamType,
        what: &str,
    ) -> Result<Option<Vec<[f32; N]>>, SceneError> {
        let Some(v) = self.floats_of(name, ty, what)? else {
            return Ok(None);
        };
        let out = v
            .chunks_exact(N)
            .map(|c| {
                let mut a = [0.0; N];
                a.copy_from_slice(c);
                a
            })
            .collect();
        Ok(Some(out))
    }

    /// A spectrum given as rgb, blackbody or spectrum, if present.
    pub fn get_spectrum(&self, name: &str) -> Result<Option<ParamSpectrum>, SceneError> {
        let types = [ParamType::Rgb, ParamType::Blackbody, ParamType::Spectrum];
        let what = "a spectrum (rgb, blackbody or spectrum)";
        let Some(p) = self.lookup(name, &types, what)? else {
            return Ok(None);
        };
        match (&p.ty, &p.value) {
            (ParamType::Rgb, ParamValue::Floats(v)) => match <[f32; 3]>::try_from(v.as_slice()) {
                Ok(a) => Ok(Some(ParamSpectrum::Rgb(a))),
                Err(_) => Err(count_error(self, name, "an rgb", 3, v.len())),
            },
            (ParamType::Blackbody, ParamValue::Floats(v)) => match v.as_slice() {
                [t] => Ok(Some(ParamSpectrum::Value(SpectrumValue::Blackbody(*t)))),
                _ => Err(count_error(self, name, "a blackbody", 1, v.len())),
            },
            (_, ParamValue::Spectrum(s)) => Ok(Some(ParamSpectrum::Value(s.clone()))),
            _ => Err(kind_error(p, what)),
        }
    }

    /// The texture name of a `texture` parameter; `None` if absent or if
    /// the parameter has another type (then it is left unmarked).
    pub fn get_texture(&self, name: &str) -> Option<String> {
        let p = self.get(name).filter(|p| p.ty == ParamType::Texture)?;
        p.used.set(true);
        match &p.value {
            ParamValue::Strings(v) => v.first().cloned(),
            _ => None,
        }
    }

    /// A file name parameter resolved like pbrt-v4: relative to the main
    /// scene file's directory; absolute paths are kept.
    pub fn get_filename(&self, name: &str) -> Result<Option<PathBuf>, SceneError> {
        match self.lookup(name, &[ParamType::String], "a string")? {
            None => Ok(None),
            Some(p) => {
                let s = one_string(p, "a file name")?;
                Ok(Some(resolve_path(&self.base_dir, &s)))
            }
        }
    }
}

/// The single string value of `p`.
fn one_string(p: &Param, what: &str) -> Result<String, SceneError> {
    match &p.value {
        ParamValue::Strings(v) if v.len() == 1 => Ok(v[0].clone()),
        ParamValue::Strings(v) => Err(SceneError::at(
            &p.loc,
            format!("expected one value for '{}', found {}", p.name, v.len()),
        )),
        _ => Err(kind_error(p, what)),
    }
}

/// Error for a parameter whose stored values do not match its type.
fn kind_error(p: &Param, what: &str) -> SceneError {
    SceneError::at(&p.loc, format!("expected {what} for '{}'", p.name))
}

/// Error for a parameter with the wrong number of values.
fn count_error(set: &ParamSet, name: &str, what: &str, want: usize, got: usize) -> SceneError {
    let loc = set
        .param_loc(name)
        .cloned()
        .unwrap_or_else(|| Loc::file_only(Path::new("")));
    let unit = if want == 1 { "value" } else { "numbers" };
    SceneError::at(
        &loc,
        format!("expected {what} ({want} {unit}) for '{name}', found {got} values"),
    )
}
