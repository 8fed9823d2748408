//! Loop subdivision surfaces (pbrt-v4's `loopsubdiv`), refined at load time
//! into a triangle mesh with limit-surface positions and normals.
//!
//! Each level splits every triangle into four [Loop 1987, "Smooth
//! Subdivision Surfaces Based on Triangles", MS thesis, Univ. of Utah]:
//! * an *odd* vertex on every edge: ⅜(a + b) + ⅛(c + d), where c and d are
//!   the vertices opposite the edge; ½(a + b) on a boundary edge;
//! * every *even* (old) vertex of valence n moves to (1 − nβ)p + βΣ qᵢ over
//!   its one-ring qᵢ, with β = 3/16 for n = 3 and 3/(8n) otherwise (Warren's
//!   simplification, as pbrt-v4 §C.2 uses); on the boundary to
//!   ¾p + ⅛(q₀ + q_last), which refines the boundary as a cubic B-spline.
//!
//! After the last level every vertex is pushed to its limit position, the
//! left eigenvector of the local subdivision matrix for eigenvalue 1
//! [Hoppe et al. 1994, "Piecewise Smooth Surface Reconstruction", SIGGRAPH]:
//! (1 − nγ)p + γΣ qᵢ with γ = 1/(n + 3/(8β)) inside, and ⅔p + ⅙(q₀ + q_last)
//! on the boundary, the limit of the cubic B-spline the boundary rules
//! refine. pbrt-v4 uses ⅗p + ⅕(q₀ + q_last) there, which is not invariant
//! under its own refinement; the difference is ¹⁄₃₀ of the boundary's second
//! difference at the finest level.
//!
//! Limit tangents come from the subdominant eigenvector masks
//! S = Σ cos(2πj/n) qⱼ, T = Σ sin(2πj/n) qⱼ (interior) and pbrt-v4's
//! boundary masks (S = q_last − q₀ and a valence-dependent T), and the
//! per-vertex shading normal is S × T, normalised. We apply the masks to the
//! control points of the final level, where the interior masks and the
//! boundary masks of valence ≤ 4 are exact eigenvectors (the general boundary
//! mask is an approximation); pbrt-v4 applies them to the already-limit
//! positions, a slightly smoothed estimate.
//!
//! One-rings are ordered as pbrt-v4's `SDVertex::oneRing` orders them:
//! interior rings run from a neighbour to the next vertex of the face that
//! follows it (the side of the opposite winding), boundary rings from the
//! boundary neighbour that ends that walk. With these orders S × T points
//! to the side *opposite* the counter-clockwise winding normal of the
//! faces, for interior and boundary vertices alike; we keep pbrt-v4's sign
//! because triangles with per-vertex normals put their geometric normal on
//! the shading normal's side, which decides where one-sided area lights
//! emit.
//!
//! pbrt-v4 builds the same topology with pointers and neither checks nor
//! survives non-manifold input; here edges shared by more than two faces
//! (or by two faces of opposite winding), vertices whose faces form more
//! than one fan, repeated vertices within a face and bad indices are errors.

use crate::math::{Vec3, PI};
use std::collections::HashMap;
use thiserror::Error;

/// Largest number of triangles subdivision may produce.
const MAX_TRIANGLES: usize = 1 << 27;

/// Why a `loopsubdiv` control mesh was rejected.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum LoopSubdivError {
    /// No faces.
    #[error("loopsubdiv needs at least one triangle")]
    Empty,
    /// The index count is not a multiple of three.
    #[error("loopsubdiv has {0} indices, not a multiple of 3")]
    IndexCount(usize),
    /// A negative or too large vertex index.
    #[error("loopsubdiv vertex index {index} out of range for {vertices} vertices")]
    IndexOutOfRange {
        /// The offending index.
        index: i64,
        /// Number of vertices.
        vertices: usize,
    },
    /// A face uses one vertex twice.
    #[error("loopsubdiv face {0} uses a vertex more than once")]
    DegenerateFace(usize),
    /// An edge shared by more than two faces, or by two faces of opposite winding.
    #[error("loopsubdiv edge ({0}, {1}) is shared by more than two faces or by faces with inconsistent winding")]
    NonManifoldEdge(u32, u32),
    /// A vertex whose faces form more than one fan.
    #[error("loopsubdiv vertex {0} is non-manifold (its faces form more than one fan)")]
    NonManifoldVertex(u32),
    /// The refined mesh would be too large.
    #[error("loopsubdiv with {levels} levels would produce {triangles} triangles (limit {MAX_TRIANGLES})")]
    TooLarge {
        /// Requested levels.
        levels: u32,
        /// Resulting triangle count.
        triangles: u128,
    },
}

