//! The discrete track's state and step: two rails (lateral and vertical beams), a sleeper at
//! every interior fastener (vertical, lateral, roll) and a ballast block under each rail seat,
//! in a window that shifts by whole bays to stay centred on the vehicle.
//!
//! A step: [`TrackDynamics::begin`] (each rail mode's change under its own springs and the
//! sleepers' side of the pads, taken at the step's start), then the wheels' impulses
//! ([`TrackDynamics::free`] tells a wheel's solve how the rail under it moves and yields;
//! [`TrackDynamics::impulse`] applies what it settled on), then [`TrackDynamics::end`]: the
//! rails move, then the sleepers on the rails' new state, then the ballast blocks on the
//! sleepers' (each body linearly implicit in its own springs and dampers, its neighbours
//! taken as they stand).

use super::{Beam, DiscreteSupport};

/// Left and right rail (track y positive to the left).
const SIDES: [f64; 2] = [1.0, -1.0];

/// One degree of freedom: displacement and velocity.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Dof {
    x: f64,
    v: f64,
}

impl Dof {
    /// Moves under the force `f` (N, all forces at the current state) with its own stiffness
    /// `k` and damping `c` taken at the step's end, mass `m`, step `dt`.
    #[inline]
    fn step(&mut self, f: f64, m: f64, k: f64, c: f64, dt: f64) {
        let dv = dt * (f - k * dt * self.v) / (m + dt * c + dt * dt * k);
        self.v += dv;
        self.x += dt * self.v;
    }
}

/// A sleeper: vertical (m, up), roll (rad, left seat up) and lateral (m, left).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Sleeper {
    z: Dof,
    roll: Dof,
    y: Dof,
}

/// A force on a rail, held over a step (N; lateral positive to the left, vertical up).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Load {
    /// 0 left rail, 1 right rail.
    pub side: usize,
    /// Along-track position, m.
    pub s: f64,
    /// Lateral force, N.
    pub lateral: f64,
    /// Vertical force, N.
    pub vertical: f64,
}

/// The discrete track in its window.
#[derive(Debug, Clone)]
pub struct TrackDynamics {
    p: DiscreteSupport,
    /// Along-track position of the window's start (a sleeper position), m.
    start: f64,
    /// `[side][0 lateral, 1 vertical]`.
    rails: [[Beam; 2]; 2],
    sleepers: Vec<Sleeper>,
    /// Ballast blocks under the left and right seats.
    ballast: Vec<[Dof; 2]>,
    /// `sin((k+1)π(j+1)/N)`, (N−1)² (symmetric).
    sines: Vec<f64>,
    phi: Vec<f64>,
    /// Scratch: nodal values, modal forces.
    nodes: [Vec<f64>; 2],
    modal: Vec<f64>,
}

impl TrackDynamics {
    /// The track at rest, its window centred on `centre` (m along the track; sleepers at
    /// whole multiples of the spacing).
    pub fn new(p: DiscreteSupport, centre: f64) -> Self {
        let n = p.bays - 1;
        let beam = |ei: f64, pad: super::KelvinVoigt| {
            Beam::new(
                p.bays,
                p.spacing,
                p.rail_mass,
                ei,
                pad.stiffness,
                pad.damping,
            )
        };
        let lat = beam(p.rail_ei_lateral, p.pad_lateral);
        let ver = beam(p.rail_ei_vertical, p.pad_vertical);
        let nb = p.bays as f64;
        let sines = (0..n * n)
            .map(|i| ((i / n + 1) as f64 * ((i % n) + 1) as f64 * std::f64::consts::PI / nb).sin())
            .collect();
        TrackDynamics {
            start: ((centre - 0.5 * p.window()) / p.spacing).round() * p.spacing,
            rails: [[lat.clone(), ver.clone()], [lat, ver]],
            sleepers: vec![Sleeper::default(); n],
            ballast: vec![[Dof::default(); 2]; n],
            sines,
            phi: vec![0.0; n],
            nodes: [vec![0.0; n], vec![0.0; n]],
            modal: vec![0.0; n],
            p,
        }
    }

    /// The parameters.
    pub fn support(&self) -> &DiscreteSupport {
        &self.p
    }

    /// Along-track position of the window's start, m.
    pub fn start(&self) -> f64 {
        self.start
    }

