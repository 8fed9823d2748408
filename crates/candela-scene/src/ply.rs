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
//!
//! The reader is strict where a lenient one would silently lose geometry:
//! the header must declare a `vertex` element with `x y z` and a `face`
//! element with a vertex index list; a face with fewer than three indices,
//! an index past the vertex count, and any data left after the last
//! declared element (apart from trailing whitespace in ASCII files) are
//! errors. Trailing data almost always means a header count is too small,
//! which would otherwise shift every later record and read as a mesh with
//! no triangles. Errors in ASCII bodies name `file:line:col`; in binary
//! bodies the byte offset in the file. Counts in the header are trusted for
//! loops only: every record consumes input, so a count larger than the file
//! ends at "unexpected end" instead of allocating what the header claims.

use std::path::Path;

use crate::error::{Loc, SceneError};
use crate::input;

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
    /// Header line of the `element` declaration.
    line: u32,
}

/// What the header says: encoding, elements and where the body starts.
struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Byte offset of the body in the file.
    body_start: usize,
    /// Line number of `end_header`.
    lines: u32,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    Ascii,
    Little,
    Big,
}

/// Reads a PLY file (gunzipping `.gz`) into triangles.
pub fn read_ply(path: &Path) -> Result<MeshData> {
    let bytes = input::read_file(path, &Loc::file_only(path), input::MAX_PLY_FILE_BYTES)?;
    parse_ply(&bytes, path)
}

/// Decodes PLY `bytes`; `path` is used for error locations.
pub fn parse_ply(bytes: &[u8], path: &Path) -> Result<MeshData> {
    let h = parse_header(bytes, path)?;
    check_elements(&h, path)?;
    let body = bytes.get(h.body_start..).unwrap_or(&[]);
    let mut mesh = match h.format {
        Format::Ascii => read_body(&mut Ascii::new(body, path, h.lines), &h.elements)?,
        Format::Little => read_body(
            &mut Binary::<false>::new(body, path, h.body_start),
            &h.elements,
        )?,
        Format::Big => read_body(
            &mut Binary::<true>::new(body, path, h.body_start),
            &h.elements,
        )?,
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

/// Requires a `vertex` element with `x y z` and a `face` element with a
/// vertex index list, so a mesh cannot silently come out empty.
fn check_elements(h: &Header, path: &Path) -> Result<()> {
    let at = |line: u32, m: String| {
        let loc = Loc {
            file: path.into(),
            line,
            col: 1,
        };
        SceneError::at(&loc, m)
    };
    let find = |name: &str| h.elements.iter().find(|e| e.name == name);
    let Some(v) = find("vertex") else {
        return Err(at(
            h.lines,
            "PLY header declares no 'vertex' element".into(),
        ));
    };
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        if !v.props.iter().any(|p| p.slot == Slot::Pos(axis)) {
            let m = format!("PLY 'vertex' element has no '{name}' property");
            return Err(at(v.line, m));
        }
    }
    let faces = find("face").filter(|f| f.props.iter().any(|p| p.slot == Slot::VertexIndices));
    if faces.is_none() {
        return Err(at(
            find("face").map_or(h.lines, |f| f.line),
            "PLY header declares no 'face' element with a 'vertex_indices' list".into(),
        ));
    }
    Ok(())
}

/// Parses the header.
fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    let mut pos = 0;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut lines = 0;
    for line_no in 1u32.. {
        lines = line_no;
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
                if elements.iter().any(|e| e.name == *name) {
                    return Err(err(format!("PLY element '{name}' declared twice")));
                }
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                    line: line_no,
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
    Ok(Header {
        format,
        elements,
        body_start: pos,
        lines,
    })
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
    /// An error about the value read last, located in the file.
    fn error(&self, message: String) -> SceneError;
    /// An error if anything but (ASCII) whitespace is left.
    fn finish(&mut self) -> Result<()>;
}

/// Binary body; `BIG` selects big-endian.
struct Binary<'a, const BIG: bool> {
    data: &'a [u8],
    pos: usize,
    /// Start of the last value read.
    last: usize,
    /// File offset of `data[0]`.
    offset: usize,
    path: &'a Path,
}

impl<'a, const BIG: bool> Binary<'a, BIG> {
    fn new(data: &'a [u8], path: &'a Path, offset: usize) -> Self {
        Binary {
            data,
            pos: 0,
            last: 0,
            offset,
            path,
        }
    }

