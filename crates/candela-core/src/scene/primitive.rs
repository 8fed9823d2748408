//! A shape with its material and optional area light.

use crate::interaction::{LightId, MaterialId};
use crate::shape::Shape;

/// One intersectable object.
#[derive(Clone, Debug)]
pub struct Primitive {
    /// Geometry.
    pub shape: Shape,
    /// Material (`None`: interface, rays pass through).
    pub material: Option<MaterialId>,
    /// Emission.
    pub area_light: Option<LightId>,
}
