//! The equal-area octahedral map between the unit square and the sphere
//! [Clarberg 2008, "Fast Equal-Area Mapping of the (Hemi)Sphere using SIMD";
//! pbrt-v4 `EqualAreaSquareToSphere`, `EqualAreaSphereToSquare`, §3.8.3].
//!
//! The square [−1, 1]² is folded like an octahedron: the diamond |u| + |v| ≤ 1
//! holds the upper hemisphere (z ≥ 0) and the four corner triangles the lower
//! one. Within a quadrant, the signed distance to the diamond's edge gives
//! r = 1 − |1 − |u| − |v||, with |z| = 1 − r² (so a band of constant r has
//! area ∝ r dr ∝ d|z|: Archimedes' hat-box theorem makes it equal-area), and
//! the position along the edge gives φ linearly in [0, π/2]. Every cell of
//! the square thus covers solid angle 4π × its area: a density p(u, v) on
//! the square is p/(4π) per steradian. pbrt-v4 stores environment maps in
//! this parameterisation ("equal-area" square images, (u, v) ∈ [0, 1]²).
//!
//! The inverse uses the exact arctangent where pbrt-v4 uses a minimax
//! polynomial (error ≈ 10⁻⁶ in φ); the maps are inverse to float precision.

use crate::math::{Vec2, Vec3, PI};

/// Unit direction of point `p` ∈ [0, 1]² of the equal-area square.
pub fn equal_area_square_to_sphere(p: Vec2) -> Vec3 {
    debug_assert!((0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y));
    let (u, v) = (2.0 * p.x - 1.0, 2.0 * p.y - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    // Signed distance from the diamond's edge: > 0 inside (upper hemisphere).
    let signed_distance = 1.0 - (up + vp);
    let r = 1.0 - signed_distance.abs();
    // φ runs linearly along the edge, from the u axis to the v axis.
    let phi = if r == 0.0 {
        PI / 4.0
    } else {
        ((vp - up) / r + 1.0) * PI / 4.0
    };
    let z = (1.0 - r * r).copysign(signed_distance);
    let sin_theta = r * (2.0 - r * r).max(0.0).sqrt();
    Vec3::new(
        phi.cos().copysign(u) * sin_theta,
        phi.sin().copysign(v) * sin_theta,
        z,
    )
}

/// Point of the equal-area square ([0, 1]²) of unit direction `d`.
pub fn equal_area_sphere_to_square(d: Vec3) -> Vec2 {
    debug_assert!((d.length_squared() - 1.0).abs() < 1e-3, "not unit: {d}");
    let (x, y, z) = (d.x.abs(), d.y.abs(), d.z.abs());
    let r = (1.0 - z).max(0.0).sqrt();
    // φ/(π/2) in the first quadrant, from the smaller over the larger of x, y.
    let (a, b) = (x.max(y), x.min(y));
    let t = if a == 0.0 { 0.0 } else { b / a };
    let mut phi = t.atan() * (2.0 / PI);
    if x < y {
        phi = 1.0 - phi;
    }
    let mut v = phi * r;
    let mut u = r - v;
    if d.z < 0.0 {
        // Lower hemisphere: mirror across the quadrant's diagonal edge.
        (u, v) = (1.0 - v, 1.0 - u);
    }
    let (u, v) = (u.copysign(d.x), v.copysign(d.y));
    Vec2::new(0.5 * (u + 1.0), 0.5 * (v + 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Pcg32;

    #[test]
    fn round_trips_both_ways() {
        let mut r = Pcg32::new(3, 1);
        let mut worst = (0.0f32, 0.0f32);
        for _ in 0..100_000 {
            let p = Vec2::new(r.uniform_f32(), r.uniform_f32());
            let d = equal_area_square_to_sphere(p);
            assert!((d.length() - 1.0).abs() < 1e-5, "{p} -> {d}");
            let q = equal_area_sphere_to_square(d);
            worst.0 = worst.0.max((q - p).abs().max_element());
            let back = equal_area_square_to_sphere(q);
            worst.1 = worst.1.max((back - d).abs().max_element());
        }
        assert!(worst.0 < 1e-4 && worst.1 < 1e-5, "worst {worst:?}");
        // Poles and the seam.
        assert!((equal_area_square_to_sphere(Vec2::splat(0.5)) - Vec3::Z).length() < 1e-6);
        assert!((equal_area_square_to_sphere(Vec2::ZERO) + Vec3::Z).length() < 1e-6);
        assert!((equal_area_square_to_sphere(Vec2::ONE) + Vec3::Z).length() < 1e-6);
        let e = equal_area_square_to_sphere(Vec2::new(1.0, 0.5));
        assert!((e - Vec3::X).length() < 1e-6, "{e}");
    }

    #[test]
    fn cells_cover_equal_solid_angles() {
        // Jacobian of the map by central differences: |∂d/∂u × ∂d/∂v| = 4π everywhere
        // away from the folds.
        let mut r = Pcg32::new(9, 2);
        let h = 1e-3f64;
        for _ in 0..2000 {
            let p = Vec2::new(r.uniform_f32(), r.uniform_f32()) * 0.9 + Vec2::splat(0.05);
            let (pu, pv) = (p.x as f64, p.y as f64);
            let f = |u: f64, v: f64| {
                equal_area_square_to_sphere(Vec2::new(u as f32, v as f32)).as_dvec3()
            };
            let du = (f(pu + h, pv) - f(pu - h, pv)) / (2.0 * h);
            let dv = (f(pu, pv + h) - f(pu, pv - h)) / (2.0 * h);
            let j = du.cross(dv).length();
            // Folds (|u|+|v| = 1 and the axes) make finite differences straddle kinks.
            let (u, v) = (2.0 * pu - 1.0, 2.0 * pv - 1.0);
            let near_fold =
                (1.0 - u.abs() - v.abs()).abs() < 4.0 * h || u.abs() < 4.0 * h || v.abs() < 4.0 * h;
            if !near_fold {
                let rel = (j / (4.0 * std::f64::consts::PI) - 1.0).abs();
                assert!(rel < 2e-3, "Jacobian {j} at {p}");
            }
        }
    }
}
