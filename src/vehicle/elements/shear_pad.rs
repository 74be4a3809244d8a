//! Axle-box rubber shear pad: linear spring–damper in three directions.

use super::Relative;
use crate::error::Result;
use crate::vehicle::binder::Binder;
use crate::vehicle::body::{Attachment, BodyState, Wrench};
use nalgebra::Vector3;
use serde::Deserialize;

/// Shear pad between a side frame (upper) and a wheelset's axle box (lower).
#[derive(Debug, Clone, PartialEq)]
pub struct ShearPad {
    /// Side frame.
    pub upper: Attachment,
    /// Axle box: a point on the axle's axis, so the wheelset's spin does not move it.
    pub lower: Attachment,
    /// Stiffness (x, y, z), N/m.
    pub stiffness: Vector3<f64>,
    /// Damping (x, y, z), N·s/m.
    pub damping: Vector3<f64>,
    /// Static vertical load carried, N.
    pub preload: f64,
}

impl ShearPad {
    pub(crate) fn apply(&self, states: &[BodyState], wrenches: &mut [Wrench]) {
        let r = Relative::new(&self.upper, &self.lower, states);
        let f = self.stiffness.component_mul(&r.d)
            + self.damping.component_mul(&r.v)
            + Vector3::new(0.0, 0.0, self.preload);
        r.apply(f, &self.upper, &self.lower, states, wrenches);
    }
}

/// `[[shear_pad]]` in a vehicle file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ShearPadFile {
    upper: String,
    lower: String,
    at: [f64; 3],
    stiffness: [f64; 3],
    #[serde(default)]
    damping: [f64; 3],
}

impl ShearPad {
    pub(crate) fn bind(f: &str, e: &ShearPadFile, b: &Binder) -> Result<Self> {
        b.non_negative(format!("{f}.stiffness"), &e.stiffness)?;
        b.non_negative(format!("{f}.damping"), &e.damping)?;
        let (upper, lower) = b.pair(f, &e.upper, &e.lower, e.at)?;
        Ok(ShearPad {
            upper,
            lower,
            stiffness: Vector3::from(e.stiffness),
            damping: Vector3::from(e.damping),
            preload: 0.0,
        })
    }
}
