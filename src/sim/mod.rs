//! Time-domain simulation of a vehicle on a track.
//!
//! Rigid bodies in the world frame (x, y horizontal, z up), integrated at a fixed step (default:
//! linearly implicit in the wheel–rail damping and the contact's Hertz spring at 5/6 ms, each
//! wheelset solved with its rail masses and each side frame in its pads' damping; the same without the Hertz spring at 0.5 ms and
//! semi-implicit Euler at 0.2 ms selectable: `integrator`), gyroscopic terms included
//! (wheelsets spin).
//! Every step the project computes all force elements and the wheel–rail contact from the body
//! states and the track (curvature, cant, gradient, irregularities under each wheel). Signals
//! are low-pass filtered at the integration rate and decimated to the output rate.
//!
//! Why not rapier: the brief's measurement puts rapier3d-f64 0.36 at 7.08 µs per step for the
//! same 11 bodies without colliders (assets/docs/performance.md) — above the whole 5 µs per step that 20× real time allows at the
//! 0.1–0.2 ms step the creep forces need — and every force here is computed by the project;
//! a direct integrator over 11 bodies costs well under a microsecond.

pub mod channels;
pub mod checks;
mod element_solve;
pub mod fidelity;
mod filter;
pub mod hitch;
mod integrator;
pub mod modes;
pub mod output;
pub mod profile;
mod rail_beams;
mod request;
pub mod step_study;
mod track_frame;
mod watch;
mod wheel_rail;
mod wheelset_solve;

pub use integrator::{
    Integrator, MAX_STEP_ON_BEAMS, MAX_STEP_SHORT_WAVES, MAX_TRAVEL_ON_BEAMS,
    STEPS_PER_SHORTEST_WAVE, Stepping, step_on_beams,
};
pub use output::{Recorder, RunSummary};
pub use request::RunRequest;
pub use track_frame::{TrackFrame, project};
pub use wheel_rail::WheelResult;
pub use wheelset_solve::RailState;
use wheelset_solve::{RailCoupling, Shares};

use crate::error::{Error, Result};
use crate::track::Track;
use crate::vehicle::{BodyState, Element, Vehicle, Wrench};
use nalgebra::{UnitQuaternion, Vector3};
use profile::{StepProfile, timed};

/// Settings of a run.
#[derive(Debug, Clone)]
pub struct SimConfig {
    /// Running speed held by the hauling control, m/s.
    pub speed: f64,
    /// Recorded duration after settling, s.
    pub duration: f64,
    /// Settling time at the start, not recorded, s.
    pub settle: f64,
    /// Integration step, s.
    pub dt: f64,
    /// Output sampling rate, Hz.
    pub output_rate: f64,
    /// Anti-alias cut-off, Hz.
    pub cutoff: f64,
    /// Distance along the track of the vehicle centre at the start, m (None: just far enough
    /// for the rear wheelset to be on the track).
    pub start: Option<f64>,
    /// Stop the run at a derailment (otherwise it is only reported).
    pub stop_on_derailment: bool,
    /// Stop the run, too, when |Y/Q| stays above Nadal's limit for longer than `nadal_time` (a
    /// derailment *risk*, the Chinese time criterion; the wheel has not climbed). Otherwise it
    /// is reported and the run goes on: data generation keeps such runs, whose forces an
    /// identification must learn (a drawn wagon of a fleet may reach it).
    pub stop_on_derailment_risk: bool,
    /// Flange angle for the Nadal limit, rad (None: the vehicle's `contact.flange_angle_deg`).
    pub nadal_angle: Option<f64>,
    /// How long |Y/Q| may stay above Nadal's limit before a derailment is declared, s.
    pub nadal_time: f64,
    /// A wheel risen on its flange by this share of the flange height (lift included) has
    /// derailed (the flange tip is rounded).
    pub climb_limit: f64,
    /// A wheel this far sideways from its rail (m) has derailed.
    pub lateral_limit: f64,
    /// A body moving this fast away from the running motion (m/s) means the run diverged.
    pub runaway_speed: f64,
    /// Lateral offset of the whole vehicle at the start, m (a perturbation for stability and
    /// kinematic-oscillation checks).
    pub initial_offset: f64,
    /// How the bodies are integrated ([`Integrator`]).
    pub integrator: Integrator,
    /// The train around the wagon (None: the wagon alone, its speed held by the vehicle
    /// file's `[hauling]` control).
    pub train: Option<hitch::TrainSetup>,
    /// Record the couplers' channels even for a wagon alone (zeros: it has no coupler), so
    /// a data set mixing runs alone and in a train has one set of channels.
    pub coupler_channels: bool,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            speed: 60.0 / 3.6,
            duration: 10.0,
            settle: 3.0,
            dt: Integrator::default().default_step(),
            output_rate: 200.0,
            cutoff: 50.0,
            start: None,
            stop_on_derailment: true,
            stop_on_derailment_risk: true,
            nadal_angle: None,
            nadal_time: 0.05,
            climb_limit: 0.9,
            lateral_limit: 39e-3,
            runaway_speed: 20.0,
            initial_offset: 0.0,
            integrator: Integrator::default(),
            train: None,
            coupler_channels: false,
        }
    }
}

