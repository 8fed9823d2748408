//! `Shape` directives → render-space shapes, with pbrt-v4's parameter names
//! and defaults [pbrt-v4 `Shape::Create`, File Format §Shapes].
//!
//! | shape | parameters (default) |
//! |---|---|
//! | `sphere` | `radius` (1), `zmin` (−radius), `zmax` (radius), `phimax` (360) |
//! | `cylinder` | `radius` (1), `zmin` (−1), `zmax` (1), `phimax` (360) |
//! | `disk` | `height` (0), `radius` (1), `innerradius` (0), `phimax` (360) |
//! | `trianglemesh` | `P`, `indices` (0 1 2 for three points), `N`, `uv`, `faceIndices` |
//! | `plymesh` | `filename` |
//! | `bilinearmesh` | `P`, `indices` (0 1 2 3 for four points), `N`, `uv`, `faceIndices` |
//! | `loopsubdiv` | `levels` (3), `indices`, `P`; `scheme` is read and ignored, as pbrt-v4 does |
//!
//! Parameters no shape reads are reported as unused by the caller.

use super::BuildError;
use crate::math::{Transform, Vec2, Vec3};
use crate::shape::{
    loop_subdivide, BilinearPatch, BilinearPatchMesh, Cylinder, Disk, Shape, Sphere, Triangle,
    TriangleMesh,
};
use candela_scene::{ParamSet, SceneError, ShapeDesc};
use std::sync::Arc;

/// The shapes one `Shape` directive creates, placed by `t`.
pub fn build_shape(s: &ShapeDesc, t: &Transform) -> Result<Vec<Shape>, BuildError> {
    let p = &s.params;
    let (ro, tt) = (s.reverse_orientation, Arc::new(*t));
    Ok(match s.name.as_str() {
        "sphere" => {
            let r = p.get_float("radius", 1.0)?;
            let (zmin, zmax, phimax) = quadric_range(p, -r, r)?;
            vec![Shape::Sphere(Sphere::new(tt, ro, r, zmin, zmax, phimax))]
        }
        "cylinder" => {
            let r = p.get_float("radius", 1.0)?;
            let (zmin, zmax, phimax) = quadric_range(p, -1.0, 1.0)?;
            vec![Shape::Cylinder(Cylinder::new(tt, ro, r, zmin, zmax, phimax))]
        }
        "disk" => {
            let (h, r, ri, phimax) = (
                p.get_float("height", 0.0)?,
                p.get_float("radius", 1.0)?,
                p.get_float("innerradius", 0.0)?,
                p.get_float("phimax", 360.0)?,
            );
            vec![Shape::Disk(Disk::new(tt, ro, h, r, ri, phimax))]
        }
        "trianglemesh" => trianglemesh(s, t)?,
        "plymesh" => plymesh(s, t)?,
        "bilinearmesh" => bilinearmesh(s, t)?,
        "loopsubdiv" => loopsubdiv(s, t)?,
        other => {
            return Err(BuildError::at(
                &s.loc,
                format!("shape \"{other}\" is not supported yet (supported: trianglemesh, plymesh, bilinearmesh, loopsubdiv, sphere, cylinder, disk)"),
            ))
        }
    })
}

/// `zmin`, `zmax` and `phimax` of a quadric.
fn quadric_range(p: &ParamSet, zmin: f32, zmax: f32) -> Result<(f32, f32, f32), BuildError> {
    Ok((
        p.get_float("zmin", zmin)?,
        p.get_float("zmax", zmax)?,
        p.get_float("phimax", 360.0)?,
    ))
}

/// Object-space vertex data of a mesh directive.
struct MeshInput {
    p: Vec<[f32; 3]>,
    indices: Vec<i32>,
    n: Option<Vec<[f32; 3]>>,
    uv: Option<Vec<[f32; 2]>>,
    face: Option<Vec<i32>>,
}

/// Reads `P`, `indices` (defaulting to 0‥k−1 when `P` has exactly `k`
/// points), `N`, `uv` and `faceIndices`.
fn mesh_input(s: &ShapeDesc, k: usize) -> Result<MeshInput, BuildError> {
    let p = &s.params;
    let pos = p
        .get_point3s("P")?
        .ok_or_else(|| BuildError::at(&s.loc, format!("{} needs \"point3 P\"", s.name)))?;
    let indices = match p.get_ints("indices")? {
        Some(i) => i,
        None if pos.len() == k => (0..k as i32).collect(),
        None => {
            return Err(BuildError::at(
                &s.loc,
                format!(
                    "{} needs \"integer indices\" unless it has exactly {k} vertices",
                    s.name
                ),
            ))
        }
    };
    Ok(MeshInput {
        p: pos,
        indices,
        n: p.get_normals("N")?,
        uv: p.get_point2s("uv")?,
        face: p.get_ints("faceIndices")?,
    })
}

/// Checks `indices` against the vertex count and face arity `k`; returns them as `u32`.
fn checked_indices(s: &ShapeDesc, m: &MeshInput, k: usize) -> Result<Vec<u32>, BuildError> {
    let what = if k == 3 {
        "triangle mesh"
    } else {
        "bilinear patch mesh"
    };
    if !m.indices.len().is_multiple_of(k) {
        return Err(BuildError::at(
            &s.loc,
            format!(
                "{what} has {} indices, not a multiple of {k}",
                m.indices.len()
            ),
        ));
    }
    if let Some(bad) = m
        .indices
        .iter()
        .find(|&&i| i < 0 || i as usize >= m.p.len())
    {
        return Err(BuildError::at(
            &s.loc,
            format!(
                "vertex index {bad} out of range (mesh has {} vertices)",
                m.p.len()
            ),
        ));
    }
    if m.n.as_ref().is_some_and(|n| n.len() != m.p.len())
        || m.uv.as_ref().is_some_and(|u| u.len() != m.p.len())
    {
        return Err(BuildError::at(
            &s.loc,
            "\"N\" and \"uv\" must have one entry per vertex of \"P\"",
        ));
    }
    Ok(m.indices.iter().map(|&i| i as u32).collect())
}

