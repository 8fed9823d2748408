//! VCM's multiple importance sampling by three recursive partial
//! quantities per subpath vertex, dVCM, dVC and dVM [Georgiev, Křivánek,
//! Davidovič & Slusallek 2012, tech. rep. "Implementing Vertex Connection
//! and Merging", eqs. 31–45; SmallVCM `vertexcm.hxx`].
//!
//! Every quantity is already raised to the heuristic's power ([`mis`]: the
//! power heuristic, β = 2), so each full-path weight is 1/(w_light + 1 +
//! w_camera) with the two partial sums of eq. 37 built from the stored
//! quantities and the densities next to the join. With η_VCM = π r² N_light
//! (eq. 20, n_VC = 1, n_VM = N_light), merging enters through
//! `vm = mis(η_VCM)` and connections through `vc = mis(1/η_VCM)`; a mode
//! without merges sets `vm = 0`, one without connections `connect = 0`.
//! η may differ from vertex to vertex (a radius field, [`super::field`]):
//! each merge technique's term carries the η of its own vertex, so d_VM is
//! kept without the evaluated merge's 1/η and [`Partial::merge_weight`]
//! multiplies it in with the factors of the merge's vertex; with one η
//! everywhere this is SmallVCM's recursion term for term.
//!
//! Densities are per unit solid angle at the sampling vertex except where a
//! name ends in `_a` (per unit area). The cosines of the area conversions are
//! geometric (|ω·n_g|), as in [`crate::integrator::subpath::to_area`], on
//! both subpaths, so every technique is weighed with the same densities.
//! Russian roulette is left out of the densities: weights built from the
//! same density functions on every technique still sum to one.
//!
//! **Merges next to the light** (`"string directmerges"`). A merge at the
//! vertex x_1 that the light reaches directly estimates direct light by
//! density, which next-event estimation, light tracing and hitting the
//! light sample without a kernel; on a diffuse scene those merges add the
//! kernel's bias (across a crease it averages the lit and the unlit face)
//! and, from the few light vertices in a disk of pixel size, more noise
//! than they take away. SPPM leaves them out the same way: its photons are
//! stored from their second vertex and direct light comes by light
//! sampling [Hachisuka & Jensen 2009, §4; pbrt-v4 `SPPMIntegrator`]. But
//! when the camera sees x_1 only through a specular vertex x_2 (a floor
//! behind glass), the merge is what smooths it: next-event estimation sees
//! the glass's shadow sharp where the light's photons arrive. So by
//! default (`afterspecular`) the merge at x_1 is a technique of a path
//! exactly when x_2 is specular; `always` keeps every such merge (the modes
//! without connections, `bpm` and `ppm`, whose only technique for direct
//! light they are), `never` none. Whether a path has the technique is a
//! function of the path, so the weights of every other technique must
//! count it exactly then: its term enters the light subpath's recursion at
//! x_1 only once x_2 is known to scatter specularly ([`Deferred`]); a
//! connection's weight at a vertex next to the light counts it when that
//! vertex's camera-side neighbour is specular ([`Partial::connect_weight`]:
//! next-event estimation's camera vertex reached by a delta scattering;
//! never a light vertex x_1, whose neighbour is a connection's end); and
//! the camera subpath hitting the light counts it when the vertex it last
//! left was itself reached by a delta scattering (its d_VC without that
//! term is [`Deferred::d_vc_without`]).
//!
//! **Next-event density.** The technique s = 1 (next-event estimation at
//! x_1) samples the light point x_0 with the light sampler's own density,
//! which for a sphere light is uniform over the cone it subtends from x_1,
//! not uniform over its area as the emission sampling is; SmallVCM and
//! pbrt-v4's BDPT weigh it with the emission's area density. Weights that
//! use another density than the sampler's still sum to one (the estimate
//! stays unbiased), but they no longer favour each technique where it
//! samples well. So every weight that involves s = 1 uses
//! p_NEE(x_0 | x_1) = P(light) · p_ω(x_1 → x_0) · |cos θ_0| / d²
//! ([`crate::integrator::nee::nee_area_density`]): the light subpath multiplies it
//! into d_VCM on reaching x_1 (eq. 31 with the density known only there),
//! next-event estimation uses the density it sampled with, and the camera
//! subpath hitting the light evaluates it from the vertex it left. Shapes
//! sampled by area (triangles, disks, …) keep the emission's density, which
//! is then the same number.

/// The heuristic's power applied to a density or density ratio (β = 2)
/// [Veach 1997, eq. 9.13].
#[inline]
pub fn mis(x: f32) -> f32 {
    x * x
}

