//! The train around the 3-D wagon in a run: the consist's longitudinal dynamics
//! ([`crate::train`]) stepped beside the multibody, its two couplers acting on the carbody at
//! their pivots and at their real height, in the direction in which the neighbouring vehicles
//! stand on the track, and the air brake's shoes on the wagon's treads.
//!
//! - **Coupler force**: the 1-D train gives each coupler's force from the along-track
//!   distance between the wagon (the carbody's place, moved by the 3-D run) and its
//!   neighbours (moved by the train). Tension positive.
//! - **Direction**: from the wagon's pivot (on the carbody, `±arm` from its centre at the
//!   consist's coupler height, [`COUPLER_HEIGHT`] in the built-in files) to the neighbour's
//!   pivot. A neighbour is a rigid body whose axis is
//!   the chord between its bogie centres on the track centre line, at
//!   [`BOGIE_SHARE`] of its length either side of its centre (an estimate for vehicles whose
//!   bogie spacing the consist does not give; the C80's is 8.2 m of 12 m), offset sideways by
//!   the carbody's own mean offset from its bogie chord (identical wagons curve alike). In a
//!   curve of radius R both couplers swing inward by L/(2R) (L the cars' centre spacing), so
//!   tension F pulls the wagon inward by F·L/R, compression pushes it outward.
//! - **Brake shoes**: the train's shoe force on the wagon, shared by its wheels, brakes each
//!   wheelset's spin with μ·N·r per wheel; the reaction turns the body nearest each wheel
//!   (the side frame that carries the brake beam).
//!
//! The train steps every [`TRAIN_EVERY`] run steps, taking the wagon where the run has
//! moved it; in between the wagon reads its couplers every step from the neighbours moved on
//! at their velocities. The carbody's along-track pull is linearly implicit in the couplers'
//! stiffness and damping (the draft gears' branch switch is a steep damping).

use crate::error::Result;
use crate::track::Track;
use crate::train::{Consist, Neighbour, Route, Train, WagonAt};
use crate::vehicle::{BodyState, Vehicle, Wrench};
use nalgebra::Vector3;

/// Height of the coupler centre line over the rail top in the built-in consists, m: 880 mm,
/// the figure commonly given for Chinese freight wagons; an estimate (no public text of the
/// standard was found). A consist file's `coupler.height_m` sets it.
pub const COUPLER_HEIGHT: f64 = 0.880;

/// A neighbour's bogie centres stand this share of its length either side of its centre
/// (the C80: 4.1 m of 12 m). An estimate for other vehicles.
pub const BOGIE_SHARE: f64 = 4.1 / 12.0;

/// The train moves on every this many steps of the run (8.3 ms at the default 5/6 ms step):
/// the linearly implicit train step is stable there, and the wagon reads its couplers every
/// step from the neighbours moved on at their velocities
/// ([`Train::coupler_jacobians_ahead`]). A 212-vehicle train step costs about 5.7 µs
/// (tests/train.rs, release): every 10th step keeps the train under a tenth of the run's step
/// (assets/docs/performance.md).
pub const TRAIN_EVERY: u32 = 10;

/// Steps between refreshes of the neighbours' chords (their place on the track moves by
/// under 0.3 m in that time; the chord is shifted along itself in between).
const REFRESH_STEPS: u64 = 10;

/// Time constant of the carbody's mean lateral offset the neighbours share, s: long against
/// the wagon's own lateral modes (about 1 Hz), short against a curve's passage.
pub const OFFSET_TIME: f64 = 2.0;

/// What a run's train is: the consist and the wagon's place in it.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainSetup {
    /// The consist.
    pub consist: Consist,
    /// The 3-D wagon's place as a fraction of the train's length from the head (None: the
    /// consist file's own `position`).
    pub position: Option<f64>,
}

/// The track as the train sees it: grade and curvature; beyond the described track the line
/// goes on straight at its end's grade.
pub struct TrackRoute<'a>(pub &'a Track);

impl Route for TrackRoute<'_> {
    fn grade(&self, s: f64) -> f64 {
        let s = s.clamp(0.0, self.0.length());
        self.0.spec().profile.at(s).1
    }

    fn curvature(&self, s: f64) -> f64 {
        // Straight beyond the ends, as the neighbours' geometry is ([`Hitch`]).
        if (0.0..=self.0.length()).contains(&s) {
            self.0.centre_line(s).3
        } else {
            0.0
        }
    }
}

/// One coupler of the wagon as the last step left it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CouplerReading {
    /// Force, N, tension positive.
    pub force: f64,
    /// Angle of the coupler relative to the carbody's axis, rad, + toward the carbody's left.
    pub yaw: f64,
}

