//! Cross-bracing of a three-piece bogie: resists warping, the parallelogram mode in which the
//! two side frames shift along the track relative to each other. Warp angle
//! `γ = atan2(d'_x, d'_y)`, with `d'` the vector from the right to the left side frame in the
//! axes of their mean yaw; energy `½·k·γ²`, applied as the matching pair of longitudinal forces
//! and yaw torques (no net force, no net moment).

use super::{Element, ForceElement, Memory};
use crate::error::Result;
use crate::vehicle::binder::Binder;
use crate::vehicle::body::{BodyState, Wrench};
use nalgebra::Vector3;
use serde::Deserialize;

/// Cross-bracing between the left and right side frames of one bogie.
#[derive(Debug, Clone, PartialEq)]
pub struct CrossBracing {
    /// Left side frame body index.
    pub left: usize,
    /// Right side frame body index.
    pub right: usize,
    /// Warp stiffness, N·m/rad.
    pub warp_stiffness: f64,
}

fn yaw(s: &BodyState) -> f64 {
    let m = s.matrix();
    m[(1, 0)].atan2(m[(0, 0)])
}

impl CrossBracing {
    /// Warp angle, rad.
    pub fn warp(&self, states: &[BodyState]) -> f64 {
        self.geometry(states).0
    }

    fn geometry(&self, states: &[BodyState]) -> (f64, f64, Vector3<f64>) {
        let (l, r) = (&states[self.left], &states[self.right]);
        let (yl, yr) = (yaw(l), yaw(r));
        let diff = (yl - yr + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
            - std::f64::consts::PI;
        let mean = yr + 0.5 * diff;
        let (s, c) = mean.sin_cos();
        let d = l.position - r.position;
        let dx = c * d.x + s * d.y;
        let dy = -s * d.x + c * d.y;
        (crate::angle::atan2(dx, dy), dy, Vector3::new(c, s, 0.0))
    }

    fn forces(&self, states: &[BodyState], wrenches: &mut [Wrench]) {
        let (gamma, dy, ex) = self.geometry(states);
        let m = self.warp_stiffness * gamma;
        let f = ex * (m / dy.abs().max(1e-3));
        wrenches[self.left].force -= f;
        wrenches[self.right].force += f;
        wrenches[self.left].torque.z -= 0.5 * m;
        wrenches[self.right].torque.z -= 0.5 * m;
    }
}

/// `[[cross_bracing]]` in a vehicle file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CrossBracingFile {
    left: String,
    right: String,
    warp_stiffness: f64,
}

impl CrossBracing {
    fn from_row(f: &str, e: &CrossBracingFile, b: &Binder) -> Result<Self> {
        b.non_negative(format!("{f}.warp_stiffness"), &[e.warp_stiffness])?;
        Ok(CrossBracing {
            left: b.find(format!("{f}.left"), &e.left)?,
            right: b.find(format!("{f}.right"), &e.right)?,
            warp_stiffness: e.warp_stiffness,
        })
    }
}

impl ForceElement for CrossBracing {
    const TABLE: &'static str = "cross_bracing";
    type File = CrossBracingFile;
    fn bind(f: &str, e: &CrossBracingFile, b: &Binder, _: &[Element]) -> Result<Self> {
        Self::from_row(f, e, b)
    }
    #[inline]
    fn apply(&self, states: &[BodyState], _: &mut Memory, wrenches: &mut [Wrench], _: f64) {
        self.forces(states, wrenches)
    }
}
