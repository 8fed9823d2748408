//! A merge radius that varies over the scene (`"bool localradius"`).
//!
//! One radius for the whole image is a compromise between places: where
//! light vertices are dense (a caustic's bright lines) a small kernel has
//! little variance and removes the blur that a large one spreads into the
//! dark next to them; where they are sparse a small kernel is all noise.
//! SPPM makes that choice per pixel by shrinking each visible point's
//! radius with the photons it found [Hachisuka & Jensen 2009, eqs. 6–8];
//! photon mapping by k nearest neighbours [Jensen 2001, §7.2]. Measured on
//! the pool (module doc of [`super`]): the best of four uniform radii
//! chosen per 8 × 8 block had half the error of the best one radius.
//!
//! **The field.** The pilot ([`super::pilot`]) stores the light vertices
//! of [`FIELD_PASSES`] light passes and counts, around each, the others
//! within the global default radius r_g (the radius whose disk holds
//! K = 3 others around the median vertex of one pass). Space is cut into
//! cells of side r_g; a cell's radius is the one whose disk would hold K
//! vertices of one pass at the mean count of the vertices in it,
//! r_g √(K P / m̄) for P passes, within the global rule's lower bound in
//! pixel footprints ([`super::pilot::MIN_FOOTPRINTS`]) and the smaller of
//! its upper bound and 2 r_g; a cell without a pilot vertex has the upper
//! bound. The radius of iteration i at x is the field's at x times the
//! global schedule's factor √(ppm_radius2(i + 1, α)), so every place
//! shrinks at the same rate.
//!
//! **Only where it changes something.** The lookups cost about 4 % of an
//! iteration on the Cornell box (one per light and per camera vertex),
//! where the global rule sits at its lower bound and 99.5 % of the pilot's
//! vertices lie in cells whose radius is within 20 % of r_g; so the field
//! is dropped when fewer than 5 % of them lie in cells that differ by more
//! (the pool 37 %, caustic-glass 24 %, the sphere furnace of tests/vcm.rs
//! 9–12 % from counting noise alone). Without the growth bound of 2 r_g a
//! sparse Cornell cell took 3 r_g, which cost merge lookups and, at equal
//! iterations, gained nothing (relMSE 0.000904 / 0.000848 / 0.000866 at
//! 90 iterations, seeds 1–3, against 0.000901 / 0.000844 / 0.000860).
//! The rule is tried first on the counts of the one pilot pass that the
//! global radius needs: their noise moves more cells away from r_g, not
//! fewer (shares with one pass and four: the Cornell box at 128² 2.9 % and
//! 0.5 %, the pool 60 % and 38 %, caustic-glass 28 % and 24 %, both at
//! half resolution), so a field one pass drops is not worth the other
//! three passes, which cost 50 ms of a 4-s Cornell render (10 iterations
//! at 128², 2 threads: 0.50 s against 0.55 s; 0.49 s without the field).
//!
//! **MIS.** The field is a fixed function of position, the same for both
//! subpaths, so the merge technique at a vertex x of a path has the density
//! of eq. 20 with η(x) = π r(x)² N_light, and each term of the recursive
//! quantities takes the η of the vertex it belongs to ([`super::mis`]:
//! d_VM is kept without the evaluated merge's 1/η, which the merge's own
//! vertex supplies). A merge's kernel is centred on its camera vertex with
//! that vertex's radius, so it still integrates to one over the light
//! vertex's position, and its weight uses the camera vertex's η: the
//! merged path's vertex is the camera's, as in eq. 38. The brute-force
//! check (`vcm::mis_brute`, a test module) gives every vertex its own radius.
//!
//! **Passes stay independent.** The pilot's light passes have pass indices
//! of their own, so every process of a `--pass-range` render builds the
//! same field.

use super::mis::{DirectMerges, Factors};
use crate::math::Vec3;
use crate::spatial::CellMap;

/// Light passes the field's pilot stores (module doc).
pub const FIELD_PASSES: u64 = 4;

/// Radii per cell of space (a [`CellMap`]) and their range.
#[derive(Clone, Debug)]
pub struct RadiusField {
    radii: CellMap<f32>,
    /// Smallest and largest radius anywhere.
    range: (f32, f32),
}