/// A neighbour's body axis on the track, as last refreshed.
#[derive(Debug, Clone, Copy)]
struct Chord {
    /// Along-track position of its centre when refreshed, m.
    centre: f64,
    /// World point of its centre at rail level, m.
    mid: Vector3<f64>,
    /// Unit vector along it (+ in the direction of travel).
    along: Vector3<f64>,
    /// Unit vector up, normal to the track plane.
    up: Vector3<f64>,
    /// Unit vector to the left, in the track plane.
    left: Vector3<f64>,
}

/// The train hitched to a run's carbody.
#[derive(Clone)]
pub struct Hitch {
    train: Train,
    /// The carbody.
    pub body: usize,
    /// Carbody frame position of the front pivot (the rear one mirrors its x), m.
    pivot_local: Vector3<f64>,
    chords: [Option<Chord>; 2],
    refreshed: Option<u64>,
    /// Front and rear couplers after the last force evaluation.
    pub readings: [CouplerReading; 2],
    /// Per wheelset: the body that takes each wheel's brake reaction (left, right).
    brake_reactions: Vec<[usize; 2]>,
    wheelsets: Vec<usize>,
    wheel_radius: f64,
    /// The carbody's lateral offset from the track centre line, m, averaged over
    /// [`OFFSET_TIME`]: the neighbours stand offset by it, as identical wagons in the same
    /// curve at the same speed do on average. `None` until the first step.
    offset: Option<f64>,
    /// Half the wagon's length over its couplers, m.
    half_length: f64,
    /// Steps of the run since the train's last step.
    since: u32,
    /// The coupler centre line's height over the rail, m (the consist's).
    height: f64,
    /// The carbody's mass, kg (the mass the couplers act on directly).
    mass: f64,
}

impl Hitch {
    /// The train of `setup` at steady state at the carbody's start `s0`, moving at `speed`.
    pub fn new(
        setup: &TrainSetup,
        vehicle: &Vehicle,
        body: usize,
        track: &Track,
        s0: f64,
        speed: f64,
    ) -> Result<Hitch> {
        let at = setup.position.map_or(WagonAt::File, WagonAt::Fraction);
        let train = Train::new(setup.consist.clone(), at, s0, speed, &TrackRoute(track))?;
        let arm = train.wagon_pivot_arm();
        let half_length = 0.5 * train.consist().vehicles[train.wagon_index()].length;
        let cg = vehicle.bodies[body].position;
        let height = train.consist().coupler_height;
        let pivot_local = Vector3::new(arm, 0.0, height - cg.z);
        let wheelsets = &vehicle.contact.wheelsets;
        let half = vehicle.contact.geometry.tape_circle_half;
        let brake_reactions = wheelsets
            .iter()
            .map(|&w| {
                let c = vehicle.bodies[w].position;
                let nearest = |y: f64| {
                    let p = Vector3::new(c.x, c.y + y, c.z);
                    (0..vehicle.bodies.len())
                        .filter(|&i| i != body && !wheelsets.contains(&i))
                        .min_by(|&a, &b| {
                            let da = (vehicle.bodies[a].position - p).norm();
                            let db = (vehicle.bodies[b].position - p).norm();
                            da.total_cmp(&db)
                        })
                        .unwrap_or(body)
                };
                [nearest(half), nearest(-half)]
            })
            .collect();
        Ok(Hitch {
            train,
            body,
            pivot_local,
            chords: [None, None],
            refreshed: None,
            readings: [CouplerReading::default(); 2],
            brake_reactions,
            wheelsets: wheelsets.clone(),
            wheel_radius: vehicle.contact.geometry.nominal_radius,
            offset: None,
            half_length,
            since: 0,
            height,
            mass: vehicle.bodies[body].mass,
        })
    }

    /// The train (its vehicles, driver and brake).
    pub fn train(&self) -> &Train {
        &self.train
    }

    /// The centre-line point at `s` and the track's up direction there; beyond the track's
    /// ends the line goes on straight along its end's direction (a neighbour may stand off
    /// the described track).
    fn point(track: &Track, s: f64) -> (Vector3<f64>, Vector3<f64>) {
        let end = s.clamp(0.0, track.length());
        let f = super::TrackFrame::at(track, end);
        (
            f.origin + f.axes.column(0) * (s - end),
            f.axes.column(2).into_owned(),
        )
    }

    fn chord(track: &Track, n: &Neighbour) -> Chord {
        let a = BOGIE_SHARE * 2.0 * n.half_length;
        let (o1, z1) = Self::point(track, n.centre - a);
        let (o2, z2) = Self::point(track, n.centre + a);
        let along = (o2 - o1).normalize();
        let up = (z1 + z2).normalize();
        Chord {
            centre: n.centre,
            mid: 0.5 * (o1 + o2),
            along,
            up,
            left: up.cross(&along).normalize(),
        }
    }

