//! The train's state and its step: every vehicle's position and velocity along the line.
//!
//! The step is linearly implicit Euler: the coupling forces are linearised in the vehicles'
//! positions and velocities (their stiffness and the draft gears' steep friction switch), the
//! resistance and the shoe friction in each vehicle's own velocity, and the tridiagonal system
//! `(M − dt·C − dt²·K)·Δv = dt·F + dt²·K·v` is solved in O(n); then `s += dt·v`. Traction is
//! explicit. A 3-D wagon driven by the caller is a row whose `Δv` is known (the caller moved it
//! first): the system splits into the vehicles ahead of it and those behind it, each driven by
//! its motion. Nothing allocates in a step.

use super::brake::{BrakeState, Lag};
use super::consist::Consist;
use super::driver::{Command, Driver};
use super::locomotive::Locomotive;
use super::resistance::{BasicResistance, STOP_SPEED, curve_per_kn, grade_force};
use super::{Route, smooth_sign};
use tridiagonal::solve_tridiagonal;

mod readout;
mod start;
mod tridiagonal;

/// How far the head moves between two samples of the route's grade and curvature under every
/// vehicle, m: the line's grade and curvature change over tens of metres (vertical curves,
/// transitions), so half a metre keeps the sampled forces within a fraction of a per cent and
/// spares the route two calls per vehicle and step.
pub const ROUTE_REFRESH: f64 = 0.5;

/// Which vehicle is the 3-D wagon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WagonAt {
    /// The consist file's `position`.
    File,
    /// A fraction of the train's length from the head, in [0, 1].
    Fraction(f64),
    /// A vehicle index (0 = head).
    Index(usize),
}

/// A neighbour of the 3-D wagon, along the line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbour {
    /// Its index in the consist.
    pub index: usize,
    /// Along-line position of its centre, m.
    pub centre: f64,
    /// Along-line position of its coupler pivot on the wagon's side, m.
    pub pivot: f64,
    /// Half its length over the coupler faces, m.
    pub half_length: f64,
    /// Distance from its coupler face in to the pivot, m.
    pub pivot_inset: f64,
}

/// The 3-D wagon's neighbours: ahead (`front`, its rear coupler faces the wagon's front one)
/// and behind (`rear`); `None` at an end of the train.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Neighbours {
    /// The vehicle ahead.
    pub front: Option<Neighbour>,
    /// The vehicle behind.
    pub rear: Option<Neighbour>,
}

/// A consist on the line: state, driver, brake and the stepper.
///
/// The coupled mode, a 3-D wagon stepped at `dt` and the train every `k`-th of its steps
/// (`k = 1`: every step):
///
/// ```text
/// each 3-D step, τ = time since the train's last step:
///     (front, rear) = train.coupler_jacobians_ahead(τ, s, v)   // forces and their slopes
///     shoes = train.wagon_brake()                              // normal force, μ
///     advance the 3-D wagon to s', v' with front.force − rear.force along the track at the
///     coupler height, the shoes on its treads
///     every k-th step: train.step_to(k·dt, s', v', &route)
/// ```
///
/// ([`Train::step`] instead takes the wagon's state at the step's start, for a caller that
/// advances the train before its wagon.)
#[derive(Debug, Clone)]
pub struct Train {
    consist: Consist,
    wagon: usize,
    mass: Vec<f64>,
    total_mass: f64,
    basic: Vec<BasicResistance>,
    /// Full-service shoe force of each vehicle, N.
    shoe: Vec<f64>,
    locos: Vec<(usize, Locomotive)>,
    s: Vec<f64>,
    v: Vec<f64>,
    /// Rest distance between the centres of vehicles j and j + 1, m.
    rest: Vec<f64>,
    /// Sampled route under each vehicle: grade force (N) and curvature (1/m).
    grade: Vec<f64>,
    curvature: Vec<f64>,
    route_at: f64,
    brake: BrakeState,
    sources: Vec<(usize, f64)>,
    driver: Driver,
    air_queue: Vec<Command>,
    time: f64,
    last_external: f64,
    // solver buffers
    diag: Vec<f64>,
    off: Vec<f64>,
    rhs: Vec<f64>,
    work: Vec<f64>,
    piv: Vec<f64>,
    dv: Vec<f64>,
}

