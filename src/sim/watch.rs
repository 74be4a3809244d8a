//! The run's watch, every step: a non-finite state (before anything looks the track up with
//! it), runaway motion, chatter and derailment end the run with the time, the body or wheel
//! and why.
//!
//! Chatter is a mode stiffer than the step follows, oscillating from step to step while the
//! state stays bounded: the wheel loads then jump by many times their static load from one
//! step to the next. The C80 with its pads 20 % stiffer than the step takes chatters at
//! 1.2 MN rms (ten static loads) from the start; a sound run's wheel loads change by about
//! 20 kN rms from step to step (R 400 m at 100 km/h, class 5: the wheel–rail mode, far above
//! the recorded band). Between lie runs whose contact outruns the step in bursts: a
//! three-quarter-loaded C80 hunting at 100 km/h on class-4 track, |Y/Q| peaking at 2.5,
//! 154–289 kN (1.6–3 static loads) while flanges strike; pads 15 % stiffer, 266 kN. An rms
//! step-to-step change over a second above four static wheel loads, and above 100 kN, ends
//! the run: that is gross chatter. The bursts below it are not caught here; the shipped fleet
//! and estimates keep the pads where the step holds them (physics.md §2).

/// Window of the chatter check, s.
const CHATTER_WINDOW: f64 = 1.0;
/// Largest rms step-to-step change of a wheel load over the window, in static wheel loads,
/// and never below [`CHATTER_FLOOR`].
const CHATTER_LIMIT: f64 = 4.0;
/// Smallest chatter limit, N (light vehicles' loads swing by more than their whole load when
/// they hunt).
const CHATTER_FLOOR: f64 = 100e3;
/// A wheel off its rail with less lateral shift than this has jumped, not climbed its flange
/// (the flange meets the rail beyond the flangeway, about 8 mm from centred), m.
const JUMP_SHIFT: f64 = 4e-3;

use super::{Simulation, wheel_name};
use crate::error::{Error, Result};

