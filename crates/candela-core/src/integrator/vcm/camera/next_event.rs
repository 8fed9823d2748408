//! VCM's camera pass: next-event estimation at a camera vertex (s = 1).

use super::CameraVisitor;
use crate::bsdf::{Bsdf, SampleFlags, TransportMode};
use crate::integrator::nee::{sample_light, Receiver};
use crate::integrator::subpath::Vertex;
use crate::integrator::vcm::densities::light_densities;
use crate::integrator::vcm::mis::{mis, weight};
use crate::sampler::Sampler;
use crate::spectrum::SampledWavelengths;

impl CameraVisitor<'_, '_> {
    /// s = 1: a light sample for `v` [eqs. 44–45].
    pub(super) fn next_event(
        &mut self,
        v: &Vertex,
        bsdf: &Bsdf,
        lambda: &SampledWavelengths,
        rng: &mut Sampler,
    ) {
        let scene = self.ctx.scene;
        let Some(r) = Receiver::at_vertex(v) else {
            return;
        };
        let Some(ls) = sample_light(scene, scene.light_sampler(), &r, lambda, rng) else {
            return;
        };
        let light = scene.light(ls.light);
        let e = ls.vertex(scene);
        let (direct, emission, cos_light) = light_densities(scene, ls.light, &e.it, -ls.wi);
        if direct <= 0.0 {
            return;
        }
        // An area light point's density is the one this sample was drawn
        // with, per unit area (nee.rs, `nee_area_density`).
        let direct = if !light.samples_li_by_area() {
            ls.pmf * ls.pdf.0 * cos_light / (e.p() - v.p()).length_squared()
        } else {
            direct
        };
        let bsdf_dir = if light.is_hittable() {
            bsdf.pdf(v.wo, ls.wi, TransportMode::Radiance, SampleFlags::ALL)
                .0
        } else {
            0.0
        };
        let bsdf_rev = bsdf
            .pdf(ls.wi, v.wo, TransportMode::Importance, SampleFlags::ALL)
            .0;
        let cos_recv = ls.wi.dot(v.it.n).abs();
        let inv_d2 = if e.at_infinity() {
            1.0
        } else {
            1.0 / (e.p() - v.p()).length_squared()
        };
        let w_light = mis(bsdf_dir * cos_light * inv_d2 / direct);
        let ratio = emission * cos_recv * inv_d2 / direct;
        // A merge at v, next to the light, exists after a specular vertex.
        let merge = self.cp.ff.merges_at(true, self.arrived_delta);
        let w_cam = self
            .partial(v.depth)
            .connect_weight(ratio, bsdf_rev, &self.f_here, merge);
        self.add(v.depth, v.beta * ls.unweighted() * weight(w_light, w_cam));
    }
}