impl Train {
    /// Samples the route's grade and curvature under every vehicle.
    fn sample_route(&mut self, route: &dyn Route) {
        for i in 0..self.s.len() {
            self.grade[i] = grade_force(self.mass[i], route.grade(self.s[i]));
            self.curvature[i] = route.curvature(self.s[i]);
        }
        self.route_at = self.s[0];
    }

    /// Resistance (basic, curve), grade and shoe brake on vehicle `i` at velocity `v` with
    /// brake share `level`: force along +s and its derivative in `v`. The step's form of
    /// [`BasicResistance::force`], [`curve_force`](super::resistance::curve_force) and
    /// [`AirBrake::shoe_force`](super::AirBrake::shoe_force) together, with one smooth sign.
    #[inline]
    fn passive_force(&self, i: usize, v: f64, level: f64) -> (f64, f64) {
        let r = &self.basic[i];
        let weight_kn = self.mass[i] * (crate::GRAVITY / 1000.0);
        let k = v.abs() * 3.6;
        let per_kn = r.a + r.b * k + r.c * k * k + curve_per_kn(self.curvature[i]);
        let slope = (r.b + 2.0 * r.c * k) * 3.6 * v.signum();
        let (sg, dsg) = smooth_sign(v, STOP_SPEED);
        let mut f = self.grade[i] - weight_kn * per_kn * sg;
        let mut df = -weight_kn * (slope * sg + per_kn * dsg);
        let normal = level * self.shoe[i];
        if normal > 0.0 {
            let mu_n = self.consist.brake.friction_at(v) * normal;
            f -= mu_n * sg;
            df -= mu_n * dsg;
        }
        (f, df)
    }

    /// One step of `dt` s in the coupled mode, the 3-D wagon at the step's start: centre at
    /// `wagon_s`, moving at `wagon_v` (the state the caller took the coupler forces at). Every
    /// other vehicle advances with the wagon taken to move on at `wagon_v` over the step; the
    /// next call corrects it to where the caller's wagon went.
    pub fn step(&mut self, dt: f64, wagon_s: f64, wagon_v: f64, route: &dyn Route) {
        let w = self.wagon;
        self.s[w] = wagon_s;
        self.v[w] = wagon_v;
        self.advance(dt, Some((wagon_s + dt * wagon_v, wagon_v)), route);
    }

    /// One step of `dt` s in the coupled mode, the 3-D wagon already advanced over it: the
    /// caller moved its wagon first (with the coupler forces of the step's start,
    /// [`Self::coupler_jacobians_ahead`]) and passes where it ends, centre at `wagon_s` moving
    /// at `wagon_v`. Every other vehicle advances with the wagon's motion over the step known:
    /// its velocity change and displacement enter its neighbours' implicit equations, which
    /// follows the alone mode more closely than [`Self::step`] (tests/train.rs).
    pub fn step_to(&mut self, dt: f64, wagon_s: f64, wagon_v: f64, route: &dyn Route) {
        self.advance(dt, Some((wagon_s, wagon_v)), route);
    }

    /// One step of `dt` s in the alone mode: the 3-D wagon is a plain 1-D mass like the others.
    pub fn step_alone(&mut self, dt: f64, route: &dyn Route) {
        self.advance(dt, None, route);
    }

    /// Runs the alone mode for `duration` s at steps of `dt`, calling `each` after every step.
    pub fn run_alone(
        &mut self,
        duration: f64,
        dt: f64,
        route: &dyn Route,
        each: &mut dyn FnMut(&Train),
    ) {
        let steps = (duration / dt).round() as usize;
        for _ in 0..steps {
            self.step_alone(dt, route);
            each(self);
        }
    }

