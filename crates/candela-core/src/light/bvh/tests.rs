//! Tests of the BVH light sampler: sampling against its own pmf, the pmf's
//! normalisation, the importance against the angle bound it implements,
//! and that every light reaching a receiver can be chosen there.

use super::*;
use crate::light::{DiffuseAreaLight, LightBounds, LightSpectrum, PointLight, SpotLight};
use crate::math::{DirectionCone, Frame, Mat4, Transform, Vec2};
use crate::sampling::{sample_uniform_sphere, Pcg32};
use crate::shape::{Disk, Shape, Sphere, Triangle, TriangleMesh};
use crate::spectrum::{SampledWavelengths, Spectrum};
use std::sync::Arc;

fn u3(r: &mut Pcg32) -> Vec3 {
    Vec3::new(r.uniform_f32(), r.uniform_f32(), r.uniform_f32()) * 2.0 - Vec3::ONE
}

fn dir(r: &mut Pcg32) -> Vec3 {
    sample_uniform_sphere(Vec2::new(r.uniform_f32(), r.uniform_f32()))
}

fn spectrum(v: f32) -> LightSpectrum {
    Spectrum::Constant(v)
}

/// A one-sided or two-sided area light on `shape`.
fn area(shape: Shape, l: f32, two_sided: bool) -> Light {
    Light::DiffuseArea(DiffuseAreaLight::new(shape, spectrum(l), 1.0, two_sided))
}

/// The frame at `c` whose +z is `n`.
fn frame_at(c: Vec3, n: Vec3) -> Transform {
    let f = Frame::from_z(n);
    let m = Mat4::from_cols(
        f.x.extend(0.0),
        f.y.extend(0.0),
        f.z.extend(0.0),
        c.extend(1.0),
    );
    Transform::new(m, m.inverse())
}

/// A disk of radius `radius` at `c` facing `n`.
fn disk(c: Vec3, n: Vec3, radius: f32) -> Shape {
    Shape::Disk(Disk::new(
        Arc::new(frame_at(c, n)),
        false,
        0.0,
        radius,
        0.0,
        360.0,
    ))
}

/// The triangle `p` (normal (p1 − p0) × (p2 − p0)).
fn triangle(p: [Vec3; 3]) -> Shape {
    let mesh = TriangleMesh::new(
        &Transform::IDENTITY,
        false,
        vec![0, 1, 2],
        p.to_vec(),
        None,
        None,
        None,
    );
    Shape::Triangle(Triangle::new(Arc::new(mesh.expect("valid triangle")), 0))
}

/// 56 small lights of every bounded kind scattered in [−4, 4]³ (one-sided
/// emitters and spots facing random ways), then one light of every kind
/// from the power tests (goniometric, projection, distant and infinite
/// among them), preprocessed with the unit scene.
fn many_lights(seed: u64) -> Vec<Light> {
    let mut r = Pcg32::new(seed, 0);
    let mut lights = Vec::new();
    for k in 0..56 {
        let c = 4.0 * u3(&mut r);
        let l = 0.5 + 4.0 * r.uniform_f32();
        lights.push(match k % 7 {
            0 => Light::Point(PointLight::new(Transform::translate(c), spectrum(l), 1.0)),
            1 => {
                let t = frame_at(c, dir(&mut r));
                let end = 10.0 + 40.0 * r.uniform_f32();
                // Every third spot has a hard edge (no falloff band).
                let start = if k % 3 == 0 { end } else { end - 5.0 };
                Light::Spot(SpotLight::new(t, spectrum(l), 1.0, end, start))
            }
            2 => area(disk(c, dir(&mut r), 0.1 + 0.3 * r.uniform_f32()), l, false),
            3 => area(
                triangle([c, c + 0.5 * u3(&mut r), c + 0.5 * u3(&mut r)]),
                l,
                false,
            ),
            4 => area(
                triangle([c, c + 0.5 * u3(&mut r), c + 0.5 * u3(&mut r)]),
                l,
                true,
            ),
            5 => {
                let s = Sphere::new(
                    Arc::new(Transform::translate(c)),
                    false,
                    0.2,
                    -0.2,
                    0.2,
                    360.0,
                );
                area(Shape::Sphere(s), l, false)
            }
            _ => area(disk(c, dir(&mut r), 0.2), l, true),
        });
    }
    lights.extend(
        crate::light::tests::power::lights_with_phi()
            .into_iter()
            .map(|(_, l, _)| l),
    );
    lights
}

