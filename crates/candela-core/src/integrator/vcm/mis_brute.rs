//! Brute-force check of VCM's MIS weights: for random paths of 1–7
//! segments (random diffuse/glossy densities, specular vertices, area,
//! point and infinite lights; one segment: a light seen from the lens) every technique's weight from the recursive
//! quantities of [`super::mis`] equals the power-heuristic weight computed
//! from every technique's full path density, and the weights sum to one
//! [Veach 1997, eq. 9.13; Georgiev et al. 2012, eqs. 20, 37].
//!
//! A path is x_0 (on the light) … x_m (seen from the lens), segment k
//! joining x_k and x_{k+1}, and segment "cam" joining x_m and the lens. Its
//! techniques, with the sample counts of eq. 20 folded into the densities:
//! - connection s (s light vertices, 0 ≤ s ≤ m + 1): Π_{k<s} pL(x_k) ·
//!   Π_{k≥s} pE(x_k), times N_light for s = m + 1 (light tracing: every
//!   light path splats), whose heuristic term is also multiplied by the
//!   path's variance factor c ([`super::variance`]; √c on the density;
//!   c = 1 when m = 0, where light tracing joins x_0 itself);
//! - merge at x_i (1 ≤ i ≤ m): Π_{k≤i} pL(x_k) · Π_{k≥i} pE(x_k) · π r² N_light;
//!   at x_1, next to the light, only with `directmerges always`, or
//!   `afterspecular` (the default) when x_2 is specular;
//!
//! where pL(x_k), pE(x_k) are the area densities (solid angle at infinity)
//! with which the light and the camera subpath generate x_k. Techniques
//! that join at a specular vertex, hit a delta light, or use a connection
//! at a specular end are impossible. The recursion is driven with the same
//! calls, in the same order and with the same arguments, as the light pass
//! (`light.rs`: `Partial::light`, `scatter`, `hit`, t = 1) and the camera
//! pass (`camera.rs`: `hit`, `scatter`, emission, NEE, connection, merge)
//! make; the test is seen to fail when one density given to the recursion
//! is perturbed (last test).

use super::mis::{mis, weight, CameraPartial, Deferred, DirectMerges, Factors, Partial};
use crate::sampling::{PathRng, StreamRng};

/// The light at x_0.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Emitter {
    Area,
    Point,
    Infinite,
}

/// One random path.
#[derive(Clone, Debug)]
struct Path {
    light: Emitter,
    /// Light selection × position density (area; 1 for a point light).
    p_pos: f32,
    /// Light selection × next-event density of x_0 seen from x_1 (area; for
    /// an area light it differs from `p_pos`: cone sampling of a sphere,
    /// nee.rs `nee_area_density`; else it is `p_pos`, or `p_inf_dir` at
    /// infinity).
    p_nee: f32,
    /// Emission direction density (solid angle; 1 for an infinite light's
    /// direction, whose density is in `p_inf_dir`).
    p_dir: f32,
    /// An infinite light's direction density (solid angle).
    p_inf_dir: f32,
    /// Per vertex 1..=m: specular?
    delta: Vec<bool>,
    /// Per vertex: density of the light side's next direction (towards
    /// x_{k+1}, or the lens for x_m), solid angle.
    pl_dir: Vec<f32>,
    /// Per vertex: density of the camera side's next direction (towards x_{k-1}).
    pe_dir: Vec<f32>,
    /// Per segment k: distance², cosine at x_k, cosine at x_{k+1}.
    seg: Vec<(f32, f32, f32)>,
    /// The camera segment: distance², cosine at x_m.
    cam: (f32, f32),
    pdf_pixel: f32,
    n_light: f32,
    /// Per vertex 0..=m: the merge radius there (a radius field,
    /// [`super::field`]; on half the paths one radius for all).
    radius: Vec<f32>,
    /// Light tracing's variance factor c on this path.
    lt_c: f32,
}

fn uniform(rng: &mut StreamRng, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * rng.u1()
}

