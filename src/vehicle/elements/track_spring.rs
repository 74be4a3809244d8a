//! Spring from a body to the track: lateral and yaw restraint relative to the local track
//! frame, as used by Wickens' single restrained wheelset (a wheelset held by springs to a
//! frame that runs exactly along the track). Not part of a real wagon.

use super::{Element, ForceElement, Memory};
use crate::error::Result;
use crate::vehicle::binder::Binder;
use crate::vehicle::body::{BodyState, Wrench};
use nalgebra::Matrix3;
use serde::Deserialize;

/// Lateral and yaw spring between a body and the track frame at its position.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackSpring {
    /// Body index.
    pub body: usize,
    /// Lateral stiffness, N/m.
    pub lateral_stiffness: f64,
    /// Yaw stiffness, N·m/rad.
    pub yaw_stiffness: f64,
}

impl TrackSpring {
    /// Adds the restoring force and torque; `origin` and `axes` are the track frame at the
    /// body.
    pub(crate) fn restore(
        &self,
        states: &[BodyState],
        origin: &nalgebra::Vector3<f64>,
        axes: &Matrix3<f64>,
        wrenches: &mut [Wrench],
    ) {
        let st = &states[self.body];
        let rel = axes.transpose() * (st.position - origin);
        let axle = axes.transpose() * st.matrix().column(1);
        let yaw = crate::angle::atan2(-axle.x, axle.y);
        let lateral = axes.column(1).into_owned();
        let up = axes.column(2).into_owned();
        wrenches[self.body].force -= lateral * (self.lateral_stiffness * rel.y);
        wrenches[self.body].torque -= up * (self.yaw_stiffness * yaw);
    }
}

/// `[[track_spring]]` in a vehicle file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TrackSpringFile {
    link: String,
    lateral_stiffness: f64,
    yaw_stiffness: f64,
}

impl TrackSpring {
    fn from_row(f: &str, e: &TrackSpringFile, b: &Binder) -> Result<Self> {
        b.non_negative(format!("{f}.lateral_stiffness"), &[e.lateral_stiffness])?;
        b.non_negative(format!("{f}.yaw_stiffness"), &[e.yaw_stiffness])?;
        Ok(TrackSpring {
            body: b.find(format!("{f}.link"), &e.link)?,
            lateral_stiffness: e.lateral_stiffness,
            yaw_stiffness: e.yaw_stiffness,
        })
    }
}

impl ForceElement for TrackSpring {
    const TABLE: &'static str = "track_spring";
    type File = TrackSpringFile;
    fn bind(f: &str, e: &TrackSpringFile, b: &Binder, _: &[Element]) -> Result<Self> {
        Self::from_row(f, e, b)
    }
    /// Needs the track frame: the simulation applies it ([`TrackSpring::restore`]).
    fn apply(&self, _: &[BodyState], _: &mut Memory, _: &mut [Wrench], _: f64) {}
}
