//! The start of a light subpath: a light chosen in proportion to power and
//! an emitted ray [Veach 1997, §10.2; pbrt-v3 `GenerateLightSubpath`].
//!
//! The first β is β₀ = Le·|cos θ|/(p_light·p_pos·p_dir), the subpath's
//! share of the emitted power Φ (exactly Φ for a single point light; seed
//! §3.2). The light endpoint carries 1/(p_light·p_pos), what a connection
//! through it still needs, and its forward density p_light·p_pos (for a
//! light at infinity the direction's density: its position is on the
//! scene's disk). From a light at infinity the first surface vertex's
//! density is the disk position density times its cosine (parallel rays).

use super::{Start, Vertex};
use crate::interaction::Interaction;
use crate::light::LightType;
use crate::math::{Ray, Vec3};
use crate::sampling::{PathRng, PdfArea, PdfSolidAngle};
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// A light subpath's endpoint and the walk that continues from it.
#[derive(Clone, Copy, Debug)]
pub struct LightStart {
    /// The light endpoint.
    pub vertex: Vertex,
    /// The emitted ray with β₀.
    pub start: Start,
    /// Probability of having chosen the light.
    pub pmf: f32,
    /// Density of the emitted ray's origin (1 for delta positions).
    pub pdf_pos: PdfArea,
    /// Density of its direction (1 for delta directions).
    pub pdf_dir: PdfSolidAngle,
}

/// Samples a light, a point on it and an emitted direction (three numbers:
/// 1D, 2D, 2D) at `time`, or at a time drawn from the shutter when `None`;
/// `None` when the emission sample carries nothing.
pub fn start_light_subpath<R: PathRng + ?Sized>(
    scene: &Scene,
    lambda: &SampledWavelengths,
    rng: &mut R,
    time: Option<f32>,
) -> Option<LightStart> {
    let (id, p_light) = scene.light_sampler().sample(rng.u1())?;
    let light = scene.light(id);
    let les = light.sample_le(rng.u2(), rng.u2(), lambda)?;
    let time = time.unwrap_or_else(|| scene.sample_time(|| rng.u1()));
    let les = les.at_time(time);
    if les.pdf_pos.0 == 0.0 || les.pdf_dir.0 == 0.0 || les.l.is_black() {
        return None;
    }
    let at_infinity = matches!(
        light.light_type(),
        LightType::Infinite | LightType::DeltaDirection
    );
    let it = les.intr.unwrap_or(Interaction {
        time,
        ..Interaction::at_point(les.ray.o)
    });
    let w_inf = if at_infinity { les.ray.d } else { Vec3::ZERO };
    let mut vertex = Vertex::light(
        id,
        it,
        w_inf,
        SampledSpectrum::splat(1.0 / (p_light * les.pdf_pos.0)),
    );
    vertex.pdf_fwd = PdfArea(match light.light_type() {
        LightType::Infinite => p_light * light.pdf_le(&Ray::new(it.p, w_inf)).1 .0,
        LightType::DeltaDirection => 0.0,
        _ => p_light * les.pdf_pos.0,
    });
    let pdf_dir = if at_infinity {
        PdfSolidAngle(les.pdf_pos.0)
    } else {
        les.pdf_dir
    };
    Some(LightStart {
        vertex,
        start: Start {
            ray: les.ray,
            beta: les.beta0(p_light),
            depth: 0,
            from: Some(vertex),
            pdf_dir,
        },
        pmf: p_light,
        pdf_pos: les.pdf_pos,
        pdf_dir: les.pdf_dir,
    })
}
