//! VCM's variance-aware weights for light tracing (`"string ltweights"
//! "variance"`, the default): the factors and their pilot are
//! [`crate::integrator::lt_weights`]'s; here, how a VCM iteration feeds the
//! pilot. Measured on the Cornell box's direct light (module doc of
//! [`super`]): light tracing took 46 % of it by density and 73 % of its
//! variance.
//!
//! Measured on the Cornell box (half resolution, 36 iterations, relMSE
//! against a 1200-s path-traced reference, seeds 1 and 2): 0.00195 and
//! 0.00193 against 0.00234 and 0.00230 by density alone (−17 %); its direct
//! light alone (`maxdepth 1`, against 4096 spp of `path`) 0.00065 and
//! 0.00053 against 0.00131 and 0.00120 (`path` at 36 spp: 0.00103). Multiplying by c² instead (the
//! power of the factor, as the densities are raised) gave 0.00206 and
//! 0.00205: at lengths k ≥ 2, where the camera side's V / M is 0.3–0.9,
//! light tracing was weighed down more than its variance warrants. On
//! caustic-glass (32 iterations) 0.02130 and 0.01478 against 0.02118 and
//! 0.01467 (+0.6 %, the caustic on the floor keeps c near 1); the pool is
//! unchanged (the camera sees its floor only through the water, where light
//! tracing cannot reach the lens).

use super::VcmIntegrator;
pub use crate::integrator::lt_weights::{ByLength, LtWeights, LENGTHS, NO_LT};
use crate::integrator::RenderContext;

impl VcmIntegrator {
    /// Whether light tracing's factors come from the pilot: `ltweights
    /// variance`, and light tracing is one of several techniques.
    pub(super) fn variance_pilot(&self, ctx: &RenderContext<'_>) -> bool {
        let t = self.techniques;
        self.settings.variance_lt && t.connect && !t.light_only && ctx.camera.is_connectable()
    }

    /// Light tracing's factors in the weights: from the pilot passes'
    /// estimates, those this process did not render computed now by the
    /// same iteration code (not added to the image); 1 everywhere without
    /// the pilot. `None` if cancelled.
    pub(super) fn lt_weights(&self, ctx: &RenderContext<'_>) -> Option<&LtWeights> {
        let enabled = self.variance_pilot(ctx);
        self.pilot.weights(ctx, enabled, |quiet, pass| {
            self.iteration(quiet, pass, &NO_LT, true)?.samples
        })
    }
}
