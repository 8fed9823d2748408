//! Probability densities that carry their measure.
//!
//! Mixing a solid-angle density with an area density is the classic
//! bidirectional bug; the two are distinct types and convert only through
//! the geometry term [Veach 1997, eq. 8.10]: p_A = p_ω · |cos θ'| / d².

/// Density with respect to solid angle [1/sr].
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd, Default)]
pub struct PdfSolidAngle(pub f32);

/// Density with respect to surface area [1/m²].
#[derive(Clone, Copy, Debug, PartialEq, PartialOrd, Default)]
pub struct PdfArea(pub f32);

/// p_A = p_ω · |cos θ_to| / d², where θ_to is measured at the receiving point.
#[inline]
pub fn pdf_solid_angle_to_area(p: PdfSolidAngle, dist2: f32, abs_cos_to: f32) -> PdfArea {
    PdfArea(p.0 * abs_cos_to / dist2)
}

/// p_ω = p_A · d² / |cos θ_from|, θ at the sampled point; 0 when grazing.
#[inline]
pub fn pdf_area_to_solid_angle(p: PdfArea, dist2: f32, abs_cos_at_sample: f32) -> PdfSolidAngle {
    if abs_cos_at_sample == 0.0 {
        return PdfSolidAngle(0.0);
    }
    PdfSolidAngle(p.0 * dist2 / abs_cos_at_sample)
}
