//! Unit tests of texture mappings, nodes and noise.

use super::*;
use crate::math::{Transform, PI};
use crate::sampling::Pcg32;
use crate::spectrum::ColorSpace;

fn at_uv(u: f32, v: f32) -> TextureEvalContext {
    TextureEvalContext {
        uv: Vec2::new(u, v),
        ..Default::default()
    }
}

fn at_p(p: Vec3) -> TextureEvalContext {
    TextureEvalContext {
        p,
        ..Default::default()
    }
}

fn c(v: f32) -> FloatTexture {
    FloatTexture::Constant(v)
}

fn checker(map: CheckerMap) -> FloatTexture {
    FloatTexture::Checkerboard(Arc::new(Checkerboard {
        map,
        tex1: c(10.0),
        tex2: c(20.0),
    }))
}

#[test]
fn checkerboard_2d_alternates_by_cell_parity() {
    let t = checker(CheckerMap::Planar(TextureMapping2D::UV));
    for (u, v, want) in [
        (0.25, 0.25, 10.0),
        (1.25, 0.25, 20.0),
        (0.25, 1.75, 20.0),
        (1.5, 1.5, 10.0),
        (-0.25, 0.25, 20.0),
        (-0.25, -0.25, 10.0),
        (2.99, 0.01, 10.0),
    ] {
        assert_eq!(t.evaluate(&at_uv(u, v)), want, "uv ({u}, {v})");
    }
    // uscale 4: the cell boundary moves to u = 0.25.
    let scaled = checker(CheckerMap::Planar(TextureMapping2D::Uv {
        su: 4.0,
        sv: 1.0,
        du: 0.0,
        dv: 0.0,
    }));
    assert_eq!(scaled.evaluate(&at_uv(0.2, 0.5)), 10.0);
    assert_eq!(scaled.evaluate(&at_uv(0.3, 0.5)), 20.0);
}

#[test]
fn checkerboard_3d_alternates_by_cube_parity() {
    let map = TextureMapping3D {
        texture_from_render: Transform::IDENTITY,
    };
    let t = checker(CheckerMap::Solid(map));
    assert_eq!(t.evaluate(&at_p(Vec3::new(0.5, 0.5, 0.5))), 10.0);
    assert_eq!(t.evaluate(&at_p(Vec3::new(1.5, 0.5, 0.5))), 20.0);
    assert_eq!(t.evaluate(&at_p(Vec3::new(1.5, 1.5, 0.5))), 10.0);
    assert_eq!(t.evaluate(&at_p(Vec3::new(1.5, 1.5, -0.5))), 20.0);
}

#[test]
fn checkerboard_filter_averages_wide_footprints() {
    // A footprint many cells wide sees half of each colour.
    let map = CheckerMap::Planar(TextureMapping2D::UV);
    let mut ctx = at_uv(0.3, 0.6);
    ctx.dudx = 40.0;
    ctx.dvdy = 40.0;
    let w = checkerboard_weight(&map, &ctx);
    assert!((w - 0.5).abs() < 0.02, "weight {w}");
    // A footprint inside one cell is the point value.
    ctx.dudx = 0.05;
    ctx.dvdy = 0.05;
    assert_eq!(checkerboard_weight(&map, &ctx), 0.0);
}

#[test]
fn bilerp_reproduces_corners_and_centre() {
    let t = FloatTexture::Bilerp(Arc::new(Bilerp {
        map: TextureMapping2D::UV,
        v: [1.0, 2.0, 3.0, 5.0],
    }));
    assert_eq!(t.evaluate(&at_uv(0.0, 0.0)), 1.0);
    assert_eq!(t.evaluate(&at_uv(0.0, 1.0)), 2.0);
    assert_eq!(t.evaluate(&at_uv(1.0, 0.0)), 3.0);
    assert_eq!(t.evaluate(&at_uv(1.0, 1.0)), 5.0);
    assert_eq!(t.evaluate(&at_uv(0.5, 0.5)), 2.75);
}