    fn take<const N: usize>(&mut self) -> Result<[u8; N]> {
        self.last = self.pos;
        let bytes = self
            .data
            .get(self.pos..self.pos.saturating_add(N))
            .and_then(|s| <[u8; N]>::try_from(s).ok());
        match bytes {
            Some(b) => {
                self.pos += N;
                Ok(b)
            }
            None => Err(self.error("unexpected end of PLY data".into())),
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

    fn error(&self, message: String) -> SceneError {
        let at = self.offset.saturating_add(self.last);
        SceneError::at(
            &Loc::file_only(self.path),
            format!("{message} (binary data at byte {at})"),
        )
    }

    fn finish(&mut self) -> Result<()> {
        let left = self.data.len().saturating_sub(self.pos);
        if left == 0 {
            return Ok(());
        }
        self.last = self.pos;
        Err(self.error(format!("{left} bytes {TRAILING}")))
    }
}

/// The message for data after the last element.
const TRAILING: &str =
    "of data after the last element the header declares (are the header's counts too small?)";

/// ASCII body: whitespace-separated numbers.
struct Ascii<'a> {
    data: &'a [u8],
    pos: usize,
    /// Line and column of the last word read.
    line: u32,
    col: u32,
    /// Current line number and the offset where it starts.
    cur_line: u32,
    line_start: usize,
    path: &'a Path,
}

impl<'a> Ascii<'a> {
    /// A reader of `data`, which starts after header line `header_lines`.
    fn new(data: &'a [u8], path: &'a Path, header_lines: u32) -> Self {
        let first = header_lines.saturating_add(1);
        Ascii {
            data,
            pos: 0,
            line: first,
            col: 1,
            cur_line: first,
            line_start: 0,
            path,
        }
    }

    /// Skips whitespace, then returns the next word (empty at the end).
    fn word(&mut self) -> &'a [u8] {
        let d = self.data;
        while let Some(&b) = d.get(self.pos).filter(|b| b.is_ascii_whitespace()) {
            self.pos += 1;
            if b == b'\n' {
                self.cur_line = self.cur_line.saturating_add(1);
                self.line_start = self.pos;
            }
        }
        let start = self.pos;
        while d.get(self.pos).is_some_and(|b| !b.is_ascii_whitespace()) {
            self.pos += 1;
        }
        self.line = self.cur_line;
        self.col = u32::try_from(start - self.line_start + 1).unwrap_or(u32::MAX);
        d.get(start..self.pos).unwrap_or(&[])
    }
}

impl Source for Ascii<'_> {
    fn value(&mut self, _ty: Scalar) -> Result<f64> {
        let word = self.word();
        if word.is_empty() {
            return Err(self.error("unexpected end of PLY data".into()));
        }
        match std::str::from_utf8(word)
            .ok()
            .and_then(|s| s.parse::<f64>().ok())
        {
            Some(v) => Ok(v),
            None => Err(self.error(format!(
                "expected a number, found '{}'",
                String::from_utf8_lossy(word)
            ))),
        }
    }

    fn error(&self, message: String) -> SceneError {
        let loc = Loc {
            file: self.path.into(),
            line: self.line,
            col: self.col,
        };
        SceneError::at(&loc, message)
    }

    fn finish(&mut self) -> Result<()> {
        let word = self.word();
        if word.is_empty() {
            return Ok(());
        }
        Err(self.error(format!("'{}' {TRAILING}", String::from_utf8_lossy(word))))
    }
}

/// Reads all elements, then requires the body to end there.
fn read_body<S: Source>(src: &mut S, elements: &[Element]) -> Result<MeshData> {
    let mut mesh = MeshData::default();
    let mut poly = Vec::new();
    let nverts = elements
        .iter()
        .find(|e| e.name == "vertex")
        .map_or(0, |e| e.count);
    for el in elements {
        let has = |f: fn(&Slot) -> bool| el.props.iter().any(|p| f(&p.slot));
        let want_n = has(|s| matches!(s, Slot::Normal(_)));
        let want_uv = has(|s| matches!(s, Slot::Uv(_)));
        let want_fi = has(|s| *s == Slot::FaceIndex);
        // Records without properties are empty: skip them without looping
        // over a count that may be absurd.
        if el.props.is_empty() {
            continue;
        }
        for record in 0..el.count {
            let mut rec = Record::default();
            for p in &el.props {
                read_property(src, p, &mut rec, &mut poly, nverts)?;
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
                if poly.len() < 3 {
                    return Err(src.error(format!(
                        "face {record} has {} vertex indices (a face needs at least 3)",
                        poly.len()
                    )));
                }
                triangulate(&poly, &mut mesh, want_fi.then_some(rec.face_index));
                poly.clear();
            }
        }
    }
    src.finish()?;
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

/// Reads one property into `rec` (or `poly` for vertex indices, which must
/// be below `nverts`).
fn read_property<S: Source>(
    src: &mut S,
    p: &Property,
    rec: &mut Record,
    poly: &mut Vec<u32>,
    nverts: usize,
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
        return Err(src.error(format!("invalid list count {count}")));
    }
    for _ in 0..count as usize {
        let v = src.value(p.ty)?;
        if p.slot == Slot::VertexIndices {
            if !(v >= 0.0 && v.fract() == 0.0 && v < nverts as f64) {
                let m = format!("vertex index {v} out of range (the mesh has {nverts} vertices)");
                return Err(src.error(m));
            }
            poly.push(v as u32);
        }
    }
    Ok(())
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
