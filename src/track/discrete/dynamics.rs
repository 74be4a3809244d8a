//! The discrete track's state and step, one wavenumber at a time.
//!
//! With identical sleepers at every interior fastener of the window, ballast shear between
//! neighbours and everything at rest beyond the window's ends, every field of the track (each
//! rail's vertical and lateral deflection at the fasteners, the sleepers' motion, the ballast
//! blocks') is a sum of the same sines `sin(kπj/N)`, k = 1 … N−1, and the sines do not mix:
//! the track falls apart into N−1 independent small systems, one per wavenumber, of six
//! vertical degrees of freedom (the two rails' amplitudes, the sleepers' bounce and roll, the
//! two ballast blocks') and three lateral (the two rails, the sleepers' sway). A rail's modal
//! coordinate `q_k` of `φ_k = √(2/mL)·sin(kπx/L)` is its amplitude at the fasteners divided
//! by `√(2/mL)`, so the rail's amplitude behaves as a mass `m·s` per fastener with the bending
//! stiffness `s·EI·(kπ/L)⁴` of its mode; the ballast's shear adds `2·k_w·(1 − cos(kπ/N))` to
//! each block. A wheel's force `P` at `x` enters each amplitude as `(2/N)·sin(kπx/L)·P` and
//! the rail's deflection there is `Σ_k a_k·sin(kπx/L)`.
//!
//! Each system steps as the vehicle's wheelsets do, symplectic Euler with its springs and
//! dampers shared into the step's end, its inverse built once per step length:
//! `(M + Δt/2·C + Δt²/12·K + Δt²·B)·Δv = Δt·(F − K·x − B·(x + Δt·v) − C·v)`, `Δx = Δt·(v + Δv)`.
//! `B`, the rails' bending and their own pads, is backward Euler: the bending modes up to
//! 1.4 kHz, which no step of the run follows, are damped rather than left ringing (with no
//! numerical damping on them, α = ¼, Q's standard deviation was 34 % off at 0.5 ms on
//! R 400 m at 100 km/h). `K`, the rest of the pads, the sleepers and the ballast, takes Fox and
//! Goodwin's share (α = 1/12: a linear spring's frequency right to fourth order, stable below
//! ω·Δt = 2.45, no numerical damping); the damping `C` takes θ = ½. The trapezoidal rule's
//! displacement `Δt·(v + Δv/2)` is not the one the wheel's solve takes for the rail, and burst.
//! The nodal fields are needed only when the window shifts by whole bays (every 0.6 m of
//! travel): the sines' transform and its inverse, exact.

use super::DiscreteSupport;
use nalgebra::{SVector, Vector3, Vector6};

/// Left and right rail (track y positive to the left): the sign of a rail seat's lever
/// about the sleeper's centre.
const SIDES: [f64; 2] = [1.0, -1.0];

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

impl Load {
    /// A wheelset's two wheels at `s`: `lateral` and `vertical` N on each rail.
    pub fn wheelset(s: f64, lateral: f64, vertical: f64) -> [Load; 2] {
        [0, 1].map(|side| Load {
            side,
            s,
            lateral,
            vertical,
        })
    }
}

/// One wavenumber's mass, stiffness and damping (`D` degrees of freedom).
#[derive(Debug, Clone, Copy)]
struct System<const D: usize> {
    /// The rails' bending (diagonal), taken whole at the step's end.
    bend: SVector<f64, D>,
    k: nalgebra::SMatrix<f64, D, D>,
    c: nalgebra::SMatrix<f64, D, D>,
    /// `(M + Δt/2·C + Δt²/12·K + Δt²·B)⁻¹` at the current step (`B` the bending).
    inv: nalgebra::SMatrix<f64, D, D>,
    /// The step's free velocity change from the displacement and from the velocity:
    /// `−Δt·inv·(K + B)` and `−Δt·inv·(C + Δt·B)`.
    from_x: nalgebra::SMatrix<f64, D, D>,
    from_v: nalgebra::SMatrix<f64, D, D>,
    m: SVector<f64, D>,
}