fn vec3s(v: &[[f32; 3]]) -> Vec<Vec3> {
    v.iter().map(|a| Vec3::from_array(*a)).collect()
}

fn vec2s(v: &[[f32; 2]]) -> Vec<Vec2> {
    v.iter().map(|a| Vec2::from_array(*a)).collect()
}

/// Triangles of a render-space mesh built from `m`.
fn triangles(s: &ShapeDesc, t: &Transform, m: MeshInput) -> Result<Vec<Shape>, BuildError> {
    let indices = checked_indices(s, &m, 3)?;
    let mesh = TriangleMesh::new(
        t,
        s.reverse_orientation,
        indices,
        vec3s(&m.p),
        m.n.as_deref().map(vec3s),
        m.uv.as_deref().map(vec2s),
        m.face,
    )
    .map_err(|e| BuildError::at(&s.loc, format!("invalid triangle mesh: {e}")))?;
    Ok(triangle_shapes(mesh))
}

/// One shape per triangle of `mesh` (collected straight into shapes: a
/// million-triangle mesh would otherwise be copied through a `Vec<Triangle>`).
fn triangle_shapes(mesh: TriangleMesh) -> Vec<Shape> {
    let mesh = Arc::new(mesh);
    (0..mesh.triangle_count() as u32)
        .map(|i| Shape::Triangle(Triangle::new(mesh.clone(), i)))
        .collect()
}

fn trianglemesh(s: &ShapeDesc, t: &Transform) -> Result<Vec<Shape>, BuildError> {
    let m = mesh_input(s, 3)?;
    triangles(s, t, m)
}

fn plymesh(s: &ShapeDesc, t: &Transform) -> Result<Vec<Shape>, BuildError> {
    let p = &s.params;
    let file = p
        .get_filename("filename")?
        .ok_or_else(|| BuildError::at(&s.loc, "plymesh needs \"string filename\""))?;
    if p.get_texture("displacement").is_some() {
        return Err(BuildError::at(
            &s.loc,
            "plymesh \"displacement\" is not supported yet",
        ));
    }
    // A missing file is reported at the "filename" parameter; a malformed
    // one at the directive, followed by the place in the PLY file.
    let m = candela_scene::read_ply(&file).map_err(|e| match e {
        SceneError::Io { path, error, .. } => {
            let at = p.param_loc("filename").unwrap_or(&s.loc);
            BuildError::Scene(SceneError::io(at, &path, error))
        }
        other => BuildError::at(&s.loc, format!("bad PLY file: {other}")),
    })?;
    let input = MeshInput {
        p: m.positions,
        indices: m.indices.iter().map(|&i| i as i32).collect(),
        n: m.normals,
        uv: m.uvs,
        face: m.face_indices,
    };
    triangles(s, t, input)
}

/// A bilinear patch mesh [pbrt-v4 `BilinearPatch::CreateMesh`].
fn bilinearmesh(s: &ShapeDesc, t: &Transform) -> Result<Vec<Shape>, BuildError> {
    if let Some(f) = s.params.get_filename("emissionfilename")? {
        return Err(BuildError::at(
            &s.loc,
            format!(
                "bilinearmesh \"emissionfilename\" ({}) is not supported yet",
                f.display()
            ),
        ));
    }
    let m = mesh_input(s, 4)?;
    let indices = checked_indices(s, &m, 4)?;
    let mesh = BilinearPatchMesh::new(
        t,
        s.reverse_orientation,
        indices,
        vec3s(&m.p),
        m.n.as_deref().map(vec3s),
        m.uv.as_deref().map(vec2s),
        m.face,
    )
    .map_err(|e| BuildError::at(&s.loc, format!("invalid bilinear patch mesh: {e}")))?;
    Ok(BilinearPatch::all(&Arc::new(mesh))
        .into_iter()
        .map(Shape::BilinearPatch)
        .collect())
}

/// A Loop subdivision surface, refined into a triangle mesh with limit
/// normals [pbrt-v4 `LoopSubdivide`].
fn loopsubdiv(s: &ShapeDesc, t: &Transform) -> Result<Vec<Shape>, BuildError> {
    let p = &s.params;
    let levels = p.get_int("levels", 3)?;
    let levels = u32::try_from(levels).map_err(|_| {
        BuildError::at(
            &s.loc,
            format!("loopsubdiv \"levels\" must be ≥ 0, not {levels}"),
        )
    })?;
    let indices = p
        .get_ints("indices")?
        .ok_or_else(|| BuildError::at(&s.loc, "loopsubdiv needs \"integer indices\""))?;
    let pos = p
        .get_point3s("P")?
        .ok_or_else(|| BuildError::at(&s.loc, "loopsubdiv needs \"point3 P\""))?;
    // pbrt-v4 reads the scheme name and ignores it.
    let _ = p.get_string("scheme", "loop")?;
    let surf = loop_subdivide(levels, &indices, &vec3s(&pos))
        .map_err(|e| BuildError::at(&s.loc, format!("{e}")))?;
    let mesh = TriangleMesh::new(
        t,
        s.reverse_orientation,
        surf.indices,
        surf.p,
        Some(surf.n),
        None,
        None,
    )
    .map_err(|e| BuildError::at(&s.loc, format!("invalid subdivided mesh: {e}")))?;
    Ok(triangle_shapes(mesh))
}
