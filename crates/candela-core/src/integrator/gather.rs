//! Which photons near a gather point count, with which direction and at
//! which kernel distance: the one rule `sppm`, `ppm`, `photonmap` and the
//! merging of `vcm` share.
//!
//! **The estimate.** L_r(x, ωo) ≈ Σ_p f(x, ωo, ω'_p) ΔΦ_p K(d_p) / (π r²)
//! [Jensen 2001, eq. 7.6; Hachisuka & Jensen 2009, eq. 7]. It is exact for a
//! uniform irradiance when the photons counted are those landing on a piece
//! of surface of area exactly π r², and each photon's direction is expressed
//! relative to its own surface (ω'_p), so a photon stands for the same
//! reflection at x as where it landed.
//!
//! **Smooth surfaces: the chord kernel.** On a sphere of radius R the cap
//! within chord distance r of x has area 2πR·h with r² = 2Rh, i.e. exactly
//! π r² [Archimedes; the chord is Lambert's azimuthal equal-area map].
//! Counting photons within the Euclidean ball and carrying each photon's ωp
//! by the rotation taking its normal to x's (Rodrigues) makes the
//! unit-sphere furnace exact at any radius; on a plane it changes nothing.
//! This is used when the two geometric normals are within 60°
//! (|n_p·n_x| ≥ [`SMOOTH_COS`]); a normal pointing against x's is first
//! flipped (the same surface wound the other way, or the back of a thin
//! sheet, whose photons then arrive below x's horizon where a reflective f
//! is zero and a transmissive one counts them).
//!
//! **Creases: the unfolded kernel.** At an edge between two planes the
//! Euclidean ball holds a part of the neighbouring face that is *not* the
//! part of x's face it cuts off: at distance d from a 90° edge the ball
//! misses M(d) = r² acos(d/r) − d√(r² − d²) of x's face and holds
//! W(d) = π(r² − d²)/2 of the wall. Rejecting the wall's photons loses M
//! (over a strip of width r, ∫M dd = (2/3) r³ per unit edge length: rooms
//! darken toward their walls); counting them as they are, as pbrt-v4 does,
//! over-counts W − M (∫ = (π/3 − 2/3) r³ ≈ 0.38 r³). Unfolding the
//! neighbouring face onto x's plane about the line where the two tangent
//! planes meet is an isometry, so the photons whose *unfolded* position lies
//! within r of x cover exactly π r² of surface; with the continuous
//! irradiance of a symmetric corner the estimate is exact, otherwise it
//! averages the two faces' irradiance across the edge (a smooth-kernel bias
//! that vanishes with r). With n_x oriented towards ωo and n_p towards ωp
//! (the lit sides), the line L is {x + a s + c u}, u = n_p × n_x/|…|,
//! s = u × n_x, a = (p − x)·n_p / (s·n_p); the photon sits at b along
//! s' = u × n_p from L, b = (p − x)·s' − a (s·s'), and unfolds to
//! x + (a + b) s + c u, c = (p − x)·u, so d² = (a + b)² + c². A photon whose
//! unfolding lands on x's side of L (a·b < 0) is on a face whose lit side
//! turns away from x (the far side of a thin wall): not counted [Jensen
//! 2001, §7.1, against leaks]. Corners (three faces) are not developable:
//! the unfolded disk there covers 3/4 of π r² at the vertex, a loss confined
//! to within r of the corner.
//!
//! Unfolded distances are never shorter than chords, so the callers' ball
//! queries (radius r) find every photon this rule counts.

use crate::math::Vec3;

/// |n_p·n_x| at and above which two normals are taken as one smooth surface.
pub const SMOOTH_COS: f32 = 0.5;

/// A point on a surface with its geometric normal (either orientation) and
/// a direction leaving it: ωo for a gather point, ωp for a photon.
#[derive(Clone, Copy, Debug)]
pub struct Surfel {
    /// Position.
    pub p: Vec3,
    /// Geometric normal.
    pub n: Vec3,
    /// Direction away from the surface (towards the viewer or the light).
    pub w: Vec3,
}

/// A counted photon: its direction in the gather point's frame and the
/// squared distance the kernel uses.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Counted {
    /// ω'_p, to evaluate the gather point's BSDF with.
    pub wi: Vec3,
    /// Squared kernel distance (chord or unfolded, module doc).
    pub dist2: f32,
}