#[test]
fn scale_and_mix_arithmetic() {
    let scale = FloatTexture::Scale(Arc::new(Scale {
        tex: c(3.0),
        scale: c(0.5),
    }));
    let ctx = at_uv(0.0, 0.0);
    assert_eq!(scale.evaluate(&ctx), 1.5);
    let mix = FloatTexture::Mix(Arc::new(Mix {
        tex1: c(2.0),
        tex2: scale.clone(),
        amount: c(0.25),
    }));
    assert_eq!(mix.evaluate(&ctx), 0.75 * 2.0 + 0.25 * 1.5);
    // Spectral mix of constants, per wavelength.
    let lambda = SampledWavelengths::sample_visible(0.3);
    let smix = SpectrumTexture::Mix(Arc::new(Mix {
        tex1: SpectrumTexture::Constant(Spectrum::Constant(0.2)),
        tex2: SpectrumTexture::Constant(Spectrum::Constant(0.6)),
        amount: c(0.75),
    }));
    let v = smix.evaluate(&ctx, &lambda);
    for k in 0..4 {
        assert!((v[k] - 0.5).abs() < 1e-6);
    }
}

#[test]
fn direction_mix_weights_by_normal_alignment() {
    let t = FloatTexture::DirectionMix(Arc::new(DirectionMix {
        tex1: c(1.0),
        tex2: c(0.0),
        dir: Vec3::Y,
    }));
    let mut ctx = at_uv(0.0, 0.0);
    ctx.n = Vec3::Y;
    assert_eq!(t.evaluate(&ctx), 1.0);
    ctx.n = -Vec3::Y;
    assert_eq!(t.evaluate(&ctx), 1.0);
    ctx.n = Vec3::X;
    assert_eq!(t.evaluate(&ctx), 0.0);
    ctx.n = Vec3::new(0.6, 0.8, 0.0);
    assert!((t.evaluate(&ctx) - 0.8).abs() < 1e-6);
}

#[test]
fn permutation_table_is_a_permutation() {
    let mut seen = [false; 256];
    for &v in perm::PERM.iter() {
        assert!(!seen[v as usize], "{v} repeated");
        seen[v as usize] = true;
    }
    // Pins the table to Perlin's (and pbrt-v4's) order: Σ i·PERM[i] of the
    // reference table.
    assert_eq!(&perm::PERM[..4], &[151, 160, 137, 91]);
    let weighted: usize = perm::PERM
        .iter()
        .enumerate()
        .map(|(i, &v)| i * v as usize)
        .sum();
    assert_eq!(weighted, 4_373_588);
}

#[test]
fn noise_vanishes_on_the_lattice() {
    for x in -3..4 {
        for y in -3..4 {
            for z in [-300, -1, 0, 1, 255, 256, 1000] {
                let n = noise(x as f32, y as f32, z as f32);
                assert_eq!(n, 0.0, "noise({x}, {y}, {z}) = {n}");
            }
        }
    }
}

#[test]
fn noise_matches_a_transcription_of_pbrt() {
    // Reference values from a separate double-precision Python transcription
    // of pbrt-v4's `Noise` (util/noise.cpp) with the same table.
    for (p, want) in [
        ([0.5, 0.5, 0.5], -0.125),
        ([1.25, -2.75, 3.5], 0.120_097_16),
        ([10.1, 20.2, -30.3], 0.268_966_16),
        ([-0.3, 0.7, 100.9], -0.330_789),
        ([255.5, 255.5, 255.5], -0.375),
    ] {
        let n = noise(p[0], p[1], p[2]);
        assert!((n - want).abs() < 2e-5, "noise{p:?} = {n}, want {want}");
    }
}

#[test]
fn noise_is_bounded_and_not_trivial() {
    let mut rng = Pcg32::new(7, 1);
    let (mut lo, mut hi) = (0.0f32, 0.0f32);
    for _ in 0..200_000 {
        let p = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 64.0
            - Vec3::splat(32.0);
        let n = noise_at(p);
        assert!((-1.0..=1.0).contains(&n), "noise({p}) = {n}");
        lo = lo.min(n);
        hi = hi.max(n);
    }
    eprintln!("noise range over the samples: [{lo}, {hi}]");
    assert!(lo < -0.5 && hi > 0.5, "range [{lo}, {hi}] too narrow");
}

