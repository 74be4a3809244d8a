//! Lateral stop with clearance (the bolster gibs of a three-piece bogie against the side frame
//! columns): no force within ±`clearance` of the static position, beyond it a stiff spring
//! `k·(|d_y| − c)` pushing back, with damping only while in contact.

use super::{Element, ForceElement, Memory, Relative};
use crate::error::Result;
use crate::vehicle::binder::Binder;
use crate::vehicle::body::{Attachment, BodyState, Wrench};
use nalgebra::Vector3;
use serde::Deserialize;

/// Lateral stop between a bolster end (upper) and a side frame (lower).
#[derive(Debug, Clone, PartialEq)]
pub struct LateralStop {
    /// Bolster gib.
    pub upper: Attachment,
    /// Side frame column.
    pub lower: Attachment,
    /// Static offset of the lower point from the upper (`lower_at − upper_at`), m.
    pub rest: Vector3<f64>,
    /// Free play each way from the static position, m.
    pub clearance: f64,
    /// Contact stiffness, N/m.
    pub stiffness: f64,
    /// Contact damping, N·s/m.
    pub damping: f64,
}

impl LateralStop {
    /// Lateral force on the upper body (upper axes) for displacement `d` and velocity `v` of
    /// the lower attachment relative to the upper, N.
    #[inline]
    pub fn force(&self, d: f64, v: f64) -> f64 {
        let over = d.abs() - self.clearance;
        if over <= 0.0 {
            return 0.0;
        }
        // The spring pushes the lower body back toward the centre; the damper never pulls.
        let f = self.stiffness * over + self.damping * v * d.signum();
        d.signum() * f.max(0.0)
    }

    fn forces(&self, states: &[BodyState], wrenches: &mut [Wrench]) {
        let r = Relative::new(&self.upper, &self.lower, &self.rest, states);
        let fy = self.force(r.d.y, r.v.y);
        if fy != 0.0 {
            r.apply(
                Vector3::new(0.0, fy, 0.0),
                &self.upper,
                &self.lower,
                states,
                wrenches,
            );
        }
    }
}

/// `[[lateral_stop]]` in a vehicle file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LateralStopFile {
    upper: String,
    lower: String,
    /// Refused: one point for both bodies (see `Binder::pair`).
    at: Option<[f64; 3]>,
    /// Where the element meets the upper body, vehicle frame, m.
    upper_at: Option<[f64; 3]>,
    /// Where the element meets the lower body, vehicle frame, m.
    lower_at: Option<[f64; 3]>,
    clearance_m: f64,
    stiffness: f64,
    #[serde(default)]
    damping: f64,
}

impl LateralStop {
    fn from_row(f: &str, e: &LateralStopFile, b: &Binder) -> Result<Self> {
        b.non_negative(format!("{f}.clearance_m"), &[e.clearance_m])?;
        b.positive(format!("{f}.stiffness"), e.stiffness)?;
        b.non_negative(format!("{f}.damping"), &[e.damping])?;
        let (upper, lower, rest) =
            b.pair(f, (&e.upper, &e.lower), e.at, (e.upper_at, e.lower_at))?;
        Ok(LateralStop {
            upper,
            lower,
            rest,
            clearance: e.clearance_m,
            stiffness: e.stiffness,
            damping: e.damping,
        })
    }
}

impl ForceElement for LateralStop {
    const TABLE: &'static str = "lateral_stop";
    type File = LateralStopFile;
    fn bind(f: &str, e: &LateralStopFile, b: &Binder, _: &[Element]) -> Result<Self> {
        Self::from_row(f, e, b)
    }
    #[inline]
    fn apply(&self, states: &[BodyState], _: &mut Memory, wrenches: &mut [Wrench], _: f64) {
        self.forces(states, wrenches)
    }
}
