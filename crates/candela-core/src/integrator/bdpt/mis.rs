//! Multiple importance sampling weights of BDPT strategies by recursive
//! density ratios [Veach 1997, §10.2.1, eqs. 10.9–10.11].
//!
//! A path x₀…x_{n−1} (x₀ on a light, x_{n−1} on the camera) can be made by
//! the strategies k = 0…n−1 that take k vertices from a light subpath and
//! n − k from a camera subpath. With p_L[i] the area density of x_i generated
//! from the light side and p_E[i] from the camera side, strategy k has
//! density p_k = Π_{i<k} p_L[i] · Π_{i≥k} p_E[i], so p_{k+1}/p_k = p_L[k]/p_E[k].
//! Walking these ratios outward from the strategy used gives every p_k/p_s
//! without products that under- or overflow. A strategy counts only if it
//! can sample the path: its connection must not touch a specular vertex,
//! k = 0 needs a hittable emitter at x₀, and t = 1 a camera that can be
//! connected to. Zero densities (specular vertices) are mapped to 1 so the
//! ratios pass through them, as in pbrt.
//!
//! The densities next to the connection are unknown to either subpath and
//! are computed here ([`JoinDensities::of`]), or by the connection itself
//! where it evaluates its ends anyway ([`super::density::join_end`], handed
//! over in [`PathView::join`]); all others were stored by the random walks.
//!
//! **Next-event density.** Strategy k = 1 (next-event estimation at x₁)
//! draws x₀ with the light sampler's own density p_NEE(x₀ | x₁), which for
//! a sphere light (cone sampling) is not the emission's uniform-area p_L[0]
//! that the other strategies use (pbrt-v4 weighs it with p_L[0]). So p_1
//! carries the factor q = p_NEE/p_L[0] ([`nee_factor`]; 1 for lights
//! sampled by area): the term of k = 1 is multiplied by q, and when s = 1
//! every other term is divided by it. The module doc of
//! [`crate::integrator::vcm::mis`] gives the reason.
//!
//! **Variance-aware light tracing.** The term of light tracing (k = n − 1,
//! t = 1) in every weight of a path is multiplied by the factor c of the
//! path's image block and length ([`crate::integrator::lt_weights`]): w_s =
//! c_s h(p_s) / Σ_k c_k h(p_k), c_k = 1 for every other strategy. Any c
//! that is a function of the path keeps the weights summing to one.

use super::density::{pdf, pdf_light_origin, pdf_scatter_pair, JoinEnd};
use crate::bsdf::TransportMode;
use crate::camera::Camera;
use crate::integrator::nee::{nee_area_density, nee_context};
use crate::integrator::subpath::{Vertex, VertexKind};
use crate::light::LightType;
use crate::scene::Scene;

/// The weighting function applied to the strategy densities.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MisHeuristic {
    /// w_s = p_s / Σ p_k [Veach 1997, eq. 9.10].
    Balance,
    /// w_s = p_s² / Σ p_k² [Veach 1997, eq. 9.13].
    Power,
}

impl MisHeuristic {
    #[inline]
    fn apply(self, r: f32) -> f32 {
        match self {
            MisHeuristic::Balance => r,
            MisHeuristic::Power => r * r,
        }
    }
}

/// The full path of strategy (s, t), indexed from the light: vertex i is
/// `light[i]` for i < s and `cam[n − 1 − i]` otherwise, with optional
/// replacements for the two connection endpoints (sampled light or lens points).
pub(crate) struct PathView<'a> {
    /// Light subpath (at least `s` vertices).
    pub light: &'a [Vertex],
    /// Camera subpath (at least `t` vertices).
    pub cam: &'a [Vertex],
    /// Vertices taken from the light subpath.
    pub s: usize,
    /// Vertices taken from the camera subpath.
    pub t: usize,
    /// Replaces `light[s − 1]`.
    pub light_end: Option<Vertex>,
    /// Replaces `cam[t − 1]`.
    pub cam_end: Option<Vertex>,
    /// The connection's densities when the connection computed them
    /// ([`JoinDensities::of_ends`]); else [`JoinDensities::of`] does.
    pub join: Option<JoinDensities>,
}