    /// The couplers' forces on the carbody and the shoes' torques on the wheelsets, added to
    /// `wrenches`; with `advance`, the train then moves on by `dt` (the run's accepted step).
    #[allow(clippy::too_many_arguments)]
    pub fn apply(
        &mut self,
        track: &Track,
        states: &[BodyState],
        wagon_s: f64,
        frame: &super::TrackFrame,
        step: u64,
        dt: f64,
        advance: bool,
        wrenches: &mut [Wrench],
    ) {
        let st = &states[self.body];
        let wagon_v = st.velocity.dot(&frame.axes.column(0));
        let rot = st.rotation.to_rotation_matrix();
        if self
            .refreshed
            .is_none_or(|r| step >= r + REFRESH_STEPS || step < r)
        {
            let n = self.train.neighbours();
            self.chords = [
                n.front.map(|x| Self::chord(track, &x)),
                n.rear.map(|x| Self::chord(track, &x)),
            ];
            // The wagon's lateral offset at coupler height from its own chord (the line of
            // its bogie centres on the track): what identical neighbours share on average.
            let own = Self::chord(
                track,
                &Neighbour {
                    index: self.train.wagon_index(),
                    centre: wagon_s,
                    pivot: wagon_s,
                    half_length: self.half_length,
                    pivot_inset: 0.0,
                },
            );
            let at_height = st.position + rot * Vector3::new(0.0, 0.0, self.pivot_local.z);
            let y = (at_height - own.mid - own.up * self.height).dot(&own.left);
            let waited = self.refreshed.map_or(0, |r| step.saturating_sub(r)) as f64 * dt;
            self.offset = Some(match self.offset {
                Some(m) => m + (y - m) * (waited / OFFSET_TIME).min(1.0),
                None => y,
            });
            self.refreshed = Some(step);
        }
        let offset = self.offset.unwrap_or(0.0);
        // The wagon has moved over the train's interval: the train catches up first.
        if advance && self.since >= TRAIN_EVERY {
            self.train.step_to(
                f64::from(self.since) * dt,
                wagon_s,
                wagon_v,
                &TrackRoute(track),
            );
            self.since = 0;
        }
        let ahead = f64::from(self.since) * dt;
        let (front, rear) = self.train.coupler_jacobians_ahead(ahead, wagon_s, wagon_v);
        let (f_front, f_rear) = (front.force, rear.force);
        let n = self.train.neighbours();
        for (k, (force, neighbour)) in [(f_front, n.front), (f_rear, n.rear)]
            .into_iter()
            .enumerate()
        {
            let (Some(nb), Some(ch)) = (neighbour, self.chords[k]) else {
                self.readings[k] = CouplerReading::default();
                continue;
            };
            let sign = if k == 0 { 1.0 } else { -1.0 };
            let local = Vector3::new(sign * self.pivot_local.x, 0.0, self.pivot_local.z);
            let mine = st.position + rot * local;
            let moved = self.train.velocities()[nb.index] * ahead;
            let theirs = ch.mid
                + ch.along * (nb.pivot + moved - ch.centre)
                + ch.left * offset
                + ch.up * self.height;
            let Some(dir) = (theirs - mine).try_normalize(1e-9) else {
                continue;
            };
            wrenches[self.body].add_at(dir * force, mine, st.position);
            let d = rot.transpose() * dir;
            self.readings[k] = CouplerReading {
                force,
                yaw: crate::angle::atan2(d.y, sign * d.x),
            };
        }
        // Linearly implicit in the couplers' along-track stiffness and damping (the draft
        // gears' branch switch is a steep damping, up to about 5·10⁷ N·s/m: explicit, it
        // would ring an empty carbody at this step): the carbody's whole along-track force
        // (every other force is in its wrench already) becomes what the implicit Euler step of
        // its along-track motion gives, F·m / (m + (c + k·Δt)·Δt). At rest in the train (F
        // = 0) nothing changes.
        let c = front.damping + rear.damping;
        let k = front.stiffness + rear.stiffness;
        let along = frame.axes.column(0).into_owned();
        let f_along = wrenches[self.body].force.dot(&along);
        let keep = self.mass / (self.mass + (c + k * dt) * dt);
        wrenches[self.body].force -= along * (f_along * (1.0 - keep));
        let shoes = self.train.wagon_brake();
        if shoes.normal_force > 0.0 {
            let wheels = 2.0 * self.brake_reactions.len() as f64;
            let per_wheel = shoes.friction * shoes.normal_force / wheels * self.wheel_radius;
            for (&body, react) in self.wheelsets.iter().zip(&self.brake_reactions) {
                let axle = states[body].rotation * Vector3::y();
                let spin = states[body].angular_velocity.dot(&axle);
                // Opposes the spin, smoothly through zero (0.1 rad/s: 4 cm/s at the tread).
                let (sg, _) = crate::train::smooth_sign(spin, 0.1);
                for &r in react {
                    let t = axle * (per_wheel * sg);
                    wrenches[body].torque -= t;
                    wrenches[r].torque += t;
                }
            }
        }
        if advance {
            self.since += 1;
        }
    }
}

