//! Forks of a walk (module doc of [`super`], "Splitting"): the walker's own,
//! at a vertex whose visitor forks, and the rule and walk of a fork for an
//! estimator with a loop of its own (the path tracer).

use super::{
    run, scatter, walk, Dispersion, Escape, Fixed, Flow, Start, State, Vertex, Visitor, Walk,
};
use crate::bsdf::{Bsdf, BsdfSample, BxdfFlags, SampleFlags, TransportMode};
use crate::interaction::SurfaceInteraction;
use crate::sampling::PathRng;
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Walks the reflection alone from `v` with a [`Visitor::fork`] of the
/// visitor when it forks there, joins what the fork found, and marks `st`
/// as forked here (module doc, "Splitting").
pub(super) fn fork_reflection<R, V>(
    fixed: &Fixed<'_>,
    lambda: &SampledWavelengths,
    rng: &mut R,
    flow: Flow,
    v: &Vertex,
    st: &mut State,
    visitor: &mut V,
) where
    R: PathRng + ?Sized,
    V: Visitor<R>,
{
    if !V::FORKS || !v.bsdf.as_ref().is_some_and(forks_at) {
        return;
    }
    let Some(mut branch) = visitor.fork(v) else {
        return;
    };
    // No roulette: the fork's β starts at F times the walk's, which the
    // walk's rule would read as a path hardly worth going on with.
    let w = Walk {
        dispersion: Dispersion::Fold,
        roulette: None,
        ..*fixed.w
    };
    let at_fork = Fixed {
        scene: fixed.scene,
        w: &w,
        initial: *lambda,
    };
    let mut lambda_r = *lambda;
    let mut st_r = State {
        fork: true,
        fork_emission: false,
        ..st.clone()
    };
    let reflection = SampleFlags::REFLECTION;
    if scatter(v, &w, flow, reflection, &mut st_r, &mut branch, rng).is_none() {
        run(&at_fork, &mut lambda_r, rng, st_r, &mut branch);
    }
    visitor.join(branch);
    st.forked_here = true;
}

/// A walk may fork at a vertex with this BSDF: a smooth reflection and
/// transmission pair (module doc, "Splitting").
pub fn forks_at(bsdf: &Bsdf) -> bool {
    bsdf.flags() == BxdfFlags::SPECULAR | BxdfFlags::REFLECTION | BxdfFlags::TRANSMISSION
}

/// Whether emission reached after sample `bs` is a fork's
/// ([`Vertex::fork_emission`]): `before`, whether it was before `bs`;
/// `forked_here`, whether the walk forked where `bs` was drawn.
pub fn fork_emission_after(before: bool, forked_here: bool, bs: &BsdfSample) -> bool {
    bs.is_specular() && (before || (forked_here && bs.is_reflection()))
}

/// What a fork counts, for an estimator with a loop of its own (the path
/// tracer): the emission a walk from `start` reaches along delta
/// scatterings, at full weight, visiting vertices to depth `max_depth`,
/// with no roulette and its dispersion folded into β (module doc,
/// "Splitting").
pub fn delta_emission<R: PathRng + ?Sized>(
    scene: &Scene,
    lambda: &SampledWavelengths,
    rng: &mut R,
    max_depth: u32,
    start: Start,
) -> SampledSpectrum {
    let w = Walk {
        mode: TransportMode::Radiance,
        max_depth,
        roulette: None,
        regularize: false,
        dispersion: Dispersion::Fold,
    };
    let mut lambda = *lambda;
    let mut found = DeltaEmission {
        scene,
        l: SampledSpectrum::zero(),
    };
    walk(scene, &mut lambda, rng, &w, start, &mut found);
    found.l
}

/// The visitor of [`delta_emission`].
struct DeltaEmission<'a> {
    scene: &'a Scene,
    l: SampledSpectrum,
}

impl<R: PathRng + ?Sized> Visitor<R> for DeltaEmission<'_> {
    fn vertex(
        &mut self,
        v: &Vertex,
        _: &SurfaceInteraction,
        lambda: &mut SampledWavelengths,
        _: &mut R,
    ) -> Flow {
        if let Some(id) = v.area_light {
            let le = self.scene.light(id).l(v.p(), v.it.n, v.it.uv, v.wo, lambda);
            self.l += v.beta * le;
        }
        Flow::SpecularOnly
    }

    fn escaped(&mut self, e: &Escape, lambda: &SampledWavelengths) {
        for &id in self.scene.infinite_lights() {
            self.l += e.beta * self.scene.light(id).le(&e.ray, lambda);
        }
    }
}
