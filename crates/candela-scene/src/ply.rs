//! A small PLY mesh reader (ascii, binary little- and big-endian, `.ply.gz`).
//!
//! The header declares elements (`element vertex 8`) with scalar or list
//! properties; the body stores them in order. We keep what pbrt-v4's
//! `plymesh` uses — vertex `x y z`, `nx ny nz`, `u v` (or `s t`,
//! `texture_u texture_v`, `texture_s texture_t`), face `vertex_indices`
//! (or `vertex_index`) and `face_indices` — and skip everything else, of
//! any scalar type or list. Polygons are fan-triangulated (a quad becomes
//! two triangles), and every index is checked against the vertex count.
//!
//! The whole file is read into memory and the body decoded by a reader
//! generic over the encoding, so a binary file decodes with one
//! `from_le_bytes` per value.

use std::io::Read;
use std::path::Path;

use crate::error::{Loc, SceneError};

type Result<T> = std::result::Result<T, SceneError>;

/// Triangle mesh data read from a PLY file.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions.
    pub positions: Vec<[f32; 3]>,
    /// Per-vertex normals, if the file has `nx ny nz`.
    pub normals: Option<Vec<[f32; 3]>>,
    /// Per-vertex texture coordinates, if the file has them.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Three vertex indices per triangle.
    pub indices: Vec<u32>,
    /// Per-triangle `face_indices` values, if present.
    pub face_indices: Option<Vec<i32>>,
}

/// A PLY scalar type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn is_int(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

/// What a property feeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Slot {
    Pos(usize),
    Normal(usize),
    Uv(usize),
    VertexIndices,
    FaceIndex,
    Skip,
}

#[derive(Debug, Clone)]
struct Property {
    /// `Some(count type)` for list properties.
    list: Option<Scalar>,
    ty: Scalar,
    slot: Slot,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    Ascii,
    Little,
    Big,
}

/// Reads a PLY file (gunzipping `.gz`) into triangles.
pub fn read_ply(path: &Path) -> Result<MeshData> {
    let loc = Loc::file_only(path);
    let raw = std::fs::read(path).map_err(|e| SceneError::io(&loc, path, e))?;
    let bytes = if path.extension().is_some_and(|e| e == "gz") {
        let mut out = Vec::new();
        flate2::read::MultiGzDecoder::new(raw.as_slice())
            .read_to_end(&mut out)
            .map_err(|e| SceneError::io(&loc, path, e))?;
        out
    } else {
        raw
    };
    parse_ply(&bytes, path)
}

/// Decodes PLY `bytes`; `path` is used for error locations.
pub fn parse_ply(bytes: &[u8], path: &Path) -> Result<MeshData> {
    let (format, elements, body_start) = parse_header(bytes, path)?;
    let body = bytes.get(body_start..).unwrap_or(&[]);
    let mut mesh = match format {
        Format::Ascii => read_body(&mut Ascii::new(body, path), &elements, body.len())?,
        Format::Little => read_body(&mut Binary::<false>::new(body, path), &elements, body.len())?,
        Format::Big => read_body(&mut Binary::<true>::new(body, path), &elements, body.len())?,
    };
    let n = mesh.positions.len();
    if let Some(bad) = mesh.indices.iter().find(|&&i| i as usize >= n) {
        return Err(SceneError::at(
            &Loc::file_only(path),
            format!("vertex index {bad} out of range (the mesh has {n} vertices)"),
        ));
    }
    if mesh.normals.as_ref().is_some_and(|v| v.is_empty()) && n > 0 {
        mesh.normals = None;
    }
    Ok(mesh)
}

/// Parses the header; returns the format, elements and body offset.
fn parse_header(bytes: &[u8], path: &Path) -> Result<(Format, Vec<Element>, usize)> {
    let mut pos = 0;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    for line_no in 1u32.. {
        let err = |m: String| {
            SceneError::at(
                &Loc {
                    file: path.into(),
                    line: line_no,
                    col: 1,
                },
                m,
            )
        };
        let rest = bytes.get(pos..).unwrap_or(&[]);
        let Some(nl) = rest.iter().position(|&b| b == b'\n') else {
            return Err(err("unexpected end of file in PLY header".into()));
        };
        pos += nl + 1;
        let line = String::from_utf8_lossy(rest.get(..nl).unwrap_or(&[]));
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["ply"] if line_no == 1 => {}
            _ if line_no == 1 => return Err(err("not a PLY file (missing 'ply' magic)".into())),
            ["format", f, _] => {
                format = Some(match *f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Little,
                    "binary_big_endian" => Format::Big,
                    _ => return Err(err(format!("unknown PLY format '{f}'"))),
                })
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            ["element", name, count] => {
                let count = count
                    .parse()
                    .map_err(|_| err(format!("bad element count '{count}'")))?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                });
            }
            ["property", rest @ ..] => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| err("property before any element".into()))?;
                let prop = property(rest, &el.name).map_err(err)?;
                el.props.push(prop);
            }
            ["end_header"] => break,
            _ => return Err(err(format!("unexpected PLY header line '{line}'"))),
        }
    }
    let format = format
        .ok_or_else(|| SceneError::at(&Loc::file_only(path), "PLY header has no 'format' line"))?;
    Ok((format, elements, pos))
}