impl Path {
    /// A random path with `m` scattering vertices (0: the lens sees the
    /// light).
    fn random(rng: &mut StreamRng, m: usize) -> Self {
        let light = match (rng.u1() * 3.0) as u32 {
            0 => Emitter::Area,
            1 => Emitter::Point,
            _ => Emitter::Infinite,
        };
        let mut delta = vec![false; m + 1];
        let (mut pl_dir, mut pe_dir) = (vec![0.0; m + 1], vec![0.0; m + 1]);
        for k in 1..=m {
            delta[k] = rng.u1() < 0.3;
            // Diffuse ~ 1/π, glossy up to tens; a delta lobe's two
            // densities are equal (they cancel in every ratio).
            pl_dir[k] = uniform(rng, 0.05, 8.0);
            pe_dir[k] = if delta[k] {
                pl_dir[k]
            } else {
                uniform(rng, 0.05, 8.0)
            };
        }
        let seg = (0..m)
            .map(|_| {
                (
                    uniform(rng, 0.2, 4.0),
                    uniform(rng, 0.1, 1.0),
                    uniform(rng, 0.1, 1.0),
                )
            })
            .collect();
        let p_pos = if light == Emitter::Point {
            0.5
        } else {
            uniform(rng, 0.1, 3.0)
        };
        let (p_dir, p_inf_dir) = (uniform(rng, 0.1, 1.0), uniform(rng, 0.05, 2.0));
        Path {
            light,
            p_pos,
            p_dir,
            p_inf_dir,
            delta,
            pl_dir,
            pe_dir,
            seg,
            cam: (uniform(rng, 0.5, 5.0), uniform(rng, 0.2, 1.0)),
            pdf_pixel: uniform(rng, 1e3, 1e5),
            n_light: uniform(rng, 1e3, 1e5),
            radius: if rng.u1() < 0.5 {
                vec![uniform(rng, 0.002, 0.05); m + 1]
            } else {
                (0..=m).map(|_| uniform(rng, 0.002, 0.05)).collect()
            },
            lt_c: if m == 0 || rng.u1() < 0.25 {
                1.0
            } else {
                uniform(rng, 1.0 / 32.0, 1.0)
            },
            p_nee: match light {
                Emitter::Area => uniform(rng, 0.1, 3.0),
                Emitter::Point => p_pos,
                Emitter::Infinite => p_inf_dir,
            },
        }
    }

    fn m(&self) -> usize {
        self.seg.len()
    }

    fn at_infinity(&self) -> bool {
        self.light == Emitter::Infinite
    }

    /// (direct, emission, cos at the light) as `light_densities` gives them.
    fn light_densities(&self) -> (f32, f32, f32) {
        match self.light {
            Emitter::Area => {
                let cos = self.seg.first().map_or(self.cam.1, |s| s.1);
                (self.p_nee, self.p_pos * self.p_dir, cos)
            }
            Emitter::Point => (self.p_pos, self.p_pos * self.p_dir, 1.0),
            Emitter::Infinite => (self.p_inf_dir, self.p_inf_dir * self.p_pos, 1.0),
        }
    }

    /// pL(x_k): the light subpath's density of x_k.
    fn pl(&self, k: usize) -> f64 {
        let (d2, _, cos_in) = if k > 0 {
            self.seg[k - 1]
        } else {
            (1.0, 1.0, 1.0)
        };
        let v = match (k, self.light) {
            (0, Emitter::Infinite) => self.p_inf_dir,
            (0, _) => self.p_pos,
            (1, Emitter::Infinite) => self.p_pos * cos_in,
            (1, _) => self.p_dir * cos_in / d2,
            _ => self.pl_dir[k - 1] * cos_in / d2,
        };
        v as f64
    }

    /// pE(x_k): the camera subpath's density of x_k.
    fn pe(&self, k: usize) -> f64 {
        let v = if k == self.m() {
            self.pdf_pixel * self.cam.1 / self.cam.0
        } else if k == 0 && self.at_infinity() {
            self.pe_dir[1]
        } else {
            let (d2, cos_k, _) = self.seg[k];
            self.pe_dir[k + 1] * cos_k / d2
        };
        v as f64
    }

    fn specular(&self, k: usize) -> bool {
        k > 0 && self.delta[k]
    }
}

/// A technique of a path: connection with `s` light vertices, or merge at x_i.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Technique {
    Connect(usize),
    Merge(usize),
}