#[test]
fn noise_is_continuous_across_cells() {
    // The value is C¹ with slopes of order 1, so points 2.6h apart differ
    // by well under 0.01 (a discontinuity would jump by O(1)); straddle
    // cell faces, where a wrong corner hash would break continuity.
    let mut rng = Pcg32::new(3, 5);
    let h = 1e-3;
    for _ in 0..20_000 {
        let mut p = Vec3::new(rng.uniform_f32(), rng.uniform_f32(), rng.uniform_f32()) * 16.0;
        p.x = p.x.round(); // on a cell face
        let d = Vec3::new(h, h * 0.5, -h * 0.7);
        let (a, b) = (noise_at(p - d), noise_at(p + d));
        assert!((a - b).abs() < 0.01, "jump {} at {p}", (a - b).abs());
    }
}

#[test]
fn octave_count_follows_the_footprint() {
    let z = Vec3::ZERO;
    assert_eq!(octave_count(z, z, 8), 8.0);
    // |dpdx| = 2⁻ᵏ allows n = k − 1 octaves.
    assert_eq!(octave_count(Vec3::new(0.125, 0.0, 0.0), z, 8), 2.0);
    assert_eq!(octave_count(z, Vec3::new(0.0, 0.0, 1.0 / 64.0), 8), 5.0);
    assert_eq!(octave_count(Vec3::new(0.0, 1.0 / 64.0, 0.0), z, 3), 3.0);
    assert_eq!(octave_count(Vec3::splat(10.0), z, 8), 0.0);
    // The larger of the two footprints decides.
    assert_eq!(
        octave_count(Vec3::X / 8.0, Vec3::X / 2.0f32.powf(6.5), 8),
        2.0
    );
}

#[test]
fn fbm_and_turbulence_sum_the_allowed_octaves() {
    let p = Vec3::new(0.31, 1.7, -2.2);
    let (omega, f) = (0.6, 1.99);
    let dpdx = Vec3::new(0.125, 0.0, 0.0); // two whole octaves, no partial one
    let n0 = noise_at(p);
    let n1 = noise_at(f * p);
    let fb = fbm(p, dpdx, Vec3::ZERO, omega, 8);
    assert!((fb - (n0 + omega * n1)).abs() < 1e-6, "fbm {fb}");
    // Octaves 3 and 4 of 4 that the footprint drops add 0.2 each (and the
    // faded-out partial octave adds 0.2 too, as in pbrt-v4).
    let tu = turbulence(p, dpdx, Vec3::ZERO, omega, 4);
    let want = n0.abs() + omega * n1.abs() + 0.2 * omega.powi(2) * 2.0 + 0.2 * omega.powi(3);
    assert!((tu - want).abs() < 1e-6, "turbulence {tu} vs {want}");
    // Without a footprint, fbm sums every octave.
    let all: f32 = (0..5)
        .map(|i| omega.powi(i) * noise_at(f.powi(i) * p))
        .sum();
    assert!((fbm(p, Vec3::ZERO, Vec3::ZERO, omega, 5) - all).abs() < 1e-5);
}

#[test]
fn spherical_mapping_at_known_points() {
    // Texture space centred at (1, 2, 3).
    let map = TextureMapping2D::Spherical {
        texture_from_render: Transform::translate(Vec3::new(1.0, 2.0, 3.0)).inverse(),
    };
    let st = |p: Vec3| map.map(&at_p(p + Vec3::new(1.0, 2.0, 3.0))).st;
    let near = |a: Vec2, b: Vec2| (a - b).length() < 1e-6;
    assert!(near(st(Vec3::Z), Vec2::new(0.0, 0.0)));
    assert!(near(st(-2.0 * Vec3::Z), Vec2::new(1.0, 0.0)));
    assert!(near(st(Vec3::X), Vec2::new(0.5, 0.0)));
    assert!(near(st(3.0 * Vec3::Y), Vec2::new(0.5, 0.25)));
    assert!(near(st(-Vec3::Y), Vec2::new(0.5, 0.75)));
    let d = Vec3::new(1.0, 1.0, 2.0f32.sqrt());
    assert!(near(st(d), Vec2::new(0.25, 0.125)));
}

