//! Variable-friction wedge damper: Coulomb friction, vertical and lateral, whose normal force
//! follows the load of the spring nest beside it (friction ≈ 0.08–0.1 × nest force), smoothed
//! near zero velocity by `tanh(|v|/v_ref)` — never an ideal sign function.

use super::{Relative, friction_dir};
use crate::vehicle::body::{Attachment, BodyState, Wrench};
use nalgebra::Vector3;

/// Wedge damper between a bolster end (upper) and a side frame (lower).
#[derive(Debug, Clone, PartialEq)]
pub struct WedgeDamper {
    /// Bolster end.
    pub upper: Attachment,
    /// Side frame column.
    pub lower: Attachment,
    /// Friction force over nest force.
    pub friction_ratio: f64,
    /// Regularisation velocity, m/s.
    pub regularisation_velocity: f64,
    /// The nest whose load presses the wedge.
    pub nest: super::SpringNest,
}

impl WedgeDamper {
    pub(crate) fn apply(&self, states: &[BodyState], wrenches: &mut [Wrench]) {
        let r = Relative::new(&self.upper, &self.lower, states);
        let normal = self.nest.vertical_force(&r);
        let slip = Vector3::new(0.0, r.v.y, r.v.z);
        // The lower body slides at v relative to the upper: friction drags the upper along.
        let f = friction_dir(slip, self.regularisation_velocity) * (self.friction_ratio * normal);
        r.apply(f, &self.upper, &self.lower, states, wrenches);
    }
}
