//! The driver: holds a target speed by notches, or follows a schedule of commands.
//!
//! Holding: a PI controller on the train's speed gives a control `u ∈ [−1, 1]` (positive: a
//! share of full traction; negative: a share of full dynamic brake), quantised to the handle's
//! notches with a quarter-notch hysteresis and at most one notch change per `notch_interval`
//! (a handle moved by hand, not a servo). With no notches (`traction_notches = 0`) the handle
//! is stepless and the control is the PI's output itself. All locomotives take the same notch
//! (distributed power in synchronous mode). When the control sits at its limit and the speed
//! still misses the target by more than the tolerance, the locomotives cannot hold it: the
//! train runs as physics lets it and the driver counts the time ([`Driver::not_held_s`]).
//!
//! The schedule is a list of timed commands: a fixed notch, holding a speed, an air-brake
//! application (a share of full service), an emergency application, a release.

/// A driver's command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Command {
    /// Hold a fixed notch (positive traction, negative dynamic brake, 0 idle); stops holding
    /// a speed.
    Notch(i32),
    /// Hold this speed, m/s, by notches.
    Hold(f64),
    /// A service air-brake application: this share of a full service, in (0, 1].
    AirBrake(f64),
    /// An emergency application.
    Emergency,
    /// Release the air brake.
    Release,
}

/// A command at a time of the run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScheduleEntry {
    /// Time from the start of the run, s.
    pub time: f64,
    /// What the driver does then.
    pub command: Command,
}

/// The driver's settings (the consist file's `[driver]` table), SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct DriverSettings {
    /// Traction notches of the handle (0: stepless).
    pub traction_notches: u32,
    /// Dynamic-brake notches of the handle (0: stepless).
    pub brake_notches: u32,
    /// Proportional gain, control per m/s of speed error.
    pub proportional: f64,
    /// Integral gain, control per m of integrated speed error.
    pub integral: f64,
    /// Shortest time between two notch changes, s.
    pub notch_interval: f64,
    /// Speed error beyond which a saturated control means the speed is not held, m/s.
    pub tolerance: f64,
    /// Timed commands, times ascending.
    pub schedule: Vec<ScheduleEntry>,
    /// Cyclic air braking while holding a speed on a descent (None: the dynamic brake only).
    pub cyclic: Option<CyclicBraking>,
}

/// Cyclic air braking, as heavy-haul drivers hold a speed down a long grade the dynamic brake
/// alone cannot hold: with the dynamic brake at its full notch and the train running
/// `apply_above` faster than the speed held, a service application of `level`; deeper by
/// `level` again every [`CyclicBraking::DEEPEN_AFTER`] seconds while the train still gains
/// speed above that, up to a full service; released when the train has slowed to
/// `release_below` under the speed held, and again on the next rise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CyclicBraking {
    /// Speed above the held one at which the driver applies the air brake, m/s.
    pub apply_above: f64,
    /// Speed below the held one at which the driver releases it, m/s.
    pub release_below: f64,
    /// Share of a full service the application makes, in (0, 1].
    pub level: f64,
}

impl CyclicBraking {
    /// Seconds between deepening steps of an application that does not slow the train (the
    /// brake cylinders take seconds to fill: an estimate of a driver's patience).
    pub const DEEPEN_AFTER: f64 = 10.0;
}

/// Quarter-notch hysteresis of the quantiser: the notch moves when the controller asks for
/// more than 0.75 notch away from it.
const HYSTERESIS: f64 = 0.25;

/// The driver's state.
#[derive(Debug, Clone)]
pub struct Driver {
    settings: DriverSettings,
    /// Target speed when holding, m/s.
    target: Option<f64>,
    integral: f64,
    notch: i32,
    control: f64,
    last_change: f64,
    next_entry: usize,
    not_held_s: f64,
    not_held: bool,
    /// Whether the cyclic braking has the air brake applied, at which level, since when, and
    /// at what speed.
    air_on: bool,
    air_level: f64,
    air_since: f64,
    air_speed: f64,
    /// Cyclic applications made.
    applications: u32,
}

