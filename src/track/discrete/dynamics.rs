//! The discrete track's state and step, one wavenumber at a time.
//!
//! With identical sleepers at every interior fastener of the window, ballast shear between
//! neighbours and everything at rest beyond the window's ends, every field of the track is a
//! sum of the same sines `sin(kπj/N)`, and the sines do not mix except by aliasing: at the
//! fasteners the rail's wavenumber `2N − k` reads as `−sin(kπj/N)`. The rail carries the
//! wavenumbers 1 … 2N − 1 (half a bay its shortest half-wave, so it bends between the
//! sleepers), the sleepers and the ballast 1 … N − 1. The track falls apart into N − 1
//! independent small systems, one per wavenumber k, of eight vertical degrees of freedom (the
//! two rails' amplitudes of k and of 2N − k, the sleepers' bounce and roll, the two ballast
//! blocks') and five lateral (the rails' two amplitudes each, the sleepers' sway), and the
//! pinned–pinned modes (k = N, nodes at every fastener: no pad reaches them), one per rail and
//! direction. A rail's modal coordinate `q_k` of `φ_k = √(2/(m_k·L))·sin(kπx/L)` (`m_k` the mode's
//! mass per length) is its amplitude divided by `√(2/(m_k·L))`, so the amplitude behaves as a mass `m_k·s` per fastener with the
//! bending stiffness `s·m_k·ω_k²` of its free wave ([`super::DiscreteSupport::bending`]:
//! Timoshenko's flexural branch, or Euler–Bernoulli's `EI·κ⁴`); a pad stretches by the
//! difference of the two amplitudes; the ballast's shear adds `2·k_w·(1 − cos(kπ/N))` to each
//! block. A wheel's force `P` at `x` enters each amplitude as `(2/N)·sin(kπx/L)·P` and the
//! rail's deflection there is `Σ_k a_k·sin(kπx/L)`.
//!
//! Each system steps as the vehicle's wheelsets do, symplectic Euler with its springs and
//! dampers shared into the step's end, its inverse built once per step length:
//! `(M + Δt/2·C + Δt²/12·K + Δt²·B)·Δv = Δt·(F − K·x − B·(x + Δt·v) − C·v)`, `Δx = Δt·(v + Δv)`.
//! `B`, the rails' bending and their own pads, is backward Euler: the bending modes up to
//! 2.8 kHz (half a bay, vertical), which no step of the run follows, are damped rather than left ringing (with no
//! numerical damping on them, α = ¼, Q's standard deviation was 34 % off at 0.5 ms on
//! R 400 m at 100 km/h). `K`, the rest of the pads, the sleepers and the ballast, takes Fox and
//! Goodwin's share (α = 1/12: a linear spring's frequency right to fourth order, stable below
//! ω·Δt = 2.45, no numerical damping); the damping `C` takes θ = ½. The trapezoidal rule's
//! displacement `Δt·(v + Δv/2)` is not the one the wheel's solve takes for the rail, and burst.
//! The nodal fields are needed only when the window shifts by whole bays (every 0.6 m of
//! travel): the sines' transform and its inverse, exact (the rails' at every half bay).

