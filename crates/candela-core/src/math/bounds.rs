//! Axis-aligned bounding boxes.

use glam::Vec3;

/// An axis-aligned box; empty when `min > max` on any axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds3 {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Default for Bounds3 {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Bounds3 {
    /// The empty box (identity of `union`).
    pub const EMPTY: Self = Self {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// Box around one point.
    #[inline]
    pub fn from_point(p: Vec3) -> Self {
        Self { min: p, max: p }
    }
    /// Box spanned by two points.
    #[inline]
    pub fn from_points(a: Vec3, b: Vec3) -> Self {
        Self {
            min: a.min(b),
            max: a.max(b),
        }
    }
    /// Smallest box containing both.
    #[inline]
    pub fn union(self, o: Self) -> Self {
        Self {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }
    /// Smallest box containing `self` and `p`.
    #[inline]
    pub fn union_point(self, p: Vec3) -> Self {
        Self {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }
    /// True when the box holds no point.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }
    /// Edge lengths.
    #[inline]
    pub fn diagonal(&self) -> Vec3 {
        self.max - self.min
    }
    /// Centre.
    #[inline]
    pub fn centroid(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }
    /// Surface area (0 for an empty box).
    #[inline]
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let d = self.diagonal();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }
    /// Index of the longest axis.
    #[inline]
    pub fn max_extent(&self) -> usize {
        let d = self.diagonal();
        if d.x > d.y && d.x > d.z {
            0
        } else if d.y > d.z {
            1
        } else {
            2
        }
    }
    /// Position of `p` relative to the corners (0 at min, 1 at max).
    #[inline]
    pub fn offset(&self, p: Vec3) -> Vec3 {
        let mut o = p - self.min;
        let d = self.diagonal();
        for i in 0..3 {
            if d[i] > 0.0 {
                o[i] /= d[i];
            }
        }
        o
    }
    /// Centre and radius of a sphere enclosing the box.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        if self.is_empty() {
            return (Vec3::ZERO, 0.0);
        }
        let c = self.centroid();
        (c, (self.max - c).length())
    }
}