impl<const D: usize> System<D> {
    /// No spring yet, masses (or inertias) `m`.
    fn new(m: SVector<f64, D>) -> Self {
        let zero = nalgebra::SMatrix::<f64, D, D>::zeros();
        System {
            bend: SVector::zeros(),
            k: zero,
            c: zero,
            inv: zero,
            from_x: zero,
            from_v: zero,
            m,
        }
    }

    /// The rails' own stiffness (their diagonal in `k`: the pads' rail side) moved into the
    /// backward-Euler part beside their bending.
    fn rails_backward_euler(&mut self) {
        for side in RAIL {
            self.bend[side] += self.k[(side, side)];
            self.k[(side, side)] = 0.0;
        }
    }

    /// Adds a spring `k` and damper `c` whose elongation is `e·x`.
    fn spring(&mut self, e: SVector<f64, D>, k: f64, c: f64) {
        self.k += e * e.transpose() * k;
        self.c += e * e.transpose() * c;
    }

    fn factor(&mut self, dt: f64) {
        let bend = nalgebra::SMatrix::<f64, D, D>::from_diagonal(&self.bend);
        let a = nalgebra::SMatrix::<f64, D, D>::from_diagonal(&self.m)
            + self.c * (0.5 * dt)
            + self.k * (dt * dt / 12.0)
            + bend * (dt * dt);
        self.inv = a.try_inverse().unwrap_or_else(nalgebra::SMatrix::zeros);
        self.from_x = self.inv * (self.k + bend) * -dt;
        self.from_v = self.inv * (self.c + bend * dt) * -dt;
    }
}

/// One wavenumber's state: displacement, velocity and the step's velocity change so far.
#[derive(Debug, Clone, Copy)]
struct State<const D: usize> {
    x: SVector<f64, D>,
    v: SVector<f64, D>,
    dv: SVector<f64, D>,
}

impl<const D: usize> Default for State<D> {
    fn default() -> Self {
        State {
            x: SVector::zeros(),
            v: SVector::zeros(),
            dv: SVector::zeros(),
        }
    }
}

/// Vertical degrees of freedom: rails (left, right), sleeper bounce and roll, ballast (left,
/// right). Lateral: rails (left, right), sleeper sway.
const RAIL: [usize; 2] = [0, 1];

/// One direction of the track (lateral, `D` = 3, or vertical, 6): every wavenumber's system
/// and state.
#[derive(Debug, Clone)]
struct Direction<const D: usize> {
    systems: Vec<System<D>>,
    states: Vec<State<D>>,
}

impl<const D: usize> Direction<D> {
    fn new(systems: Vec<System<D>>) -> Self {
        let states = vec![State::default(); systems.len()];
        Direction { systems, states }
    }

    /// Rail `r`'s displacement and velocity at the point whose sines are `sines`.
    fn point(&self, sines: &[f64], r: usize) -> (f64, f64) {
        let (mut x, mut v) = (0.0, 0.0);
        for (sn, st) in sines.iter().zip(&self.states) {
            x += sn * st.x[r];
            v += sn * st.v[r];
        }
        (x, v)
    }

    fn begin(&mut self) {
        for (st, sys) in self.states.iter_mut().zip(&self.systems) {
            st.dv = sys.from_x * st.x + sys.from_v * st.v;
        }
    }

    /// Rail `r`'s velocity change so far and its mobility at the point of `sines`; `g` is
    /// `2/N`.
    fn free(&self, sines: &[f64], r: usize, g: f64) -> (f64, f64) {
        let (mut dv, mut w) = (0.0, 0.0);
        for ((sn, st), sys) in sines.iter().zip(&self.states).zip(&self.systems) {
            dv += sn * st.dv[r];
            w += g * sn * sn * sys.inv[(r, r)];
        }
        (dv, w)
    }

    /// An impulse on rail `r` at the point of `sines`, `g` its `2/N` share.
    fn impulse(&mut self, sines: &[f64], r: usize, g: f64) {
        for ((sn, st), sys) in sines.iter().zip(&mut self.states).zip(&self.systems) {
            st.dv += sys.inv.column(r) * (g * sn);
        }
    }