    /// Where `s` lies in the window, m from its start (held inside the window's interior).
    fn local(&self, s: f64) -> f64 {
        let l = self.p.window();
        (s - self.start).clamp(1e-6 * l, (1.0 - 1e-6) * l)
    }

    /// The rail `side`'s lateral and vertical displacement and velocity at `s`: `[y, vy, z,
    /// vz]` (m, m/s; y to the left, z up).
    pub fn rail(&mut self, side: usize, s: f64) -> [f64; 4] {
        let x = self.local(s);
        let (y, vy) = self.rails[side][0].point(x, &mut self.phi);
        let (z, vz) = self.rails[side][1].point(x, &mut self.phi);
        [y, vy, z, vz]
    }

    /// Shifts the window by whole bays so that its centre is within half a bay of `centre`.
    pub fn recentre(&mut self, centre: f64) {
        let n = ((centre - (self.start + 0.5 * self.p.window())) / self.p.spacing).round();
        if n == 0.0 {
            return;
        }
        self.start += n * self.p.spacing;
        let shift = n as i64;
        let len = self.sleepers.len();
        let moved = |j: usize| -> Option<usize> {
            let i = j as i64 + shift;
            (0..len as i64).contains(&i).then_some(i as usize)
        };
        for rail in self.rails.iter_mut().flatten() {
            for which in 0..2 {
                let m = if which == 0 { &rail.q } else { &rail.v };
                rail.nodes_from_modes(m, &self.sines, &mut self.nodes[0]);
                for j in 0..len {
                    self.nodes[1][j] = moved(j).map_or(0.0, |i| self.nodes[0][i]);
                }
                rail.modes_from_nodes(&self.nodes[1], &self.sines, &mut self.modal);
                let m = if which == 0 { &mut rail.q } else { &mut rail.v };
                m.copy_from_slice(&self.modal);
            }
        }
        let sleepers = (0..len)
            .map(|j| moved(j).map_or(Sleeper::default(), |i| self.sleepers[i]))
            .collect();
        let ballast = (0..len)
            .map(|j| moved(j).map_or([Dof::default(); 2], |i| self.ballast[i]))
            .collect();
        self.sleepers = sleepers;
        self.ballast = ballast;
    }

    /// Starts a step of `dt` s: every rail mode's change under its own springs and dampers
    /// and the sleepers' side of the pads.
    pub fn begin(&mut self, dt: f64) {
        let (b, pl, pv) = (
            self.p.seat_half_distance,
            self.p.pad_lateral,
            self.p.pad_vertical,
        );
        for (side, sign) in SIDES.iter().enumerate() {
            for dir in 0..2 {
                for (f, sl) in self.nodes[0].iter_mut().zip(&self.sleepers) {
                    *f = if dir == 0 {
                        pl.stiffness * sl.y.x + pl.damping * sl.y.v
                    } else {
                        pv.stiffness * (sl.z.x + sign * b * sl.roll.x)
                            + pv.damping * (sl.z.v + sign * b * sl.roll.v)
                    };
                }
                let rail = &mut self.rails[side][dir];
                // Modal force Σ_j φ_k(x_j)·f_j: the DST-I of the nodal forces.
                rail.nodes_from_modes(&self.nodes[0], &self.sines, &mut self.modal);
                rail.begin(dt, &self.modal);
            }
        }
    }

    /// Rail `side`'s velocity change so far in the step at `s` in direction `dir` (0 lateral,
    /// 1 vertical), m/s, and its mobility there, m/s per N·s.
    pub fn free(&mut self, side: usize, dir: usize, s: f64) -> (f64, f64) {
        let x = self.local(s);
        self.rails[side][dir].free(x, &mut self.phi)
    }

    /// An impulse on rail `side` at `s` in direction `dir` (N·s).
    pub fn impulse(&mut self, side: usize, dir: usize, s: f64, i: f64) {
        let x = self.local(s);
        self.rails[side][dir].impulse(x, i, &mut self.phi);
    }