/// How photon `ph` counts at gather point `x` for a kernel of squared
/// radius `r2`, or `None` when it does not (module doc).
pub fn gather(x: &Surfel, ph: &Surfel, r2: f32) -> Option<Counted> {
    let d = ph.p - x.p;
    let c = ph.n.dot(x.n);
    if c.abs() >= SMOOTH_COS {
        let dist2 = d.length_squared();
        if dist2 > r2 {
            return None;
        }
        let from = if c < 0.0 { -ph.n } else { ph.n };
        let wi = rotate_between(ph.w, from, x.n);
        return Some(Counted { wi, dist2 });
    }
    let nx = if x.w.dot(x.n) < 0.0 { -x.n } else { x.n };
    let np = if ph.w.dot(ph.n) < 0.0 { -ph.n } else { ph.n };
    let u = np.cross(nx).normalize();
    let (s, s1) = (u.cross(nx), u.cross(np));
    let a = d.dot(np) / s.dot(np);
    let b = d.dot(s1) - a * s.dot(s1);
    if a * b < 0.0 {
        return None;
    }
    let cu = d.dot(u);
    let dist2 = (a + b) * (a + b) + cu * cu;
    if dist2.is_nan() || dist2 > r2 {
        return None;
    }
    Some(Counted {
        wi: rotate_between(ph.w, np, nx),
        dist2,
    })
}

/// Applies the rotation taking unit vector `a` to unit vector `b` to `v`
/// \[Rodrigues\]: R v = (a·b) v + (a×b)×v + (a×b)((a×b)·v)/(1 + a·b);
/// the identity when a ≈ b.
pub fn rotate_between(v: Vec3, a: Vec3, b: Vec3) -> Vec3 {
    let c = a.dot(b);
    if c >= 1.0 - 1e-7 {
        return v;
    }
    let k = a.cross(b);
    c * v + k.cross(v) + k * (k.dot(v) / (1.0 + c))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn floor(p: Vec3) -> Surfel {
        Surfel {
            p,
            n: Vec3::Z,
            w: Vec3::new(0.3, 0.1, 1.0).normalize(),
        }
    }

    #[test]
    fn rotation_between_normals_maps_a_to_b_and_keeps_angles() {
        let a = Vec3::new(0.2, 0.3, 0.9).normalize();
        let b = Vec3::new(-0.4, 0.1, 0.8).normalize();
        assert!((rotate_between(a, a, b) - b).length() < 1e-6);
        let v = Vec3::new(0.6, -0.7, 0.2).normalize();
        let w = rotate_between(v, a, b);
        assert!((w.length() - 1.0).abs() < 1e-6);
        assert!((w.dot(b) - v.dot(a)).abs() < 1e-6, "angle kept");
        assert!((rotate_between(v, a, a) - v).length() < 1e-6);
    }

    #[test]
    fn a_wall_photon_unfolds_beyond_the_edge_for_either_winding() {
        // Gather at the origin, wall x = 0.3 (room on x < 0.3), photon 0.4 up.
        let x = floor(Vec3::ZERO);
        let wi = Vec3::new(-1.0, 0.2, 0.5).normalize();
        for n in [Vec3::X, -Vec3::X] {
            let ph = Surfel {
                p: Vec3::new(0.3, 0.2, 0.4),
                n,
                w: wi,
            };
            let c = gather(&x, &ph, 1.0).expect("counted");
            assert!((c.dist2 - (0.7f32 * 0.7 + 0.04)).abs() < 1e-5, "{c:?}");
            assert!((c.wi.z - wi.x.abs()).abs() < 1e-5, "angle to its wall kept");
            assert!(gather(&x, &ph, 0.5).is_none(), "unfolded beyond r");
        }
    }

    #[test]
    fn a_convex_edge_unfolds_and_a_thin_walls_far_side_is_not_counted() {
        let x = floor(Vec3::ZERO);
        // The side of a box whose top x lies on, 0.2 below the top.
        let side = Surfel {
            p: Vec3::new(0.3, 0.0, -0.2),
            n: Vec3::X,
            w: Vec3::new(1.0, 0.0, 0.3).normalize(),
        };
        let c = gather(&x, &side, 1.0).expect("counted");
        assert!((c.dist2 - 0.25).abs() < 1e-5, "{c:?}");
        // The far face of a thin wall, lit from beyond it.
        let back = Surfel {
            p: Vec3::new(0.35, 0.0, 0.2),
            n: Vec3::X,
            w: Vec3::new(1.0, 0.0, 0.3).normalize(),
        };
        assert!(gather(&x, &back, 1.0).is_none());
    }

    #[test]
    fn smooth_neighbours_use_the_chord() {
        let x = floor(Vec3::ZERO);
        let n = Vec3::new(-0.3, 0.0, 1.0).normalize();
        let ph = Surfel {
            p: Vec3::new(0.5, 0.0, 0.08),
            n,
            w: n,
        };
        let c = gather(&x, &ph, 1.0).expect("counted");
        assert!((c.dist2 - ph.p.length_squared()).abs() < 1e-6);
        assert!((c.wi - Vec3::Z).length() < 1e-5);
    }
}
