//! One wavenumber's small system of the discrete track and one direction's set of them
//! ([`super::dynamics`] explains the decomposition and the step).
//!
//! A direction (vertical or lateral) carries `R` rail fields (vertical: each rail's deflection;
//! lateral: each rail's sway and roll), each with its wavenumber k and its folded 2N − k in
//! every system, and the pinned–pinned modes (k = N) apart. A point of the rail is read along a
//! direction in the rail fields (`c`, one coefficient per field: the contact point's lateral
//! motion is its rail's sway less the torsion centre's height times its roll), and an impulse
//! enters along one.

use nalgebra::{SMatrix, SVector};

/// One wavenumber's mass, stiffness and damping (`D` degrees of freedom).
#[derive(Debug, Clone, Copy)]
pub(super) struct System<const D: usize> {
    /// The rails' bending (diagonal), taken whole at the step's end.
    pub bend: SVector<f64, D>,
    k: SMatrix<f64, D, D>,
    c: SMatrix<f64, D, D>,
    /// `(M + Δt/2·C + Δt²/12·K + Δt²·B)⁻¹` at the current step (`B` the bending).
    inv: SMatrix<f64, D, D>,
    /// The step's free velocity change from the displacement and from the velocity:
    /// `−Δt·inv·(K + B)` and `−Δt·inv·(C + Δt·B)`.
    from_x: SMatrix<f64, D, D>,
    from_v: SMatrix<f64, D, D>,
    m: SVector<f64, D>,
}