/// Which merges at a vertex next to the light are a technique (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectMerges {
    /// Every one.
    Always,
    /// Where the path's next vertex towards the camera is specular.
    AfterSpecular,
    /// None.
    Never,
}

impl DirectMerges {
    /// The setting named `s`, if any.
    pub fn from_name(s: &str) -> Option<Self> {
        match s {
            "always" => Some(DirectMerges::Always),
            "afterspecular" => Some(DirectMerges::AfterSpecular),
            "never" => Some(DirectMerges::Never),
            _ => None,
        }
    }

    /// Names accepted by [`DirectMerges::from_name`].
    pub const NAMES: &'static str = "always, afterspecular, never";
}

/// The constants of eq. 20 and the merge normalisation at one vertex: with
/// a radius field ([`super::field`]) η_VCM differs from vertex to vertex,
/// and each merge technique of a path uses the η of its own vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Factors {
    /// mis(η_VCM) when merging is on, else 0: a merge at this vertex
    /// relative to a connection.
    pub vm: f32,
    /// mis(1/η_VCM): a connection relative to a merge at this vertex (only
    /// merge weights use it).
    pub vc: f32,
    /// 1 when connecting is on, else 0.
    pub connect: f32,
    /// 1/η_VCM = 1/(π r² N_light), the merge kernel's normalisation.
    pub merge_norm: f32,
    /// The merge radius r here.
    pub radius: f32,
    /// Which merges next to the light exist (module doc).
    pub direct: DirectMerges,
}

impl Factors {
    /// The constants for radius `r`, `n_light` light paths and the merges
    /// next to the light `direct`.
    pub fn new(r: f32, n_light: f32, connect: bool, merge: bool, direct: DirectMerges) -> Self {
        let eta = std::f32::consts::PI * r * r * n_light;
        Self {
            vm: if merge { mis(eta) } else { 0.0 },
            vc: mis(1.0 / eta),
            connect: if connect { 1.0 } else { 0.0 },
            merge_norm: 1.0 / eta,
            radius: r,
            direct,
        }
    }

    /// Whether a merge at a vertex is a technique (merging on): always
    /// unless the vertex is next to the light; there, by `direct` and
    /// whether its camera-side neighbour is specular (`after_delta`).
    #[inline]
    pub fn merges_at(&self, next_to_light: bool, after_delta: bool) -> bool {
        !next_to_light
            || match self.direct {
                DirectMerges::Always => true,
                DirectMerges::AfterSpecular => after_delta,
                DirectMerges::Never => false,
            }
    }
}

/// dVCM, dVC, dVM of a subpath at its last vertex.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Partial {
    /// Shared by connections and merges.
    pub d_vcm: f32,
    /// Connections only.
    pub d_vc: f32,
    /// Merges only, without the evaluated merge's own 1/η (its vertex's
    /// [`Factors::vc`] multiplies it in [`Partial::merge_weight`]), so that
    /// each term keeps the η of the vertex it belongs to.
    pub d_vm: f32,
}

/// The terms of a merge at the vertex a scattering left, for a caller that
/// learns only later whether that merge exists (module doc), and d_VC
/// without them; carried along by [`Deferred::hit`] as the partials are.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Deferred {
    /// The merge's term of d_VC.
    pub vc: f32,
    /// The merge's term of d_VM (without 1/η, as d_VM).
    pub vm: f32,
    /// d_VC without the merge's term.
    pub d_vc_without: f32,
}

impl Deferred {
    /// The arrival at the next vertex ([`Partial::hit`]).
    pub fn hit(&mut self, cos: f32) {
        let c = mis(cos);
        if c == 0.0 {
            *self = Self::default();
            return;
        }
        self.vc /= c;
        self.vm /= c;
        self.d_vc_without /= c;
    }
}

impl Partial {
    /// A light subpath leaving its light [eqs. 31–33]: `direct` is the
    /// next-event density of the light point (area, or solid angle at
    /// infinity), `emission` the emission density (position × direction),
    /// `cos` the cosine at the light (1 at infinity), both densities with
    /// the light-selection probability.
    pub fn light(direct: f32, emission: f32, cos: f32, delta: bool, f: &Factors) -> Self {
        let d_vc = if delta { 0.0 } else { mis(cos / emission) };
        Self {
            d_vcm: mis(direct / emission),
            d_vc,
            d_vm: d_vc * f.connect,
        }
    }