#[test]
fn cylindrical_mapping_at_known_points() {
    let map = TextureMapping2D::Cylindrical {
        texture_from_render: Transform::scale(Vec3::splat(0.5)),
    };
    let st = |p: Vec3| map.map(&at_p(p)).st;
    assert!((st(Vec3::new(2.0, 0.0, 4.0)) - Vec2::new(0.5, 2.0)).length() < 1e-6);
    assert!((st(Vec3::new(0.0, 2.0, 0.0)) - Vec2::new(0.75, 0.0)).length() < 1e-6);
    assert!((st(Vec3::new(0.0, -2.0, -2.0)) - Vec2::new(0.25, -1.0)).length() < 1e-6);
}

#[test]
fn planar_mapping_at_known_points() {
    // Texture space rotated 90° about z: render x is texture −y.
    let rot = Transform::new(
        glam::Mat4::from_rotation_z(PI / 2.0),
        glam::Mat4::from_rotation_z(-PI / 2.0),
    );
    let map = TextureMapping2D::Planar {
        texture_from_render: rot.inverse(),
        vs: Vec3::X,
        vt: Vec3::new(0.0, 1.0, 1.0),
        ds: 0.5,
        dt: -1.0,
    };
    let st = map.map(&at_p(Vec3::new(2.0, 3.0, 4.0))).st;
    // Texture-space point (3, −2, 4): s = 0.5 + 3, t = −1 + (−2 + 4).
    assert!((st - Vec2::new(3.5, 1.0)).length() < 1e-5, "{st}");
}

#[test]
fn uv_mapping_scales_then_offsets() {
    let map = TextureMapping2D::Uv {
        su: 2.0,
        sv: 3.0,
        du: 0.5,
        dv: -1.0,
    };
    assert_eq!(map.map(&at_uv(0.25, 1.0)).st, Vec2::new(1.0, 2.0));
}

#[test]
fn polka_dots_sit_in_cells_with_positive_noise() {
    let (mut with, mut without) = (0, 0);
    for sc in -10..10 {
        for tc in -10..10 {
            let (s, t) = (sc as f32, tc as f32);
            let has_dot = noise(s + 0.5, t + 0.5, 0.5) > 0.0;
            // The dot centre is within 0.15 of the cell centre, radius 0.35.
            let centre_inside = inside_polka_dot(Vec2::new(s, t));
            assert_eq!(centre_inside, has_dot, "cell ({sc}, {tc})");
            assert!(!inside_polka_dot(Vec2::new(s + 0.49, t + 0.49)));
            if has_dot {
                with += 1
            } else {
                without += 1
            }
        }
    }
    assert!(with > 50 && without > 50, "{with} dots, {without} empty");
}

#[test]
fn marble_spline_and_spectrum_table() {
    let r0 = marble_rgb(0.0);
    assert!((r0.r - 0.87).abs() < 1e-6 && (r0.b - 0.9).abs() < 1e-6);
    let r1 = marble_rgb(1.0);
    assert!((r1.g - 0.87).abs() < 1e-6);
    // t = 5/6 starts the segment through the dark vein colour (0.2, 0.2, 0.33).
    let dark = marble_rgb(5.5 / 6.0);
    assert!(dark.r < 0.7 && dark.b > dark.r, "{dark:?}");
    // At a table node the spectrum is the sigmoid fit of that colour.
    let lambda = SampledWavelengths::sample_visible(0.71);
    let t = 0.5; // node 96 of 192
    let want = Spectrum::rgb_albedo(ColorSpace::srgb(), marble_rgb(t)).sample(&lambda);
    let got = marble_spectrum(t, &lambda);
    for k in 0..4 {
        assert!((got[k] - want[k]).abs() < 1e-6, "{got:?} vs {want:?}");
        assert!((0.0..=1.0).contains(&got[k]));
    }
}
