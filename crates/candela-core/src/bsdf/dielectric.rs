//! Dielectric interfaces (glass, water): smooth or rough reflection + refraction.
//!
//! **Smooth** (effectively smooth distribution): two delta lobes. Reflection is
//! chosen with probability R = F(cos θo) and refraction with T = 1 − R, so each
//! sample's throughput f·|cos θi|/p is exactly 1 in importance mode
//! [pbrt-v4 §9.5].
//!
//! **Rough**: the microfacet model of [Walter et al. 2007]. The generalized half
//! vector ωm = ĥ(η′ωi + ωo), with η′ the relative index crossed (1 for
//! reflection) [Walter et al. 2007, eq. 16], identifies the facet. Reflection is
//! Torrance–Sparrow, D F G / (4 |cos θo cos θi|); transmission is
//! f = D (1 − F) G |ωi·ωm| |ωo·ωm| / (|cos θi cos θo| (ωi·ωm + ωo·ωm/η′)²)
//! [Walter et al. 2007, eq. 21; pbrt-v4 §9.7]. Sampling draws a visible
//! normal [Heitz 2018], then reflects or refracts with probability R or T; the
//! refraction Jacobian is dωm/dωi = |ωi·ωm| / (ωi·ωm + ωo·ωm/η′)²
//! [Walter et al. 2007, eq. 17; pbrt-v4 §9.7].
//!
//! **Transport modes.** Radiance is not symmetric across a refractive boundary:
//! in radiance mode transmission is divided by η′² [Veach 1997, §5.2;
//! pbrt-v4 §9.5]; importance mode leaves it unscaled, which makes it the
//! adjoint: f_importance(ωo, ωi) = f_radiance(ωi, ωo). Radiance-mode values obey
//! f(ωo, ωi)/η_o² = f(ωi, ωo)/η_i², η_o and η_i the indices on each side.
//! Importance mode conserves power: ∫ f |cos θi| dωi = 1 for the smooth model.
//!
//! **Geometry.** `eta` is the index below the surface (−z) over the index
//! above; wo may lie on either side. With `eta == 1` the interface is invisible
//! and the model is a pure delta pass-through, however rough.
//!
//! **Wavelength dependence (contract with the material layer).** This BxDF
//! takes a single scalar `eta`. When the material's index varies with
//! wavelength, the material evaluates it at the hero wavelength λ₀ and calls
//! `SampledWavelengths::terminate_secondary` before building the BxDF, so the
//! path carries only λ₀ from then on [pbrt-v4 §10.5]; a constant index leaves
//! all wavelengths alive.

use super::fresnel::{fr_dielectric, ft_dielectric, ft_dielectric_pair, refract};
use super::microfacet::TrowbridgeReitz;
use super::{BsdfSample, BxdfFlags, SampleFlags, TransportMode};
use crate::math::{local, sqr, Vec2, Vec3};
use crate::sampling::PdfSolidAngle;
use crate::spectrum::SampledSpectrum;

/// Dielectric interface with relative index `eta` (below over above).
#[derive(Clone, Copy, Debug)]
pub struct DielectricBxdf {
    /// Relative index of refraction (inside over outside).
    pub eta: f32,
    /// Microfacet distribution (smooth → delta lobes).
    pub distrib: TrowbridgeReitz,
}

/// The facet joining a pair of directions, with its cosines.
struct HalfVector {
    wm: Vec3,
    etap: f32,
    reflect: bool,
    dot_o: f32,
    dot_i: f32,
    denom: f32,
}

/// Probabilities of choosing reflection and transmission, masked by `allowed`.
fn lobe_probs(r: f32, t: f32, allowed: SampleFlags) -> (f32, f32) {
    let pr = if allowed.contains(SampleFlags::REFLECTION) {
        r
    } else {
        0.0
    };
    let pt = if allowed.contains(SampleFlags::TRANSMISSION) {
        t
    } else {
        0.0
    };
    (pr, pt)
}

/// A rough interface's sampled direction ([`DielectricBxdf::sample_rough_direction`]).
struct RoughSample {
    /// The visible normal.
    wm: Vec3,
    wi: Vec3,
    flags: BxdfFlags,
    /// Relative index across the interface (1 for reflection).
    etap: f32,
    /// Fresnel reflectance and transmittance at ωo·ωm.
    fresnel: (f32, f32),
    /// The lobes' selection weights from them.
    probs: (f32, f32),
}

impl DielectricBxdf {
    /// New dielectric interface.
    pub fn new(eta: f32, distrib: TrowbridgeReitz) -> Self {
        Self { eta, distrib }
    }