    fn end(&mut self, dt: f64) {
        for st in &mut self.states {
            st.v += st.dv;
            st.x += st.v * dt;
        }
    }

    /// Every field moved by `moved` (amplitudes in, amplitudes out).
    fn shift(&mut self, moved: &impl Fn(Vec<f64>) -> Vec<f64>) {
        for d in 0..D {
            let x = moved(self.states.iter().map(|st| st.x[d]).collect());
            let v = moved(self.states.iter().map(|st| st.v[d]).collect());
            for ((st, x), v) in self.states.iter_mut().zip(x).zip(v) {
                (st.x[d], st.v[d]) = (x, v);
            }
        }
    }
}

/// The discrete track in its window.
#[derive(Debug, Clone)]
pub struct TrackDynamics {
    p: DiscreteSupport,
    /// Along-track position of the window's start (a sleeper position), m.
    start: f64,
    vertical: Direction<6>,
    lateral: Direction<3>,
    /// The step the inverses were built for, s.
    dt: f64,
    /// `sin(kπx/L)` at the last position asked for, k = 1 … N−1, and that position relative
    /// to the window's start.
    sines: Vec<f64>,
    sines_at: f64,
    /// `sin(kπj/N)`, (N−1)², for the window's shifts.
    table: Vec<f64>,
}