/// Parses `property <type> <name>` or `property list <ct> <it> <name>`.
fn property(words: &[&str], element: &str) -> std::result::Result<Property, String> {
    let ty = |s: &str| Scalar::parse(s).ok_or_else(|| format!("unknown PLY type '{s}'"));
    let (list, t, name) = match words {
        ["list", c, t, name] => (Some(ty(c)?), ty(t)?, *name),
        [t, name] => (None, ty(t)?, *name),
        _ => {
            return Err(format!(
                "malformed property line 'property {}'",
                words.join(" ")
            ))
        }
    };
    let slot = match (element, name, list.is_some()) {
        ("vertex", "x", false) => Slot::Pos(0),
        ("vertex", "y", false) => Slot::Pos(1),
        ("vertex", "z", false) => Slot::Pos(2),
        ("vertex", "nx", false) => Slot::Normal(0),
        ("vertex", "ny", false) => Slot::Normal(1),
        ("vertex", "nz", false) => Slot::Normal(2),
        ("vertex", "u" | "s" | "texture_u" | "texture_s", false) => Slot::Uv(0),
        ("vertex", "v" | "t" | "texture_v" | "texture_t", false) => Slot::Uv(1),
        ("face", "vertex_indices" | "vertex_index", true) => Slot::VertexIndices,
        ("face", "face_indices", false) => Slot::FaceIndex,
        _ => Slot::Skip,
    };
    if slot == Slot::VertexIndices && !t.is_int() {
        return Err(format!("'{name}' must have an integer type"));
    }
    Ok(Property { list, ty: t, slot })
}

/// A body decoder.
trait Source {
    /// Reads one value of type `ty`.
    fn value(&mut self, ty: Scalar) -> Result<f64>;
    /// The file being decoded.
    fn path(&self) -> &Path;
}

/// Binary body; `BIG` selects big-endian.
struct Binary<'a, const BIG: bool> {
    data: &'a [u8],
    pos: usize,
    path: &'a Path,
}

impl<'a, const BIG: bool> Binary<'a, BIG> {
    fn new(data: &'a [u8], path: &'a Path) -> Self {
        Binary { data, pos: 0, path }
    }

    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        let bytes = self
            .data
            .get(self.pos..self.pos + N)
            .and_then(|s| <[u8; N]>::try_from(s).ok());
        match bytes {
            Some(b) => {
                self.pos += N;
                Ok(b)
            }
            None => Err(SceneError::at(
                &Loc::file_only(self.path),
                format!("unexpected end of PLY data at body byte {}", self.pos),
            )),
        }
    }
}

macro_rules! decode {
    ($self:ident, $t:ty, $n:literal) => {{
        let b = $self.take::<$n>()?;
        (if BIG {
            <$t>::from_be_bytes(b)
        } else {
            <$t>::from_le_bytes(b)
        }) as f64
    }};
}

impl<const BIG: bool> Source for Binary<'_, BIG> {
    fn path(&self) -> &Path {
        self.path
    }

    fn value(&mut self, ty: Scalar) -> Result<f64> {
        Ok(match ty {
            Scalar::I8 => decode!(self, i8, 1),
            Scalar::U8 => decode!(self, u8, 1),
            Scalar::I16 => decode!(self, i16, 2),
            Scalar::U16 => decode!(self, u16, 2),
            Scalar::I32 => decode!(self, i32, 4),
            Scalar::U32 => decode!(self, u32, 4),
            Scalar::F32 => decode!(self, f32, 4),
            Scalar::F64 => decode!(self, f64, 8),
        })
    }
}

/// ASCII body: whitespace-separated numbers.
struct Ascii<'a> {
    data: &'a [u8],
    pos: usize,
    path: &'a Path,
}

