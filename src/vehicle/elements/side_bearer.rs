//! Constant-contact side bearer: preloaded vertical spring that only pushes, with sliding
//! friction in the horizontal plane (smoothed by tanh).

use super::{Relative, friction_dir};
use crate::vehicle::body::{Attachment, BodyState, Wrench};
use nalgebra::Vector3;

/// Side bearer between the carbody (upper) and a bolster (lower).
#[derive(Debug, Clone, PartialEq)]
pub struct SideBearer {
    /// Carbody wear plate.
    pub upper: Attachment,
    /// Bolster bearer.
    pub lower: Attachment,
    /// Vertical stiffness, N/m.
    pub stiffness: f64,
    /// Preload at the static position, N.
    pub preload: f64,
    /// Friction coefficient.
    pub friction: f64,
    /// Regularisation velocity, m/s.
    pub regularisation_velocity: f64,
}

impl SideBearer {
    pub(crate) fn apply(&self, states: &[BodyState], wrenches: &mut [Wrench]) {
        let r = Relative::new(&self.upper, &self.lower, states);
        let normal = (self.preload + self.stiffness * r.d.z).max(0.0);
        let slip = Vector3::new(r.v.x, r.v.y, 0.0);
        let mut f = friction_dir(slip, self.regularisation_velocity) * (self.friction * normal);
        f.z = normal;
        r.apply(f, &self.upper, &self.lower, states, wrenches);
    }
}