impl TrackDynamics {
    /// The track at rest, its window centred on `centre` (m along the track; sleepers at
    /// whole multiples of the spacing).
    pub fn new(p: DiscreteSupport, centre: f64) -> Self {
        let n = p.bays - 1;
        let nb = p.bays as f64;
        let (b, ms) = (p.seat_half_distance, p.rail_mass * p.spacing);
        let mut vertical = Vec::with_capacity(n);
        let mut lateral = Vec::with_capacity(n);
        for k in 1..=n {
            let kappa4 = (k as f64 * std::f64::consts::PI / p.window()).powi(4);
            let shear = 2.0 * (1.0 - (k as f64 * std::f64::consts::PI / nb).cos());
            let mut v = System::new(Vector6::new(
                ms,
                ms,
                p.sleeper_mass,
                p.sleeper_roll_inertia,
                p.ballast_mass,
                p.ballast_mass,
            ));
            for (side, sign) in SIDES.iter().enumerate() {
                let unit = |i: usize| Vector6::from_fn(|r, _| if r == i { 1.0 } else { 0.0 });
                let seat = unit(2) + unit(3) * (sign * b);
                v.bend[side] = p.spacing * p.rail_ei_vertical * kappa4;
                let (pad, bal) = (p.pad_vertical, p.ballast);
                v.spring(unit(side) - seat, pad.stiffness, pad.damping);
                v.spring(seat - unit(4 + side), bal.stiffness, bal.damping);
                let (sg, sh) = (p.subgrade, p.ballast_shear);
                v.spring(unit(4 + side), sg.stiffness, sg.damping);
                v.spring(unit(4 + side), shear * sh.stiffness, shear * sh.damping);
            }
            v.rails_backward_euler();
            vertical.push(v);
            let mut l = System::new(Vector3::new(ms, ms, p.sleeper_mass));
            for side in 0..2 {
                let rail = Vector3::from_fn(|r, _| if r == side { 1.0 } else { 0.0 });
                l.bend[side] = p.spacing * p.rail_ei_lateral * kappa4;
                let pad = p.pad_lateral;
                l.spring(rail - Vector3::z(), pad.stiffness, pad.damping);
            }
            let sl = p.sleeper_lateral;
            l.spring(Vector3::z(), sl.stiffness, sl.damping);
            l.rails_backward_euler();
            lateral.push(l);
        }
        let table = (0..n * n)
            .map(|i| ((i / n + 1) as f64 * ((i % n) + 1) as f64 * std::f64::consts::PI / nb).sin())
            .collect();
        TrackDynamics {
            start: ((centre - 0.5 * p.window()) / p.spacing).round() * p.spacing,
            vertical: Direction::new(vertical),
            lateral: Direction::new(lateral),
            dt: 0.0,
            sines: vec![0.0; n],
            sines_at: f64::NAN,
            table,
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

    /// `sin(kπx/L)` for every wavenumber at `s` (held inside the window) into `self.sines`,
    /// by the Chebyshev recurrence.
    fn sines_at(&mut self, s: f64) {
        let l = self.p.window();
        let x = (s - self.start).clamp(1e-6 * l, (1.0 - 1e-6) * l);
        if x == self.sines_at {
            return;
        }
        self.sines_at = x;
        let a = std::f64::consts::PI * x / l;
        let (c2, mut prev, mut cur) = (2.0 * a.cos(), 0.0, a.sin());
        for p in self.sines.iter_mut() {
            *p = cur;
            let next = c2 * cur - prev;
            prev = cur;
            cur = next;
        }
    }

    /// The rail `side`'s lateral and vertical displacement and velocity at `s`: `[y, vy, z,
    /// vz]` (m, m/s; y to the left, z up).
    pub fn rail(&mut self, side: usize, s: f64) -> [f64; 4] {
        self.sines_at(s);
        let (y, vy) = self.lateral.point(&self.sines, RAIL[side]);
        let (z, vz) = self.vertical.point(&self.sines, RAIL[side]);
        [y, vy, z, vz]
    }

    /// Shifts the window by whole bays so that its centre is within half a bay of `centre`:
    /// every field to the fasteners, moved, and back (the track entering the window at rest).
    pub fn recentre(&mut self, centre: f64) {
        let n = ((centre - (self.start + 0.5 * self.p.window())) / self.p.spacing).round();
        if n == 0.0 {
            return;
        }
        self.start += n * self.p.spacing;
        let shift = n as i64;
        let (len, g) = (self.sines.len(), 2.0 / self.p.bays as f64);
        let table = &self.table;
        // One field's amplitudes to the fasteners, shifted, and back.
        let moved = |amps: Vec<f64>| -> Vec<f64> {
            let nodes: Vec<f64> = (0..len)
                .map(|j| dot(&table[j * len..(j + 1) * len], &amps))
                .collect();
            let shifted: Vec<f64> = (0..len as i64)
                .map(|j| {
                    let i = j + shift;
                    if (0..len as i64).contains(&i) {
                        nodes[i as usize]
                    } else {
                        0.0
                    }
                })
                .collect();
            (0..len)
                .map(|k| g * dot(&table[k * len..(k + 1) * len], &shifted))
                .collect()
        };
        self.vertical.shift(&moved);
        self.lateral.shift(&moved);
    }

    /// Starts a step of `dt` s: every wavenumber's velocity change under its own springs and
    /// dampers.
    pub fn begin(&mut self, dt: f64) {
        if dt != self.dt {
            self.vertical.systems.iter_mut().for_each(|s| s.factor(dt));
            self.lateral.systems.iter_mut().for_each(|s| s.factor(dt));
            self.dt = dt;
        }
        self.vertical.begin();
        self.lateral.begin();
    }

    /// Rail `side`'s velocity change so far in the step at `s` in direction `dir` (0 lateral,
    /// 1 vertical), m/s, and its mobility there (m/s per N·s of impulse), each wavenumber
    /// solved whole (the sleepers and ballast yield within the step).
    pub fn free(&mut self, side: usize, dir: usize, s: f64) -> (f64, f64) {
        self.sines_at(s);
        let (r, g) = (RAIL[side], 2.0 / self.p.bays as f64);
        if dir == 0 {
            self.lateral.free(&self.sines, r, g)
        } else {
            self.vertical.free(&self.sines, r, g)
        }
    }

    /// An impulse on rail `side` at `s` in direction `dir` (N·s).
    pub fn impulse(&mut self, side: usize, dir: usize, s: f64, i: f64) {
        self.sines_at(s);
        let (r, g) = (RAIL[side], 2.0 / self.p.bays as f64 * i);
        if dir == 0 {
            self.lateral.impulse(&self.sines, r, g);
        } else {
            self.vertical.impulse(&self.sines, r, g);
        }
    }

    /// Ends the step: velocities take their change, displacements move with them.
    pub fn end(&mut self, dt: f64) {
        self.vertical.end(dt);
        self.lateral.end(dt);
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

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