impl<'a> Ascii<'a> {
    fn new(data: &'a [u8], path: &'a Path) -> Self {
        Ascii { data, pos: 0, path }
    }
}

impl Source for Ascii<'_> {
    fn path(&self) -> &Path {
        self.path
    }

    fn value(&mut self, _ty: Scalar) -> Result<f64> {
        let d = self.data;
        while d.get(self.pos).is_some_and(|b| b.is_ascii_whitespace()) {
            self.pos += 1;
        }
        let start = self.pos;
        while d.get(self.pos).is_some_and(|b| !b.is_ascii_whitespace()) {
            self.pos += 1;
        }
        let word = d.get(start..self.pos).unwrap_or(&[]);
        match std::str::from_utf8(word)
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
        {
            Some(v) => Ok(v),
            None => Err(SceneError::at(
                &Loc::file_only(self.path),
                format!(
                    "expected a number in ASCII PLY body at byte {start}, found '{}'",
                    String::from_utf8_lossy(word)
                ),
            )),
        }
    }
}

/// Reads all elements; `len` bounds preallocation for corrupt counts.
fn read_body<S: Source>(src: &mut S, elements: &[Element], len: usize) -> Result<MeshData> {
    let mut mesh = MeshData::default();
    let mut poly = Vec::new();
    for el in elements {
        let has = |f: fn(&Slot) -> bool| el.props.iter().any(|p| f(&p.slot));
        let want_n = has(|s| matches!(s, Slot::Normal(_)));
        let want_uv = has(|s| matches!(s, Slot::Uv(_)));
        let want_fi = has(|s| *s == Slot::FaceIndex);
        if el.props.is_empty() && el.count > len {
            return Err(SceneError::at(
                &Loc::file_only(src.path()),
                format!(
                    "element '{}' claims {} records but has no properties",
                    el.name, el.count
                ),
            ));
        }
        let cap = el.count.min(len);
        if el.name == "vertex" {
            mesh.positions.reserve(cap);
        }
        for _ in 0..el.count {
            let mut rec = Record::default();
            for p in &el.props {
                read_property(src, p, &mut rec, &mut poly)?;
            }
            if el.name == "vertex" {
                mesh.positions.push(rec.pos);
                if want_n {
                    mesh.normals.get_or_insert_with(Vec::new).push(rec.normal);
                }
                if want_uv {
                    mesh.uvs.get_or_insert_with(Vec::new).push(rec.uv);
                }
            } else if el.name == "face" {
                triangulate(&poly, &mut mesh, want_fi.then_some(rec.face_index));
                poly.clear();
            }
        }
    }
    Ok(mesh)
}

/// The kept values of one element record.
#[derive(Default)]
struct Record {
    pos: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
    face_index: i32,
}

/// Reads one property into `rec` (or `poly` for vertex indices).
fn read_property<S: Source>(
    src: &mut S,
    p: &Property,
    rec: &mut Record,
    poly: &mut Vec<u32>,
) -> Result<()> {
    let Some(count_ty) = p.list else {
        let v = src.value(p.ty)?;
        match p.slot {
            Slot::Pos(i) => rec.pos[i] = v as f32,
            Slot::Normal(i) => rec.normal[i] = v as f32,
            Slot::Uv(i) => rec.uv[i] = v as f32,
            Slot::FaceIndex => rec.face_index = v as i32,
            Slot::VertexIndices | Slot::Skip => {}
        }
        return Ok(());
    };
    let count = src.value(count_ty)?;
    if count < 0.0 || count.fract() != 0.0 {
        return Err(bad_value(src, "list count", count));
    }
    for _ in 0..count as usize {
        let v = src.value(p.ty)?;
        if p.slot == Slot::VertexIndices {
            if !(0.0..=u32::MAX as f64).contains(&v) {
                return Err(bad_value(src, "vertex index", v));
            }
            poly.push(v as u32);
        }
    }
    Ok(())
}

fn bad_value<S: Source>(src: &S, what: &str, v: f64) -> SceneError {
    SceneError::at(&Loc::file_only(src.path()), format!("invalid {what} {v}"))
}

/// Fan-triangulates one polygon into `mesh` (degenerate ones are skipped).
fn triangulate(poly: &[u32], mesh: &mut MeshData, face_index: Option<i32>) {
    let Some((&first, rest)) = poly.split_first() else {
        return;
    };
    for pair in rest.windows(2) {
        mesh.indices.extend_from_slice(&[first, pair[0], pair[1]]);
        if let Some(fi) = face_index {
            mesh.face_indices.get_or_insert_with(Vec::new).push(fi);
        }
    }
}