impl PathView<'_> {
    /// Number of vertices.
    #[inline]
    pub fn n(&self) -> usize {
        self.s + self.t
    }

    /// Vertex i counted from the light end.
    #[inline]
    pub fn get(&self, i: usize) -> &Vertex {
        if i < self.s {
            match &self.light_end {
                Some(v) if i == self.s - 1 => v,
                _ => &self.light[i],
            }
        } else {
            let j = self.n() - 1 - i;
            match &self.cam_end {
                Some(v) if j == self.t - 1 => v,
                _ => &self.cam[j],
            }
        }
    }
}

/// The densities only the connection of strategy (s, t) determines:
/// p_L[s] (at s = 0 the emitter's origin density p_L[0]), p_L[s + 1],
/// p_E[s − 1] and p_E[s − 2], where they exist.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct JoinDensities {
    /// p_L[s], p_L[s + 1].
    pub p_light: [f32; 2],
    /// p_E[s − 1], p_E[s − 2].
    pub p_eye: [f32; 2],
}

impl JoinDensities {
    /// Computes them for `view`; at a surface vertex with both neighbours the
    /// two densities of a connection end come from one pair evaluation
    /// ([`pdf_scatter_pair`]).
    pub fn of(scene: &Scene, camera: &Camera, view: &PathView<'_>) -> Self {
        let (n, s) = (view.n(), view.s);
        let (imp, rad) = (TransportMode::Importance, TransportMode::Radiance);
        let x = |i: usize| view.get(i);
        let surface = |i: usize| x(i).kind == VertexKind::Surface;
        let mut j = Self::default();
        if s == 0 {
            j.p_light[0] = pdf_light_origin(scene, x(0), x(1));
        } else if s >= 2 && surface(s - 1) {
            (j.p_light[0], j.p_eye[1]) = pdf_scatter_pair(x(s - 1), x(s - 2), x(s), imp);
        } else {
            let prev = (s >= 2).then(|| x(s - 2));
            j.p_light[0] = pdf(scene, camera, x(s - 1), prev, x(s), imp);
            if s >= 2 {
                j.p_eye[1] = pdf(scene, camera, x(s - 1), Some(x(s)), x(s - 2), rad);
            }
        }
        if s >= 1 && view.t >= 2 && surface(s) {
            (j.p_eye[0], j.p_light[1]) = pdf_scatter_pair(x(s), x(s + 1), x(s - 1), rad);
            return j;
        }
        if s >= 1 {
            let prev = (view.t >= 2).then(|| x(s + 1));
            j.p_eye[0] = pdf(scene, camera, x(s), prev, x(s - 1), rad);
        }
        if s + 1 < n {
            let prev = (s >= 1).then(|| x(s - 1));
            j.p_light[1] = pdf(scene, camera, x(s), prev, x(s + 1), imp);
        }
        j
    }

    /// They for a connection of two surface vertices (s, t ≥ 2) whose
    /// ends were evaluated once for the contribution and the weight
    /// ([`join_end`]: the light end's, then the camera end's).
    pub fn of_ends(light: &JoinEnd, cam: &JoinEnd) -> Self {
        Self {
            p_light: [light.pdf_fwd, cam.pdf_rev],
            p_eye: [cam.pdf_fwd, light.pdf_rev],
        }
    }

    /// They for light tracing (t = 1) from surface vertex x_{s−1}, s ≥ 2,
    /// whose end was evaluated once ([`join_end`]), with `p_lens`, the
    /// lens's area density of generating x_{s−1}. (p_L[s], the density of
    /// the lens point, enters no weight, t = 0 being no strategy; it is
    /// kept so the tests compare every density.)
    pub fn of_lens(light: &JoinEnd, p_lens: f32) -> Self {
        Self {
            p_light: [light.pdf_fwd, 0.0],
            p_eye: [p_lens, light.pdf_rev],
        }
    }

    /// The connection's own ([`PathView::join`]) or computed ones.
    #[inline]
    pub fn of_view(scene: &Scene, camera: &Camera, view: &PathView<'_>) -> Self {
        view.join.unwrap_or_else(|| Self::of(scene, camera, view))
    }

    /// p_L[i] of `view`: these where the connection determines it, the
    /// walks' stored densities elsewhere.
    #[inline]
    fn p_light(&self, view: &PathView<'_>, i: usize) -> f32 {
        let s = view.s;
        if i == s {
            self.p_light[0]
        } else if i == s + 1 {
            self.p_light[1]
        } else if i < s {
            view.get(i).pdf_fwd.0
        } else {
            view.get(i).pdf_rev.0
        }
    }