    /// A camera subpath leaving the lens [eqs. 31–33]: `pdf_pixel` is the
    /// ray's solid-angle density per unit pixel area; 0 dVCM when the camera
    /// cannot be connected to (no light-tracing technique).
    pub fn camera(pdf_pixel: f32, n_light: f32, connectable: bool) -> Self {
        Self {
            d_vcm: if connectable && pdf_pixel > 0.0 {
                mis(n_light / pdf_pixel)
            } else {
                0.0
            },
            d_vc: 0.0,
            d_vm: 0.0,
        }
    }

    /// Arrival at a vertex at distance² `d2` with geometric cosine `cos`
    /// there [eqs. 34–36, completed]; `d2` is skipped (1) for the first
    /// vertex after a light at infinity [tech. rep. §5.1].
    pub fn hit(&mut self, d2: f32, cos: f32) {
        self.d_vcm *= mis(d2);
        let c = mis(cos);
        if c == 0.0 {
            *self = Self::default();
            return;
        }
        self.d_vcm /= c;
        self.d_vc /= c;
        self.d_vm /= c;
    }

    /// A scattering with forward density `pdf_fwd`, reverse density
    /// `pdf_rev` and geometric outgoing cosine `cos_out` [eqs. 34–36]; a
    /// delta lobe keeps the chain (its two densities are equal and cancel).
    /// The term of a merge at the vertex left is added when `merge_here`,
    /// and returned either way (module doc).
    pub fn scatter(
        &mut self,
        delta: bool,
        pdf_fwd: f32,
        pdf_rev: f32,
        cos_out: f32,
        f: &Factors,
        merge_here: bool,
    ) -> Deferred {
        self.step(delta, pdf_fwd, pdf_rev, cos_out, f, merge_here, 1.0)
    }

    /// [`Partial::scatter`] without the terms the scattering vertex itself
    /// adds (its d_VCM and its merge's): the linear part of eqs. 34–36,
    /// which carries what earlier vertices started ([`CameraPartial`]).
    pub fn propagate(
        &mut self,
        delta: bool,
        pdf_fwd: f32,
        pdf_rev: f32,
        cos_out: f32,
        f: &Factors,
    ) -> Deferred {
        self.step(delta, pdf_fwd, pdf_rev, cos_out, f, false, 0.0)
    }

    /// Eqs. 34–36 with the vertex's own terms times `source` (1 or 0).
    #[allow(clippy::too_many_arguments)]
    fn step(
        &mut self,
        delta: bool,
        pdf_fwd: f32,
        pdf_rev: f32,
        cos_out: f32,
        f: &Factors,
        merge_here: bool,
        source: f32,
    ) -> Deferred {
        if delta {
            self.d_vcm = 0.0;
            self.d_vc *= mis(cos_out);
            self.d_vm *= mis(cos_out);
            return Deferred {
                d_vc_without: self.d_vc,
                ..Deferred::default()
            };
        }
        if pdf_fwd <= 0.0 {
            *self = Self::default();
            return Deferred::default();
        }
        let g = mis(cos_out / pdf_fwd);
        let rev = mis(pdf_rev);
        let merge = Deferred {
            vc: source * g * f.vm,
            vm: source * g * f.vm,
            d_vc_without: g * (self.d_vc * rev + self.d_vcm),
        };
        *self = Self {
            d_vcm: source * mis(1.0 / pdf_fwd),
            d_vc: merge.d_vc_without,
            d_vm: g * (self.d_vm * rev + self.d_vcm * f.connect),
        };
        if merge_here {
            self.add(&merge);
        }
        merge
    }

    /// Adds the terms of a merge found to exist after the scattering.
    pub fn add(&mut self, merge: &Deferred) {
        self.d_vc += merge.vc;
        self.d_vm += merge.vm;
    }

    /// The partial weight of this subpath when the other side's join
    /// generated its last vertex with area density `pdf_join_a` and this
    /// vertex's BSDF would have continued back with `pdf_rev` [eqs. 40, 41,
    /// 45; for a light-tracing join eq. 46]. A merge at this vertex counts
    /// where it exists ([`Factors::merges_at`]).
    pub fn connect_weight(&self, pdf_join_a: f32, pdf_rev: f32, f: &Factors, merge: bool) -> f32 {
        self.connect_weight_vm(pdf_join_a, pdf_rev, if merge { f.vm } else { 0.0 })
    }

    /// [`Partial::connect_weight`] with the merge at this vertex given by
    /// its factor `vm` (its [`Factors::vm`], 0 where it does not exist), as
    /// a stored light vertex keeps it.
    #[inline]
    pub fn connect_weight_vm(&self, pdf_join_a: f32, pdf_rev: f32, vm: f32) -> f32 {
        mis(pdf_join_a) * (vm + self.d_vcm + self.d_vc * mis(pdf_rev))
    }

