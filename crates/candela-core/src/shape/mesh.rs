//! Indexed triangle meshes stored in render space.
//!
//! Vertex data are transformed once at load time, so triangles intersect in
//! render space without per-ray transforms [pbrt-v4 §6.5.1, `TriangleMesh`].
//! Positions go through the point transform, normals through the inverse
//! transpose; normals are negated when the shape's orientation is reversed,
//! as pbrt-v4 does, so shading normals and geometric normals stay on the
//! same side.

use crate::math::{Transform, Vec2, Vec3};
use thiserror::Error;

/// Why a mesh description was rejected.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum MeshError {
    /// The index count is not a multiple of three.
    #[error("triangle mesh has {0} indices, not a multiple of 3")]
    IndexCount(usize),
    /// The index count is not a multiple of four (bilinear patch meshes).
    #[error("bilinear patch mesh has {0} indices, not a multiple of 4")]
    PatchIndexCount(usize),
    /// An index refers past the vertex arrays.
    #[error("mesh vertex index {index} out of range for {vertices} vertices")]
    IndexOutOfRange {
        /// The offending index.
        index: u32,
        /// Number of vertices.
        vertices: usize,
    },
    /// A per-vertex attribute array has the wrong length.
    #[error("mesh attribute \"{name}\" has {len} entries, expected {expected}")]
    AttributeLength {
        /// Attribute name (`N`, `uv`, `faceIndices`).
        name: &'static str,
        /// Given length.
        len: usize,
        /// Required length.
        expected: usize,
    },
}

/// A triangle mesh in render space.
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleMesh {
    /// Vertex positions (render space).
    pub p: Vec<Vec3>,
    /// Per-vertex shading normals (render space, already flipped by `reverse_orientation`).
    pub n: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates.
    pub uv: Option<Vec<Vec2>>,
    /// Three vertex indices per triangle.
    pub indices: Vec<u32>,
    /// Per-triangle face index (for `ptex`-style lookups).
    pub face_indices: Option<Vec<i32>>,
    /// The shape's `ReverseOrientation` flag.
    pub reverse_orientation: bool,
    /// Whether the object-to-render transform flips handedness.
    pub transform_swaps_handedness: bool,
}

impl TriangleMesh {
    /// Builds a render-space mesh from object-space data.
    pub fn new(
        render_from_object: &Transform,
        reverse_orientation: bool,
        indices: Vec<u32>,
        p: Vec<Vec3>,
        n: Option<Vec<Vec3>>,
        uv: Option<Vec<Vec2>>,
        face_indices: Option<Vec<i32>>,
    ) -> Result<Self, MeshError> {
        validate(3, &indices, p.len(), &n, &uv, &face_indices)?;
        let p = p.iter().map(|&q| render_from_object.point(q)).collect();
        let n = n.map(|ns| render_normals(render_from_object, reverse_orientation, &ns));
        Ok(Self {
            p,
            n,
            uv,
            indices,
            face_indices,
            reverse_orientation,
            transform_swaps_handedness: render_from_object.swaps_handedness(),
        })
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// The three vertex indices of triangle `tri`.
    #[inline]
    pub fn vertex_indices(&self, tri: u32) -> [usize; 3] {
        let i = 3 * tri as usize;
        [
            self.indices[i] as usize,
            self.indices[i + 1] as usize,
            self.indices[i + 2] as usize,
        ]
    }

    /// The three render-space vertex positions of triangle `tri`.
    #[inline]
    pub fn positions(&self, tri: u32) -> [Vec3; 3] {
        let v = self.vertex_indices(tri);
        [self.p[v[0]], self.p[v[1]], self.p[v[2]]]
    }
}

/// Normals moved to render space (inverse transpose), negated when the
/// orientation is reversed [pbrt-v4 `TriangleMesh`, `BilinearPatchMesh`].
pub(super) fn render_normals(t: &Transform, reverse_orientation: bool, ns: &[Vec3]) -> Vec<Vec3> {
    ns.iter()
        .map(|&v| {
            let w = t.normal(v);
            if reverse_orientation {
                -w
            } else {
                w
            }
        })
        .collect()
}

/// Checks index count and range and attribute lengths of a mesh whose
/// faces have `arity` vertices (3: triangles, 4: bilinear patches).
pub(super) fn validate(
    arity: usize,
    indices: &[u32],
    nv: usize,
    n: &Option<Vec<Vec3>>,
    uv: &Option<Vec<Vec2>>,
    face_indices: &Option<Vec<i32>>,
) -> Result<(), MeshError> {
    if !indices.len().is_multiple_of(arity) {
        return Err(if arity == 4 {
            MeshError::PatchIndexCount(indices.len())
        } else {
            MeshError::IndexCount(indices.len())
        });
    }
    if let Some(&index) = indices.iter().find(|&&i| i as usize >= nv) {
        return Err(MeshError::IndexOutOfRange {
            index,
            vertices: nv,
        });
    }
    let check = |name, len, expected| {
        if len == expected {
            Ok(())
        } else {
            Err(MeshError::AttributeLength {
                name,
                len,
                expected,
            })
        }
    };
    if let Some(n) = n {
        check("N", n.len(), nv)?;
    }
    if let Some(uv) = uv {
        check("uv", uv.len(), nv)?;
    }
    if let Some(f) = face_indices {
        check("faceIndices", f.len(), indices.len() / arity)?;
    }
    Ok(())
}
