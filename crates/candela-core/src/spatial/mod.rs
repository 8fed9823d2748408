//! Spatial queries over points and spheres, for the photon-mapping
//! integrators.
//!
//! The structures here know nothing about photons or visible points: they
//! index anything that has a position (or a position and a radius) and hand
//! back item indices and squared distances. The integrators keep their own
//! payloads.
//!
//! - [`PointKdTree`] — a balanced kd-tree over owned items, stored implicitly
//!   in one array, with fixed-radius and k-nearest-neighbour queries. The
//!   shape of Jensen's photon map ("Realistic Image Synthesis Using Photon
//!   Mapping", 2001, §6.3) and of Mitsuba 0.6's generic `PointKDTree`
//!   (`include/mitsuba/core/kdtree.h`), which keeps the tree apart from the
//!   photon map that uses it. Use it when the query needs the k nearest
//!   points (classic photon mapping) or the radius varies per query.
//! - [`HashGrid`] — a uniform grid hashed into a table the size of the point
//!   set, built by counting sort, for fixed-radius queries where the radius
//!   is known at build time (progressive photon mapping, VCM's merging).
//!   After SmallVCM's `src/hashgrid.hxx` [Georgiev et al. 2012].
//! - [`SphereGrid`] — the transpose problem of stochastic progressive photon
//!   mapping: the stored items are spheres (visible points with their own
//!   radius) and the query is a photon hit point; each sphere is entered in
//!   every cell its bounding box overlaps, so a query reads one cell.
//!   After pbrt-v3's SPPM grid (`src/integrators/sppm.cpp`, PBR 3rd ed.
//!   §16.2.3).
//!
//! - [`CellMap`] — a value per occupied cell of the same hashed grid, looked
//!   up by position (VCM's radius field).
//!
//! The three search structures use closed balls: a point at exactly the radius is inside.

mod cell_map;
mod hash_grid;
mod kdtree;
mod soa_points;
mod sphere_grid;
#[cfg(test)]
mod tests;

use glam::Vec3;

pub use cell_map::CellMap;
pub use hash_grid::HashGrid;
pub use kdtree::{Neighbor, PointKdTree};
pub use sphere_grid::SphereGrid;

/// Something with a position in space: a photon, a visible point, a vertex.
pub trait HasPosition {
    /// The point to index.
    fn position(&self) -> Vec3;
}

impl HasPosition for Vec3 {
    #[inline]
    fn position(&self) -> Vec3 {
        *self
    }
}

/// Something with a bounding sphere: an SPPM visible point and its radius.
pub trait HasSphere {
    /// Centre of the sphere.
    fn center(&self) -> Vec3;
    /// Radius of the sphere; a negative or NaN radius means "no sphere".
    fn radius(&self) -> f32;
}

impl HasSphere for (Vec3, f32) {
    #[inline]
    fn center(&self) -> Vec3 {
        self.0
    }
    #[inline]
    fn radius(&self) -> f32 {
        self.1
    }
}