    /// Delta lobes only (smooth or index-matched).
    #[inline]
    fn is_specular(&self) -> bool {
        self.eta == 1.0 || self.distrib.effectively_smooth()
    }

    /// Lobes present.
    pub fn flags(&self) -> BxdfFlags {
        let lobes = if self.eta == 1.0 {
            BxdfFlags::TRANSMISSION
        } else {
            BxdfFlags::REFLECTION | BxdfFlags::TRANSMISSION
        };
        lobes
            | if self.is_specular() {
                BxdfFlags::SPECULAR
            } else {
                BxdfFlags::GLOSSY
            }
    }

    /// Widens the microfacet lobe.
    pub fn regularize(&mut self) {
        self.distrib.regularize()
    }

    /// Generalized half vector of (wo, wi) [Walter et al. 2007, eq. 16], or
    /// `None` for degenerate or back-facing configurations.
    ///
    /// Built in f64: near-grazing facets make ωo·ωm a small difference of
    /// O(1) terms, and f ∝ (ωo·ωm)² there, so f32 round-off alone broke
    /// reciprocity by ~10⁻⁴; in f64 both argument orders give the same facet.
    fn half_vector(&self, wo: Vec3, wi: Vec3) -> Option<HalfVector> {
        let (cos_o, cos_i) = (local::cos_theta(wo), local::cos_theta(wi));
        if cos_i == 0.0 || cos_o == 0.0 {
            return None;
        }
        let reflect = cos_i * cos_o > 0.0;
        // η′ in f64 too: 1/η rounded to f32 alone tilts ωm by an ulp.
        let etap = match (reflect, cos_o > 0.0) {
            (true, _) => 1.0,
            (false, true) => self.eta as f64,
            (false, false) => 1.0 / self.eta as f64,
        };
        let (o, i) = (wo.as_dvec3(), wi.as_dvec3());
        let mut wm = i * etap + o;
        if wm.length_squared() == 0.0 {
            return None;
        }
        wm = wm.normalize();
        if wm.z < 0.0 {
            wm = -wm;
        }
        let (mut dot_o, mut dot_i) = (o.dot(wm), i.dot(wm));
        if reflect {
            // Equal in exact arithmetic; the mean is symmetric in (ωo, ωi), which
            // matters where Fresnel is steep (the critical angle).
            dot_o = 0.5 * (dot_o + dot_i);
            dot_i = dot_o;
        }
        // Microfacets seen from behind by either direction contribute nothing.
        if dot_i * cos_i as f64 <= 0.0 || dot_o * cos_o as f64 <= 0.0 {
            return None;
        }
        Some(HalfVector {
            wm: wm.as_vec3(),
            etap: etap as f32,
            reflect,
            dot_o: dot_o as f32,
            dot_i: dot_i as f32,
            // (ωi·ωm + ωo·ωm/η′)², the refraction Jacobian's denominator.
            denom: (dot_i + dot_o / etap).powi(2) as f32,
        })
    }

    /// f(wo, wi): zero for the delta cases.
    pub fn f(&self, wo: Vec3, wi: Vec3, mode: TransportMode) -> SampledSpectrum {
        if self.is_specular() {
            return SampledSpectrum::zero();
        }
        let Some(h) = self.half_vector(wo, wi) else {
            return SampledSpectrum::zero();
        };
        let dg = self.distrib.d(h.wm) * self.distrib.g(wo, wi);
        SampledSpectrum::splat(self.f_at(&h, wo, wi, dg, mode))
    }

    /// f at the half vector `h` of (wo, wi), given D(ωm)·G(ωo, ωi).
    #[inline]
    fn f_at(&self, h: &HalfVector, wo: Vec3, wi: Vec3, dg: f32, mode: TransportMode) -> f32 {
        let (cos_o, cos_i) = (local::cos_theta(wo), local::cos_theta(wi));
        if h.reflect {
            let fr = fr_dielectric(h.dot_o, self.eta);
            return dg * fr / (4.0 * cos_i * cos_o).abs();
        }
        // [Walter et al. 2007, eq. 21]; Fresnel from both facet cosines keeps
        // f reciprocal to round-off near the critical angle.
        let t = ft_dielectric_pair(h.dot_o.abs(), h.dot_i.abs(), h.etap);
        let mut ft = dg * t * (h.dot_i * h.dot_o / (h.denom * cos_i * cos_o)).abs();
        if mode == TransportMode::Radiance {
            ft /= sqr(h.etap);
        }
        ft
    }