/// A refined triangle mesh on the limit surface (object space).
#[derive(Clone, Debug, PartialEq)]
pub struct LoopSurface {
    /// Limit positions.
    pub p: Vec<Vec3>,
    /// Unit limit normals (zero where the tangents are degenerate or the
    /// vertex is used by no face).
    pub n: Vec<Vec3>,
    /// Three vertex indices per triangle.
    pub indices: Vec<u32>,
}

/// A control mesh at one level.
struct Level {
    p: Vec<Vec3>,
    faces: Vec<[u32; 3]>,
}

/// Connectivity of a level: ordered one-rings and the face of each directed edge.
struct Topology {
    /// Concatenated one-rings; vertex v's ring is `ring[start[v]..start[v + 1]]`.
    ring: Vec<u32>,
    start: Vec<usize>,
    boundary: Vec<bool>,
    /// Directed edge (a, b) → index of the face containing it.
    edge_face: HashMap<(u32, u32), u32>,
}

impl Topology {
    /// The one-ring of `v` and whether `v` is on the boundary.
    fn ring(&self, v: usize) -> (&[u32], bool) {
        (
            &self.ring[self.start[v]..self.start[v + 1]],
            self.boundary[v],
        )
    }
}

/// Subdivides the control mesh `levels` times and pushes it to the limit
/// surface.
pub fn loop_subdivide(
    levels: u32,
    indices: &[i32],
    p: &[Vec3],
) -> Result<LoopSurface, LoopSubdivError> {
    let faces = control_faces(indices, p.len())?;
    let triangles = faces.len() as u128 * 4u128.pow(levels.min(60));
    if levels > 60 || triangles > MAX_TRIANGLES as u128 {
        return Err(LoopSubdivError::TooLarge { levels, triangles });
    }
    let mut level = Level {
        p: p.to_vec(),
        faces,
    };
    let mut topo = topology(&level)?;
    for _ in 0..levels {
        level = refine(&level, &topo);
        topo = topology(&level)?;
    }
    let n = (0..level.p.len())
        .map(|v| limit_normal(&level, &topo, v))
        .collect();
    let p = (0..level.p.len())
        .map(|v| limit_position(&level, &topo, v))
        .collect();
    Ok(LoopSurface {
        p,
        n,
        indices: level.faces.concat(),
    })
}

/// Validates the index list and groups it into triangles.
fn control_faces(indices: &[i32], nv: usize) -> Result<Vec<[u32; 3]>, LoopSubdivError> {
    if indices.is_empty() {
        return Err(LoopSubdivError::Empty);
    }
    if !indices.len().is_multiple_of(3) {
        return Err(LoopSubdivError::IndexCount(indices.len()));
    }
    if let Some(&bad) = indices.iter().find(|&&i| i < 0 || i as usize >= nv) {
        return Err(LoopSubdivError::IndexOutOfRange {
            index: bad as i64,
            vertices: nv,
        });
    }
    let faces: Vec<[u32; 3]> = indices
        .chunks_exact(3)
        .map(|f| [f[0] as u32, f[1] as u32, f[2] as u32])
        .collect();
    if let Some(i) = faces
        .iter()
        .position(|f| f[0] == f[1] || f[1] == f[2] || f[2] == f[0])
    {
        return Err(LoopSubdivError::DegenerateFace(i));
    }
    Ok(faces)
}