    fn advance(&mut self, dt: f64, wagon_end: Option<(f64, f64)>, route: &dyn Route) {
        let n = self.s.len();
        let w = self.wagon;
        let prescribed = wagon_end.is_some();
        // the wagon's velocity change over the step, and its displacement beyond dt·v_end
        let (dvw, slip) = wagon_end.map_or((0.0, 0.0), |(s_end, v_end)| {
            (v_end - self.v[w], (s_end - self.s[w]) - dt * v_end)
        });
        if (self.s[0] - self.route_at).abs() > ROUTE_REFRESH {
            self.sample_route(route);
        }
        // driver and brake at the start of the step
        let speed = self.speed();
        let q = &mut self.air_queue;
        q.clear();
        self.driver.update(self.time, dt, speed, &mut |c| q.push(c));
        for k in 0..self.air_queue.len() {
            let c = self.air_queue[k];
            self.issue_air(c);
        }
        self.brake.advance(&self.consist.brake, self.time, dt);
        let u = self.driver.control();
        let coupling = self.consist.coupling;
        let (dt2, mut external) = (dt * dt, 0.0);
        // vehicles: external forces and their velocity derivative
        for i in 0..n {
            if prescribed && i == w {
                self.diag[i] = 1.0;
                self.rhs[i] = dvw;
                self.work[i] = 0.0;
                continue;
            }
            let v = self.v[i];
            let (f, d) = self.passive_force(i, v, self.brake.level[i]);
            self.diag[i] = self.mass[i] - dt * d;
            self.rhs[i] = dt * f;
            self.work[i] = d; // kept for the momentum bookkeeping
            external += f;
        }
        for &(i, l) in &self.locos {
            if !(prescribed && i == w) {
                let f = l.effort(u, self.v[i]);
                self.rhs[i] += dt * f;
                external += f;
            }
        }
        // couplings
        for j in 0..n - 1 {
            let e = self.s[j] - self.s[j + 1] - self.rest[j];
            let de = self.v[j] - self.v[j + 1];
            let g = coupling.force(e, de);
            let k = dt * g.damping + dt2 * g.stiffness;
            let push = dt * g.force + dt2 * g.stiffness * de;
            let (front_free, rear_free) = (!(prescribed && j == w), !(prescribed && j + 1 == w));
            // the wagon's known motion over the step, moved to its neighbour's right side
            let known = if front_free && rear_free {
                0.0
            } else {
                k * dvw + dt * g.stiffness * slip
            };
            if front_free {
                self.diag[j] += k;
                self.rhs[j] += known - push;
            }
            if rear_free {
                self.diag[j + 1] += k;
                self.rhs[j + 1] += known + push;
            }
            self.off[j] = if front_free && rear_free { -k } else { 0.0 };
        }
        solve_tridiagonal(
            &self.diag,
            &self.off,
            &mut self.rhs,
            &mut self.piv,
            &mut self.dv,
        );
        for (i, &dv) in self.dv.iter().enumerate() {
            external += self.work[i] * dv;
            self.v[i] += dv;
            self.s[i] += dt * self.v[i];
        }
        if let Some((s_end, v_end)) = wagon_end {
            self.s[w] = s_end;
            self.v[w] = v_end;
        }
        self.last_external = external;
        self.time += dt;
    }

    /// Sends an air-brake command (from the schedule or the caller) down the pipe now.
    fn issue_air(&mut self, c: Command) {
        let (target, lag) = match c {
            Command::AirBrake(level) => (level, Lag::Apply),
            Command::Emergency => (self.consist.brake.emergency_ratio, Lag::Emergency),
            Command::Release => (0.0, Lag::Release),
            Command::Notch(_) | Command::Hold(_) => return,
        };
        self.brake.command(
            &self.consist.brake,
            self.time,
            &self.s,
            &self.sources,
            target,
            lag,
        );
    }

    /// The driver's command now: a notch, a speed to hold, an air-brake application or
    /// release (sent down the pipe from the head, and from every locomotive with distributed
    /// power).
    pub fn command(&mut self, c: Command) {
        if let Some(air) = self.driver.apply(c) {
            self.issue_air(air);
        }
    }
}