/// A receiver in [−5, 5]³: on a surface with a random normal, or (one in
/// four) in free space (zero normal).
fn receiver(r: &mut Pcg32) -> LightSampleContext {
    let p = 5.0 * u3(r);
    let n = if r.uniform_f32() < 0.25 {
        Vec3::ZERO
    } else {
        dir(r)
    };
    LightSampleContext {
        p,
        p_error: Vec3::ZERO,
        n,
        ns: n,
    }
}

/// Probability mass of the walks that end at an interior node whose two
/// children both have zero importance (top-down, every branch).
fn dead_end_mass(s: &BvhLightSampler, ctx: &LightSampleContext) -> f64 {
    fn walk(s: &BvhLightSampler, i: usize, mass: f64, ctx: &LightSampleContext) -> f64 {
        let node = &s.nodes[i];
        if node.is_leaf() {
            let alive = i > 0 || s.root_importance(ctx.p, ctx.ns) > 0.0;
            return if alive { 0.0 } else { mass };
        }
        let pr = s.child_probabilities(i, ctx.p, ctx.ns);
        if pr == [0.0; 2] {
            return mass;
        }
        let child = [i + 1, node.target() as usize];
        (0..2)
            .filter(|&k| pr[k] > 0.0)
            .map(|k| walk(s, child[k], mass * pr[k] as f64, ctx))
            .sum()
    }
    if s.nodes.is_empty() {
        return 0.0;
    }
    walk(s, 0, 1.0 - s.p_infinite() as f64, ctx)
}

#[test]
fn every_trail_leads_to_its_light() {
    let lights = many_lights(1);
    let s = BvhLightSampler::new(&lights);
    let mut in_tree = 0;
    for (id, slot) in s.slots.iter().enumerate() {
        match (slot, lights[id].bounds()) {
            (Slot::Tree(trail), Some(lb)) => {
                assert!(lb.phi > 0.0);
                let (mut i, mut t) = (0, *trail);
                while !s.nodes[i].is_leaf() {
                    i = if t & 1 == 0 {
                        i + 1
                    } else {
                        s.nodes[i].target() as usize
                    };
                    t >>= 1;
                }
                assert_eq!(s.nodes[i].target() as usize, id);
                in_tree += 1;
            }
            (Slot::Infinite, None) => {}
            (slot, b) => panic!("light {id}: {slot:?} with bounds {b:?}"),
        }
    }
    assert_eq!(s.nodes.len(), 2 * in_tree - 1);
    assert_eq!(s.infinite.len(), 2);
}

/// Bins `n` samples at `ctx` per light (plus "no light") and compares each
/// count with n·pmf: binomial, so |count − n·p| ≤ 5·√(n·p·(1 − p)) (5σ;
/// with ~70 bins × 6 receivers a false alarm has probability ~2·10⁻⁴, and
/// the seed is fixed); a bin of pmf 0 must stay empty. Each sample's pmf
/// must be exactly `pmf()`'s.
#[test]
fn sample_frequencies_match_the_pmf() {
    let lights = many_lights(2);
    let s = BvhLightSampler::new(&lights);
    let mut r = Pcg32::new(4, 0);
    let n = 300_000usize;
    for _ in 0..6 {
        let ctx = receiver(&mut r);
        let mut counts = vec![0usize; lights.len() + 1];
        for _ in 0..n {
            match s.sample(&ctx, r.uniform_f32()) {
                Some((id, pmf)) => {
                    assert_eq!(pmf, s.pmf(&ctx, id), "light {id:?} at {ctx:?}");
                    counts[id.0 as usize] += 1;
                }
                None => counts[lights.len()] += 1,
            }
        }
        let mut p: Vec<f64> = (0..lights.len())
            .map(|i| s.pmf(&ctx, LightId(i as u32)) as f64)
            .collect();
        p.push((1.0 - p.iter().sum::<f64>()).max(0.0));
        for (bin, (&c, &p)) in counts.iter().zip(&p).enumerate() {
            let (e, sigma) = (n as f64 * p, (n as f64 * p * (1.0 - p)).sqrt());
            assert!(
                (c as f64 - e).abs() <= 5.0 * sigma,
                "bin {bin} at {ctx:?}: {c} samples, expected {e:.1} ± {sigma:.1}"
            );
        }
    }
}