impl Simulation<'_> {
    /// Non-finite states, runaway motion, derailment.
    pub(super) fn check(&mut self) -> Result<()> {
        self.step_count += 1;
        // A non-finite state, every step and before anything looks the track up with it: a
        // NaN position must end the run with its name, not reach a grid lookup. One sum
        // carries any NaN or infinity of the state (inf − inf is NaN too).
        let sum: f64 = self
            .states
            .iter()
            .map(|st| {
                st.position.sum()
                    + st.velocity.sum()
                    + st.angular_velocity.sum()
                    + st.rotation.coords.sum()
            })
            .sum();
        if !sum.is_finite() {
            for (i, st) in self.states.iter().enumerate() {
                let finite = st.position.iter().all(|v| v.is_finite())
                    && st.velocity.iter().all(|v| v.is_finite())
                    && st.angular_velocity.iter().all(|v| v.is_finite())
                    && st.rotation.coords.iter().all(|v| v.is_finite());
                if !finite {
                    return Err(Error::Domain(format!(
                        "simulation diverged at t = {:.4} s: body '{}' has a non-finite state",
                        self.time, self.vehicle.bodies[i].name
                    )));
                }
            }
            return Err(Error::Domain(format!(
                "simulation diverged at t = {:.4} s: the state grew beyond floating point",
                self.time
            )));
        }
        // Whole-state checks every 100 steps (10 ms at the default step); wheels every step.
        let full = self.step_count.is_multiple_of(100);
        if full {
            self.refresh_frames();
        }
        for (i, st) in self.states.iter().enumerate().filter(|_| full) {
            let rel_v = st.velocity - self.frames[i].axes.column(0) * self.cfg.speed;
            let name = &self.vehicle.bodies[i].name;
            if rel_v.norm() > self.cfg.runaway_speed {
                return Err(Error::Domain(format!(
                    "simulation diverged at t = {:.4} s: body '{name}' moves {:.1} m/s away from the running motion (runaway energy)",
                    self.time,
                    rel_v.norm()
                )));
            }
        }
        // Chatter: each wheel's step-to-step load change, its rms over each window.
        let window = (CHATTER_WINDOW / self.cfg.dt).round().max(1.0) as u64;
        for (k, w) in self.wheels.iter().enumerate() {
            let (last, sum) = &mut self.chatter[k];
            *sum += (w.q - *last).powi(2);
            *last = w.q;
        }
        if self.step_count.is_multiple_of(window) {
            for k in 0..self.chatter.len() {
                let rms = (self.chatter[k].1 / window as f64).sqrt();
                self.chatter[k].1 = 0.0;
                if rms > (CHATTER_LIMIT * self.static_load).max(CHATTER_FLOOR) {
                    return Err(Error::Domain(format!(
                        "simulation diverged at t = {:.3} s: wheel {}'s load jumped by {:.1} kN rms from step to step over the last {CHATTER_WINDOW} s (more than four times its static {:.1} kN, and more than 100 kN): a mode stiffer than the {:.3} ms step chatters (a stiffer element, a rubber with more loss, or a longer step than the vehicle takes)",
                        self.time,
                        wheel_name(k),
                        rms / 1e3,
                        self.static_load / 1e3,
                        self.cfg.dt * 1e3
                    )));
                }
            }
        }
        let limit = self.nadal_limit;
        let flange = self.flange_height;
        for k in 0..self.wheels.len() {
            let w = &self.wheels[k];
            let name = || wheel_name(k);
            // Climb: how far the wheel has risen on its flange (contact radius above the tape
            // circle) plus any gap; derailed at 90 % of the flange height (the tip is rounded).
            let off =
                w.climb > self.cfg.climb_limit * flange || w.y_rel.abs() > self.cfg.lateral_limit;
            let first = off && !self.off_rail[k];
            self.off_rail[k] = off;
            if off && (first || self.cfg.stop_on_derailment) {
                let mut msg = format!(
                    "derailment at t = {:.3} s, s = {:.1} m: wheel {} climbed {:.1} mm of its {:.1} mm flange (lateral shift {:.1} mm relative to its rail)",
                    self.time,
                    w.s,
                    name(),
                    w.climb * 1e3,
                    flange * 1e3,
                    w.y_rel * 1e3
                );
                // Risen off the rail without moving onto the flange: a jump, not a climb. A
                // step too coarse for a stiff coupling bursts this way (the loaded C80 stepped
                // at 1 ms past the step guard, its side frames' pitch on the pads growing:
                // 26.7 mm up, 0.7 mm across, within 0.04 s).
                if w.lift > 0.5 * w.climb && w.y_rel.abs() < JUMP_SHIFT {
                    msg += &format!(
                        ": it rose {:.1} mm off the rail without moving onto its flange, a jump; a step too coarse for a stiff coupling (the wheel–rail contact, the pads) bursts this way ({:.4} ms here: try a finer --dt)",
                        w.lift * 1e3,
                        self.cfg.dt * 1e3
                    );
                }
                if self.cfg.stop_on_derailment {
                    return Err(Error::Derailment(msg));
                }
                eprintln!(
                    "warning: {msg}; the run goes on (warned again only after the wheel is back on its rail)"
                );
            }
            if w.q > 1.0 && (w.y / w.q).abs() > limit {
                self.over_nadal[k] += self.cfg.dt;
            } else {
                self.over_nadal[k] = 0.0;
            }
            if self.over_nadal[k] > self.cfg.nadal_time {
                let msg = format!(
                    "derailment risk at t = {:.3} s, s = {:.1} m: wheel {} has |Y/Q| above the Nadal limit {limit:.3} for more than {:.0} ms",
                    self.time,
                    w.s,
                    name(),
                    self.cfg.nadal_time * 1e3
                );
                if self.cfg.stop_on_derailment && self.cfg.stop_on_derailment_risk {
                    return Err(Error::Derailment(msg));
                }
                eprintln!("warning: {msg}; the run goes on");
                self.over_nadal[k] = f64::NEG_INFINITY;
            }
        }
        Ok(())
    }
}