/// Every possible technique's density with its sample count (eq. 20).
fn brute_force(p: &Path, direct: DirectMerges) -> Vec<(Technique, f64)> {
    let m = p.m();
    let eta = |i: usize| std::f64::consts::PI * (p.radius[i] as f64).powi(2) * p.n_light as f64;
    let light = |s: usize| (0..s).map(|k| p.pl(k)).product::<f64>();
    let camera = |from: usize| (from..=m).map(|k| p.pe(k)).product::<f64>();
    let mut out = Vec::new();
    for s in 0..=m + 1 {
        let ok = match s {
            0 => p.light == Emitter::Area || p.light == Emitter::Infinite,
            // Light tracing joins x_0 itself only on an area light.
            1 if m == 0 => p.light == Emitter::Area,
            _ if s == m + 1 => !p.specular(m),
            _ => !p.specular(s) && !p.specular(s - 1),
        };
        if ok {
            let n = if s == m + 1 {
                p.n_light as f64 * (p.lt_c as f64).sqrt()
            } else {
                1.0
            };
            // Next-event estimation samples x_0 with its own density.
            let l = if s == 1 && m > 0 {
                p.p_nee as f64
            } else {
                light(s)
            };
            out.push((Technique::Connect(s), n * l * camera(s)));
        }
    }
    let merge_at_1 = match direct {
        DirectMerges::Always => true,
        DirectMerges::AfterSpecular => m >= 2 && p.specular(2),
        DirectMerges::Never => false,
    };
    for i in 1..=m {
        if !p.specular(i) && (i >= 2 || merge_at_1) {
            out.push((Technique::Merge(i), light(i + 1) * camera(i) * eta(i)));
        }
    }
    out
}

/// The light subpath's quantities at x_1 ..= x_m, built as light.rs
/// (`trace_light`, `vertex`) builds them.
fn light_states(p: &Path, f: &[Factors]) -> Vec<Partial> {
    let m = p.m();
    let (direct, emission, cos_light) = p.light_densities();
    let seg = |k: usize| p.seg[k];
    let mut lp = vec![Partial::default(); m + 1];
    // An area light's next-event density enters at x_1 (light.rs).
    let (area, point) = (p.light == Emitter::Area, p.light == Emitter::Point);
    let mut st = Partial::light(
        if area { 1.0 } else { direct },
        emission,
        cos_light,
        point,
        &f[0],
    );
    let mut first: Option<Deferred> = None;
    for (k, state) in lp.iter_mut().enumerate().skip(1) {
        if k >= 2 {
            if let Some(t) = first.take() {
                if p.delta[k - 1] {
                    st.add(&t);
                }
            }
            let next_to_light = k - 1 == 1;
            let merge_here = f[0].merges_at(next_to_light, false);
            let t = st.scatter(
                p.delta[k - 1],
                p.pl_dir[k - 1],
                p.pe_dir[k - 1],
                seg(k - 1).1,
                &f[k - 1],
                merge_here,
            );
            if next_to_light && !merge_here && f[0].merges_at(true, true) {
                first = Some(t);
            }
        }
        let d2 = if k == 1 && p.at_infinity() {
            1.0
        } else {
            seg(k - 1).0
        };
        st.hit(d2, seg(k - 1).2);
        if k == 1 && area {
            st.d_vcm *= mis(direct);
        }
        if let Some(t) = &mut first {
            t.hit(seg(k - 1).2);
        }
        *state = st;
    }
    lp
}

/// The light subpath's quantities at x_1 ..= x_m, the camera subpath's at
/// x_m ..= x_0 and the camera's for its emission weight at x_0, built as
/// light.rs and camera.rs build them.
fn subpath_states(p: &Path, f: &[Factors]) -> (Vec<Partial>, Vec<Partial>, Partial) {
    let (m, seg) = (p.m(), |k: usize| p.seg[k]);
    let lp = light_states(p, f);
    // Camera subpath: the state at x_m ..= x_1, then at the light
    // (camera.rs `apply_scatter`, `emission_weight`).
    // Every technique of the path has its m scattering vertices: one factor.
    let c = p.lt_c;
    let mut cp = vec![Partial::default(); m + 1];
    let mut st = CameraPartial::camera(p.pdf_pixel, p.n_light, true);
    st.hit(p.cam.0, p.cam.1);
    cp[m] = st.with_lt(c);
    let mut last = super::mis::CameraDeferred::default();
    let (mut arrived_delta, mut last_after_delta) = (false, false);
    for k in (0..m).rev() {
        last = st.scatter(
            p.delta[k + 1],
            p.pe_dir[k + 1],
            p.pl_dir[k + 1],
            seg(k).2,
            &f[k + 1],
        );
        last_after_delta = arrived_delta;
        arrived_delta = p.delta[k + 1];
        if !(k == 0 && p.at_infinity()) {
            // An escaped ray has no arrival (camera.rs `escaped`).
            st.hit(seg(k).0, seg(k).1);
            last.hit(seg(k).1);
        }
        cp[k] = st.with_lt(c);
    }
    let emitted = if f[0].merges_at(true, last_after_delta) {
        cp[0]
    } else {
        Partial {
            d_vc: last.d_vc_without(c),
            ..cp[0]
        }
    };
    (lp, cp, emitted)
}