impl<const D: usize> System<D> {
    /// No spring yet, masses (or inertias) `m`.
    pub fn new(m: SVector<f64, D>) -> Self {
        let zero = SMatrix::<f64, D, D>::zeros();
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
    pub fn rails_backward_euler(&mut self, fields: &[(usize, usize)]) {
        for &(low, fold) in fields {
            for d in [low, fold] {
                self.bend[d] += self.k[(d, d)];
                self.k[(d, d)] = 0.0;
            }
        }
    }

    /// Adds a spring `k` and damper `c` whose elongation is `e·x`.
    pub fn spring(&mut self, e: SVector<f64, D>, k: f64, c: f64) {
        self.k += e * e.transpose() * k;
        self.c += e * e.transpose() * c;
    }

    fn factor(&mut self, dt: f64) {
        let bend = SMatrix::<f64, D, D>::from_diagonal(&self.bend);
        let a = SMatrix::<f64, D, D>::from_diagonal(&self.m)
            + self.c * (0.5 * dt)
            + self.k * (dt * dt / 12.0)
            + bend * (dt * dt);
        self.inv = a.try_inverse().unwrap_or_else(SMatrix::zeros);
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

/// `sin(kπx/L)` at one point for every wavenumber: `low` k = 1 … N − 1, `pinned` k = N,
/// `high` the folded 2N − k beside each k of `low`.
#[derive(Debug, Clone)]
pub(super) struct Sines {
    pub low: Vec<f64>,
    pub pinned: f64,
    pub high: Vec<f64>,
}

/// One direction of the track (`D` degrees of freedom per wavenumber, `R` rail fields): every
/// wavenumber's system and state, and the rails' pinned–pinned modes (wavenumber N, nodes at
/// every fastener: no pad moves them, so they stand alone, one per rail field).
#[derive(Debug, Clone)]
pub(super) struct Direction<const D: usize, const R: usize> {
    pub systems: Vec<System<D>>,
    states: Vec<State<D>>,
    /// Each rail field's degrees of freedom: its wavenumber k's and its folded 2N − k's.
    fields: [(usize, usize); R],
    pub pinned: System<R>,
    pinned_state: State<R>,
}

/// The nonzero coefficients of a direction in the rail fields.
fn nonzero<const R: usize>(c: &[f64; R]) -> impl Iterator<Item = (usize, f64)> + '_ {
    c.iter()
        .enumerate()
        .filter(|(_, c)| **c != 0.0)
        .map(|(j, &c)| (j, c))
}

impl<const D: usize, const R: usize> Direction<D, R> {
    pub fn new(systems: Vec<System<D>>, fields: [(usize, usize); R], pinned: System<R>) -> Self {
        let states = vec![State::default(); systems.len()];
        Direction {
            systems,
            states,
            fields,
            pinned,
            pinned_state: State::default(),
        }
    }

    /// The rail's displacement and velocity along `c` at the point whose sines are `s`.
    pub fn point(&self, s: &Sines, c: &[f64; R]) -> (f64, f64) {
        let pp = &self.pinned_state;
        let (mut x, mut v) = (0.0, 0.0);
        for (j, cj) in nonzero(c) {
            let (lo, fo) = self.fields[j];
            let (mut xj, mut vj) = (s.pinned * pp.x[j], s.pinned * pp.v[j]);
            for ((a, b), st) in s.low.iter().zip(&s.high).zip(&self.states) {
                xj += a * st.x[lo] + b * st.x[fo];
                vj += a * st.v[lo] + b * st.v[fo];
            }
            x += cj * xj;
            v += cj * vj;
        }
        (x, v)
    }

    pub fn begin(&mut self) {
        for (st, sys) in self.states.iter_mut().zip(&self.systems) {
            st.dv = sys.from_x * st.x + sys.from_v * st.v;
        }
        let (st, sys) = (&mut self.pinned_state, &self.pinned);
        st.dv = sys.from_x * st.x + sys.from_v * st.v;
    }

    /// The step's velocity change so far along each direction of `c` at the point of `s`, and
    /// the mobility between them (m/s per N·s of impulse along the other); `g` is `2/N`.
    pub fn free<const P: usize>(
        &self,
        s: &Sines,
        c: &[[f64; R]; P],
        g: f64,
    ) -> (SVector<f64, P>, SMatrix<f64, P, P>) {
        let (mut dv, mut w) = (SVector::<f64, P>::zeros(), SMatrix::<f64, P, P>::zeros());
        let (pp, pi) = (&self.pinned_state, &self.pinned.inv);
        for p in 0..P {
            for (j, cj) in nonzero(&c[p]) {
                let (lo, fo) = self.fields[j];
                dv[p] += cj * s.pinned * pp.dv[j];
                for ((a, b), st) in s.low.iter().zip(&s.high).zip(&self.states) {
                    dv[p] += cj * (a * st.dv[lo] + b * st.dv[fo]);
                }
                for q in p..P {
                    for (l, cl) in nonzero(&c[q]) {
                        let (lo2, fo2) = self.fields[l];
                        let mut sum = s.pinned * s.pinned * pi[(j, l)];
                        for ((a, b), sys) in s.low.iter().zip(&s.high).zip(&self.systems) {
                            let i = &sys.inv;
                            sum += a * (a * i[(lo, lo2)] + b * i[(lo, fo2)])
                                + b * (a * i[(fo, lo2)] + b * i[(fo, fo2)]);
                        }
                        w[(p, q)] += g * cj * cl * sum;
                    }
                }
            }
            for q in 0..p {
                w[(p, q)] = w[(q, p)];
            }
        }
        (dv, w)
    }

    /// An impulse along `c` at the point of `s`, `g` its `2/N` share times its size (N·s).
    pub fn impulse(&mut self, s: &Sines, c: &[f64; R], g: f64) {
        for (j, cj) in nonzero(c) {
            let (lo, fo) = self.fields[j];
            self.pinned_state.dv += self.pinned.inv.column(j) * (g * cj * s.pinned);
            for (((a, b), st), sys) in s
                .low
                .iter()
                .zip(&s.high)
                .zip(&mut self.states)
                .zip(&self.systems)
            {
                st.dv += sys.inv.column(lo) * (g * cj * a) + sys.inv.column(fo) * (g * cj * b);
            }
        }
    }

    pub fn end(&mut self, dt: f64) {
        for st in &mut self.states {
            st.v += st.dv;
            st.x += st.v * dt;
        }
        let pp = &mut self.pinned_state;
        pp.v += pp.dv;
        pp.x += pp.v * dt;
    }

    /// Builds every system's step at `dt`.
    pub fn factor(&mut self, dt: f64) {
        self.systems.iter_mut().for_each(|s| s.factor(dt));
        self.pinned.factor(dt);
    }

    /// Every field moved: the sleepers' and the ballast's by `at_fasteners` (N − 1
    /// amplitudes in and out), each rail field's by `at_half_bays` (2N − 1: its wavenumbers
    /// 1 … N − 1, N and the folded N + 1 … 2N − 1).
    pub fn shift(
        &mut self,
        at_fasteners: &impl Fn(Vec<f64>) -> Vec<f64>,
        at_half_bays: &impl Fn(Vec<f64>) -> Vec<f64>,
    ) {
        let n = self.states.len();
        let rail = |d: usize| self.fields.iter().any(|&(lo, fo)| d == lo || d == fo);
        let sleeper: Vec<usize> = (0..D).filter(|&d| !rail(d)).collect();
        for v in [false, true] {
            for &d in &sleeper {
                let moved = at_fasteners(self.states.iter().map(|st| st.field(v)[d]).collect());
                for (st, m) in self.states.iter_mut().zip(moved) {
                    st.field_mut(v)[d] = m;
                }
            }
            for (j, &(lo, fo)) in self.fields.iter().enumerate() {
                let amps: Vec<f64> = (self.states.iter().map(|st| st.field(v)[lo]))
                    .chain(std::iter::once(self.pinned_state.field(v)[j]))
                    .chain(self.states.iter().rev().map(|st| st.field(v)[fo]))
                    .collect();
                for (k, m) in at_half_bays(amps).into_iter().enumerate() {
                    match k.cmp(&n) {
                        std::cmp::Ordering::Less => self.states[k].field_mut(v)[lo] = m,
                        std::cmp::Ordering::Equal => self.pinned_state.field_mut(v)[j] = m,
                        std::cmp::Ordering::Greater => self.states[2 * n - k].field_mut(v)[fo] = m,
                    }
                }
            }
        }
    }
}

/// `sin((i+1)(j+1)π/n)` for i, j < n − 1.
pub(super) fn sine_table(n: usize) -> Vec<f64> {
    let m = n - 1;
    (0..m * m)
        .map(|i| {
            ((i / m + 1) as f64 * ((i % m) + 1) as f64 * std::f64::consts::PI / n as f64).sin()
        })
        .collect()
}

/// A field's amplitudes over the sines of `n` intervals (`table` their `n − 1` sines at the
/// `n − 1` interior points), taken to the points, moved by `shift` points (what enters is at
/// rest), and back: the sine transform is its own inverse up to `2/n`.
pub(super) fn moved(table: &[f64], n: usize, shift: i64, amps: Vec<f64>) -> Vec<f64> {
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