impl Driver {
    /// A driver holding `target` m/s whose control already is `u0` (the steady state's).
    pub fn new(settings: DriverSettings, target: f64, u0: f64) -> Self {
        let mut d = Driver {
            settings,
            target: Some(target),
            integral: u0.clamp(-1.0, 1.0),
            notch: 0,
            control: 0.0,
            last_change: f64::NEG_INFINITY,
            next_entry: 0,
            not_held_s: 0.0,
            not_held: false,
            air_on: false,
            air_level: 0.0,
            air_since: 0.0,
            air_speed: 0.0,
            applications: 0,
        };
        d.notch = d.nearest_notch(u0);
        d.control = d.quantised(u0);
        d
    }

    fn stepless(&self) -> bool {
        self.settings.traction_notches == 0 || self.settings.brake_notches == 0
    }

    /// The control as a real notch position (traction notches above 0, brake notches below).
    fn notch_of(&self, u: f64) -> f64 {
        if u >= 0.0 {
            u * self.settings.traction_notches as f64
        } else {
            u * self.settings.brake_notches as f64
        }
    }

    fn nearest_notch(&self, u: f64) -> i32 {
        self.notch_of(u.clamp(-1.0, 1.0)).round() as i32
    }

    fn control_of(&self, n: i32) -> f64 {
        if n >= 0 {
            n as f64 / self.settings.traction_notches.max(1) as f64
        } else {
            n as f64 / self.settings.brake_notches.max(1) as f64
        }
    }

    fn quantised(&self, u: f64) -> f64 {
        if self.stepless() {
            u.clamp(-1.0, 1.0)
        } else {
            self.control_of(self.nearest_notch(u))
        }
    }

    /// The control applied now, in [−1, 1].
    pub fn control(&self) -> f64 {
        self.control
    }

    /// The notch now (0 for a stepless handle).
    pub fn notch(&self) -> i32 {
        if self.stepless() { 0 } else { self.notch }
    }

    /// The speed held, m/s, or `None` on a fixed notch.
    pub fn target(&self) -> Option<f64> {
        self.target
    }

    /// Total time the target speed was not held, s.
    pub fn not_held_s(&self) -> f64 {
        self.not_held_s
    }

    /// Cyclic air-brake applications made so far.
    pub fn applications(&self) -> u32 {
        self.applications
    }

    /// Whether the target speed is not held now (control saturated, error beyond tolerance).
    pub fn not_held(&self) -> bool {
        self.not_held
    }

    /// Applies a notch or hold command; returns air-brake commands for the brake to carry out.
    pub fn apply(&mut self, c: Command) -> Option<Command> {
        match c {
            Command::Notch(n) => {
                self.target = None;
                let n = n.clamp(
                    -(self.settings.brake_notches as i32),
                    self.settings.traction_notches as i32,
                );
                self.notch = n;
                self.control = self.control_of(n);
                self.integral = self.control;
                None
            }
            Command::Hold(v) => {
                self.target = Some(v);
                self.integral = self.control;
                None
            }
            air => Some(air),
        }
    }

