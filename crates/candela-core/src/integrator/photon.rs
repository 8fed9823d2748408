//! Photon shooting shared by every photon integrator (`photonmap`, `sppm`,
//! `ppm`) [Jensen 2001, ch. 5; pbrt-v4 §15 SPPM photon pass; seed §3].
//!
//! A photon is a light subpath. Its light is chosen in proportion to power
//! and its first β is β₀ = Le|cos θ|/(p_light·p_pos·p_dir), the path's share
//! of the total power Φ (exactly Φ for a single point light). Each
//! scattering multiplies β by f|cos θ|/p in importance mode (with the adjoint
//! shading-normal correction [Veach 1997, eq. 5.19]); Russian roulette then
//! keeps the photon with probability min(1, |β'|/|β|) and divides by it, so
//! photons keep roughly constant power and absorption is what ends them.
//! With N photons per pass each deposit carries β/N watts.
//!
//! **Spectral representation.** All photons and all camera paths of one pass
//! share the pass's four stratified wavelengths, so a photon carries its
//! power as a [`SampledSpectrum`] at exactly the wavelengths the visible
//! point's BSDF is evaluated at: f·ΔΦ is formed spectrally and converted to
//! sensor RGB only after the density estimate. (Per-photon wavelengths, as
//! in pbrt-v4, force a conversion to RGB at every deposit.) A dispersive
//! refraction that terminates the secondary wavelengths of one photon is
//! folded into its β (hero ×4, others 0), which has the same expectation.
//!
//! Photon `i` of pass `p` draws its numbers from a PCG32 stream seeded by
//! hash(seed, p, i): results do not depend on threads or scheduling.

use crate::bsdf::{Bsdf, SampleFlags, TransportMode};
use crate::interaction::SurfaceInteraction;
use crate::math::Vec2;
use crate::sampling::{hash_u64s, Pcg32};
use crate::scene::Scene;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};

/// Where a photon path meets a non-specular surface.
pub struct PhotonHit<'a> {
    /// The surface hit.
    pub si: &'a SurfaceInteraction,
    /// Its BSDF at the pass wavelengths.
    pub bsdf: &'a Bsdf,
    /// Power arriving with the photon (W at the pass wavelengths, not yet divided by N).
    pub beta: SampledSpectrum,
    /// Number of surfaces hit so far (1 for the first: direct illumination).
    pub depth: u32,
    /// Every earlier scattering was specular and there was at least one (an L S+ D path).
    pub caustic: bool,
    /// A dispersive refraction left only the hero wavelength (already folded into `beta`).
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

/// Uniform numbers of one photon.
struct PhotonRng(Pcg32);

impl PhotonRng {
    fn u1(&mut self) -> f32 {
        self.0.uniform_f32()
    }
    fn u2(&mut self) -> Vec2 {
        Vec2::new(self.0.uniform_f32(), self.0.uniform_f32())
    }
}

/// Traces photon `index` of `pass` at the pass wavelengths `lambda`, calling
/// `on_hit` at every non-specular surface it reaches.
pub fn trace_photon(
    scene: &Scene,
    lambda: &SampledWavelengths,
    settings: &ShootSettings,
    pass: u64,
    index: u64,
    mut on_hit: impl FnMut(&PhotonHit<'_>),
) -> PhotonFate {
    let mut fate = PhotonFate::default();
    let mut rng = PhotonRng(Pcg32::new(hash_u64s(&[settings.seed, pass, index]), 0));
    let Some((id, p_light)) = scene.light_sampler().sample(rng.u1()) else {
        return fate;
    };
    let Some(les) = scene.light(id).sample_le(rng.u2(), rng.u2(), lambda) else {
        return fate;
    };
    let les = les.at_time(scene.sample_time(|| rng.u1()));
    let mut beta = les.beta0(p_light);
    let mut ray = les.ray;
    let mut lam = *lambda;
    let mut caustic = true;
    let mut depth = 0;
    while !beta.is_black() {
        let Some(mut si) = scene.intersect(&ray, f32::INFINITY) else {
            fate.escaped = beta;
            break;
        };
        let was_terminated = lam.secondary_terminated();
        let Some(bsdf) = scene.bsdf(&mut si, &mut lam) else {
            ray = si.spawn_ray(ray.d);
            continue;
        };
        if lam.secondary_terminated() && !was_terminated {
            beta *= lambda.pdf().safe_div(lam.pdf());
        }
        depth += 1;
        if bsdf.flags().is_non_specular() {
            on_hit(&PhotonHit {
                si: &si,
                bsdf: &bsdf,
                beta,
                depth,
                caustic: caustic && depth > 1,
                terminated: lam.secondary_terminated(),
            });
        }
        if depth >= settings.max_depth {
            break;
        }
        let wo = si.wo;
        let Some(bs) = bsdf.sample_f(
            wo,
            rng.u1(),
            rng.u2(),
            TransportMode::Importance,
            SampleFlags::ALL,
        ) else {
            fate.absorbed = beta;
            break;
        };
        let new_beta = beta
            * bs.f
            * (si.importance_shading_correction(wo, bs.wi) * bs.wi.dot(bsdf.ns()).abs() / bs.pdf.0);
        caustic &= bs.is_specular();
        if settings.caustic_only && !caustic {
            break;
        }
        // Russian roulette keeps |β| roughly constant [pbrt-v4 SPPM photon pass].
        let survive = (new_beta.max_component() / beta.max_component()).min(1.0);
        if survive.is_nan() || survive <= 0.0 || rng.u1() >= survive {
            fate.absorbed = beta;
            break;
        }
        beta = new_beta / survive;
        ray = si.spawn_ray(bs.wi);
    }
    fate
}