    /// Ends the step: the rails move, then the sleepers, then the ballast.
    pub fn end(&mut self, dt: f64) {
        let p = self.p;
        let n = self.sleepers.len();
        // Rail nodal displacement and velocity, [side][dir], after the rails' step.
        let mut nodal = [
            [(vec![0.0; n], vec![0.0; n]), (vec![0.0; n], vec![0.0; n])],
            [(vec![0.0; n], vec![0.0; n]), (vec![0.0; n], vec![0.0; n])],
        ];
        for (side, rails) in self.rails.iter_mut().enumerate() {
            for (dir, rail) in rails.iter_mut().enumerate() {
                rail.end(dt);
                let (w, v) = &mut nodal[side][dir];
                rail.nodes_from_modes(&rail.q, &self.sines, w);
                rail.nodes_from_modes(&rail.v, &self.sines, v);
            }
        }
        let (b, pv, pl, bal) = (
            p.seat_half_distance,
            p.pad_vertical,
            p.pad_lateral,
            p.ballast,
        );
        let (kz, cz) = (
            2.0 * (pv.stiffness + bal.stiffness),
            2.0 * (pv.damping + bal.damping),
        );
        let (ky, cy) = (
            2.0 * pl.stiffness + p.sleeper_lateral.stiffness,
            2.0 * pl.damping + p.sleeper_lateral.damping,
        );
        for (j, (sl, bl)) in self.sleepers.iter_mut().zip(&self.ballast).enumerate() {
            let (mut fz, mut mx, mut fy) = (0.0, 0.0, 0.0);
            for (side, sign) in SIDES.iter().enumerate() {
                let seat = sl.z.x + sign * b * sl.roll.x;
                let seat_v = sl.z.v + sign * b * sl.roll.v;
                let f = pv.stiffness * (nodal[side][1].0[j] - seat)
                    + pv.damping * (nodal[side][1].1[j] - seat_v)
                    - bal.stiffness * (seat - bl[side].x)
                    - bal.damping * (seat_v - bl[side].v);
                fz += f;
                mx += sign * b * f;
                fy += pl.stiffness * (nodal[side][0].0[j] - sl.y.x)
                    + pl.damping * (nodal[side][0].1[j] - sl.y.v);
            }
            fy -= p.sleeper_lateral.stiffness * sl.y.x + p.sleeper_lateral.damping * sl.y.v;
            sl.z.step(fz, p.sleeper_mass, kz, cz, dt);
            sl.roll
                .step(mx, p.sleeper_roll_inertia, b * b * kz, b * b * cz, dt);
            sl.y.step(fy, p.sleeper_mass, ky, cy, dt);
        }
        let (sh, sg) = (p.ballast_shear, p.subgrade);
        let kb = bal.stiffness + sg.stiffness + 2.0 * sh.stiffness;
        let cb = bal.damping + sg.damping + 2.0 * sh.damping;
        let old = self.ballast.clone();
        for (j, (bl, sl)) in self.ballast.iter_mut().zip(&self.sleepers).enumerate() {
            for (side, sign) in SIDES.iter().enumerate() {
                let seat = sl.z.x + sign * b * sl.roll.x;
                let seat_v = sl.z.v + sign * b * sl.roll.v;
                let me = old[j][side];
                let nb = |k: Option<usize>| {
                    k.and_then(|k| old.get(k))
                        .map_or(Dof::default(), |d| d[side])
                };
                let (l, r) = (nb(j.checked_sub(1)), nb(Some(j + 1)));
                let f = bal.stiffness * (seat - me.x) + bal.damping * (seat_v - me.v)
                    - sg.stiffness * me.x
                    - sg.damping * me.v
                    - sh.stiffness * (2.0 * me.x - l.x - r.x)
                    - sh.damping * (2.0 * me.v - l.v - r.v);
                bl[side].step(f, p.ballast_mass, kb, cb, dt);
            }
        }
    }

    /// One whole step under loads held over it (the track alone: tests, checks).
    pub fn step(&mut self, dt: f64, loads: &[Load]) {
        self.begin(dt);
        for l in loads {
            self.impulse(l.side, 0, l.s, l.lateral * dt);
            self.impulse(l.side, 1, l.s, l.vertical * dt);
        }
        self.end(dt);
    }

    /// Settles the track under loads held still, `seconds` of steps of `dt`.
    pub fn settle(&mut self, dt: f64, seconds: f64, loads: &[Load]) {
        for _ in 0..(seconds / dt).ceil() as usize {
            self.step(dt, loads);
        }
    }
}