use super::DiscreteSupport;
use nalgebra::{SVector, Vector2};

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
    /// backward-Euler part beside their bending (`fold`: the folded modes' first index).
    fn rails_backward_euler(&mut self, fold: usize) {
        for side in [0, 1, fold, fold + 1] {
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

impl<const D: usize> State<D> {
    /// The velocities (`v`) or the displacements.
    fn field(&self, v: bool) -> &SVector<f64, D> {
        if v { &self.v } else { &self.x }
    }

    fn field_mut(&mut self, v: bool) -> &mut SVector<f64, D> {
        if v { &mut self.v } else { &mut self.x }
    }
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

/// The rails' (left, right) first degrees of freedom in either direction.
const RAIL: [usize; 2] = [0, 1];

/// One direction of the track (lateral, `D` = 5, or vertical, 8): every wavenumber's system
/// and state, and the rails' pinned–pinned modes (wavenumber N, nodes at every fastener: no
/// pad moves them, so they stand alone, one per rail).
#[derive(Debug, Clone)]
struct Direction<const D: usize> {
    systems: Vec<System<D>>,
    states: Vec<State<D>>,
    /// The rails' folded modes' degrees of freedom (`2N − k` beside `k`).
    fold: usize,
    pinned: System<2>,
    pinned_state: State<2>,
}

impl<const D: usize> Direction<D> {
    fn new(systems: Vec<System<D>>, fold: usize, pinned: System<2>) -> Self {
        let states = vec![State::default(); systems.len()];
        Direction {
            systems,
            states,
            fold,
            pinned,
            pinned_state: State::default(),
        }
    }

    /// Rail `r`'s displacement and velocity at the point whose sines are `s`.
    fn point(&self, s: &Sines, r: usize) -> (f64, f64) {
        let (f, pp) = (self.fold + r, &self.pinned_state);
        let (mut x, mut v) = (s.pinned * pp.x[r], s.pinned * pp.v[r]);
        for ((a, b), st) in s.low.iter().zip(&s.high).zip(&self.states) {
            x += a * st.x[r] + b * st.x[f];
            v += a * st.v[r] + b * st.v[f];
        }
        (x, v)
    }

    fn begin(&mut self) {
        for (st, sys) in self.states.iter_mut().zip(&self.systems) {
            st.dv = sys.from_x * st.x + sys.from_v * st.v;
        }
        let (st, sys) = (&mut self.pinned_state, &self.pinned);
        st.dv = sys.from_x * st.x + sys.from_v * st.v;
    }

    /// Rail `r`'s velocity change so far and its mobility at the point of `s`; `g` is `2/N`.
    fn free(&self, s: &Sines, r: usize, g: f64) -> (f64, f64) {
        let f = self.fold + r;
        let (pp, pi) = (&self.pinned_state, &self.pinned.inv);
        let (mut dv, mut w) = (s.pinned * pp.dv[r], g * s.pinned * s.pinned * pi[(r, r)]);
        for (((a, b), st), sys) in s
            .low
            .iter()
            .zip(&s.high)
            .zip(&self.states)
            .zip(&self.systems)
        {
            dv += a * st.dv[r] + b * st.dv[f];
            let i = &sys.inv;
            w += g * (a * a * i[(r, r)] + a * b * (i[(r, f)] + i[(f, r)]) + b * b * i[(f, f)]);
        }
        (dv, w)
    }

    /// An impulse on rail `r` at the point of `s`, `g` its `2/N` share.
    fn impulse(&mut self, s: &Sines, r: usize, g: f64) {
        let f = self.fold + r;
        let pp = &mut self.pinned_state;
        pp.dv += self.pinned.inv.column(r) * (g * s.pinned);
        for (((a, b), st), sys) in s
            .low
            .iter()
            .zip(&s.high)
            .zip(&mut self.states)
            .zip(&self.systems)
        {
            st.dv += sys.inv.column(r) * (g * a) + sys.inv.column(f) * (g * b);
        }
    }

    fn end(&mut self, dt: f64) {
        for st in &mut self.states {
            st.v += st.dv;
            st.x += st.v * dt;
        }
        let pp = &mut self.pinned_state;
        pp.v += pp.dv;
        pp.x += pp.v * dt;
    }

    /// Every field moved: the sleepers' and the ballast's by `at_fasteners` (N − 1
    /// amplitudes in and out), each rail's by `at_half_bays` (2N − 1: its wavenumbers
    /// 1 … N − 1, N and the folded N + 1 … 2N − 1).
    fn shift(
        &mut self,
        at_fasteners: &impl Fn(Vec<f64>) -> Vec<f64>,
        at_half_bays: &impl Fn(Vec<f64>) -> Vec<f64>,
    ) {
        let n = self.states.len();
        for v in [false, true] {
            for d in (0..self.fold).filter(|d| !RAIL.contains(d)) {
                let moved = at_fasteners(self.states.iter().map(|st| st.field(v)[d]).collect());
                for (st, m) in self.states.iter_mut().zip(moved) {
                    st.field_mut(v)[d] = m;
                }
            }
            for r in RAIL {
                let f = self.fold + r;
                let amps: Vec<f64> = (self.states.iter().map(|st| st.field(v)[r]))
                    .chain(std::iter::once(self.pinned_state.field(v)[r]))
                    .chain(self.states.iter().rev().map(|st| st.field(v)[f]))
                    .collect();
                for (k, m) in at_half_bays(amps).into_iter().enumerate() {
                    match k.cmp(&n) {
                        std::cmp::Ordering::Less => self.states[k].field_mut(v)[r] = m,
                        std::cmp::Ordering::Equal => self.pinned_state.field_mut(v)[r] = m,
                        std::cmp::Ordering::Greater => self.states[2 * n - k].field_mut(v)[f] = m,
                    }
                }
            }
        }
    }
}

/// `sin(kπx/L)` at one point for every wavenumber: `low` k = 1 … N − 1, `pinned` k = N,
/// `high` the folded 2N − k beside each k of `low`.
#[derive(Debug, Clone)]
struct Sines {
    low: Vec<f64>,
    pinned: f64,
    high: Vec<f64>,
}

/// The discrete track in its window.
#[derive(Debug, Clone)]
pub struct TrackDynamics {
    p: DiscreteSupport,
    /// Along-track position of the window's start (a sleeper position), m.
    start: f64,
    vertical: Direction<8>,
    lateral: Direction<5>,
    /// The step the inverses were built for, s.
    dt: f64,
    /// The sines at the last position asked for, and that position relative to the window's
    /// start.
    sines: Sines,
    sines_at: f64,
    /// `sin(kπj/N)`, (N−1)², and `sin(kπi/2N)`, (2N−1)², for the window's shifts.
    table: Vec<f64>,
    table_half: Vec<f64>,
}

/// Vertical degrees of freedom: rails (left, right), sleeper bounce and roll, ballast (left,
/// right), the rails' folded modes (left, right). Lateral: rails, sleeper sway, folded modes.
const FOLD_VERTICAL: usize = 6;
const FOLD_LATERAL: usize = 3;

/// `sin((i+1)(j+1)π/n)` for i, j < n − 1.
fn sine_table(n: usize) -> Vec<f64> {
    let m = n - 1;
    (0..m * m)
        .map(|i| {
            ((i / m + 1) as f64 * ((i % m) + 1) as f64 * std::f64::consts::PI / n as f64).sin()
        })
        .collect()
}

impl TrackDynamics {
    /// The track at rest, its window centred on `centre` (m along the track; sleepers at
    /// whole multiples of the spacing).
    pub fn new(p: DiscreteSupport, centre: f64) -> Self {
        let n = p.bays - 1;
        let nb = p.bays as f64;
        let b = p.seat_half_distance;
        // A rail mode of wavenumber k: its amplitude's mass and bending stiffness per fastener.
        let mode = |k: usize, lateral: bool| {
            let (m, kb) = p.bending(k as f64 * std::f64::consts::PI / p.window(), lateral);
            (m * p.spacing, kb * p.spacing)
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
                let unit = |i: usize| SVector::<f64, 8>::from_fn(|r, _| f64::from(r == i));
                let seat = unit(2) + unit(3) * (sign * b);
                let rail = unit(side) - unit(FOLD_VERTICAL + side);
                v.bend[side] = kl;
                v.bend[FOLD_VERTICAL + side] = kh;
                let (pad, bal) = (p.pad_vertical, p.ballast);
                v.spring(rail - seat, pad.stiffness, pad.damping);
                v.spring(seat - unit(4 + side), bal.stiffness, bal.damping);
                let (sg, sh) = (p.subgrade, p.ballast_shear);
                v.spring(unit(4 + side), sg.stiffness, sg.damping);
                v.spring(unit(4 + side), shear * sh.stiffness, shear * sh.damping);
            }
            v.rails_backward_euler(FOLD_VERTICAL);
            vertical.push(v);
            let ((ml, kl), (mh, kh)) = (mode(k, true), mode(2 * p.bays - k, true));
            let mut l = System::new(SVector::<f64, 5>::from_column_slice(&[
                ml,
                ml,
                p.sleeper_mass,
                mh,
                mh,
            ]));
            for side in 0..2 {
                let unit = |i: usize| SVector::<f64, 5>::from_fn(|r, _| f64::from(r == i));
                let rail = unit(side) - unit(FOLD_LATERAL + side);
                l.bend[side] = kl;
                l.bend[FOLD_LATERAL + side] = kh;
                let pad = p.pad_lateral;
                l.spring(rail - unit(2), pad.stiffness, pad.damping);
            }
            let sl = p.sleeper_lateral;
            l.spring(
                SVector::<f64, 5>::from_fn(|r, _| f64::from(r == 2)),
                sl.stiffness,
                sl.damping,
            );
            l.rails_backward_euler(FOLD_LATERAL);
            lateral.push(l);
        }
        // The pinned–pinned modes: bending alone (no pad reaches them).
        let pinned = |lateral: bool| {
            let (m, k) = mode(p.bays, lateral);
            let mut s = System::new(Vector2::new(m, m));
            s.bend = Vector2::new(k, k);
            s
        };
        TrackDynamics {
            start: ((centre - 0.5 * p.window()) / p.spacing).round() * p.spacing,
            vertical: Direction::new(vertical, FOLD_VERTICAL, pinned(false)),
            lateral: Direction::new(lateral, FOLD_LATERAL, pinned(true)),
            dt: 0.0,
            sines: Sines {
                low: vec![0.0; n],
                pinned: 0.0,
                high: vec![0.0; n],
            },
            sines_at: f64::NAN,
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

    /// `sin(kπx/L)` for every wavenumber k = 1 … 2N − 1 at `s` (held inside the window) into
    /// `self.sines`, by the Chebyshev recurrence.
    fn sines_at(&mut self, s: f64) {
        let l = self.p.window();
        let x = (s - self.start).clamp(1e-6 * l, (1.0 - 1e-6) * l);
        if x == self.sines_at {
            return;
        }
        self.sines_at = x;
        let a = std::f64::consts::PI * x / l;
        let n = self.sines.low.len();
        let (c2, mut prev, mut cur) = (2.0 * a.cos(), 0.0, a.sin());
        for k in 0..2 * n + 1 {
            match k.cmp(&n) {
                std::cmp::Ordering::Less => self.sines.low[k] = cur,
                std::cmp::Ordering::Equal => self.sines.pinned = cur,
                std::cmp::Ordering::Greater => self.sines.high[2 * n - k] = cur,
            }
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
            self.vertical.systems.iter_mut().for_each(|s| s.factor(dt));
            self.lateral.systems.iter_mut().for_each(|s| s.factor(dt));
            self.vertical.pinned.factor(dt);
            self.lateral.pinned.factor(dt);
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

/// A field's amplitudes over the sines of `n` intervals (`table` their `n − 1` sines at the
/// `n − 1` interior points), taken to the points, moved by `shift` points (what enters is at
/// rest), and back: the sine transform is its own inverse up to `2/n`.
fn moved(table: &[f64], n: usize, shift: i64, amps: Vec<f64>) -> Vec<f64> {
    let len = n - 1;
    let row = |j: usize| &table[j * len..(j + 1) * len];
    let nodes: Vec<f64> = (0..len).map(|j| dot(row(j), &amps)).collect();
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
    let g = 2.0 / n as f64;
    (0..len).map(|k| g * dot(row(k), &shifted)).collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
