//! The densities with which a light point is sampled, as VCM's MIS weights
//! take them [tech. rep. eqs. 31, 43, 45]: by next-event estimation from a
//! receiver ([`crate::integrator::nee::nee_area_density`], shared with
//! BDPT), and by emission (position × direction).

use crate::interaction::{Interaction, LightId};
use crate::light::LightType;
use crate::math::{Ray, Vec3};
use crate::scene::Scene;

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
