//! The discrete track's state and step, one wavenumber at a time.
//!
//! With identical sleepers at every interior fastener of the window, ballast shear between
//! neighbours and everything at rest beyond the window's ends, every field of the track is a
//! sum of the same sines `sin(kπj/N)`, and the sines do not mix except by aliasing: at the
//! fasteners the rail's wavenumber `2N − k` reads as `−sin(kπj/N)`. The rail carries the
//! wavenumbers 1 … 2N − 1 (half a bay its shortest half-wave, so it bends and twists between
//! the sleepers), the sleepers and the ballast 1 … N − 1. The track falls apart into N − 1
//! independent small systems, one per wavenumber k, of eight vertical degrees of freedom (the
//! two rails' amplitudes of k and of 2N − k, the sleepers' bounce and roll, the two ballast
//! blocks') and nine lateral (each rail's sway and roll, each of k and of 2N − k, and the
//! sleepers' sway), and the pinned–pinned modes (k = N, nodes at every fastener: no pad reaches
//! them), one per rail field. A rail's modal coordinate `q_k` of `φ_k = √(2/(m_k·L))·sin(kπx/L)`
//! (`m_k` the mode's mass per length) is its amplitude divided by `√(2/(m_k·L))`, so the
//! amplitude behaves as a mass `m_k·s` per fastener with the bending stiffness `s·m_k·ω_k²` of
//! its free wave ([`super::DiscreteSupport::bending`]: Timoshenko's flexural branch, or
//! Euler–Bernoulli's `EI·κ⁴`); a roll amplitude as an inertia `ρI₀·s` with St Venant's
//! torsional stiffness `s·GK·κ²` (warping left out); a pad stretches by the difference of the
//! two amplitudes; the ballast's shear adds `2·k_w·(1 − cos(kπ/N))` to each block. A wheel's
//! force `P` at `x` enters each amplitude as `(2/N)·sin(kπx/L)·P` and the rail's deflection
//! there is `Σ_k a_k·sin(kπx/L)`.
//!
//! The rail rolls about its torsion centre (`torsion_centre_depth_m` below its top): a point
//! at height `h` above it and `e` to its left (track y) moves by `(−h·θ, e·θ)` as the rail rolls
//! by `θ` (about the track's x), so a force `(F_y, F_z)` there twists the rail by
//! `e·F_z − h·F_y`. The lateral pad acts at the rail's foot, `a` below the torsion centre
//! (it stretches by `y + a·θ − y_sleeper`), and the vertical pad's two halves at `±b` restrain
//! the roll by `k_v·b²`; that restraint is taken against the ground, not the sleeper's own roll
//! (which lives in the vertical systems, about a tenth of the rail's under a flanging wheel: an
//! estimate that keeps the directions apart).
//!
//! Each system steps as the vehicle's wheelsets do, symplectic Euler with its springs and
//! dampers shared into the step's end, its inverse built once per step length:
//! `(M + Δt/2·C + Δt²/12·K + Δt²·B)·Δv = Δt·(F − K·x − B·(x + Δt·v) − C·v)`, `Δx = Δt·(v + Δv)`.
//! `K`, the pads, sleepers and ballast and the rail waves the step follows, takes Fox and
//! Goodwin's share (α = 1/12: a linear spring's frequency right to fourth order, stable below
//! ω·Δt = 2.45, no numerical damping); the damping `C` takes θ = ½. `B` is backward Euler: each
//! rail degree of freedom whose free frequency (its bending or twisting and its own pad
//! stiffness on its mass) the step does not follow, `ω·Δt > 1` (at 0.1 ms the waves above
//! 1.6 kHz, up to 2.8 kHz at half a bay), and the pinned–pinned modes, which no pad damps. Those
//! are damped rather than left ringing (with no numerical damping on them, α = ¼, Q's standard
//! deviation was 34 % off at 0.5 ms on R 400 m at 100 km/h). Backward Euler on the waves the
//! step follows as well would add a damper `Δt·B` to the pads (6.5 kN·s/m beside their 75 at
//! 0.1 ms) and leave FQ's 20–50 Hz band 6.5 % off at 0.1 ms (physics.md §3.3).
//! The trapezoidal rule's displacement `Δt·(v + Δv/2)` is not the one the wheel's solve takes
//! for the rail, and burst. The nodal fields are needed only when the window shifts by whole
//! bays (every 0.6 m of travel): the sines' transform and its inverse, exact (the rails' at
//! every half bay).

