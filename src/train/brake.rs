//! The automatic air brake: a brake-pipe signal travelling along the train, each car's brake
//! cylinder following it, and the shoes' friction on the treads.
//!
//! An empirical model in the sense of Wu et al., "Freight train air brake models", Int. J. Rail
//! Transp. 11(1):1–49, 2023: the driver's command (a share of a full-service application, an
//! emergency, a release) starts at the head and, with distributed power, at each remote
//! locomotive after a radio delay; it reaches a car after the pipe's propagation time to it
//! plus the valve's delay; from then the car's shoe force moves to its target with a first-order
//! lag. A car's shoe force at a full-service application is a file value; an emergency
//! application reaches `emergency_ratio` times it. The shoes' friction coefficient is a table
//! against speed. Numbers and their sources are in the consist file; the propagation speed,
//! delays and time constants are estimates.

use super::resistance::STOP_SPEED;
use super::smooth_sign;

/// The air brake's settings (the consist file's `[brake]` table), SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct AirBrake {
    /// Propagation speed of the brake-pipe signal, m/s.
    pub pipe_speed: f64,
    /// Delay of a car's valve after the signal reaches it, s.
    pub valve_delay: f64,
    /// Time constant of a service application's shoe force, s.
    pub apply_time_constant: f64,
    /// Time constant of an emergency application's shoe force, s.
    pub emergency_time_constant: f64,
    /// Time constant of a release, s.
    pub release_time_constant: f64,
    /// Shoe force of an emergency application over that of a full service one.
    pub emergency_ratio: f64,
    /// Whether the command also starts at every locomotive but the head (distributed power
    /// by radio); false: from the head only.
    pub distributed: bool,
    /// Delay of the remote locomotives' brake-pipe reduction after the head's, s.
    pub radio_delay: f64,
    /// Shoe friction coefficient against speed: (m/s, μ), speeds ascending; clamped at both
    /// ends, linear between.
    pub friction: Vec<(f64, f64)>,
}

/// The brake shoes on one vehicle's treads: what the 3-D wagon's wheels receive.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ShoeBrake {
    /// Total normal force of all the vehicle's shoes on their treads, N.
    pub normal_force: f64,
    /// Shoe–tread friction coefficient at the vehicle's speed.
    pub friction: f64,
}

impl AirBrake {
    /// The shoes' friction coefficient at speed `v` (m/s, magnitude used).
    pub fn friction_at(&self, v: f64) -> f64 {
        let v = v.abs();
        let t = &self.friction;
        if v <= t[0].0 {
            return t[0].1;
        }
        for w in t.windows(2) {
            let ((v0, m0), (v1, m1)) = (w[0], w[1]);
            if v <= v1 {
                return m0 + (m1 - m0) * (v - v0) / (v1 - v0);
            }
        }
        t[t.len() - 1].1
    }

    /// The brake force along +s of shoes pressing with `normal` N on a vehicle moving at `v`
    /// m/s (opposing the motion), and its derivative in `v`.
    pub fn shoe_force(&self, normal: f64, v: f64) -> (f64, f64) {
        if normal <= 0.0 {
            return (0.0, 0.0);
        }
        let mu = self.friction_at(v);
        let (sg, dsg) = smooth_sign(v, STOP_SPEED);
        // μ's own slope against speed is small beside the smooth sign's: left out of the
        // derivative (it only serves the step's linearisation).
        (-mu * normal * sg, -mu * normal * dsg)
    }
}

/// Which time constant a car's shoe force follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Lag {
    Apply,
    Emergency,
    Release,
}

/// The brake state of every vehicle of a train (structure of arrays: no allocation in a step).
#[derive(Debug, Clone)]
pub(crate) struct BrakeState {
    /// Current shoe force as a share of the vehicle's full-service force.
    pub level: Vec<f64>,
    /// Active target share.
    target: Vec<f64>,
    /// Active lag.
    lag: Vec<Lag>,
    /// Target, lag and time of the command on its way to the car (∞: none).
    pending: Vec<(f64, Lag, f64)>,
    /// Time the last command reached each car's valve (brake-pipe signal plus valve delay), s.
    pub arrival: Vec<f64>,
    /// Every car at its target and no command on its way: nothing to advance.
    settled: bool,
}