/// Builds the edge map and the ordered one-ring of every vertex.
fn topology(level: &Level) -> Result<Topology, LoopSubdivError> {
    let nv = level.p.len();
    let mut edge_face = HashMap::with_capacity(3 * level.faces.len());
    for (fi, f) in level.faces.iter().enumerate() {
        for k in 0..3 {
            let e = (f[k], f[(k + 1) % 3]);
            if edge_face.insert(e, fi as u32).is_some() {
                return Err(LoopSubdivError::NonManifoldEdge(e.0, e.1));
            }
        }
    }
    // Incident (next, prev) neighbour pairs per vertex, in CSR form.
    let mut count = vec![0usize; nv + 1];
    for f in &level.faces {
        for &v in f {
            count[v as usize + 1] += 1;
        }
    }
    for i in 0..nv {
        count[i + 1] += count[i];
    }
    let mut fill = count.clone();
    let mut links = vec![(0u32, 0u32); count[nv]];
    for f in &level.faces {
        for k in 0..3 {
            let v = f[k] as usize;
            links[fill[v]] = (f[(k + 1) % 3], f[(k + 2) % 3]);
            fill[v] += 1;
        }
    }
    let mut topo = Topology {
        ring: Vec::with_capacity(links.len() + nv),
        start: Vec::with_capacity(nv + 1),
        boundary: Vec::with_capacity(nv),
        edge_face,
    };
    for v in 0..nv {
        topo.start.push(topo.ring.len());
        let boundary = order_ring(v as u32, &links[count[v]..count[v + 1]], &mut topo.ring)?;
        topo.boundary.push(boundary);
    }
    topo.start.push(topo.ring.len());
    Ok(topo)
}

/// Appends the one-ring of `v` in pbrt-v4's order, given the (next, prev)
/// neighbours of `v` in each incident face; returns whether `v` is on the
/// boundary. Face (v, a, b) links b → a: an interior ring follows the
/// links, a boundary ring starts at the link chain's end and runs backwards.
fn order_ring(v: u32, links: &[(u32, u32)], ring: &mut Vec<u32>) -> Result<bool, LoopSubdivError> {
    if links.is_empty() {
        return Ok(false);
    }
    let next_of = |prev: u32| links.iter().find(|l| l.1 == prev).map(|l| l.0);
    let prev_of = |next: u32| links.iter().find(|l| l.0 == next).map(|l| l.1);
    // The chain's end: a `next` that is no face's `prev`.
    let end = links.iter().map(|l| l.0).find(|&a| next_of(a).is_none());
    let first = ring.len();
    match end {
        None => {
            let start = links[0].0;
            let mut q = start;
            loop {
                ring.push(q);
                q = next_of(q).ok_or(LoopSubdivError::NonManifoldVertex(v))?;
                if q == start || ring.len() - first > links.len() {
                    break;
                }
            }
        }
        Some(end) => {
            let mut q = Some(end);
            while let Some(x) = q {
                ring.push(x);
                if ring.len() - first > links.len() + 1 {
                    break;
                }
                q = prev_of(x);
            }
        }
    }
    // A manifold fan visits every face once: n faces, n (interior) or n + 1 vertices.
    let boundary = end.is_some();
    if ring.len() - first != links.len() + boundary as usize {
        return Err(LoopSubdivError::NonManifoldVertex(v));
    }
    Ok(boundary)
}

/// Warren's β for valence `n` [pbrt-v4 §C.2].
fn beta(n: usize) -> f32 {
    if n == 3 {
        3.0 / 16.0
    } else {
        3.0 / (8.0 * n as f32)
    }
}

/// (1 − nw)p + wΣ qᵢ.
fn weight_one_ring(p: &[Vec3], v: usize, ring: &[u32], w: f32) -> Vec3 {
    let sum: Vec3 = ring.iter().map(|&q| p[q as usize]).sum();
    (1.0 - ring.len() as f32 * w) * p[v] + w * sum
}

/// (1 − 2w)p + w(q₀ + q_last).
fn weight_boundary(p: &[Vec3], v: usize, ring: &[u32], w: f32) -> Vec3 {
    let (q0, q1) = (p[ring[0] as usize], p[ring[ring.len() - 1] as usize]);
    (1.0 - 2.0 * w) * p[v] + w * (q0 + q1)
}

