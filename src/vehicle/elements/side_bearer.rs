//! Constant-contact side bearer: preloaded vertical spring that only pushes, with sliding
//! friction in the horizontal plane (smoothed by tanh), and a solid stop: after `travel` of
//! compression beyond the static position the cage bottoms out and the much stiffer stop
//! (bolster and carbody bolster in series) carries the rest.

use super::{Relative, friction_dir};
use crate::error::Result;
use crate::vehicle::binder::Binder;
use crate::vehicle::body::{Attachment, BodyState, Wrench};
use nalgebra::Vector3;
use serde::Deserialize;

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
    /// Compression from the static position at which the bearer goes solid, m (∞: no stop).
    pub travel: f64,
    /// Stiffness of the solid stop, N/m.
    pub stop_stiffness: f64,
}

impl SideBearer {
    /// Vertical force at compression `d` (m) from the static position: the preloaded spring,
    /// plus the stop beyond `travel`; never pulls.
    #[inline]
    pub fn vertical_force(&self, d: f64) -> f64 {
        (self.preload + self.stiffness * d + self.stop_stiffness * (d - self.travel).max(0.0))
            .max(0.0)
    }

    pub(crate) fn apply(&self, states: &[BodyState], wrenches: &mut [Wrench]) {
        let r = Relative::new(&self.upper, &self.lower, states);
        let normal = self.vertical_force(r.d.z);
        let slip = Vector3::new(r.v.x, r.v.y, 0.0);
        let mut f = friction_dir(slip, self.regularisation_velocity) * (self.friction * normal);
        f.z = normal;
        r.apply(f, &self.upper, &self.lower, states, wrenches);
    }
}

/// `[[side_bearer]]` in a vehicle file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SideBearerFile {
    upper: String,
    lower: String,
    at: [f64; 3],
    stiffness: f64,
    preload_n: f64,
    friction: f64,
    regularisation_velocity: f64,
    /// Compression travel from the static position to solid, m (absent: no stop).
    travel_m: Option<f64>,
    /// Stop stiffness, N/m.
    #[serde(default = "default_stop_stiffness")]
    stop_stiffness: f64,
}

fn default_stop_stiffness() -> f64 {
    1e8
}

impl SideBearer {
    pub(crate) fn bind(f: &str, e: &SideBearerFile, b: &Binder) -> Result<Self> {
        b.non_negative(
            format!("{f}.stiffness"),
            &[e.stiffness, e.preload_n, e.friction],
        )?;
        b.positive(
            format!("{f}.regularisation_velocity"),
            e.regularisation_velocity,
        )?;
        b.non_negative(format!("{f}.stop_stiffness"), &[e.stop_stiffness])?;
        let travel = match e.travel_m {
            Some(t) => b.positive(format!("{f}.travel_m"), t)?,
            None => f64::INFINITY,
        };
        let (upper, lower) = b.pair(f, &e.upper, &e.lower, e.at)?;
        Ok(SideBearer {
            upper,
            lower,
            stiffness: e.stiffness,
            preload: e.preload_n,
            friction: e.friction,
            regularisation_velocity: e.regularisation_velocity,
            travel,
            stop_stiffness: e.stop_stiffness,
        })
    }
}