    /// Density of [`Self::sample_f`]; zero for the delta cases.
    pub fn pdf(
        &self,
        wo: Vec3,
        wi: Vec3,
        _mode: TransportMode,
        allowed: SampleFlags,
    ) -> PdfSolidAngle {
        if self.is_specular() {
            return PdfSolidAngle(0.0);
        }
        let Some(h) = self.half_vector(wo, wi) else {
            return PdfSolidAngle(0.0);
        };
        let d = self.distrib.d(h.wm);
        PdfSolidAngle(self.pdf_at(&h, wo, d, self.distrib.g1(wo), allowed))
    }

    /// The density at the half vector `h` of (wo, wi), given D(ωm) and G1(ωo).
    #[inline]
    fn pdf_at(&self, h: &HalfVector, wo: Vec3, d: f32, g1: f32, allowed: SampleFlags) -> f32 {
        let (pr, pt) = lobe_probs(
            fr_dielectric(h.dot_o, self.eta),
            ft_dielectric(h.dot_o, self.eta),
            allowed,
        );
        if pr == 0.0 && pt == 0.0 {
            return 0.0;
        }
        // Visible-normal density D_ωo(ωm) [Heitz 2018, eq. 1].
        let d_vis = g1 / local::abs_cos_theta(wo) * d * h.dot_o.abs();
        if h.reflect {
            d_vis / (4.0 * h.dot_o.abs()) * pr / (pr + pt)
        } else {
            // [Walter et al. 2007, eq. 17]
            d_vis * h.dot_i.abs() / h.denom * pt / (pr + pt)
        }
    }

    /// Samples reflection or refraction.
    pub fn sample_f(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        allowed: SampleFlags,
    ) -> Option<BsdfSample> {
        if self.is_specular() {
            self.sample_specular(wo, uc, mode, allowed)
        } else {
            self.sample_rough(wo, uc, u, mode, allowed)
        }
    }

    /// [`Self::sample_f`] for the random walks inside a layered BSDF, where a
    /// sample's f and density need not equal [`Self::f`] and [`Self::pdf`] to
    /// the last bit (nothing joins a walk's vertices by MIS across
    /// techniques; its own exits weigh densities that already differ by
    /// sampling): a rough interface's f and density come from the sampled
    /// ωm and its Fresnel terms, as pbrt-v4's `DielectricBxDF::Sample_f`
    /// computes them, not again from the generalised half vector in f64.
    /// The same values up to round-off, for about a third fewer instructions
    /// than [`Self::sample_f`]; coated surfaces' walks sample the interface
    /// several times per scattering.
    pub fn sample_f_walk(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        allowed: SampleFlags,
    ) -> Option<BsdfSample> {
        if self.is_specular() {
            return self.sample_specular(wo, uc, mode, allowed);
        }
        let RoughSample {
            wm,
            wi,
            flags,
            etap,
            fresnel: (r, t),
            probs: (pr, pt),
        } = self.sample_rough_direction(wo, uc, u, allowed)?;
        let dot_o = wo.dot(wm);
        let d = self.distrib.d(wm);
        let lambda_o = self.distrib.lambda(wo);
        let g = 1.0 / (1.0 + lambda_o + self.distrib.lambda(wi));
        let (cos_o, cos_i) = (local::cos_theta(wo), local::cos_theta(wi));
        // Visible-normal density D_ωo(ωm) [Heitz 2018, eq. 1].
        let d_vis = d * dot_o.abs() / ((1.0 + lambda_o) * cos_o.abs());
        let (f, pdf) = if flags.contains(BxdfFlags::REFLECTION) {
            let f = d * g * r / (4.0 * cos_i * cos_o).abs();
            (f, d_vis / (4.0 * dot_o.abs()) * pr / (pr + pt))
        } else {
            let dot_i = wi.dot(wm);
            let denom = sqr(dot_i + dot_o / etap);
            // [Walter et al. 2007, eqs. 17 and 21]
            let mut f = d * g * t * (dot_i * dot_o / (cos_i * cos_o * denom)).abs();
            if mode == TransportMode::Radiance {
                f /= sqr(etap);
            }
            (f, d_vis * dot_i.abs() / denom * pt / (pr + pt))
        };
        (pdf > 0.0 && f.is_finite()).then(|| BsdfSample {
            f: SampledSpectrum::splat(f),
            wi,
            pdf: PdfSolidAngle(pdf),
            flags,
            eta: etap,
            pdf_is_proportional: false,
        })
    }