/// Σ pmf over the bounded lights plus the mass of dead-end walks is the
/// tree's share 1 − p∞ (f32 products of ≤ 10 factors: 10⁻⁵ allowance), and
/// the infinite lights share p∞; with only omnidirectional lights seen from
/// free space there is no dead end and Σ pmf = 1.
#[test]
fn pmfs_sum_to_one_less_the_dead_ends() {
    let lights = many_lights(3);
    let s = BvhLightSampler::new(&lights);
    let p_inf = s.p_infinite() as f64;
    let mut r = Pcg32::new(6, 0);
    for _ in 0..300 {
        let ctx = receiver(&mut r);
        let pmf = |i: usize| s.pmf(&ctx, LightId(i as u32)) as f64;
        let (mut tree, mut inf) = (0.0, 0.0);
        for (i, light) in lights.iter().enumerate() {
            match light.bounds() {
                Some(_) => tree += pmf(i),
                None => inf += pmf(i),
            }
        }
        assert!((inf - p_inf).abs() <= 1e-6, "{inf} vs {p_inf}");
        let dead = dead_end_mass(&s, &ctx);
        assert!(
            (tree + dead - (1.0 - p_inf)).abs() <= 1e-5,
            "{tree} + {dead} at {ctx:?}"
        );
    }
    let omni: Vec<Light> = lights
        .into_iter()
        .filter(|l| {
            matches!(l, Light::Point(_))
                || matches!(l, Light::DiffuseArea(a) if matches!(a.shape(), Shape::Sphere(_)))
        })
        .collect();
    let s = BvhLightSampler::new(&omni);
    for _ in 0..100 {
        let ctx = LightSampleContext::at_point(5.0 * u3(&mut r));
        let sum: f64 = (0..omni.len())
            .map(|i| s.pmf(&ctx, LightId(i as u32)) as f64)
            .sum();
        assert!((sum - 1.0).abs() <= 1e-5, "{sum}");
    }
}

/// Wherever a light's own sampling finds radiance at a receiver, the
/// sampler can choose that light there: the bounds are conservative for
/// every light kind, through the tree and the packing.
#[test]
fn lights_that_reach_a_receiver_can_be_chosen() {
    let lights = many_lights(5);
    let s = BvhLightSampler::new(&lights);
    let lambda = SampledWavelengths::sample_visible(0.3);
    let mut r = Pcg32::new(8, 0);
    let mut reached = 0;
    for _ in 0..400 {
        let ctx = receiver(&mut r);
        for (i, light) in lights.iter().enumerate() {
            let lit = (0..8).any(|_| {
                let u = Vec2::new(r.uniform_f32(), r.uniform_f32());
                light
                    .sample_li(&ctx, u, &lambda)
                    .is_some_and(|ls| !ls.l.is_black())
            });
            if lit {
                reached += 1;
                assert!(
                    s.pmf(&ctx, LightId(i as u32)) > 0.0,
                    "light {i} reaches {ctx:?} with pmf 0"
                );
            }
        }
    }
    assert!(reached > 10_000, "{reached}");
}

/// The angle bound in f64 from explicit angles [pbrt-v4 §12.6.3]: θ' =
/// (θw ⊖ θo) ⊖ θb, zero when θ' ≥ θe, else φ·cos θ'·cos(θi ⊖ θb)/d².
/// Returns cos θ' − cos θe, the importance, and its scale φ/d².
fn reference_importance(b: &LightBounds, p: Vec3, n: Vec3) -> (f64, f64, f64) {
    let sub = |a: f64, c: f64| (a - c).max(0.0);
    let pc = b.bounds.centroid().as_dvec3();
    let d = p.as_dvec3() - pc;
    let wi = d.normalize();
    let mut theta_w = b.w.as_dvec3().dot(wi).clamp(-1.0, 1.0).acos();
    if b.two_sided {
        theta_w = theta_w.min(std::f64::consts::PI - theta_w);
    }
    let (c, radius) = b.bounds.bounding_sphere();
    let dc = (p.as_dvec3() - c.as_dvec3()).length();
    let theta_b = if dc <= radius as f64 {
        std::f64::consts::PI
    } else {
        (radius as f64 / dc).asin()
    };
    let theta_p = sub(sub(theta_w, (b.cos_theta_o as f64).acos()), theta_b);
    let mut imp = b.phi as f64 * theta_p.cos();
    if n != Vec3::ZERO {
        let theta_i = n.as_dvec3().normalize().dot(wi).abs().min(1.0).acos();
        imp *= sub(theta_i, theta_b).cos();
    }
    let d2 = d
        .length_squared()
        .max(b.bounds.diagonal().as_dvec3().length() / 2.0);
    (
        theta_p.cos() - (b.cos_theta_e as f64),
        imp / d2,
        b.phi as f64 / d2,
    )
}