use super::DiscreteSupport;
use super::system::System;
use super::wavenumber::{Direction, Sines, moved, sine_table};
use nalgebra::{Matrix2, SVector, Vector2};

/// Left and right rail (track y positive to the left): the sign of a rail seat's lever
/// about the sleeper's centre.
const SIDES: [f64; 2] = [1.0, -1.0];

/// A force on a rail at its torsion centre's line, held over a step (N, N·m; lateral positive
/// to the left, vertical up, the moment about the track's x).
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
    /// Twisting moment, N·m (+ rolls the rail's head to the right).
    pub torque: f64,
}

impl Load {
    /// A wheelset's two wheels at `s`: `lateral` and `vertical` N on each rail.
    pub fn wheelset(s: f64, lateral: f64, vertical: f64) -> [Load; 2] {
        [0, 1].map(|side| Load {
            side,
            s,
            lateral,
            vertical,
            torque: 0.0,
        })
    }
}

/// Where a wheel's contact lies on its rail: relative to the rail's torsion centre, m.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Lever {
    /// Height above the torsion centre.
    pub height: f64,
    /// Lateral offset, track y (+ left).
    pub lateral: f64,
}

/// The discrete track in its window.
#[derive(Debug, Clone)]
pub struct TrackDynamics {
    p: DiscreteSupport,
    /// Along-track position of the window's start (a sleeper position), m.
    start: f64,
    vertical: Direction<8, 2, 4>,
    lateral: Direction<9, 4, 8>,
    /// The step the inverses were built for, s.
    dt: f64,
    /// The sines at the last [`SINES_KEPT`] positions asked for (a step asks at each
    /// wheelset's), and those positions relative to the window's start; the next to replace.
    sines: Vec<Sines>,
    sines_x: Vec<f64>,
    sines_next: usize,
    /// `sin(kπj/N)`, (N−1)², and `sin(kπi/2N)`, (2N−1)², for the window's shifts.
    table: Vec<f64>,
    table_half: Vec<f64>,
}

/// Vertical degrees of freedom: rails (left, right), sleeper bounce and roll, ballast (left,
/// right), the rails' folded modes (left, right).
const VERTICAL_FIELDS: [(usize, usize); 2] = [(0, 6), (1, 7)];
/// Lateral: rails' sway (left, right), sleeper sway, rails' roll (left, right), and the folded
/// modes of sway and roll.
const LATERAL_FIELDS: [(usize, usize); 4] = [(0, 5), (1, 6), (3, 7), (4, 8)];
/// The lateral fields' order: each rail's sway, then each rail's roll.
const ROLL: usize = 2;

/// How many positions' sines the track keeps: a wheelset's each, for four-axle wagons.
const SINES_KEPT: usize = 4;

/// The unit vector along degree of freedom `i`.
fn unit<const D: usize>(i: usize) -> SVector<f64, D> {
    SVector::<f64, D>::from_fn(|r, _| f64::from(r == i))
}