impl BrakeState {
    /// All released.
    pub fn released(n: usize) -> Self {
        BrakeState {
            level: vec![0.0; n],
            target: vec![0.0; n],
            lag: vec![Lag::Release; n],
            pending: vec![(0.0, Lag::Release, f64::INFINITY); n],
            arrival: vec![f64::INFINITY; n],
            settled: true,
        }
    }

    /// A command issued at time `now`: target share `target` with lag `lag`, starting at the
    /// vehicles `sources` (index and delay) of a train whose vehicle centres stand at `s`.
    pub fn command(
        &mut self,
        brake: &AirBrake,
        now: f64,
        s: &[f64],
        sources: &[(usize, f64)],
        target: f64,
        lag: Lag,
    ) {
        for (i, &si) in s.iter().enumerate() {
            let travel = sources
                .iter()
                .map(|&(k, delay)| delay + (si - s[k]).abs() / brake.pipe_speed)
                .fold(f64::INFINITY, f64::min);
            let at = now + travel + brake.valve_delay;
            self.pending[i] = (target, lag, at);
            self.arrival[i] = at;
        }
        self.settled = false;
    }

    /// Advances every car's shoe force to time `now` over a step of `dt`.
    pub fn advance(&mut self, brake: &AirBrake, now: f64, dt: f64) {
        if self.settled {
            return;
        }
        let mut settled = true;
        let fa = 1.0 - (-dt / brake.apply_time_constant).exp();
        let fe = 1.0 - (-dt / brake.emergency_time_constant).exp();
        let fr = 1.0 - (-dt / brake.release_time_constant).exp();
        for i in 0..self.level.len() {
            let (t, lag, at) = self.pending[i];
            if now >= at {
                self.target[i] = t;
                self.lag[i] = lag;
                self.pending[i].2 = f64::INFINITY;
            } else if at.is_finite() {
                settled = false;
            }
            let d = self.target[i] - self.level[i];
            if d != 0.0 {
                let f = match self.lag[i] {
                    Lag::Apply => fa,
                    Lag::Emergency => fe,
                    Lag::Release => fr,
                };
                self.level[i] = if d.abs() < 1e-9 {
                    self.target[i]
                } else {
                    settled = false;
                    self.level[i] + f * d
                };
            }
        }
        self.settled = settled;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brake() -> AirBrake {
        AirBrake {
            pipe_speed: 250.0,
            valve_delay: 0.5,
            apply_time_constant: 4.0,
            emergency_time_constant: 1.5,
            release_time_constant: 15.0,
            emergency_ratio: 1.25,
            distributed: true,
            radio_delay: 0.0,
            friction: vec![(40.0 / 3.6, 0.31), (60.0 / 3.6, 0.30), (120.0 / 3.6, 0.28)],
        }
    }

    #[test]
    fn friction_table_interpolates_and_clamps() {
        let b = brake();
        assert_eq!(b.friction_at(0.0), 0.31);
        assert!((b.friction_at(50.0 / 3.6) - 0.305).abs() < 1e-12);
        assert_eq!(b.friction_at(200.0), 0.28);
        let (f, _) = b.shoe_force(100e3, 10.0);
        assert!((f + 0.31 * 100e3).abs() < 10.0);
        assert_eq!(b.shoe_force(0.0, 10.0).0, 0.0);
    }

    #[test]
    fn a_command_travels_from_each_source() {
        let b = brake();
        let s: Vec<f64> = (0..11).map(|i| -100.0 * i as f64).collect();
        let mut st = BrakeState::released(11);
        st.command(&b, 2.0, &s, &[(0, 0.0), (10, 0.0)], 1.0, Lag::Apply);
        assert!((st.arrival[0] - 2.5).abs() < 1e-12);
        assert!((st.arrival[2] - (2.5 + 200.0 / 250.0)).abs() < 1e-12);
        assert!((st.arrival[8] - (2.5 + 200.0 / 250.0)).abs() < 1e-12);
        // nothing before arrival; first-order lag after
        let dt = 1e-3;
        let mut t = 2.0;
        while t < 2.5 + 0.8 - 1e-9 {
            t += dt;
            st.advance(&b, t, dt);
        }
        assert!(st.level[2] < 1e-3);
        assert!(st.level[0] > 0.15);
        while t < 2.5 + 0.8 + 4.0 {
            t += dt;
            st.advance(&b, t, dt);
        }
        assert!(
            (st.level[2] - (1.0 - (-1.0f64).exp())).abs() < 0.01,
            "{}",
            st.level[2]
        );
    }
}