impl RadiusField {
    /// The field of the radii in `radii`.
    pub fn new(radii: CellMap<f32>) -> Self {
        let empty = radii.empty();
        let range = radii
            .values()
            .fold((empty, empty), |(lo, hi), &r| (lo.min(r), hi.max(r)));
        RadiusField { radii, range }
    }

    /// The radius at `p`.
    #[inline]
    pub fn at(&self, p: Vec3) -> f32 {
        self.radii.get(p)
    }

    /// The smallest and the largest radius anywhere.
    pub fn range(&self) -> (f32, f32) {
        self.range
    }
}

/// The MIS factors of one iteration, at any point: uniform, or from a
/// radius field scaled by the iteration's schedule.
#[derive(Clone, Copy, Debug)]
pub struct FactorField<'a> {
    /// The factors at the uniform radius (or the global one's).
    uniform: Factors,
    /// The uniform radius, or with a field the global default radius of the
    /// iteration (the merge grid's cells are sized for it).
    radius: f32,
    field: Option<&'a RadiusField>,
    /// The schedule's factor on the field's radii.
    scale: f32,
    n_light: f32,
    connect: bool,
    merge: bool,
}

impl<'a> FactorField<'a> {
    /// The factors for radius `r` everywhere (see [`Factors::new`]).
    pub fn uniform(r: f32, n_light: f32, connect: bool, merge: bool, direct: DirectMerges) -> Self {
        FactorField {
            uniform: Factors::new(r, n_light, connect, merge, direct),
            radius: r,
            field: None,
            scale: 1.0,
            n_light,
            connect,
            merge,
        }
    }

    /// The factors for `field`'s radii times `scale`, where `typical` is
    /// the iteration's global radius.
    pub fn of_field(field: &'a RadiusField, scale: f32, typical: f32, base: Self) -> Self {
        FactorField {
            field: Some(field),
            scale,
            radius: typical,
            ..base
        }
    }

    /// The factors at `p`.
    #[inline]
    pub fn at(&self, p: Vec3) -> Factors {
        match self.field {
            None => self.uniform,
            Some(field) => Factors::new(
                field.at(p) * self.scale,
                self.n_light,
                self.connect,
                self.merge,
                self.uniform.direct,
            ),
        }
    }

    /// The radius the merge grid's cells are sized for: the uniform one,
    /// or the global radius of a field's iteration (a larger query visits
    /// more cells; sizing the cells for the field's largest radius made
    /// every query of the Cornell box visit about 27 times the volume).
    pub fn grid_radius(&self) -> f32 {
        self.radius
    }

    /// Which merges next to the light exist (the same everywhere).
    pub fn direct(&self) -> DirectMerges {
        self.uniform.direct
    }

    /// [`Factors::merges_at`], the same everywhere.
    #[inline]
    pub fn merges_at(&self, next_to_light: bool, after_delta: bool) -> bool {
        self.uniform.merges_at(next_to_light, after_delta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every cell entered is found at every point inside it and keeps its
    /// own radius (200 cells in a table of 400 slots, so probes collide and
    /// wrap); points in no entered cell get the empty radius; the range
    /// spans both.
    #[test]
    fn cells_are_found_where_they_are() {
        let cell = 0.5;
        let mut map = CellMap::new(Vec3::ZERO, cell, 200, 0.25f32);
        let corner = |i: i32| {
            Vec3::new(
                (i % 7 - 3) as f32,
                (i / 7 - 14) as f32,
                ((i * 31) % 11 - 5) as f32,
            ) * cell
        };
        for i in 0..200 {
            *map.entry(corner(i) + Vec3::splat(0.01)) = 1.0 + i as f32;
        }
        let field = RadiusField::new(map);
        for i in 0..200 {
            for d in [Vec3::splat(0.01), Vec3::new(0.49, 0.25, 0.49)] {
                assert_eq!(field.at(corner(i) + d), 1.0 + i as f32, "cell {i}");
            }
        }
        assert_eq!(field.at(Vec3::splat(100.0)), 0.25);
        assert_eq!(field.range(), (0.25, 200.0));
    }
}