    /// Delta reflection or refraction chosen by Fresnel [pbrt-v4 §9.5].
    fn sample_specular(
        &self,
        wo: Vec3,
        uc: f32,
        mode: TransportMode,
        allowed: SampleFlags,
    ) -> Option<BsdfSample> {
        let r = fr_dielectric(local::cos_theta(wo), self.eta);
        let t = ft_dielectric(local::cos_theta(wo), self.eta);
        let (pr, pt) = lobe_probs(r, t, allowed);
        if pr == 0.0 && pt == 0.0 {
            return None;
        }
        if uc < pr / (pr + pt) {
            let wi = Vec3::new(-wo.x, -wo.y, wo.z);
            return Some(BsdfSample {
                f: SampledSpectrum::splat(r / local::abs_cos_theta(wi)),
                wi,
                pdf: PdfSolidAngle(pr / (pr + pt)),
                flags: BxdfFlags::SPECULAR_REFLECTION,
                eta: 1.0,
                pdf_is_proportional: false,
            });
        }
        let (wi, etap) = refract(wo, Vec3::Z, self.eta)?;
        let mut ft = t / local::abs_cos_theta(wi);
        if mode == TransportMode::Radiance {
            ft /= sqr(etap);
        }
        Some(BsdfSample {
            f: SampledSpectrum::splat(ft),
            wi,
            pdf: PdfSolidAngle(pt / (pr + pt)),
            flags: BxdfFlags::SPECULAR_TRANSMISSION,
            eta: etap,
            pdf_is_proportional: false,
        })
    }

    /// A visible normal ωm, then reflection or refraction about it chosen by
    /// Fresnel, with what [`Self::sample_rough`] and [`Self::sample_f_walk`]
    /// each need to value it.
    fn sample_rough_direction(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        allowed: SampleFlags,
    ) -> Option<RoughSample> {
        if wo.z == 0.0 {
            return None;
        }
        let wm = self.distrib.sample_wm(wo, u);
        let dot_o = wo.dot(wm);
        let fresnel = (
            fr_dielectric(dot_o, self.eta),
            ft_dielectric(dot_o, self.eta),
        );
        let (pr, pt) = lobe_probs(fresnel.0, fresnel.1, allowed);
        if pr == 0.0 && pt == 0.0 {
            return None;
        }
        let (wi, flags, etap) = if uc < pr / (pr + pt) {
            let wi = local::reflect(wo, wm);
            if !local::same_hemisphere(wo, wi) {
                return None;
            }
            (wi, BxdfFlags::GLOSSY_REFLECTION, 1.0)
        } else {
            let (wi, etap) = refract(wo, wm, self.eta)?;
            if local::same_hemisphere(wo, wi) || wi.z == 0.0 {
                return None;
            }
            (wi, BxdfFlags::GLOSSY_TRANSMISSION, etap)
        };
        Some(RoughSample {
            wm,
            wi,
            flags,
            etap,
            fresnel,
            probs: (pr, pt),
        })
    }

    /// Visible-normal sample, then reflection or refraction by Fresnel.
    ///
    /// The returned value and density are `f(wo, wi)` and `pdf(wo, wi)` of the
    /// chosen direction: recomputing them from the generalized half vector
    /// rather than the sampled ωm keeps sample and evaluation identical under
    /// float round-off, which MIS in BDPT relies on.
    fn sample_rough(
        &self,
        wo: Vec3,
        uc: f32,
        u: Vec2,
        mode: TransportMode,
        allowed: SampleFlags,
    ) -> Option<BsdfSample> {
        let RoughSample {
            wi, flags, etap, ..
        } = self.sample_rough_direction(wo, uc, u, allowed)?;
        // f and pdf as Self::f and Self::pdf give them, sharing the half
        // vector, D(ωm) and Λ(ωo) (the same operations, the same bits).
        let h = self.half_vector(wo, wi)?;
        let d = self.distrib.d(h.wm);
        let (lambda_o, lambda_i) = (self.distrib.lambda(wo), self.distrib.lambda(wi));
        let pdf = self.pdf_at(&h, wo, d, 1.0 / (1.0 + lambda_o), allowed);
        if pdf == 0.0 {
            return None;
        }
        let dg = d * (1.0 / (1.0 + lambda_o + lambda_i));
        Some(BsdfSample {
            f: SampledSpectrum::splat(self.f_at(&h, wo, wi, dg, mode)),
            wi,
            pdf: PdfSolidAngle(pdf),
            flags,
            eta: etap,
            pdf_is_proportional: false,
        })
    }
}
