//! Centre plate: stiff in translation, with a yaw friction torque that sticks: the plate's
//! tangential stiffness spread over its disc resists twist with `k_x·R²/2` (the disc's polar
//! moment), in series with a Coulomb slider that slips at `μ·N·(2/3)·R` (a flat circular plate
//! of radius R under uniform pressure), an elasto-plastic element like the wedges' (so a stuck
//! bogie turns with the carbody instead of being damped to it). The flat
//! plate also resists rocking (roll and pitch of the bolster under the carbody): its vertical
//! stiffness spread over the disc gives `k_z·R²/4` per axis, up to the moment `N·R` at which
//! the plate lifts at its edge. Without it a bolster loaded through a point above its centre of
//! gravity and supported below it is an inverted pendulum.

use super::{Element, ForceElement, Memory, Relative, Support, slider};
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
    /// Static offset of the lower point from the upper (`lower_at − upper_at`), m.
    pub rest: Vector3<f64>,
    /// Translational stiffness (x, y, z), N/m.
    pub stiffness: Vector3<f64>,
    /// Translational damping, N·s/m.
    pub damping: Vector3<f64>,
    /// Friction coefficient.
    pub friction: f64,
    /// Plate radius, m.
    pub radius: f64,
    /// Static vertical load, N.
    pub preload: f64,
}

impl CentrePlate {
    /// Yaw stiffness of the stuck plate, `k_x·R²/2`, N·m/rad.
    pub fn twist_stiffness(&self) -> f64 {
        self.stiffness.x * self.radius * self.radius / 2.0
    }

    /// Yaw moment at which the plate slips, `μ·N·(2/3)·R`, N·m, for the vertical load `normal`.
    pub fn slip_moment(&self, normal: f64) -> f64 {
        self.friction * normal * (2.0 / 3.0) * self.radius
    }

    fn forces(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench], dt: f64) {
        let r = Relative::new(&self.upper, &self.lower, &self.rest, states);
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
        // The vertical damping spread over the disc like the stiffness: c_z·R²/4.
        let w_rel = r.axes.transpose()
            * (states[self.lower.body].angular_velocity - states[self.upper.body].angular_velocity);
        let (k_tilt, c_tilt) = (
            self.stiffness.z * self.radius * self.radius / 4.0,
            self.damping.z * self.radius * self.radius / 4.0,
        );
        let cap = normal * self.radius;
        let m = Vector3::new(
            (k_tilt * roll + c_tilt * w_rel.x).clamp(-cap, cap),
            (k_tilt * pitch + c_tilt * w_rel.y).clamp(-cap, cap),
            0.0,
        );
        let m_world = r.axes * m;
        wrenches[self.upper.body].torque += m_world;
        wrenches[self.lower.body].torque -= m_world;
        let up = r.axes.column(2).into_owned();
        let rel_yaw_rate = (states[self.lower.body].angular_velocity
            - states[self.upper.body].angular_velocity)
            .dot(&up);
        let mut sp = nalgebra::Vector1::new(memory[0]);
        // The lower body turning by ψ drags the upper along: the torque on the upper is +M.
        let torque = slider(
            &nalgebra::Vector1::new(rel[(1, 0)]),
            &nalgebra::Vector1::new(rel_yaw_rate),
            &mut sp,
            self.twist_stiffness(),
            0.0,
            self.slip_moment(normal),
            dt,
        )
        .x;
        memory[0] = sp.x;
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
    /// Refused: one point for both bodies (see `Binder::pair`).
    at: Option<[f64; 3]>,
    /// Where the element meets the upper body, vehicle frame, m.
    upper_at: Option<[f64; 3]>,
    /// Where the element meets the lower body, vehicle frame, m.
    lower_at: Option<[f64; 3]>,
    stiffness: [f64; 3],
    #[serde(default)]
    damping: [f64; 3],
    friction: f64,
    radius_m: f64,
}

impl CentrePlate {
    fn from_row(f: &str, e: &CentrePlateFile, b: &Binder) -> Result<Self> {
        b.non_negative(format!("{f}.stiffness"), &e.stiffness)?;
        b.non_negative(format!("{f}.damping"), &e.damping)?;
        b.non_negative(format!("{f}.friction"), &[e.friction])?;
        b.positive(format!("{f}.radius_m"), e.radius_m)?;
        let (upper, lower, rest) =
            b.pair(f, (&e.upper, &e.lower), e.at, (e.upper_at, e.lower_at))?;
        Ok(CentrePlate {
            upper,
            lower,
            rest,
            stiffness: Vector3::from(e.stiffness),
            damping: Vector3::from(e.damping),
            friction: e.friction,
            radius: e.radius_m,
            preload: 0.0,
        })
    }
}

impl ForceElement for CentrePlate {
    const TABLE: &'static str = "centre_plate";
    type File = CentrePlateFile;
    fn bind(f: &str, e: &CentrePlateFile, b: &Binder, _: &[Element]) -> Result<Self> {
        Self::from_row(f, e, b)
    }
    #[inline]
    fn apply(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench], dt: f64) {
        self.forces(states, memory, wrenches, dt)
    }
    fn attachments(&self) -> Option<(&Attachment, &Attachment, &Vector3<f64>)> {
        Some((&self.upper, &self.lower, &self.rest))
    }
    fn static_deflection(&self) -> Vector3<f64> {
        super::static_compression(self.preload, self.stiffness.z)
    }
    fn gauge_stem(&self, _: &str, lower: &str, _: &str) -> Option<String> {
        Some(format!("centreplate_{lower}"))
    }
    fn gauge_axes(&self) -> &'static [usize] {
        &[2]
    }
    fn support(&self) -> Option<Support> {
        Some(Support::Shared {
            upper: self.upper,
            lower: self.lower.body,
        })
    }
    fn take_share(&mut self, share: f64) {
        self.preload = share;
    }
    fn frictionless(&mut self) {
        self.friction = 0.0;
    }
}