    /// The partial weight of this subpath in a merge whose other side would
    /// have sampled the direction with `pdf` [eqs. 38, 39], `f` the
    /// factors at the merge's (camera) vertex.
    pub fn merge_weight(&self, pdf: f32, f: &Factors) -> f32 {
        f.vc * (self.d_vcm * f.connect + self.d_vm * mis(pdf))
    }

    /// The camera subpath's partial weight when it hits a light whose
    /// next-event density is `direct` and emission density `emission`
    /// [eq. 43; the light side's is 0, eq. 42].
    pub fn emission_weight(&self, direct: f32, emission: f32) -> f32 {
        mis(direct) * self.d_vcm + mis(emission) * self.d_vc
    }
}

/// A camera subpath's partials split in two: `lt`, what light tracing's
/// density started (the camera's d_VCM of eq. 31, mis(N_light/p_pixel)) and
/// the recursion carried on, and `rest`, everything else. Every weight is
/// linear in the partials, so [`CameraPartial::with_lt`] gives the camera
/// side of a join whose path multiplies light tracing's term by a factor c:
/// the same recursion with that term scaled by c for that path alone
/// (variance-aware weights, [`super::variance`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CameraPartial {
    /// What light tracing's density started.
    pub lt: Partial,
    /// The rest.
    pub rest: Partial,
}

/// The two parts of a [`Deferred`] of a [`CameraPartial`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CameraDeferred {
    /// Of the `lt` part (its merge terms are 0: the merge is not light
    /// tracing's).
    pub lt: Deferred,
    /// Of the rest.
    pub rest: Deferred,
}

impl CameraDeferred {
    /// [`Deferred::hit`] on both parts.
    pub fn hit(&mut self, cos: f32) {
        self.lt.hit(cos);
        self.rest.hit(cos);
    }

    /// d_VC without the merge's terms, light tracing's term times `c`.
    pub fn d_vc_without(&self, c: f32) -> f32 {
        self.rest.d_vc_without + c * self.lt.d_vc_without
    }
}

impl CameraPartial {
    /// [`Partial::camera`], all of it light tracing's.
    pub fn camera(pdf_pixel: f32, n_light: f32, connectable: bool) -> Self {
        Self {
            lt: Partial::camera(pdf_pixel, n_light, connectable),
            rest: Partial::default(),
        }
    }

    /// [`Partial::hit`] on both parts.
    pub fn hit(&mut self, d2: f32, cos: f32) {
        self.lt.hit(d2, cos);
        self.rest.hit(d2, cos);
    }

    /// [`Partial::scatter`]: the vertex's own terms go to the rest.
    pub fn scatter(
        &mut self,
        delta: bool,
        pdf_fwd: f32,
        pdf_rev: f32,
        cos_out: f32,
        f: &Factors,
    ) -> CameraDeferred {
        CameraDeferred {
            lt: self.lt.propagate(delta, pdf_fwd, pdf_rev, cos_out, f),
            rest: self.rest.scatter(delta, pdf_fwd, pdf_rev, cos_out, f, true),
        }
    }

    /// The partials of a path whose light-tracing term is multiplied by `c`
    /// (the term is already raised to the heuristic's power, as every
    /// partial is; c multiplies it, not the density).
    #[inline]
    pub fn with_lt(&self, c: f32) -> Partial {
        Partial {
            d_vcm: self.rest.d_vcm + c * self.lt.d_vcm,
            d_vc: self.rest.d_vc + c * self.lt.d_vc,
            d_vm: self.rest.d_vm + c * self.lt.d_vm,
        }
    }
}

/// Russian roulette on a join by its MIS weight `w` (`"float
/// joinroulette"` τ): a join with w ≥ τ is made and keeps w; one with
/// w < τ is made with probability q = w/τ (`u` draws the uniform only
/// then) and then counts with w/q = τ. Its expected contribution is
/// unchanged, q·(X τ) = X w, so every technique keeps its weighted
/// expectation and the estimator stays unbiased [Veach 1997, §10.4.1 on
/// roulette by a path's expected contribution]; what is saved is the
/// shadow ray (and the splat) of joins whose weight would have made them
/// count little, which adds at most X²·w·τ of variance per join. τ = 0
/// makes every join of positive weight.
#[inline]
pub fn thin(w: f32, tau: f32, u: impl FnOnce() -> f32) -> Option<f32> {
    if w <= 0.0 {
        None
    } else if w >= tau {
        Some(w)
    } else if u() * tau < w {
        Some(tau)
    } else {
        None
    }
}