/// The recursive weight of every technique, driven as the two passes do.
fn recursive(p: &Path, f: &[Factors]) -> Vec<(Technique, f32)> {
    let m = p.m();
    let (direct, emission, cos_light) = p.light_densities();
    let seg = |k: usize| p.seg[k];
    let (lp, cp, emitted) = subpath_states(p, f);
    // The camera reached x_1 by a delta scattering (at x_2).
    let x1_after_delta = m >= 2 && p.delta[2];
    let mut out = Vec::new();
    if m == 0 {
        return seen_directly(p, &emitted);
    }
    if p.light != Emitter::Point {
        out.push((
            Technique::Connect(0),
            weight(0.0, emitted.emission_weight(direct, emission)),
        ));
    }
    if !p.delta[1] {
        // NEE at x_1 (camera.rs `next_event`).
        let (d2, cos_recv) = (seg(0).0, seg(0).2);
        let inv_d2 = if p.at_infinity() { 1.0 } else { 1.0 / d2 };
        let bsdf_dir = if p.light == Emitter::Point {
            0.0
        } else {
            p.pe_dir[1]
        };
        let w_light = mis(bsdf_dir * cos_light * inv_d2 / direct);
        let ratio = emission * cos_recv * inv_d2 / direct;
        let merge = f[0].merges_at(true, x1_after_delta);
        let w_cam = cp[1].connect_weight(ratio, p.pl_dir[1], &f[1], merge);
        out.push((Technique::Connect(1), weight(w_light, w_cam)));
    }
    for s in 2..=m {
        if p.delta[s] || p.delta[s - 1] {
            continue;
        }
        // Camera x_s joined to light x_{s-1} (camera.rs `connect`).
        let (d2, cos_l, cos_c) = seg(s - 1);
        let cam_dir_a = p.pe_dir[s] * cos_l / d2;
        let light_dir_a = p.pl_dir[s - 1] * cos_c / d2;
        let merge_light = f[0].merges_at(s - 1 == 1, false);
        let w_light = lp[s - 1].connect_weight(cam_dir_a, p.pe_dir[s - 1], &f[s - 1], merge_light);
        let w_cam = cp[s].connect_weight(light_dir_a, p.pl_dir[s], &f[s], true);
        out.push((Technique::Connect(s), weight(w_light, w_cam)));
    }
    if !p.delta[m] {
        // Light tracing at x_m (light.rs `connect_to_camera`).
        let pdf_cam_a = p.pdf_pixel * p.cam.1 / (p.cam.0 * p.n_light);
        let merge = f[0].merges_at(m == 1, false);
        let w_light = lp[m].connect_weight(pdf_cam_a, p.pe_dir[m], &f[m], merge) / p.lt_c;
        let w = weight(w_light, 0.0);
        out.push((Technique::Connect(m + 1), w));
    }
    for i in 1..=m {
        if !p.delta[i] && f[0].merges_at(i == 1, x1_after_delta) {
            // camera.rs `merge`: the light vertex's wo is the incident
            // direction; the factors are those at the merge's vertex.
            let w_light = lp[i].merge_weight(p.pe_dir[i], &f[i]);
            let w_cam = cp[i].merge_weight(p.pl_dir[i], &f[i]);
            out.push((Technique::Merge(i), weight(w_light, w_cam)));
        }
    }
    out
}

/// The weights of a light seen from the lens (m = 0), as camera.rs
/// (`seen_directly_weight`) and light.rs (`splat_light_point`) make them.
fn seen_directly(p: &Path, emitted: &Partial) -> Vec<(Technique, f32)> {
    match p.light {
        Emitter::Area => {
            let pdf_cam_a = p.pdf_pixel * p.cam.1 / (p.cam.0 * p.n_light);
            vec![
                (
                    Technique::Connect(0),
                    weight(0.0, mis(p.p_pos) * emitted.d_vcm),
                ),
                (Technique::Connect(1), weight(mis(pdf_cam_a / p.p_pos), 0.0)),
            ]
        }
        // Seen straight from the lens only the camera finds it.
        Emitter::Infinite => vec![(Technique::Connect(0), 1.0)],
        Emitter::Point => Vec::new(),
    }
}

