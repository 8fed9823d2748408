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
//! without merges sets `vm = 0`, one without connections `vc = 0`.
//!
//! Densities are per unit solid angle at the sampling vertex except where a
//! name ends in `_a` (per unit area). The cosines of the area conversions are
//! geometric (|ω·n_g|), as in [`crate::integrator::subpath::to_area`], on
//! both subpaths, so every technique is weighed with the same densities.
//! Russian roulette is left out of the densities: weights built from the
//! same density functions on every technique still sum to one.

/// The heuristic's power applied to a density or density ratio (β = 2)
/// [Veach 1997, eq. 9.13].
#[inline]
pub fn mis(x: f32) -> f32 {
    x * x
}

/// The per-iteration constants of eq. 20 and the merge normalisation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Factors {
    /// mis(η_VCM) when merging is on, else 0.
    pub vm: f32,
    /// mis(1/η_VCM) when connecting is on, else 0.
    pub vc: f32,
    /// 1/η_VCM = 1/(π r² N_light), the merge kernel's normalisation.
    pub merge_norm: f32,
}

impl Factors {
    /// The constants for radius `r` and `n_light` light paths.
    pub fn new(r: f32, n_light: f32, connect: bool, merge: bool) -> Self {
        let eta = std::f32::consts::PI * r * r * n_light;
        Self {
            vm: if merge { mis(eta) } else { 0.0 },
            vc: if connect { mis(1.0 / eta) } else { 0.0 },
            merge_norm: 1.0 / eta,
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
    /// Merges only.
    pub d_vm: f32,
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
            d_vm: d_vc * f.vc,
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
    pub fn scatter(&mut self, delta: bool, pdf_fwd: f32, pdf_rev: f32, cos_out: f32, f: &Factors) {
        if delta {
            self.d_vcm = 0.0;
            self.d_vc *= mis(cos_out);
            self.d_vm *= mis(cos_out);
            return;
        }
        if pdf_fwd <= 0.0 {
            *self = Self::default();
            return;
        }
        let g = mis(cos_out / pdf_fwd);
        let rev = mis(pdf_rev);
        let d_vc = g * (self.d_vc * rev + self.d_vcm + f.vm);
        let d_vm = g * (self.d_vm * rev + self.d_vcm * f.vc + 1.0);
        *self = Self {
            d_vcm: mis(1.0 / pdf_fwd),
            d_vc,
            d_vm,
        };
    }

    /// The partial weight of this subpath when the other side's join
    /// generated its last vertex with area density `pdf_join_a` and this
    /// vertex's BSDF would have continued back with `pdf_rev` [eqs. 40, 41,
    /// 45; for a light-tracing join eq. 46].
    pub fn connect_weight(&self, pdf_join_a: f32, pdf_rev: f32, f: &Factors) -> f32 {
        mis(pdf_join_a) * (f.vm + self.d_vcm + self.d_vc * mis(pdf_rev))
    }

    /// The partial weight of this subpath in a merge whose other side would
    /// have sampled the direction with `pdf` [eqs. 38, 39].
    pub fn merge_weight(&self, pdf: f32, f: &Factors) -> f32 {
        self.d_vcm * f.vc + self.d_vm * mis(pdf)
    }

    /// The camera subpath's partial weight when it hits a light whose
    /// next-event density is `direct` and emission density `emission`
    /// [eq. 43; the light side's is 0, eq. 42].
    pub fn emission_weight(&self, direct: f32, emission: f32) -> f32 {
        mis(direct) * self.d_vcm + mis(emission) * self.d_vc
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
        let f = Factors::new(0.1, n_light, true, false);
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
            light.connect_weight(pdf_pixel * cos_x_cam / e2 / n_light, bsdf_pdf_to_light, &f),
            0.0,
        );
        // Hitting y from x: camera scattered at x towards y.
        let mut cam_y = cam;
        cam_y.scatter(false, bsdf_pdf_to_light, 0.0, cos_x_light, &f);
        cam_y.hit(d2, cos_y);
        let hit = weight(0.0, cam_y.emission_weight(p_y, emission));
        let got = [hit, nee, lt];
        for (g, e) in got.iter().zip(&expect) {
            assert!((g - e).abs() < 1e-5, "{got:?} vs {expect:?}");
        }
        assert!((got.iter().sum::<f32>() - 1.0).abs() < 1e-5);
    }
}