impl SimConfig {
    /// Nadal's flange-climb limit `(tan δ − μ)/(1 + μ·tan δ)` for the flange angle δ given
    /// here, else 70°.
    pub fn nadal_limit(&self, mu: f64) -> f64 {
        crate::contact::nadal_limit(self.nadal_angle.unwrap_or(70f64.to_radians()), mu)
    }
}

/// A running simulation (a copy runs on from the same state: the step guard's).
#[derive(Clone)]
pub struct Simulation<'a> {
    vehicle: &'a Vehicle,
    track: &'a Track,
    cfg: SimConfig,
    table: &'a crate::contact::ContactTable,
    states: Vec<BodyState>,
    wrenches: Vec<Wrench>,
    /// Internal state of each force element (wedge sliders).
    memory: Vec<crate::vehicle::elements::Memory>,
    /// Along-track position of every body, m.
    body_s: Vec<f64>,
    /// Track frame at each body (wheelsets and hauled body every step, others on demand).
    frames: Vec<TrackFrame>,
    /// Bodies whose track frame is refreshed every step.
    every_step: Vec<usize>,
    /// Steps taken, and the step at which all frames were last refreshed.
    step_count: u64,
    frames_step: u64,
    /// Per wheel: the rail under it (compliant track), and the wheel's force on it (lateral,
    /// vertical) in the last step.
    rails: Vec<RailState>,
    rail_force: Vec<[f64; 2]>,
    /// Per wheel: the state the last contact evaluation was given.
    inputs: Vec<crate::contact::WheelOnRail>,
    /// Per wheel: how long Y/Q has exceeded the Nadal limit, s.
    over_nadal: Vec<f64>,
    /// Each wheel off its rail at the last step (a run told to keep going warns once per
    /// episode, not every step).
    off_rail: Vec<bool>,
    /// Per wheel: the last step's wheel load and the sum of squared step-to-step changes of
    /// it since the chatter window opened (`watch`), N and N².
    chatter: Vec<(f64, f64)>,
    /// Each wheel's static share of the weight, N.
    static_load: f64,
    hauling_integral: f64,
    /// The train the carbody is coupled into, when the run has one.
    hitch: Option<Box<hitch::Hitch>>,
    time: f64,
    /// Flange height of the wheel profile, m.
    flange_height: f64,
    /// Nadal's limit for the flange angle in force (the config's, else the vehicle's).
    nadal_limit: f64,
    /// Results of the last contact evaluation, per wheel (1L, 1R, 2L, …).
    pub wheels: Vec<WheelResult>,
    /// Accelerations of each body at the last step, world, m/s².
    pub accelerations: Vec<Vector3<f64>>,
    /// Where the steps' time goes, when profiling is on ([`Simulation::set_profiling`]).
    profile: Option<Box<StepProfile>>,
    /// Per wheelset: the wheel–rail damping of the last contact evaluation, world axes, about
    /// its centre ([`crate::contact::patch_damping`]; the linearly implicit step's).
    contact_damping: Vec<nalgebra::Matrix6<f64>>,
    /// Per wheel: the contact's damping and normal stiffness on the rail's lateral and
    /// vertical motion, track axes (the linearly implicit step's).
    rail_coupling: Vec<RailCoupling>,
    /// How the implicit solve takes the contact (none for the explicit integrators).
    shares: Option<Shares>,
    /// Per wheel: the rail surface's rate under it at the last step, track `(ẏ, ż)` (the
    /// linearly implicit step's; none before the first).
    surface_rates: Vec<Option<nalgebra::Vector2<f64>>>,
    /// The bodies the Hertz integrator solves in their stiff elements' damping.
    damped: Vec<element_solve::DampedBody>,
    /// Per body: the reaction impulse of that damping in the current step, world.
    kicks: Vec<nalgebra::Vector6<f64>>,
    /// The rails on discrete sleepers, when the track has them.
    beams: Option<Box<crate::track::discrete::TrackDynamics>>,
    /// Per wheel: its impulse on the beams in the last step, lateral and vertical, N·s.
    beam_impulses: Vec<nalgebra::Vector2<f64>>,
}