/// How far the recursive weights (from the densities of `given`) are from
/// the brute-force ones (from those of `truth`).
struct Mismatch {
    /// Largest absolute difference of a weight.
    abs: f64,
    /// Largest relative difference of a weight above 1e-9.
    rel: f64,
    /// Sum of the recursive weights.
    sum: f64,
}

impl Mismatch {
    /// The main test's criterion (f32 recursion against f64 brute force).
    fn agrees(&self) -> bool {
        self.abs < 1e-4 && self.rel < 1e-3 && (self.sum - 1.0).abs() < 1e-4
    }
}

/// Compares the two, with the merges next to the light `direct`; None
/// when the path has no technique.
fn compare(truth: &Path, given: &Path, direct: DirectMerges) -> Option<Mismatch> {
    let f: Vec<Factors> = given
        .radius
        .iter()
        .map(|&r| Factors::new(r, given.n_light, true, true, direct))
        .collect();
    let brute = brute_force(truth, direct);
    let total: f64 = brute.iter().map(|(_, q)| q * q).sum();
    if brute.is_empty() || total == 0.0 {
        return None;
    }
    let rec = recursive(given, &f);
    let kinds = |v: &[(Technique, f32)]| v.iter().map(|r| r.0).collect::<Vec<_>>();
    let brute_kinds: Vec<Technique> = brute.iter().map(|b| b.0).collect();
    assert_eq!(
        kinds(&rec),
        brute_kinds,
        "the same techniques are possible: {given:?}"
    );
    let mut m = Mismatch {
        abs: 0.0,
        rel: 0.0,
        sum: rec.iter().map(|r| r.1 as f64).sum(),
    };
    for ((_, q), (_, w)) in brute.iter().zip(&rec) {
        let (wb, w) = (q * q / total, *w as f64);
        m.abs = m.abs.max((w - wb).abs());
        if wb > 1e-9 {
            m.rel = m.rel.max((w - wb).abs() / wb);
        }
    }
    Some(m)
}

/// Every setting of merges next to the light.
const DIRECT: [DirectMerges; 3] = [
    DirectMerges::Always,
    DirectMerges::AfterSpecular,
    DirectMerges::Never,
];

/// Fixed seeds: 7000 random paths, 1000 per length 1..=7.
fn paths() -> impl Iterator<Item = Path> {
    (0..7000u64).map(|i| {
        let mut rng = StreamRng::new(0x6d69_7362, i, 0);
        Path::random(&mut rng, (i % 7) as usize)
    })
}

#[test]
fn recursive_weights_equal_brute_force_and_sum_to_one() {
    for direct in DIRECT {
        let mut checked = 0;
        for p in paths() {
            let Some(m) = compare(&p, &p, direct) else {
                continue;
            };
            assert!(
                m.agrees(),
                "{direct:?}: abs {} rel {} sum {}: {p:?}",
                m.abs,
                m.rel,
                m.sum
            );
            checked += 1;
        }
        // Nearly every path has a technique (all-specular paths under a
        // point light, and a point light seen from the lens, have none).
        assert!(checked > 5800, "{checked}");
    }
}

#[test]
fn every_kind_of_path_is_covered() {
    let all: Vec<Path> = paths().collect();
    for light in [Emitter::Area, Emitter::Point, Emitter::Infinite] {
        for m in 1..=6 {
            let n = all
                .iter()
                .filter(|p| p.light == light && p.m() == m && p.delta.iter().any(|&d| d))
                .count();
            assert!(n > 20, "{light:?} m={m}: {n} paths with a specular vertex");
        }
    }
}

/// Paths where the camera sees x_1 through a specular x_2 have the merge
/// at x_1 with `afterspecular`, and the paths of the main test hold enough
/// of both kinds for it to check the rule both ways.
#[test]
fn merges_next_to_the_light_are_checked_after_specular_and_not() {
    let (mut after, mut not) = (0, 0);
    for p in paths() {
        if p.m() >= 2 && !p.delta[1] {
            if p.delta[2] {
                after += 1;
            } else {
                not += 1;
            }
        }
    }
    assert!(after > 300 && not > 300, "{after} {not}");
}

mod caught;
