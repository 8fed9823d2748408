//! The densities with which a light point is sampled, as VCM's MIS weights
//! take them [tech. rep. eqs. 31, 43, 45]: by next-event estimation from a
//! receiver, and by emission (position × direction).

use crate::integrator::subpath::Vertex;
use crate::interaction::{Interaction, LightId};
use crate::light::{LightSampleContext, LightType};
use crate::math::{Ray, Vec3};
use crate::scene::Scene;

/// The density with which next-event estimation at `ctx` (the receiver)
/// samples the point `x0` of area light `id`: the selection probability
/// times the light's own [`Light::pdf_li`] (a sphere's cone sampling),
/// taken to area measure at `x0` [Veach 1997, eq. 8.10].
///
/// The MIS weights of every technique of a path that starts at a light
/// whose next-event sampling is not by area use this density for s = 1, not
/// the emission's uniform-area one (module doc of [`super::mis`],
/// "Next-event density").
///
/// [`Light::pdf_li`]: crate::light::Light::pdf_li
pub fn nee_area_density(
    scene: &Scene,
    id: LightId,
    x0: &Interaction,
    ctx: &LightSampleContext,
) -> f32 {
    let d = x0.p - ctx.p;
    let d2 = d.length_squared();
    if d2 <= 0.0 {
        return 0.0;
    }
    let wi = d / d2.sqrt();
    let pdf = scene.light(id).pdf_li(ctx, wi).0;
    scene.light_sampler().pmf(id) * pdf * x0.n.dot(wi).abs() / d2
}

/// The next-event context at vertex `v` (as [`Receiver::at_vertex`] makes it).
///
/// [`Receiver::at_vertex`]: crate::integrator::nee::Receiver::at_vertex
pub fn nee_context(v: &Vertex) -> LightSampleContext {
    LightSampleContext {
        p: v.it.p,
        p_error: v.it.p_error,
        n: v.it.n,
        ns: v.ns,
    }
}

/// Next-event and emission densities of light `id` emitting from `it`
/// towards `w` (the direction light travels), each with the light's
/// selection probability, and the cosine at the light (1 off surfaces)
/// [tech. rep. eqs. 31, 43, 45]. The next-event density is per unit area
/// for finite lights and per steradian at infinity; delta positions and
/// directions count as 1.
pub fn light_densities(scene: &Scene, id: LightId, it: &Interaction, w: Vec3) -> (f32, f32, f32) {
    let light = scene.light(id);
    let pmf = scene.light_sampler().pmf(id);
    let (pos, dir, cos) = match light.light_type() {
        LightType::Area => {
            let (pos, dir) = light.pdf_le_area(it, w);
            (pos.0, dir.0, it.n.dot(w).abs())
        }
        LightType::DeltaPosition => (1.0, light.pdf_le(&Ray::new(it.p, w)).1 .0, 1.0),
        LightType::DeltaDirection => (light.pdf_le(&Ray::new(it.p, w)).0 .0, 1.0, 1.0),
        LightType::Infinite => {
            let (pos, dir) = light.pdf_le(&Ray::new(it.p, w));
            (pos.0, dir.0, 1.0)
        }
    };
    let at_infinity = matches!(
        light.light_type(),
        LightType::Infinite | LightType::DeltaDirection
    );
    let direct = if at_infinity { dir } else { pos };
    (pmf * direct, pmf * pos * dir, cos)
}