impl TrackDynamics {
    /// The track at rest, its window centred on `centre` (m along the track; sleepers at
    /// whole multiples of the spacing).
    pub fn new(p: DiscreteSupport, centre: f64) -> Self {
        let n = p.bays - 1;
        let nb = p.bays as f64;
        let b = p.seat_half_distance;
        let kappa = |k: usize| k as f64 * std::f64::consts::PI / p.window();
        // A rail mode of wavenumber k: its amplitude's mass and bending stiffness per fastener.
        let mode = |k: usize, lateral: bool| {
            let (m, kb) = p.bending(kappa(k), lateral);
            (m * p.spacing, kb * p.spacing)
        };
        // Its roll: inertia and St Venant torsional stiffness per fastener.
        let twist = |k: usize| {
            (
                p.rail_polar_inertia * p.spacing,
                p.rail_torsion_stiffness * kappa(k).powi(2) * p.spacing,
            )
        };
        let mut vertical = Vec::with_capacity(n);
        let mut lateral = Vec::with_capacity(n);
        for k in 1..=n {
            let shear = 2.0 * (1.0 - (k as f64 * std::f64::consts::PI / nb).cos());
            let ((ml, kl), (mh, kh)) = (mode(k, false), mode(2 * p.bays - k, false));
            let mut v = System::new(SVector::<f64, 8>::from_column_slice(&[
                ml,
                ml,
                p.sleeper_mass,
                p.sleeper_roll_inertia,
                p.ballast_mass,
                p.ballast_mass,
                mh,
                mh,
            ]));
            for (side, sign) in SIDES.iter().enumerate() {
                let (lo, fo) = VERTICAL_FIELDS[side];
                let seat = unit(2) + unit(3) * (sign * b);
                v.bend[lo] = kl;
                v.bend[fo] = kh;
                let (pad, bal) = (p.pad_vertical, p.ballast);
                v.spring(unit(lo) - unit(fo) - seat, pad.stiffness, pad.damping);
                v.spring(seat - unit(4 + side), bal.stiffness, bal.damping);
                let (sg, sh) = (p.subgrade, p.ballast_shear);
                v.spring(unit(4 + side), sg.stiffness, sg.damping);
                v.spring(unit(4 + side), shear * sh.stiffness, shear * sh.damping);
            }
            vertical.push(v);
            let ((ml, kl), (mh, kh)) = (mode(k, true), mode(2 * p.bays - k, true));
            let ((jl, tl), (jh, th)) = (twist(k), twist(2 * p.bays - k));
            let mut l = System::new(SVector::<f64, 9>::from_column_slice(&[
                ml,
                ml,
                p.sleeper_mass,
                jl,
                jl,
                mh,
                mh,
                jh,
                jh,
            ]));
            for side in 0..2 {
                let ((yl, yf), (rl, rf)) = (LATERAL_FIELDS[side], LATERAL_FIELDS[ROLL + side]);
                l.bend[yl] = kl;
                l.bend[yf] = kh;
                l.bend[rl] = tl;
                l.bend[rf] = th;
                let (sway, roll) = (unit(yl) - unit(yf), unit(rl) - unit(rf));
                let (pad, pv, half) = (p.pad_lateral, p.pad_vertical, p.pad_vertical_half_width);
                l.spring(
                    sway + roll * p.pad_lateral_lever - unit(2),
                    pad.stiffness,
                    pad.damping,
                );
                // The vertical pad's halves at ±b: k_v·b² against the roll.
                l.spring(roll * half, pv.stiffness, pv.damping);
            }
            let sl = p.sleeper_lateral;
            l.spring(unit(2), sl.stiffness, sl.damping);
            lateral.push(l);
        }
        // The pinned–pinned modes: bending and twisting alone (no pad reaches them).
        let (mv, kv) = mode(p.bays, false);
        let mut pv = System::new(SVector::<f64, 2>::new(mv, mv));
        pv.bend = SVector::<f64, 2>::new(kv, kv);
        let ((ml, kl), (jt, kt)) = (mode(p.bays, true), twist(p.bays));
        let mut pl = System::new(SVector::<f64, 4>::new(ml, ml, jt, jt));
        pl.bend = SVector::<f64, 4>::new(kl, kl, kt, kt);
        TrackDynamics {
            start: ((centre - 0.5 * p.window()) / p.spacing).round() * p.spacing,
            vertical: Direction::new(vertical, VERTICAL_FIELDS, pv),
            lateral: Direction::new(lateral, LATERAL_FIELDS, pl),
            dt: 0.0,
            sines: vec![
                Sines {
                    low: vec![0.0; Sines::padded(n)],
                    pinned: 0.0,
                    high: vec![0.0; Sines::padded(n)],
                };
                SINES_KEPT
            ],
            sines_x: vec![f64::NAN; SINES_KEPT],
            sines_next: 0,
            table: sine_table(p.bays),
            table_half: sine_table(2 * p.bays),
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

    /// `sin(kπx/L)` for every wavenumber k = 1 … 2N − 1 at `s` (held inside the window), by
    /// the Chebyshev recurrence: the index of its entry in `self.sines`, computed unless kept.
    fn sines_at(&mut self, s: f64) -> usize {
        let l = self.p.window();
        let x = (s - self.start).clamp(1e-6 * l, (1.0 - 1e-6) * l);
        if let Some(i) = self.sines_x.iter().position(|&k| k == x) {
            return i;
        }
        let i = self.sines_next;
        self.sines_next = (i + 1) % SINES_KEPT;
        self.sines_x[i] = x;
        let sines = &mut self.sines[i];
        let a = std::f64::consts::PI * x / l;
        let n = self.p.bays - 1;
        let (c2, mut prev, mut cur) = (2.0 * a.cos(), 0.0, a.sin());
        for k in 0..2 * n + 1 {
            match k.cmp(&n) {
                std::cmp::Ordering::Less => sines.low[k] = cur,
                std::cmp::Ordering::Equal => sines.pinned = cur,
                std::cmp::Ordering::Greater => sines.high[2 * n - k] = cur,
            }
            let next = c2 * cur - prev;
            prev = cur;
            cur = next;
        }
        i
    }

    /// The lateral direction of rail `side`'s sway (`sway`) and roll (`roll`) combined.
    fn lateral_along(side: usize, sway: f64, roll: f64) -> [f64; 4] {
        let mut c = [0.0; 4];
        c[side] = sway;
        c[ROLL + side] = roll;
        c
    }

    /// The vertical direction of rail `side`.
    fn vertical_along(side: usize) -> [f64; 2] {
        let mut c = [0.0; 2];
        c[side] = 1.0;
        c
    }

    /// The rail `side`'s motion at `s`: its torsion centre's lateral and vertical displacement
    /// and velocity and its roll and roll rate, `[y, vy, z, vz, θ, θ̇]` (m, m/s, rad, rad/s; y
    /// to the left, z up, θ about the track's x).
    pub fn rail(&mut self, side: usize, s: f64) -> [f64; 6] {
        let at = self.sines_at(s);
        let sines = &self.sines[at];
        let (y, vy) = (self.lateral).point(sines, &Self::lateral_along(side, 1.0, 0.0));
        let (r, vr) = (self.lateral).point(sines, &Self::lateral_along(side, 0.0, 1.0));
        let (z, vz) = (self.vertical).point(sines, &Self::vertical_along(side));
        [y, vy, z, vz, r, vr]
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
        let bays = self.p.bays;
        let (table, half) = (&self.table, &self.table_half);
        let at_fasteners = |amps: Vec<f64>| moved(table, bays, shift, amps);
        let at_half_bays = |amps: Vec<f64>| moved(half, 2 * bays, 2 * shift, amps);
        self.vertical.shift(&at_fasteners, &at_half_bays);
        self.lateral.shift(&at_fasteners, &at_half_bays);
    }

    /// Starts a step of `dt` s: every wavenumber's velocity change under its own springs and
    /// dampers.
    pub fn begin(&mut self, dt: f64) {
        if dt != self.dt {
            self.vertical.factor(dt);
            self.lateral.factor(dt);
            self.dt = dt;
        }
        self.vertical.begin();
        self.lateral.begin();
    }

    /// The step's velocity change so far of rail `side`'s point at `s` that `lever` places on
    /// it, lateral and vertical (m/s), and its mobility there (m/s per N·s of impulse, 2×2:
    /// the roll couples the two), each wavenumber solved whole (the sleepers and ballast yield
    /// within the step).
    pub fn contact_free(
        &mut self,
        side: usize,
        s: f64,
        lever: Lever,
    ) -> (Vector2<f64>, Matrix2<f64>) {
        let at = self.sines_at(s);
        let sines = &self.sines[at];
        let g = 2.0 / self.p.bays as f64;
        let c = [
            Self::lateral_along(side, 1.0, -lever.height),
            Self::lateral_along(side, 0.0, lever.lateral),
        ];
        let (dv, mut w) = self.lateral.free(sines, &c, g);
        let (dz, wz) = (self.vertical).free(sines, &[Self::vertical_along(side)], g);
        w[(1, 1)] += wz[(0, 0)];
        (Vector2::new(dv[0], dv[1] + dz[0]), w)
    }

    /// An impulse (N·s, lateral and vertical) on rail `side`'s point at `s` that `lever`
    /// places on it.
    pub fn contact_impulse(&mut self, side: usize, s: f64, lever: Lever, i: Vector2<f64>) {
        let torque = lever.lateral * i.y - lever.height * i.x;
        self.impulse(side, s, [i.x, i.y, torque]);
    }

    /// An impulse on rail `side` at `s` on its torsion centre's line: lateral, vertical (N·s)
    /// and twisting (N·m·s).
    pub fn impulse(&mut self, side: usize, s: f64, i: [f64; 3]) {
        let at = self.sines_at(s);
        let sines = &self.sines[at];
        let g = 2.0 / self.p.bays as f64;
        let c = Self::lateral_along(side, i[0], i[2]);
        self.lateral.impulse(sines, &c, g);
        let c = Self::vertical_along(side);
        self.vertical.impulse(sines, &c, g * i[1]);
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
            self.impulse(
                l.side,
                l.s,
                [l.lateral, l.vertical, l.torque].map(|f| f * dt),
            );
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