    /// One step of length `dt` starting at time `t`, the train moving at `v` m/s: takes the
    /// schedule's commands due by `t` (the air-brake ones are handed to `air`) and updates the
    /// control.
    pub fn update(&mut self, t: f64, dt: f64, v: f64, air: &mut dyn FnMut(Command)) {
        while let Some(e) = self.settings.schedule.get(self.next_entry).copied() {
            if e.time > t {
                break;
            }
            self.next_entry += 1;
            if let Some(a) = self.apply(e.command) {
                air(a);
            }
        }
        let Some(target) = self.target else {
            self.not_held = false;
            return;
        };
        let s = &self.settings;
        let e = target - v;
        let p = s.proportional * e;
        // Conditional integration: the integral does not wind up against a saturated control.
        let raw = p + self.integral;
        if !((raw >= 1.0 && e > 0.0) || (raw <= -1.0 && e < 0.0)) {
            self.integral = (self.integral + s.integral * e * dt).clamp(-1.0, 1.0);
        }
        let u = (p + self.integral).clamp(-1.0, 1.0);
        if self.stepless() {
            self.control = u;
        } else {
            let want = self.notch_of(u);
            let gap = want - self.notch as f64;
            if gap.abs() > 0.5 + HYSTERESIS && t - self.last_change >= s.notch_interval {
                self.notch += gap.signum() as i32;
                self.last_change = t;
                self.control = self.control_of(self.notch);
            }
        }
        if let Some(cy) = s.cyclic {
            if !self.air_on && self.control <= -1.0 && v > target + cy.apply_above {
                air(Command::AirBrake(cy.level));
                (self.air_on, self.air_level) = (true, cy.level);
                (self.air_since, self.air_speed) = (t, v);
                self.applications += 1;
            } else if self.air_on
                && self.air_level < 1.0
                && t - self.air_since >= CyclicBraking::DEEPEN_AFTER
                && v > target + cy.apply_above
                && v >= self.air_speed
            {
                // Still gaining speed: deeper.
                self.air_level = (self.air_level + cy.level).min(1.0);
                air(Command::AirBrake(self.air_level));
                (self.air_since, self.air_speed) = (t, v);
            } else if self.air_on && v < target - cy.release_below {
                air(Command::Release);
                self.air_on = false;
            }
        }
        let saturated = (e > 0.0 && self.control >= 1.0) || (e < 0.0 && self.control <= -1.0);
        self.not_held = saturated && e.abs() > s.tolerance;
        if self.not_held {
            self.not_held_s += dt;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(notches: u32) -> DriverSettings {
        DriverSettings {
            traction_notches: notches,
            brake_notches: notches,
            proportional: 1.0,
            integral: 0.02,
            notch_interval: 1.0,
            tolerance: 0.5,
            cyclic: None,
            schedule: vec![
                ScheduleEntry {
                    time: 1.0,
                    command: Command::AirBrake(0.5),
                },
                ScheduleEntry {
                    time: 2.0,
                    command: Command::Notch(-3),
                },
            ],
        }
    }

    #[test]
    fn notches_quantise_and_move_one_at_a_time() {
        let mut d = Driver::new(settings(12), 20.0, 0.3);
        assert_eq!(d.notch(), 4);
        assert!((d.control() - 4.0 / 12.0).abs() < 1e-12);
        // far too slow: full traction wanted, reached one notch per second
        let mut air = Vec::new();
        let dt = 0.01;
        let mut t = 0.0;
        for _ in 0..50 {
            t += dt;
            d.update(t, dt, 10.0, &mut |c| air.push(c));
        }
        assert_eq!(d.notch(), 5);
        assert_eq!(air, vec![]);
        for _ in 0..60 {
            t += dt;
            d.update(t, dt, 10.0, &mut |c| air.push(c));
        }
        assert_eq!(air, vec![Command::AirBrake(0.5)]);
        assert_eq!(d.notch(), 6);
        for _ in 0..100 {
            t += dt;
            d.update(t, dt, 10.0, &mut |c| air.push(c));
        }
        // the schedule's fixed notch ended the holding
        assert_eq!(d.target(), None);
        assert_eq!(d.notch(), -3);
        assert!((d.control() + 0.25).abs() < 1e-12);
    }

    #[test]
    fn saturation_with_a_speed_error_is_not_held() {
        let mut s = settings(0);
        s.schedule.clear();
        let mut d = Driver::new(s, 20.0, 1.0);
        let dt = 0.1;
        for k in 1..=100 {
            d.update(k as f64 * dt, dt, 18.0, &mut |_| {});
        }
        assert!(d.not_held());
        assert!((d.not_held_s() - 10.0).abs() < 1e-9);
        assert_eq!(d.control(), 1.0);
        d.update(10.1, dt, 20.0, &mut |_| {});
        assert!(!d.not_held());
    }
}
