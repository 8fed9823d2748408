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
//!
//! Domains: every radius is positive; `phimax` lies in (0°, 360°]; a disk's
//! `innerradius` in [0, `radius`); a quadric's z range must keep some surface
//! (pbrt-v4 clamps `zmin`/`zmax` to the sphere, and so does candela, but an
//! empty range is an error); `levels` of a subdivision surface in 0‥
//! [`MAX_LOOP_LEVELS`], and the refined mesh is claimed against the memory
//! budget. Vertex data are finite (checked for the whole scene first).

use super::budget::Budget;
use super::check::{Check, Domain};
use super::BuildError;
use crate::math::{Transform, Vec2, Vec3};
use crate::shape::{
    loop_subdivide, BilinearPatch, BilinearPatchMesh, Cylinder, Disk, Shape, Sphere, Triangle,
    TriangleMesh,
};
use candela_scene::{SceneError, ShapeDesc};
use std::sync::Arc;

/// Deepest Loop subdivision (each level makes four triangles of one; 12
/// levels turn one triangle into 16.7 M).
pub const MAX_LOOP_LEVELS: i32 = 12;

/// The shapes one `Shape` directive creates, placed by `t`.
pub fn build_shape(
    s: &ShapeDesc,
    t: &Transform,
    budget: &mut Budget,
) -> Result<Vec<Shape>, BuildError> {
    let p = &s.params;
    let what = format!("Shape \"{}\"", s.name);
    let ck = Check::new(p, &s.loc, &what);
    let (ro, tt) = (s.reverse_orientation, Arc::new(*t));
    Ok(match s.name.as_str() {
        "sphere" => {
            let r = ck.float("radius", 1.0, Domain::Positive)?;
            let (zmin, zmax, phimax) = quadric_range(&ck, -r, r, Some(r))?;
            vec![Shape::Sphere(Sphere::new(tt, ro, r, zmin, zmax, phimax))]
        }
        "cylinder" => {
            let r = ck.float("radius", 1.0, Domain::Positive)?;
            let (zmin, zmax, phimax) = quadric_range(&ck, -1.0, 1.0, None)?;
            vec![Shape::Cylinder(Cylinder::new(tt, ro, r, zmin, zmax, phimax))]
        }
        "disk" => {
            let h = p.get_float("height", 0.0)?;
            let r = ck.float("radius", 1.0, Domain::Positive)?;
            let ri = p.get_float("innerradius", 0.0)?;
            if !(0.0..r).contains(&ri) {
                return Err(ck.error(
                    "innerradius",
                    format!("must lie in [0, radius {r}), found {ri}"),
                ));
            }
            let phimax = ck.float("phimax", 360.0, Domain::LeftOpen(0.0, 360.0))?;
            vec![Shape::Disk(Disk::new(tt, ro, h, r, ri, phimax))]
        }
        "trianglemesh" => trianglemesh(s, t)?,
        "plymesh" => plymesh(s, t)?,
        "bilinearmesh" => bilinearmesh(s, t)?,
        "loopsubdiv" => loopsubdiv(&ck, s, t, budget)?,
        other => {
            return Err(BuildError::at(
                &s.loc,
                format!("shape \"{other}\" is not supported yet (supported: trianglemesh, plymesh, bilinearmesh, loopsubdiv, sphere, cylinder, disk)"),
            ))
        }
    })
}

/// `zmin`, `zmax` and `phimax` of a quadric; `clamp` is a sphere's radius,
/// to which pbrt-v4 clamps the z range.
fn quadric_range(
    ck: &Check<'_>,
    zmin: f32,
    zmax: f32,
    clamp: Option<f32>,
) -> Result<(f32, f32, f32), BuildError> {
    let p = ck.params;
    let (z0, z1) = (p.get_float("zmin", zmin)?, p.get_float("zmax", zmax)?);
    let (lo, hi) = (z0.min(z1), z0.max(z1));
    let (lo, hi) = match clamp {
        Some(r) => (lo.clamp(-r, r), hi.clamp(-r, r)),
        None => (lo, hi),
    };
    if lo >= hi {
        let within = clamp.map_or(String::new(), |r| format!(" within the radius {r}"));
        return Err(ck.error(
            "zmax",
            format!("and \"zmin\" ({z0} and {z1}) leave no surface{within}"),
        ));
    }
    let phimax = ck.float("phimax", 360.0, Domain::LeftOpen(0.0, 360.0))?;
    Ok((z0, z1, phimax))
}

/// Memory of one refined triangle, for the subdivision budget: 12 bytes of
/// indices, a vertex's position and normal (24), its `Shape` and
/// `Primitive` (about 64) and BVH share (about 32).
const TRIANGLE_BYTES: u64 = 132;

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
fn loopsubdiv(
    ck: &Check<'_>,
    s: &ShapeDesc,
    t: &Transform,
    budget: &mut Budget,
) -> Result<Vec<Shape>, BuildError> {
    let p = &s.params;
    let levels = ck.int_in("levels", 3, 0, MAX_LOOP_LEVELS)? as u32;
    let indices = p
        .get_ints("indices")?
        .ok_or_else(|| BuildError::at(&s.loc, "loopsubdiv needs \"integer indices\""))?;
    // Each level makes four triangles of one; a triangle costs its indices,
    // about one vertex (position and normal) and its primitive and BVH node.
    let triangles = (indices.len() / 3) as u64 * 4u64.pow(levels);
    budget
        .claim(
            triangles.saturating_mul(TRIANGLE_BYTES),
            &format!("{triangles} triangles of the subdivided surface"),
            "lower \"levels\"",
        )
        .map_err(|m| ck.error("levels", m))?;
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