    /// p_E[i] of `view` (as [`Self::p_light`]).
    #[inline]
    fn p_eye(&self, view: &PathView<'_>, i: usize) -> f32 {
        let s = view.s;
        if i + 1 == s {
            self.p_eye[0]
        } else if i + 2 == s {
            self.p_eye[1]
        } else if i < s {
            view.get(i).pdf_rev.0
        } else {
            view.get(i).pdf_fwd.0
        }
    }
}

/// q = p_NEE(x₀ | x₁) / p_L[0] of a path of `n` vertices (module doc):
/// the ratio of strategy k = 1's density of x₀ to the emission's `p_l0`; 1
/// unless x₀ is on an area light sampled by cone and x₁ scatters (n ≥ 3;
/// at n = 2, k = 1 is light tracing of x₀).
pub(crate) fn nee_factor(scene: &Scene, x0: &Vertex, x1: &Vertex, n: usize, p_l0: f32) -> f32 {
    let Some(id) = x0.light_id() else { return 1.0 };
    let light = scene.light(id);
    if n < 3 || light.samples_li_by_area() || p_l0 <= 0.0 {
        return 1.0;
    }
    let q = nee_area_density(scene, id, &x0.it, &nee_context(x1)) / p_l0;
    if q > 0.0 && q.is_finite() {
        q
    } else {
        1.0
    }
}

/// The term of strategy k in the weight of strategy s, given r = p_k/p_s
/// without the next-event factor `q` (module doc).
#[inline(always)]
fn with_nee(r: f32, k: usize, s: usize, q: f32) -> f32 {
    let r = if k == 1 { r * q } else { r };
    if s == 1 {
        r / q
    } else {
        r
    }
}

/// Whether x_i of `view` is specular (the connection endpoints never are).
#[inline]
fn is_delta(view: &PathView<'_>, i: usize) -> bool {
    view.get(i).delta && i + 1 != view.s && i != view.s
}

/// p_L and p_E of one path gathered into arrays: the reference form of
/// what [`mis_weight`] reads in place, for the tests.
#[cfg(test)]
#[derive(Default)]
pub(crate) struct PathDensities {
    /// p_L[i].
    pub p_light: Vec<f32>,
    /// p_E[i].
    pub p_eye: Vec<f32>,
    /// Whether x_i is specular (the connection endpoints never are).
    pub delta: Vec<bool>,
    /// q = p_NEE/p_L[0] ([`nee_factor`]).
    pub nee: f32,
}

#[cfg(test)]
impl PathDensities {
    /// Gathers the densities of `view`: stored ones and [`JoinDensities`].
    pub fn of(scene: &Scene, camera: &Camera, view: &PathView<'_>) -> Self {
        let j = JoinDensities::of_view(scene, camera, view);
        let n = view.n();
        let p_l0 = j.p_light(view, 0);
        Self {
            p_light: (0..n).map(|i| j.p_light(view, i)).collect(),
            p_eye: (0..n).map(|i| j.p_eye(view, i)).collect(),
            delta: (0..n).map(|i| is_delta(view, i)).collect(),
            nee: nee_factor(scene, view.get(0), view.get(1), n, p_l0),
        }
    }
}

/// Which strategies can make a path of n vertices starting at x0: the
/// conditions that do not depend on k, evaluated once per path.
pub(crate) struct Strategies {
    n: usize,
    /// k = 0 needs a hittable emitter at x0.
    x0_hittable: bool,
    /// k = n − 1 (t = 1) needs a camera that can be connected to and, when
    /// also k = 1, a visible area light at x0.
    last_ok: bool,
}

impl Strategies {
    /// The strategies of a path of `n` vertices whose light end is `x0`.
    pub fn new(scene: &Scene, camera: &Camera, x0: &Vertex, n: usize) -> Self {
        let last_ok = camera.is_connectable()
            && (n != 2
                || x0.light_id().is_some_and(|id| {
                    // s = 1, t = 1: only a visible area light can be seen directly.
                    let l = scene.light(id);
                    l.light_type() == LightType::Area && l.is_hittable()
                }));
        Self {
            n,
            x0_hittable: x0.is_hittable_light(scene),
            last_ok,
        }
    }