#[test]
fn importance_is_zero_exactly_where_the_angle_bound_is() {
    let mut r = Pcg32::new(9, 0);
    let (mut zeros, mut checked) = (0, 0);
    for _ in 0..100_000 {
        let (a, c) = (u3(&mut r), u3(&mut r) * r.uniform_f32());
        let lb = LightBounds::new(
            Bounds3::from_points(a, a + c.abs() * 0.3),
            DirectionCone::new(dir(&mut r), 2.0 * r.uniform_f32() - 1.0),
            1.0 + r.uniform_f32(),
            (2.0 * r.uniform_f32() - 1.0).max(0.0),
            r.uniform_f32() < 0.3,
        );
        let p = 3.0 * u3(&mut r);
        let n = if r.uniform_f32() < 0.3 {
            Vec3::ZERO
        } else {
            dir(&mut r)
        };
        let (margin, expected, scale) = reference_importance(&lb, p, n);
        if margin.abs() < 1e-4 {
            continue; // At the boundary f32 round-off decides.
        }
        let got = lb.importance(p, n) as f64;
        checked += 1;
        if margin <= 0.0 {
            zeros += 1;
            assert_eq!(got, 0.0, "{lb:?} at {p:?}, n {n:?}");
        } else {
            // f32 sines and cosines of the angles: ~10⁻⁶ absolute on the cosines.
            assert!(
                (got - expected).abs() <= 1e-4 * scale,
                "{lb:?} at {p:?}: {got} vs {expected}"
            );
        }
    }
    assert!(
        zeros > 5_000 && checked - zeros > 5_000,
        "{zeros} of {checked}"
    );
}

/// Random bounds (boxes that may hold p or be a point, one- and two-sided,
/// cones from a single direction to the whole sphere), points and normals
/// (zero for free space): the pair evaluation gives each child's scalar
/// importance bit for bit, so `sample` and `pmf`, which both use it, keep
/// the probabilities pbrt-v4's scalar formula defines.
#[test]
fn pair_importances_are_the_scalar_ones_bit_for_bit() {
    let mut r = Pcg32::new(11, 3);
    let bounds = |r: &mut Pcg32| {
        let (a, c) = (u3(r), u3(r) * r.uniform_f32());
        let size = if r.uniform_f32() < 0.1 { 0.0 } else { 0.3 };
        let lb = LightBounds::new(
            Bounds3::from_points(a, a + c.abs() * size),
            DirectionCone::new(dir(r), 2.0 * r.uniform_f32() - 1.0),
            1.0 + r.uniform_f32(),
            (2.0 * r.uniform_f32() - 1.0).max(0.0),
            r.uniform_f32() < 0.3,
        );
        (lb, PreparedBounds::new(&lb))
    };
    let (mut positive, mut zero) = (0, 0);
    for _ in 0..100_000 {
        let ((la, a), (lb, b)) = (bounds(&mut r), bounds(&mut r));
        let _ = &lb;
        let p = match r.next_u32() % 4 {
            0 => la.centroid(),
            1 => la.bounds.min + (la.bounds.max - la.bounds.min) * r.uniform_f32(),
            _ => 3.0 * u3(&mut r),
        };
        let n = if r.uniform_f32() < 0.3 {
            Vec3::ZERO
        } else {
            dir(&mut r)
        };
        let got = PreparedPair::new(&a, &b).importances(p, n);
        let want = [a.importance(p, n), b.importance(p, n)];
        assert_eq!(
            got.map(f32::to_bits),
            want.map(f32::to_bits),
            "{la:?} {lb:?} at {p:?}, n {n:?}"
        );
        for w in want {
            if w > 0.0 {
                positive += 1;
            } else {
                zero += 1;
            }
        }
    }
    // Both outcomes must be common for the comparison to mean anything.
    assert!(positive > 5_000 && zero > 5_000, "{positive} {zero}");
}

/// Random cones and directions: anything in either cone is in the union.
#[test]
fn union_contains_both_cones() {
    let mut rng = Pcg32::new(7, 0);
    for _ in 0..2000 {
        let cone = |rng: &mut Pcg32| {
            let w = sample_uniform_sphere(Vec2::new(rng.uniform_f32(), rng.uniform_f32()));
            DirectionCone::new(w, 2.0 * rng.uniform_f32() - 1.0)
        };
        let (a, b) = (cone(&mut rng), cone(&mut rng));
        let u = a.union(b);
        for _ in 0..20 {
            let d = sample_uniform_sphere(Vec2::new(rng.uniform_f32(), rng.uniform_f32()));
            // The f32 round-off of a dot product (a few ulps) is the slack.
            let slack = 4.0 * f32::EPSILON;
            for c in [a, b] {
                if c.w.dot(d) >= c.cos_theta {
                    assert!(
                        u.w.dot(d) >= u.cos_theta - slack,
                        "{a:?} ∪ {b:?} = {u:?} misses {d:?}"
                    );
                }
            }
        }
    }
}
