//! Centre plate: stiff in translation, with a yaw friction torque `μ·N·(2/3)·R` (a flat
//! circular plate of radius R under uniform pressure), smoothed by `tanh(ω/ω_ref)`. The flat
//! plate also resists rocking (roll and pitch of the bolster under the carbody): its vertical
//! stiffness spread over the disc gives `k_z·R²/4` per axis, up to the moment `N·R` at which
//! the plate lifts at its edge. Without it a bolster loaded through a point above its centre of
//! gravity and supported below it is an inverted pendulum.

use super::Relative;
use crate::error::Result;
use crate::vehicle::binder::Binder;
use crate::vehicle::body::{Attachment, BodyState, Wrench};
use nalgebra::Vector3;
use serde::Deserialize;

/// Centre plate between the carbody (upper) and a bolster (lower).
#[derive(Debug, Clone, PartialEq)]
pub struct CentrePlate {
    /// Carbody centre pivot.
    pub upper: Attachment,
    /// Bolster centre bowl.
    pub lower: Attachment,
    /// Translational stiffness (x, y, z), N/m.
    pub stiffness: Vector3<f64>,
    /// Translational damping, N·s/m.
    pub damping: Vector3<f64>,
    /// Friction coefficient.
    pub friction: f64,
    /// Plate radius, m.
    pub radius: f64,
    /// Regularisation yaw rate, rad/s.
    pub regularisation_rate: f64,
    /// Static vertical load, N.
    pub preload: f64,
}

impl CentrePlate {
    pub(crate) fn apply(&self, states: &[BodyState], wrenches: &mut [Wrench]) {
        let r = Relative::new(&self.upper, &self.lower, states);
        let mut f = self.stiffness.component_mul(&r.d) + self.damping.component_mul(&r.v);
        f.z += self.preload;
        let normal = f.z.max(0.0);
        if f.z < 0.0 {
            // The plate lifts: it cannot pull.
            f = Vector3::zeros();
        }
        r.apply(f, &self.upper, &self.lower, states, wrenches);
        // Rocking: relative roll and pitch of the lower body in the upper's axes.
        let rel = r.axes.transpose() * states[self.lower.body].matrix();
        let (roll, pitch) = (rel[(2, 1)], -rel[(2, 0)]);
        let k_tilt = self.stiffness.z * self.radius * self.radius / 4.0;
        let cap = normal * self.radius;
        let m = Vector3::new(
            (k_tilt * roll).clamp(-cap, cap),
            (k_tilt * pitch).clamp(-cap, cap),
            0.0,
        );
        let m_world = r.axes * m;
        wrenches[self.upper.body].torque += m_world;
        wrenches[self.lower.body].torque -= m_world;
        let up = r.axes.column(2).into_owned();
        let rel_yaw_rate = (states[self.lower.body].angular_velocity
            - states[self.upper.body].angular_velocity)
            .dot(&up);
        let torque = self.friction
            * normal
            * (2.0 / 3.0)
            * self.radius
            * (rel_yaw_rate / self.regularisation_rate).tanh();
        wrenches[self.upper.body].torque += up * torque;
        wrenches[self.lower.body].torque -= up * torque;
    }
}

/// `[[centre_plate]]` in a vehicle file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CentrePlateFile {
    upper: String,
    lower: String,
    at: [f64; 3],
    stiffness: [f64; 3],
    #[serde(default)]
    damping: [f64; 3],
    friction: f64,
    radius_m: f64,
    regularisation_rate: f64,
}

impl CentrePlate {
    pub(crate) fn bind(f: &str, e: &CentrePlateFile, b: &Binder) -> Result<Self> {
        b.non_negative(format!("{f}.stiffness"), &e.stiffness)?;
        b.non_negative(format!("{f}.damping"), &e.damping)?;
        b.non_negative(format!("{f}.friction"), &[e.friction])?;
        b.positive(format!("{f}.radius_m"), e.radius_m)?;
        b.positive(format!("{f}.regularisation_rate"), e.regularisation_rate)?;
        let (upper, lower) = b.pair(f, &e.upper, &e.lower, e.at)?;
        Ok(CentrePlate {
            upper,
            lower,
            stiffness: Vector3::from(e.stiffness),
            damping: Vector3::from(e.damping),
            friction: e.friction,
            radius: e.radius_m,
            regularisation_rate: e.regularisation_rate,
            preload: 0.0,
        })
    }
}