    /// Whether strategy k (k light vertices, n − k camera vertices) can make
    /// the path whose specular flags `delta(i)` gives.
    #[inline(always)]
    pub fn valid(&self, delta: impl Fn(usize) -> bool, k: usize) -> bool {
        if k >= self.n {
            return false; // t = 0: candela never hits the lens.
        }
        if k == 0 {
            return self.x0_hittable;
        }
        if delta(k - 1) || delta(k) {
            return false;
        }
        k != self.n - 1 || self.last_ok
    }
}

/// [`Strategies::valid`] with the flags in a slice.
#[cfg(test)]
pub(crate) fn strategy_valid(
    scene: &Scene,
    camera: &Camera,
    x0: &Vertex,
    delta: &[bool],
    k: usize,
) -> bool {
    Strategies::new(scene, camera, x0, delta.len()).valid(|i| delta[i], k)
}

/// MIS weight of strategy `s` for the path with densities `d` (the
/// reference form of [`mis_weight`]).
#[cfg(test)]
pub(crate) fn weight_from_densities(
    scene: &Scene,
    camera: &Camera,
    x0: &Vertex,
    d: &PathDensities,
    s: usize,
    h: MisHeuristic,
    c_lt: f32,
) -> f32 {
    let n = d.delta.len();
    let remap0 = |p: f32| if p != 0.0 { p } else { 1.0 };
    let c = |k: usize| lt_factor(k, n, c_lt);
    let mut total = c(s);
    let mut r = 1.0f32;
    for k in s + 1..n {
        r *= remap0(d.p_light[k - 1]) / remap0(d.p_eye[k - 1]);
        if strategy_valid(scene, camera, x0, &d.delta, k) {
            total += c(k) * h.apply(with_nee(r, k, s, d.nee));
        }
    }
    r = 1.0;
    for k in (0..s).rev() {
        r *= remap0(d.p_eye[k]) / remap0(d.p_light[k]);
        if strategy_valid(scene, camera, x0, &d.delta, k) {
            total += c(k) * h.apply(with_nee(r, k, s, d.nee));
        }
    }
    weight_of(c(s), total)
}

/// MIS weight of the strategy that made `view`: the ratios p_k/p_s walked
/// outward from k = s (module doc), reading the walks' densities in place.
pub(crate) fn mis_weight(
    scene: &Scene,
    camera: &Camera,
    view: &PathView<'_>,
    h: MisHeuristic,
    c_lt: f32,
) -> f32 {
    let (n, s) = (view.n(), view.s);
    let j = JoinDensities::of_view(scene, camera, view);
    let x0 = view.get(0);
    let strategies = Strategies::new(scene, camera, x0, n);
    let valid = |k: usize| strategies.valid(|i| is_delta(view, i), k);
    let remap0 = |p: f32| if p != 0.0 { p } else { 1.0 };
    let q = nee_factor(scene, x0, view.get(1), n, j.p_light(view, 0));
    let c = |k: usize| lt_factor(k, n, c_lt);
    let mut total = c(s);
    let mut r = 1.0f32;
    for k in s + 1..n {
        r *= remap0(j.p_light(view, k - 1)) / remap0(j.p_eye(view, k - 1));
        if valid(k) {
            total += c(k) * h.apply(with_nee(r, k, s, q));
        }
    }
    r = 1.0;
    for k in (0..s).rev() {
        r *= remap0(j.p_eye(view, k)) / remap0(j.p_light(view, k));
        if valid(k) {
            total += c(k) * h.apply(with_nee(r, k, s, q));
        }
    }
    weight_of(c(s), total)
}

/// The factor of strategy k's term in a path of `n` vertices: `c_lt` for
/// light tracing (k = n − 1, t = 1), 1 for every other (module doc).
#[inline(always)]
fn lt_factor(k: usize, n: usize, c_lt: f32) -> f32 {
    if k + 1 == n {
        c_lt
    } else {
        1.0
    }
}

/// c_s h(p_s) / Σ_k c_k h(p_k) from the used strategy's factor `c_s` and
/// `total`, the sum of every valid strategy's term relative to h(p_s)
/// (its own, c_s, first: with c_s = 1 the same operations as without
/// factors). With c_s = 0 (light tracing in the pilot) the weight is 0, or 1
/// where no other strategy can make the path (the limit c → 0).
#[inline(always)]
fn weight_of(c_s: f32, total: f32) -> f32 {
    if !total.is_finite() {
        return 0.0;
    }
    if total == 0.0 {
        return 1.0;
    }
    c_s / total
}