/// The full-path weight of eq. 37.
#[inline]
pub fn weight(w_light: f32, w_camera: f32) -> f32 {
    let w = 1.0 / (w_light + 1.0 + w_camera);
    if w.is_finite() {
        w
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Thinning keeps a join's expected weight: over stratified uniforms
    /// the kept weights average to w (to 1/n), and joins at or above τ
    /// are kept as they are. Counting a survivor with w instead of τ (a
    /// roulette without its 1/q) would average w²/τ and fail here.
    #[test]
    fn thinning_keeps_the_expected_weight() {
        let n = 10_000;
        for (w, tau) in [(0.003f32, 0.1f32), (0.05, 0.1), (0.099, 0.1), (0.2, 0.5)] {
            let mean: f64 = (0..n)
                .filter_map(|i| thin(w, tau, || (i as f32 + 0.5) / n as f32))
                .map(f64::from)
                .sum::<f64>()
                / n as f64;
            assert!(
                (mean - f64::from(w)).abs() <= f64::from(tau) / n as f64,
                "{w} {tau} {mean}"
            );
        }
        assert_eq!(thin(0.3, 0.1, || panic!("no draw above τ")), Some(0.3));
        assert_eq!(thin(0.3, 0.0, || panic!("no draw at τ = 0")), Some(0.3));
        assert_eq!(thin(0.0, 0.1, || 0.0), None);
    }

    /// A two-segment path light → x → camera on a diffuse x: with only
    /// connections (bpt) its techniques are NEE at x (s = 1), light
    /// tracing (t = 1), and hitting the light from x (s = 0). Each
    /// weight built from the recursive quantities equals the one from the
    /// technique densities directly, and the three sum to one.
    #[test]
    fn three_techniques_of_a_short_path_sum_to_one() {
        // Densities of the path: light point y (area pdf p_y for both the
        // light path and NEE), x at distance d from y and e from the lens.
        let (p_y, p_dir_light, cos_y) = (0.25f32, 0.3f32, 0.8f32);
        let (d2, cos_x_light, cos_x_cam) = (2.0f32, 0.6f32, 0.9f32);
        let (e2, pdf_pixel, n_light) = (3.0f32, 5.0f32, 16.0f32);
        let bsdf_pdf_to_light = 0.4f32; // x's BSDF density towards y.
        let f = Factors::new(0.1, n_light, true, false, DirectMerges::Always);
        // Area densities of x from each side and of y from x.
        let x_from_light = p_dir_light * cos_x_light / d2;
        let x_from_cam = pdf_pixel * cos_x_cam / e2 / n_light; // per light path
        let y_from_x = bsdf_pdf_to_light * cos_y / d2;
        // Technique densities relative to each other (common factors dropped):
        // s=0 (camera hits y): p_cam(x)·y_from_x; s=1 (NEE): p_cam(x)·p_y;
        // t=1 (light tracing): p_y·x_from_light.
        let p = [x_from_cam * y_from_x, x_from_cam * p_y, p_y * x_from_light];
        let sum: f32 = p.iter().map(|&q| mis(q)).sum();
        let expect: Vec<f32> = p.iter().map(|&q| mis(q) / sum).collect();
        // Recursive: camera at x.
        let mut cam = Partial::camera(pdf_pixel, n_light, true);
        cam.hit(e2, cos_x_cam);
        // NEE weight at x (eqs. 44, 45).
        let emission = p_y * p_dir_light;
        let w_light = mis(bsdf_pdf_to_light * cos_y / d2 / p_y);
        let w_cam = mis(emission * cos_x_light / d2 / p_y) * (f.vm + cam.d_vcm);
        let nee = weight(w_light, w_cam);
        // Light tracing at x (eq. 46): the light subpath's state at x.
        let mut light = Partial::light(p_y, emission, cos_y, false, &f);
        light.hit(d2, cos_x_light);
        let lt = weight(
            light.connect_weight(
                pdf_pixel * cos_x_cam / e2 / n_light,
                bsdf_pdf_to_light,
                &f,
                true,
            ),
            0.0,
        );
        // Hitting y from x: camera scattered at x towards y.
        let mut cam_y = cam;
        cam_y.scatter(false, bsdf_pdf_to_light, 0.0, cos_x_light, &f, true);
        cam_y.hit(d2, cos_y);
        let hit = weight(0.0, cam_y.emission_weight(p_y, emission));
        let got = [hit, nee, lt];
        for (g, e) in got.iter().zip(&expect) {
            assert!((g - e).abs() < 1e-5, "{got:?} vs {expect:?}");
        }
        assert!((got.iter().sum::<f32>() - 1.0).abs() < 1e-5);
    }
}