/// One level of refinement: even vertices keep their indices, odd vertices follow.
fn refine(level: &Level, topo: &Topology) -> Level {
    let mut p: Vec<Vec3> = (0..level.p.len())
        .map(|v| match topo.ring(v) {
            ([], _) => level.p[v],
            (ring, true) => weight_boundary(&level.p, v, ring, 1.0 / 8.0),
            (ring, false) => weight_one_ring(&level.p, v, ring, beta(ring.len())),
        })
        .collect();
    let mut odd: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * level.faces.len() / 2);
    let mut edge_vertex = |a: u32, b: u32, p: &mut Vec<Vec3>| -> u32 {
        *odd.entry((a.min(b), a.max(b))).or_insert_with(|| {
            p.push(odd_position(level, topo, a, b));
            p.len() as u32 - 1
        })
    };
    let mut faces = Vec::with_capacity(4 * level.faces.len());
    for &[v0, v1, v2] in &level.faces {
        let e01 = edge_vertex(v0, v1, &mut p);
        let e12 = edge_vertex(v1, v2, &mut p);
        let e20 = edge_vertex(v2, v0, &mut p);
        faces.extend([
            [v0, e01, e20],
            [v1, e12, e01],
            [v2, e20, e12],
            [e01, e12, e20],
        ]);
    }
    Level { p, faces }
}

/// The vertex of face `f` that is neither `a` nor `b`.
fn opposite(f: &[u32; 3], a: u32, b: u32) -> u32 {
    f.iter()
        .copied()
        .find(|&v| v != a && v != b)
        .unwrap_or(f[0])
}

/// Position of the new vertex on edge (a, b) [Loop 1987].
fn odd_position(level: &Level, topo: &Topology, a: u32, b: u32) -> Vec3 {
    let p = &level.p;
    let (pa, pb) = (p[a as usize], p[b as usize]);
    let face = |e| topo.edge_face.get(&e).map(|&f| &level.faces[f as usize]);
    match (face((a, b)), face((b, a))) {
        (Some(f0), Some(f1)) => {
            let (c, d) = (opposite(f0, a, b), opposite(f1, a, b));
            0.375 * (pa + pb) + 0.125 * (p[c as usize] + p[d as usize])
        }
        _ => 0.5 * (pa + pb),
    }
}

/// Limit position of vertex `v` [Hoppe et al. 1994].
fn limit_position(level: &Level, topo: &Topology, v: usize) -> Vec3 {
    match topo.ring(v) {
        ([], _) => level.p[v],
        (ring, true) => weight_boundary(&level.p, v, ring, 1.0 / 6.0),
        (ring, false) => {
            let n = ring.len();
            let gamma = 1.0 / (n as f32 + 3.0 / (8.0 * beta(n)));
            weight_one_ring(&level.p, v, ring, gamma)
        }
    }
}

/// Unit limit normal S × T of vertex `v` from the tangent masks (see the module doc).
fn limit_normal(level: &Level, topo: &Topology, v: usize) -> Vec3 {
    let p = &level.p;
    let (ring, boundary) = topo.ring(v);
    if ring.is_empty() {
        return Vec3::ZERO;
    }
    let q = |j: usize| p[ring[j] as usize];
    let n = ring.len();
    let (s, t) = if !boundary {
        (0..n).fold((Vec3::ZERO, Vec3::ZERO), |(s, t), j| {
            let a = 2.0 * PI * j as f32 / n as f32;
            (s + a.cos() * q(j), t + a.sin() * q(j))
        })
    } else {
        let s = q(n - 1) - q(0);
        let t = match n {
            2 => q(0) + q(1) - 2.0 * p[v],
            3 => q(1) - p[v],
            4 => -q(0) + 2.0 * q(1) + 2.0 * q(2) - q(3) - 2.0 * p[v],
            _ => {
                let theta = PI / (n - 1) as f32;
                let inner: Vec3 = (1..n - 1)
                    .map(|k| (2.0 * theta.cos() - 2.0) * (k as f32 * theta).sin() * q(k))
                    .sum();
                -(theta.sin() * (q(0) + q(n - 1)) + inner)
            }
        };
        (s, t)
    };
    s.cross(t).normalize_or_zero()
}
