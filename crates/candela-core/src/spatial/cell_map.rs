//! A value per occupied cell of a uniform grid, looked up by position: the
//! cells and their hash are [`HashGrid`](super::HashGrid)'s (`CellHash`),
//! the table an open-addressing one keyed by the cell itself, so two cells
//! that share a bucket keep their own values. VCM's radius field
//! (`integrator::vcm::field`) is one.

use super::hash_grid::CellHash;
use glam::{IVec3, Vec3};

/// Values of type `T` per cell of side `cell_size`, `empty` where none was
/// entered.
#[derive(Clone, Debug)]
pub struct CellMap<T> {
    cells: CellHash,
    keys: Vec<IVec3>,
    occupied: Vec<bool>,
    /// Cells entered.
    used: usize,
    values: Vec<T>,
    empty: T,
}

impl<T: Copy> CellMap<T> {
    /// An empty map of cells of side `cell_size` from `origin` with room for
    /// `capacity` cells.
    ///
    /// # Panics
    /// If `cell_size` is not positive and finite.
    pub fn new(origin: Vec3, cell_size: f32, capacity: usize, empty: T) -> Self {
        let slots = (2 * capacity).max(2);
        CellMap {
            cells: CellHash::new(origin, cell_size, slots),
            keys: vec![IVec3::ZERO; slots],
            occupied: vec![false; slots],
            used: 0,
            values: vec![empty; slots],
            empty,
        }
    }

    /// The slot of cell `c`, or of the free slot where it would go.
    #[inline]
    fn slot(&self, c: IVec3) -> usize {
        let n = self.keys.len();
        let mut s = self.cells.bucket(c);
        while self.occupied[s] && self.keys[s] != c {
            s = (s + 1) % n;
        }
        s
    }

    /// The value of the cell holding `p`, entered as `empty` if it was not.
    ///
    /// # Panics
    /// When more cells are entered than the capacity given to [`Self::new`].
    pub fn entry(&mut self, p: Vec3) -> &mut T {
        let c = self.cells.cell(p);
        let s = self.slot(c);
        if !self.occupied[s] {
            assert!(
                2 * self.used < self.keys.len(),
                "more cells than the capacity"
            );
            self.used += 1;
            self.occupied[s] = true;
            self.keys[s] = c;
        }
        &mut self.values[s]
    }

    /// The value of the cell holding `p` (`empty` if none was entered).
    #[inline]
    pub fn get(&self, p: Vec3) -> T {
        let s = self.slot(self.cells.cell(p));
        if self.occupied[s] {
            self.values[s]
        } else {
            self.empty
        }
    }

    /// The value of every cell not entered.
    pub fn empty(&self) -> T {
        self.empty
    }

    /// The values of the entered cells.
    pub fn values(&self) -> impl Iterator<Item = &T> + '_ {
        self.values
            .iter()
            .zip(&self.occupied)
            .filter_map(|(v, &o)| o.then_some(v))
    }

    /// The same cells with values `f(value)`, and `empty` elsewhere.
    pub fn map<U: Copy>(&self, empty: U, f: impl Fn(T) -> U) -> CellMap<U> {
        CellMap {
            cells: self.cells.clone(),
            keys: self.keys.clone(),
            occupied: self.occupied.clone(),
            used: self.used,
            values: self
                .values
                .iter()
                .zip(&self.occupied)
                .map(|(&v, &o)| if o { f(v) } else { empty })
                .collect(),
            empty,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Points of one cell share its value, `values` lists the entered cells
    /// only, and `map` keeps the cells and replaces the empty value.
    #[test]
    fn entries_values_and_map() {
        let mut m = CellMap::new(Vec3::ZERO, 1.0, 3, 0u32);
        *m.entry(Vec3::new(0.2, 0.2, 0.2)) += 1;
        *m.entry(Vec3::new(0.9, 0.1, 0.5)) += 1;
        *m.entry(Vec3::new(5.5, 0.0, 0.0)) += 7;
        assert_eq!(m.get(Vec3::new(0.5, 0.5, 0.5)), 2);
        assert_eq!(m.get(Vec3::new(5.1, 0.9, 0.9)), 7);
        assert_eq!(m.get(Vec3::new(1.5, 0.5, 0.5)), 0);
        let mut v: Vec<u32> = m.values().copied().collect();
        v.sort_unstable();
        assert_eq!(v, [2, 7]);
        let d = m.map(-1.0f32, |x| x as f32 * 0.5);
        assert_eq!(d.get(Vec3::new(0.5, 0.5, 0.5)), 1.0);
        assert_eq!(d.get(Vec3::new(9.0, 9.0, 9.0)), -1.0);
        assert_eq!(d.empty(), -1.0);
    }
}
