//! One run as a user asks for it (`railforce simulate`, and `railforce.simulate` in Python):
//! speed, duration, settling and stepping, checked before any work and turned into the
//! simulation's configuration. One place, so both front ends refuse the same values with the
//! same words.

use super::{SimConfig, Stepping};
use crate::error::{Error, Result};

/// What a user asks of one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunRequest {
    /// Running speed, km/h, in (0, 200].
    pub speed_kmh: f64,
    /// Recorded duration after settling, s (positive).
    pub duration: f64,
    /// Settling time before recording, s (not recorded; ≥ 0).
    pub settle: f64,
    /// Integrator and step.
    pub stepping: Stepping,
    /// Stop with an error at a derailment (else report it and run on).
    pub stop_on_derailment: bool,
}

impl Default for RunRequest {
    /// `railforce simulate`'s defaults: 60 km/h, 60 s after 3 s of settling, the default
    /// stepping, stop at a derailment.
    fn default() -> Self {
        RunRequest {
            speed_kmh: 60.0,
            duration: 60.0,
            settle: 3.0,
            stepping: Stepping::default(),
            stop_on_derailment: true,
        }
    }
}

impl RunRequest {
    /// The simulation's configuration, or an error naming the value out of its range.
    pub fn config(&self) -> Result<SimConfig> {
        if !(self.duration > 0.0 && self.duration.is_finite()) {
            return Err(Error::Domain(format!(
                "the duration must be positive, got {} s",
                self.duration
            )));
        }
        if !(self.speed_kmh > 0.0 && self.speed_kmh <= 200.0) {
            return Err(Error::Domain(format!(
                "the speed must lie in (0, 200] km/h, got {}",
                self.speed_kmh
            )));
        }
        if !(self.settle >= 0.0 && self.settle.is_finite()) {
            return Err(Error::Domain(format!(
                "the settling time must not be negative, got {} s",
                self.settle
            )));
        }
        let dt = self.stepping.dt;
        if !(dt > 0.0 && dt <= 1e-3) {
            return Err(Error::Domain(format!(
                "integration step {dt} s: it must be in (0, 1 ms]"
            )));
        }
        Ok(SimConfig {
            speed: self.speed_kmh / 3.6,
            duration: self.duration,
            settle: self.settle,
            dt,
            integrator: self.stepping.integrator,
            stop_on_derailment: self.stop_on_derailment,
            ..SimConfig::default()
        })
    }
}