impl<'a> Simulation<'a> {
    /// Places the vehicle on the track in its static position, moving at the running speed.
    pub fn new(vehicle: &'a Vehicle, track: &'a Track, cfg: SimConfig) -> Result<Self> {
        if !(cfg.speed.is_finite() && cfg.speed >= 0.0) {
            return Err(Error::Domain(format!(
                "speed must be ≥ 0, got {}",
                cfg.speed
            )));
        }
        if !(cfg.dt > 0.0 && cfg.dt <= 1e-3) {
            return Err(Error::Domain(format!(
                "the integration step must lie in (0, 1 ms], got {} s",
                cfg.dt
            )));
        }
        // The contact table is built for the vehicle's gauge: the track must have it.
        let (tg, vg) = (
            track.spec().gauge,
            2.0 * vehicle.contact.geometry.half_gauge,
        );
        if (tg - vg).abs() > 5e-4 {
            return Err(Error::Domain(format!(
                "track '{}' has gauge {:.1} mm but vehicle '{}' is built for {:.1} mm (contact.gauge_m): the contact geometry would not match",
                track.spec().name,
                tg * 1e3,
                vehicle.name,
                vg * 1e3
            )));
        }
        let xs: Vec<f64> = vehicle.bodies.iter().map(|b| b.position.x).collect();
        let (x_min, x_max) = xs
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), &x| (a.min(x), b.max(x)));
        let start = cfg.start.unwrap_or(5.0 - x_min);
        let travel = cfg.speed * (cfg.settle + cfg.duration);
        let needed = start + x_max + travel + 5.0;
        if start + x_min < 0.0 || needed > track.length() {
            return Err(Error::Domain(format!(
                "track '{}' is {:.0} m long; this run needs {:.0} m ({:.0} m of travel at {:.1} km/h for {} s settling + {} s, plus the wagon's length)",
                track.spec().name,
                track.length(),
                needed,
                travel,
                cfg.speed * 3.6,
                cfg.settle,
                cfg.duration
            )));
        }
        // The vehicle is placed on the design geometry: its wheels must start on smooth rails
        // (the track's smooth lead before the irregularities fade in).
        for &w in &vehicle.contact.wheelsets {
            let r = track.at(start + vehicle.bodies[w].position.x).rails;
            let worst = [r.left_y, r.left_z, r.right_y, r.right_z]
                .iter()
                .fold(0.0f64, |a, v| a.max(v.abs()));
            if worst > 2e-4 {
                return Err(Error::Domain(format!(
                    "the vehicle would start on irregular rails ({:.1} mm at s = {:.1} m): start it on the smooth lead of track '{}' (irregularity.smooth_start_m)",
                    worst * 1e3,
                    start + vehicle.bodies[w].position.x,
                    track.spec().name
                )));
            }
        }
        let geo = &vehicle.contact.geometry;
        let table = vehicle.contact.table();
        // Static wheel load and its Hertz approach set the wheelsets' height.
        let n_wheels = 2 * vehicle.contact.wheelsets.len();
        let static_load = vehicle.mass() * crate::GRAVITY / n_wheels as f64;
        let centred = table.lookup(0.0);
        // The rails sink under the static load on a compliant track; the wheelsets sit at the
        // height where each wheel carries its share (the run's own contact evaluation).
        // On sleepers the track settles under the static loads first (the integrator that
        // takes the Hertz spring into the wheelsets' solve only).
        let beams = match track.spec().discrete_rails {
            None => None,
            Some(p) => Some(rail_beams::settled(
                p,
                vehicle,
                track,
                start,
                static_load,
                &cfg,
            )?),
        };
        let rail_z0 = match &beams {
            Some((_, sag)) => *sag,
            None => {
                (track.spec().rail_support).map_or(0.0, |s| -static_load / s.vertical.stiffness)
            }
        };
        let ws_mass = vehicle.bodies[vehicle.contact.wheelsets[0]].mass;
        let rest = crate::contact::WheelOnRail::rolling(
            crate::contact::Side::Left,
            cfg.speed,
            geo.nominal_radius,
            0.0,
            0.5 * ws_mass,
        );
        let wheelset_z =
            crate::contact::height_for_load(table, &vehicle.contact.model(), &rest, static_load)
                + rail_z0;
        let ws_body = &vehicle.bodies[vehicle.contact.wheelsets[0]];
        let dz = wheelset_z - ws_body.position.z;
        let mut states = Vec::with_capacity(vehicle.bodies.len());
        let mut body_s = Vec::with_capacity(vehicle.bodies.len());
        for (i, b) in vehicle.bodies.iter().enumerate() {
            let s = start + b.position.x;
            let f = TrackFrame::at(track, s);
            let local = Vector3::new(0.0, b.position.y + cfg.initial_offset, b.position.z + dz);
            let rot = UnitQuaternion::from_matrix(&f.axes);
            let along = f.axes.column(0).into_owned();
            let mut omega = Vector3::zeros();
            if vehicle.contact.wheelsets.contains(&i) {
                omega =
                    f.axes.column(1).into_owned() * (cfg.speed / centred.wheels[0].rolling_radius);
            }
            states.push(BodyState {
                position: f.origin + f.axes * local,
                rotation: rot,
                velocity: along * cfg.speed,
                angular_velocity: omega,
            });
            body_s.push(s);
        }
        let n = vehicle.bodies.len();
        let frames = body_s.iter().map(|&s| TrackFrame::at(track, s)).collect();
        let mut every_step = vehicle.contact.wheelsets.clone();
        for e in &vehicle.elements {
            if let Element::TrackSpring(ts) = e
                && !every_step.contains(&ts.body)
            {
                every_step.push(ts.body);
            }
        }
        if let Some(h) = vehicle.hauling {
            every_step.push(h.body);
        }
        let damped = if cfg.integrator.solves_bogie() {
            element_solve::damped_bodies(&vehicle.bodies, &vehicle.elements, &states, cfg.dt)
        } else {
            Vec::new()
        };
        let hitch = match (&cfg.train, vehicle.hauling) {
            (None, _) => None,
            (Some(setup), Some(h)) => Some(Box::new(hitch::Hitch::new(
                setup,
                vehicle,
                h.body,
                track,
                body_s[h.body],
                cfg.speed,
            )?)),
            (Some(_), None) => {
                return Err(Error::config(
                    &vehicle.source,
                    "hauling.link",
                    "a run in a train needs `[hauling] link`: the body its couplers act on",
                ));
            }
        };
        let dt0 = cfg.dt;
        let mut sim = Simulation {
            hitch,
            frames,
            every_step,
            step_count: 0,
            frames_step: 0,
            vehicle,
            track,
            table,
            states,
            wrenches: vec![Wrench::default(); n],
            memory: vec![[0.0; crate::vehicle::elements::MEMORY]; vehicle.elements.len()],
            body_s,
            rails: vec![
                RailState {
                    z: rail_z0,
                    ..RailState::default()
                };
                n_wheels
            ],
            rail_force: vec![[0.0, -static_load]; n_wheels],
            contact_damping: vec![nalgebra::Matrix6::zeros(); vehicle.contact.wheelsets.len()],
            rail_coupling: vec![RailCoupling::default(); n_wheels],
            surface_rates: vec![None; n_wheels],
            damped,
            kicks: vec![nalgebra::Vector6::zeros(); n],
            shares: cfg.integrator.shares(cfg.dt).map(|mut s| {
                if beams.is_some() && s.alpha_dt > 0.0 {
                    s.alpha_dt = wheelset_solve::ALPHA_ON_BEAMS * cfg.dt;
                }
                s
            }),
            inputs: vec![rest; n_wheels],
            over_nadal: vec![0.0; n_wheels],
            off_rail: vec![false; n_wheels],
            chatter: vec![(static_load, 0.0); n_wheels],
            static_load,
            hauling_integral: 0.0,
            time: -cfg.settle,
            flange_height: crate::contact::Flange::of(geo.wheel()).height,
            nadal_limit: SimConfig {
                nadal_angle: Some(cfg.nadal_angle.unwrap_or(vehicle.contact.flange_angle)),
                ..SimConfig::default()
            }
            .nadal_limit(vehicle.contact.friction),
            cfg,
            wheels: vec![WheelResult::default(); n_wheels],
            accelerations: vec![Vector3::zeros(); n],
            profile: None,
            beams: beams.map(|(b, _)| b),
            beam_impulses: vec![nalgebra::Vector2::new(0.0, -static_load * dt0); n_wheels],
        };
        sim.rails_from_beams();
        Ok(sim)
    }

    /// Simulated time, s (negative while settling).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Changes the running speed the hauling control holds, m/s (coasting tests).
    pub fn set_speed(&mut self, speed: f64) {
        self.cfg.speed = speed;
    }

    /// Adds `dv` (m/s) to the velocity and `dw` (rad/s) to the angular velocity of `body`,
    /// both in its track frame's axes (x along, y left, z up): a kick for stability tests (the
    /// run-down of [`fidelity::run_down`], a side frame rolled and let go).
    pub fn kick(&mut self, body: usize, dv: Vector3<f64>, dw: Vector3<f64>) {
        let axes = self.frames[body].axes;
        self.states[body].velocity += axes * dv;
        self.states[body].angular_velocity += axes * dw;
    }

    /// Settings.
    pub fn config(&self) -> &SimConfig {
        &self.cfg
    }

    /// Body states.
    pub fn states(&self) -> &[BodyState] {
        &self.states
    }

    /// Per wheel (as [`Simulation::wheels`]): the rail under it on a compliant track, from its
    /// unloaded place; zero on a rigid one.
    pub fn rails(&self) -> &[RailState] {
        &self.rails
    }

    /// Along-track position of each body, m.
    pub fn body_s(&self) -> &[f64] {
        &self.body_s
    }

    /// Along-track position of the vehicle centre, m: the mean of the wheelsets' positions,
    /// projected onto the track from their current places.
    pub fn centre_s(&self) -> f64 {
        let w = &self.vehicle.contact.wheelsets;
        // Projected from the current positions (the stored ones may be a step old).
        w.iter()
            .map(|&b| project(self.track, &self.states[b].position, self.body_s[b]))
            .sum::<f64>()
            / w.len() as f64
    }

    /// Track frame at each body (as of the last step).
    pub fn frames(&self) -> &[TrackFrame] {
        &self.frames
    }

    /// The vehicle.
    pub fn vehicle(&self) -> &Vehicle {
        self.vehicle
    }

    /// The track.
    pub fn track(&self) -> &Track {
        self.track
    }

    /// Advances one integration step.
    ///
    /// ```no_run
    /// use railforce::sim::{SimConfig, Simulation};
    /// use railforce::{track::Track, vehicle::Vehicle};
    /// let vehicle = Vehicle::load("vehicles/c80.toml".as_ref())?;
    /// let track = Track::load("tracks/curve_r400.toml".as_ref())?;
    /// let cfg = SimConfig { speed: 60.0 / 3.6, ..SimConfig::default() };
    /// let mut sim = Simulation::new(&vehicle, &track, cfg)?;
    /// sim.settle()?;
    /// for _ in 0..1_400 {
    ///     sim.step()?; // 1 s at the default 5/6 ms step
    /// }
    /// println!("Q of wheel 1L: {:.1} kN", sim.wheels[0].q / 1e3);
    /// # Ok::<(), railforce::Error>(())
    /// ```
    pub fn step(&mut self) -> Result<()> {
        let dt = self.cfg.dt;
        if self.cfg.integrator == Integrator::Heun {
            self.step_heun()?;
            self.time += dt;
            return self.check();
        }
        self.forces(true)?;
        timed!(self.profile, "rails", self.move_rails());
        let t0 = self.profile.is_some().then(std::time::Instant::now);
        self.integrate();
        if let Some(b) = self.beams.as_deref_mut() {
            b.end(dt);
        }
        if let (Some(t0), Some(p)) = (t0, self.profile.as_deref_mut()) {
            p.add("integration (11 bodies)", t0.elapsed());
            p.steps += 1;
        }
        self.time += dt;
        timed!(self.profile, "checks", self.check())
    }

    /// Turns the step profile on (cleared) or off ([`profile::StepProfile`]).
    pub fn set_profiling(&mut self, on: bool) {
        self.profile = on.then(Box::default);
    }

    /// The step profile so far, when profiling is on.
    pub fn profile(&self) -> Option<&StepProfile> {
        self.profile.as_deref()
    }

    /// Every force of the state as it stands: gravity, the force elements, the track springs,
    /// the wheel–rail contact (and its reactions on the rails) and the hauling, into the
    /// wrenches. `integrate_haul`: advance the speed controller's integral by one step (the
    /// run); without it the forces are a pure function of the state (the linearisation of
    /// [`modes`]).
    pub(crate) fn forces(&mut self, integrate_haul: bool) -> Result<()> {
        let g = crate::GRAVITY;
        for (w, b) in self.wrenches.iter_mut().zip(&self.vehicle.bodies) {
            *w = Wrench::default();
            w.force.z = -b.mass * g;
        }
        timed!(self.profile, "force elements", {
            for (e, m) in self.vehicle.elements.iter().zip(&mut self.memory) {
                e.apply(&self.states, m, &mut self.wrenches, self.cfg.dt);
            }
        });
        // Wheelsets (contact) and the hauled body need their track frame every step; the
        // others only when signals are sampled or the state is checked.
        timed!(self.profile, "track frames", {
            for k in 0..self.every_step.len() {
                let i = self.every_step[k];
                self.refresh_frame(i);
            }
        });
        timed!(self.profile, "track springs", {
            for e in &self.vehicle.elements {
                if let Element::TrackSpring(ts) = e {
                    let f = &self.frames[ts.body];
                    ts.restore(&self.states, &f.origin, &f.axes, &mut self.wrenches);
                }
            }
        });
        timed!(self.profile, "rails", self.rails_from_beams());
        timed!(self.profile, "contact (8 wheels)", self.contact())?;
        if self.hitch.is_some() {
            timed!(self.profile, "train", self.pull(integrate_haul));
        } else {
            timed!(self.profile, "hauling", self.haul(integrate_haul));
        }
        Ok(())
    }

    fn refresh_frame(&mut self, i: usize) {
        let s = project(self.track, &self.states[i].position, self.body_s[i]);
        self.body_s[i] = s;
        self.frames[i] = TrackFrame::at(self.track, s);
    }

    /// Brings the along-track position and track frame of every body up to date, unless they
    /// are less than 10 steps old (1 ms at the default step: the design frame of a body moving
    /// 2 cm along a curve turns by microradians, far below any signal of interest).
    pub fn refresh_frames(&mut self) {
        if self.step_count == 0 || self.step_count >= self.frames_step + 10 {
            for i in 0..self.states.len() {
                self.refresh_frame(i);
            }
            self.frames_step = self.step_count;
        }
    }

    /// Runs the settling phase (not recorded).
    pub fn settle(&mut self) -> Result<()> {
        while self.time < -0.5 * self.cfg.dt {
            self.step()?;
        }
        Ok(())
    }

    /// Elements, for inspection.
    pub fn elements(&self) -> &[Element] {
        &self.vehicle.elements
    }
}

pub use crate::vehicle::wheel_name;
