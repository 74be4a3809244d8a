//! Variable-friction wedge damper of a three-piece bogie as a friction element that sticks:
//! a Coulomb slider in series with a stick spring (elasto-plastic friction, e.g. Dahl's
//! bristle idea without its rate law), so a stuck wedge is a stiff spring, not a big damper,
//! and needs no tiny step. The friction limit follows the load of the spring nest beside it
//! (`friction_ratio` ≈ 0.08–0.1 × nest force, spec physics.md §2).
//!
//! - Column face (lateral y, vertical z of the bolster): force `k_s·(d − s) + c_s·v`, with the
//!   slider `s` moving only as far as keeps `|F| ≤ μ·N` (slip in the direction of the force).
//! - Longitudinal x: the wedges are pressed between bolster and column, a spring `k_x·d_x`.
//! - Warp (relative yaw ψ of side frame and bolster): the wedges' pressure moves across their
//!   faces, a moment `k_ψ·(ψ − ψ_s)` that slips at `warp_ratio·N` (N·m per N of nest force).

use super::{Memory, Relative};
use crate::error::Result;
use crate::vehicle::binder::Binder;
use crate::vehicle::body::{Attachment, BodyState, Wrench};
use nalgebra::{Vector2, Vector3};
use serde::Deserialize;

/// Wedge damper between a bolster end (upper) and a side frame (lower).
#[derive(Debug, Clone, PartialEq)]
pub struct WedgeDamper {
    /// Bolster end.
    pub upper: Attachment,
    /// Side frame column.
    pub lower: Attachment,
    /// Friction force over nest force.
    pub friction_ratio: f64,
    /// Stick stiffness on the column face (y and z), N/m.
    pub stick_stiffness: f64,
    /// Damping in parallel with the stick spring, N·s/m.
    pub stick_damping: f64,
    /// Longitudinal stiffness of the wedges between bolster and column, N/m.
    pub longitudinal_stiffness: f64,
    /// Warp (yaw) stick stiffness, N·m/rad.
    pub warp_stiffness: f64,
    /// Warp break-out moment over nest force, m.
    pub warp_ratio: f64,
    /// The nest whose load presses the wedge.
    pub nest: super::SpringNest,
}

/// One elasto-plastic slider step: the trial force `k·(d − s) + c·v` kept within `limit` by
/// moving the slider `s`; returns the force. Works for any dimension.
#[inline]
pub fn slider<const N: usize>(
    d: &nalgebra::SVector<f64, N>,
    v: &nalgebra::SVector<f64, N>,
    s: &mut nalgebra::SVector<f64, N>,
    k: f64,
    c: f64,
    limit: f64,
) -> nalgebra::SVector<f64, N> {
    let trial = (d - *s) * k + v * c;
    let n = trial.norm();
    if n <= limit || n == 0.0 {
        return trial;
    }
    let dir = trial / n;
    // Slip: the spring force sits on the limit (the damper's share is dropped with it).
    *s = d - dir * (limit / k);
    dir * limit
}

impl WedgeDamper {
    pub(crate) fn apply(&self, states: &[BodyState], memory: &mut Memory, wrenches: &mut [Wrench]) {
        let r = Relative::new(&self.upper, &self.lower, states);
        let normal = self.nest.vertical_force(&r);
        let mut s = Vector2::new(memory[0], memory[1]);
        let face = slider(
            &Vector2::new(r.d.y, r.d.z),
            &Vector2::new(r.v.y, r.v.z),
            &mut s,
            self.stick_stiffness,
            self.stick_damping,
            self.friction_ratio * normal,
        );
        memory[0] = s.x;
        memory[1] = s.y;
        // The lower body moving by d drags the upper along: force on the upper is +F.
        let f = Vector3::new(self.longitudinal_stiffness * r.d.x, face.x, face.y);
        r.apply(f, &self.upper, &self.lower, states, wrenches);
        if self.warp_stiffness > 0.0 {
            let rel = r.axes.transpose() * states[self.lower.body].matrix();
            let psi = rel[(1, 0)];
            let up = r.axes.column(2).into_owned();
            let rate = (states[self.lower.body].angular_velocity
                - states[self.upper.body].angular_velocity)
                .dot(&up);
            let mut sp = nalgebra::Vector1::new(memory[2]);
            let m = slider(
                &nalgebra::Vector1::new(psi),
                &nalgebra::Vector1::new(rate),
                &mut sp,
                self.warp_stiffness,
                0.0,
                self.warp_ratio * normal,
            )
            .x;
            memory[2] = sp.x;
            wrenches[self.upper.body].torque += up * m;
            wrenches[self.lower.body].torque -= up * m;
        }
    }
}

/// `[[wedge_damper]]` in a vehicle file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct WedgeDamperFile {
    pub upper: String,
    pub lower: String,
    at: [f64; 3],
    friction_ratio: f64,
    stick_stiffness: f64,
    #[serde(default)]
    stick_damping: f64,
    #[serde(default)]
    longitudinal_stiffness: f64,
    #[serde(default)]
    warp_stiffness: f64,
    #[serde(default)]
    warp_ratio_m: f64,
}

impl WedgeDamper {
    /// Binds the file's table; `nest` is the spring nest between the same two bodies.
    pub(crate) fn bind(
        f: &str,
        e: &WedgeDamperFile,
        nest: super::SpringNest,
        b: &Binder,
    ) -> Result<Self> {
        b.non_negative(format!("{f}.friction_ratio"), &[e.friction_ratio])?;
        b.positive(format!("{f}.stick_stiffness"), e.stick_stiffness)?;
        b.non_negative(
            format!("{f}.stick_damping"),
            &[e.stick_damping, e.longitudinal_stiffness],
        )?;
        b.non_negative(
            format!("{f}.warp_stiffness"),
            &[e.warp_stiffness, e.warp_ratio_m],
        )?;
        let (upper, lower) = b.pair(f, &e.upper, &e.lower, e.at)?;
        Ok(WedgeDamper {
            upper,
            lower,
            friction_ratio: e.friction_ratio,
            stick_stiffness: e.stick_stiffness,
            stick_damping: e.stick_damping,
            longitudinal_stiffness: e.longitudinal_stiffness,
            warp_stiffness: e.warp_stiffness,
            warp_ratio: e.warp_ratio_m,
            nest,
        })
    }
}