/// The built-in consists' files (`vehicles/NAME.consist.toml`), embedded: a run finds them
/// from any folder.
pub const BUILTIN_CONSISTS: [(&str, &str); 4] = [
    (
        "daqin_10kt",
        include_str!("../../vehicles/daqin_10kt.consist.toml"),
    ),
    (
        "daqin_10kt_empty",
        include_str!("../../vehicles/daqin_10kt_empty.consist.toml"),
    ),
    (
        "daqin_20kt",
        include_str!("../../vehicles/daqin_20kt.consist.toml"),
    ),
    (
        "daqin_20kt_empty",
        include_str!("../../vehicles/daqin_20kt_empty.consist.toml"),
    ),
];

/// The word that names no train: the wagon alone, held at its speed by `[hauling]`.
pub const ALONE: &str = "none";

impl TrainSetup {
    /// The train `spec` names: [`ALONE`] (None), a built-in consist's name
    /// ([`BUILTIN_CONSISTS`]) or a consist file (relative to `base`), with the wagon at
    /// `position` (a fraction of the train's length from the head; None: the file's own).
    /// The position is checked against the consist here, naming `field`.
    pub fn resolve(
        spec: &str,
        position: Option<f64>,
        base: &std::path::Path,
        field: &str,
    ) -> Result<Option<TrainSetup>> {
        if spec == ALONE {
            if let Some(p) = position {
                return Err(crate::error::Error::Domain(format!(
                    "{field} = \"{ALONE}\" with position {p}: a position in no train; name a consist"
                )));
            }
            return Ok(None);
        }
        // A file that exists is used as given (as vehicle and track files are); else a
        // built-in name.
        let file = base.join(spec);
        let builtin = BUILTIN_CONSISTS
            .iter()
            .find(|(n, _)| *n == spec)
            .filter(|_| !file.is_file());
        let consist = match builtin {
            Some((name, text)) => Consist::parse(
                text,
                std::path::Path::new(&format!("vehicles/{name}.consist.toml")),
            )?,
            None => {
                let path = file;
                if !path.is_file() {
                    return Err(crate::error::Error::Domain(format!(
                        "{field} = \"{spec}\": neither a built-in consist ({}) nor a file ({}); `{ALONE}` runs the wagon alone",
                        BUILTIN_CONSISTS
                            .iter()
                            .map(|(n, _)| *n)
                            .collect::<Vec<_>>()
                            .join(", "),
                        path.display()
                    )));
                }
                Consist::load(&path)?
            }
        };
        if let Some(p) = position {
            consist
                .index_at(p)
                .map_err(|e| crate::error::Error::Domain(format!("{field}: position {p}: {e}")))?;
        }
        Ok(Some(TrainSetup { consist, position }))
    }
}

/// The wagon's longitudinal drive: alone, the vehicle file's speed control; in a train, the
/// train.
impl super::Simulation<'_> {
    /// Speed control: the rest of the train pulls or brakes the wagon at the carbody, PI on
    /// the along-track speed plus the gradient's share of the weight as feed-forward.
    pub(super) fn haul(&mut self, integrate: bool) {
        let Some(h) = self.vehicle.hauling else {
            return;
        };
        let f = self.frames[h.body];
        let along = f.axes.column(0).into_owned();
        let v = self.states[h.body].velocity.dot(&along);
        let err = self.cfg.speed - v;
        if integrate {
            self.hauling_integral += err * self.cfg.dt;
        }
        let m = self.vehicle.mass();
        let force = m
            * (h.proportional * err
                + h.integral * self.hauling_integral
                // sin(atan g) = g / √(1 + g²)
                + crate::GRAVITY * f.point.gradient / (1.0 + f.point.gradient.powi(2)).sqrt());
        self.wrenches[h.body].force += along * force;
    }

    /// The train: its couplers' forces on the carbody and its shoes on the treads; with
    /// `advance`, the train moves on by one step.
    pub(super) fn pull(&mut self, advance: bool) {
        let Some(h) = self.hitch.as_deref_mut() else {
            return;
        };
        h.apply(
            self.track,
            &self.states,
            self.body_s[h.body],
            &self.frames[h.body],
            self.step_count,
            self.cfg.dt,
            advance,
            &mut self.wrenches,
        );
    }

    /// Whether the run records the couplers' channels: in a train, or asked to
    /// ([`super::SimConfig::coupler_channels`]).
    pub fn records_couplers(&self) -> bool {
        self.hitch.is_some() || self.cfg.coupler_channels
    }

    /// The train the run's carbody is coupled into, if any.
    pub fn hitch(&self) -> Option<&Hitch> {
        self.hitch.as_deref()
    }
}
