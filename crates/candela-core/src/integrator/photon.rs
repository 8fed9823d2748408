//! Photon shooting shared by every photon integrator (`photonmap`, `sppm`,
//! `ppm`) [Jensen 2001, ch. 5; pbrt-v4 §15 SPPM photon pass; seed §3].
//!
//! A photon is a light subpath ([`start_light_subpath`]: β₀ is its share of
//! the total power Φ) traced by the shared walker in importance mode
//! ([`crate::integrator::subpath`]); it is seen at every non-specular
//! surface it reaches. Russian roulette is the photon rule
//! ([`Roulette::Photon`]): photons keep roughly constant power and
//! absorption is what ends them. With N photons per pass each deposit
//! carries β/N watts.
//!
//! **Spectral representation.** A photon carries its power as a
//! [`SampledSpectrum`] at the wavelengths of its group
//! ([`crate::integrator::wavelengths`]), exactly those at which the visible
//! points of that group evaluate their BSDFs: f·ΔΦ is formed spectrally and
//! converted to sensor RGB only after the density estimate. (Per-photon
//! wavelengths, as in pbrt-v4, force a conversion to RGB at every deposit.)
//! A dispersive refraction that terminates the secondary wavelengths of one
//! photon is folded into its β (hero ×4, others 0), which has the same
//! expectation ([`Dispersion::Fold`]).
//!
//! Photon `i` of pass `p` draws its numbers from the stream
//! [`StreamRng`]`(seed, p, i)`: results do not depend on threads or
//! scheduling.

use super::roulette::Roulette;
use super::subpath::{start_light_subpath, walk, Dispersion, End, Flow, Vertex, Visitor, Walk};
use crate::bsdf::TransportMode;
use crate::interaction::SurfaceInteraction;
use crate::sampling::StreamRng;
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Where a photon path meets a non-specular surface.
pub struct PhotonHit<'a> {
    /// The surface vertex: position, normals, `wo` (the photon's incident
    /// direction), BSDF, β (power arriving, W at the group's wavelengths,
    /// not yet divided by N), depth (1 for the first surface: direct light)
    /// and `caustic` (an L S+ D path).
    pub v: &'a Vertex,
    /// A dispersive refraction left only the hero wavelength (already folded into β).
    pub terminated: bool,
}

/// How a photon path ended, for power bookkeeping.
#[derive(Clone, Copy, Debug, Default)]
pub struct PhotonFate {
    /// Power absorbed where Russian roulette ended the path (zero if it escaped or hit maxdepth).
    pub absorbed: SampledSpectrum,
    /// Power that left the scene.
    pub escaped: SampledSpectrum,
}

/// Photon tracing parameters.
#[derive(Clone, Copy, Debug)]
pub struct ShootSettings {
    /// Maximum number of surfaces a photon hits.
    pub max_depth: u32,
    /// Seed of the photon random numbers.
    pub seed: u64,
    /// End a photon at its first non-specular scattering: only caustic
    /// (L S+ D) hits are wanted, so the rest of the path would be wasted.
    pub caustic_only: bool,
}

/// The photon visitor: reports non-specular hits to `on_hit`.
struct Deposit<F> {
    on_hit: F,
    caustic_only: bool,
}

impl<F: FnMut(&PhotonHit<'_>)> Visitor<StreamRng> for Deposit<F> {
    fn vertex(
        &mut self,
        v: &Vertex,
        _: &SurfaceInteraction,
        lambda: &mut SampledWavelengths,
        _: &mut StreamRng,
    ) -> Flow {
        let non_specular = v.bsdf.as_ref().is_some_and(|b| b.flags().is_non_specular());
        if non_specular {
            (self.on_hit)(&PhotonHit {
                v,
                terminated: lambda.secondary_terminated(),
            });
        }
        if self.caustic_only {
            Flow::SpecularOnly
        } else {
            Flow::Continue
        }
    }
}

/// Traces photon `index` of `pass` at the wavelengths `lambda`, calling
/// `on_hit` at every non-specular surface it reaches.
pub fn trace_photon(
    scene: &Scene,
    lambda: &SampledWavelengths,
    settings: &ShootSettings,
    pass: u64,
    index: u64,
    on_hit: impl FnMut(&PhotonHit<'_>),
) -> PhotonFate {
    let mut fate = PhotonFate::default();
    let mut rng = StreamRng::new(settings.seed, pass, index);
    let Some(ls) = start_light_subpath(scene, lambda, &mut rng, None) else {
        return fate;
    };
    let w = Walk {
        mode: TransportMode::Importance,
        max_depth: settings.max_depth,
        roulette: Some(Roulette::Photon),
        regularize: false,
        dispersion: Dispersion::Fold,
    };
    let mut visitor = Deposit {
        on_hit,
        caustic_only: settings.caustic_only,
    };
    let mut lam = *lambda;
    match walk(scene, &mut lam, &mut rng, &w, ls.start, &mut visitor) {
        End::Escaped(beta) => fate.escaped = beta,
        End::Absorbed(beta) => fate.absorbed = beta,
        End::Ended => {}
    }
    fate
}
