//! One direction's set of the discrete track's wavenumber systems ([`super::system`];
//! [`super::dynamics`] explains the decomposition and the step).
//!
//! A direction (vertical or lateral) carries `R` rail fields (vertical: each rail's deflection;
//! lateral: each rail's sway and roll), each with its wavenumber k and its folded 2N − k in
//! every system, and the pinned–pinned modes (k = N) apart. A point of the rail is read along a
//! direction in the rail fields (`c`, one coefficient per field: the contact point's lateral
//! motion is its rail's sway less the torsion centre's height times its roll), and an impulse
//! enters along one.
//!
//! Within a step the impulses are kept as each wavenumber's generalised impulse on its rail
//! degrees of freedom (two numbers per field and wavenumber) and taken through the inverse
//! only where read: a point's velocity change reads the inverse's rail rows, the step's end
//! its rail columns. The sweeps over the wavenumbers run four lanes wide where the CPU has AVX
//! (detected at run time; no FMA, the same bits as the portable code).

use super::system::{FOLLOWED, System};
use nalgebra::{SMatrix, SVector};

/// One wavenumber's state: displacement, velocity and the step's free velocity change (under
/// its own springs and dampers; the step's impulses are kept apart until its end).
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
/// `high` the folded 2N − k beside each k of `low`; `low` and `high` padded with zeros to
/// whole blocks of [`LANES`] ([`Sines::padded`]).
#[derive(Debug, Clone)]
pub(super) struct Sines {
    pub low: Vec<f64>,
    pub pinned: f64,
    pub high: Vec<f64>,
}

impl Sines {
    /// The length of `low` and `high` for `n` wavenumbers.
    pub fn padded(n: usize) -> usize {
        n.div_ceil(LANES) * LANES
    }

    /// `low` and `high` side by side, [`LANES`] wavenumbers at a time.
    fn blocks(&self) -> impl Iterator<Item = (&Lanes, &Lanes)> {
        (self.low.as_chunks::<LANES>().0.iter()).zip(self.high.as_chunks::<LANES>().0)
    }
}

/// One direction of the track (`D` degrees of freedom per wavenumber, `R` rail fields): every
/// wavenumber's system and state, and the rails' pinned–pinned modes (wavenumber N, nodes at
/// every fastener: no pad moves them, so they stand alone, one per rail field).
#[derive(Debug, Clone)]
pub(super) struct Direction<const D: usize, const R: usize, const S: usize> {
    pub systems: Vec<System<D>>,
    states: Vec<State<D>>,
    /// Each rail field's degrees of freedom: its wavenumber k's and its folded 2N − k's.
    fields: [(usize, usize); R],
    pub pinned: System<R>,
    pinned_state: State<R>,
    /// The step's impulses so far, each wavenumber's generalised impulse on its rail degrees
    /// of freedom (`[block][slot][lane]`: wavenumber `LANES·block + lane`; slot `2j` field
    /// j's wavenumber k, `2j + 1` its folded 2N − k), taken into the velocities at the step's
    /// end: an impulse then costs two entries per field and wavenumber instead of two columns
    /// of the inverse.
    imp: Vec<[Lanes; S]>,
    /// Each system's inverse between its rail degrees of freedom, `[block][slot][slot][lane]`:
    /// what a point's velocity change and mobility read.
    rail_inv: Vec<[[Lanes; S]; S]>,
    /// Each system's rail degrees of freedom's displacement and velocity, `[block][slot][lane]`
    /// (the states' copy that a point's reading sweeps).
    x_rail: Vec<[Lanes; S]>,
    v_rail: Vec<[Lanes; S]>,
    /// Each system's free velocity change of its rail degrees of freedom,
    /// `[block][slot][lane]` (what [`Direction::begin`] leaves in the states, for the sweeps).
    free_dv: Vec<[Lanes; S]>,
    /// Each system's inverse's columns of its rail degrees of freedom, `[system][slot][D]`:
    /// what the step's end reads.
    cols: Vec<[[f64; D]; S]>,
}

/// Wavenumbers side by side in the sweeps over them (an AVX vector of f64).
const LANES: usize = 4;

/// One number of [`LANES`] consecutive wavenumbers.
type Lanes = [f64; LANES];

/// `acc + Σ term` over the wavenumbers in their order (the sums kept scalar, so that they add
/// as one system at a time would).
#[inline(always)]
fn add_in_order(acc: &mut f64, terms: &[f64]) {
    for t in terms {
        *acc += t;
    }
}

/// The nonzero coefficients of a direction in the rail fields.
fn nonzero<const R: usize>(c: &[f64; R]) -> impl Iterator<Item = (usize, f64)> + '_ {
    c.iter()
        .enumerate()
        .filter(|(_, c)| **c != 0.0)
        .map(|(j, &c)| (j, c))
}

impl<const D: usize, const R: usize, const S: usize> Direction<D, R, S> {
    pub fn new(systems: Vec<System<D>>, fields: [(usize, usize); R], pinned: System<R>) -> Self {
        assert_eq!(
            S,
            2 * R,
            "a direction's rail slots are its fields' k and 2N − k"
        );
        let states = vec![State::default(); systems.len()];
        let blocks = systems.len().div_ceil(LANES);
        Direction {
            x_rail: vec![[[0.0; LANES]; S]; blocks],
            v_rail: vec![[[0.0; LANES]; S]; blocks],
            systems,
            states,
            fields,
            pinned,
            pinned_state: State::default(),
            imp: Vec::new(),
            rail_inv: Vec::new(),
            free_dv: Vec::new(),
            cols: Vec::new(),
        }
    }

    /// Each slot's degree of freedom (slot `2j` field j's wavenumber k, `2j + 1` its folded).
    fn dofs(&self) -> [usize; S] {
        std::array::from_fn(|i| {
            let (lo, fo) = self.fields[i / 2];
            if i.is_multiple_of(2) { lo } else { fo }
        })
    }

    /// How many wavenumbers each block of [`LANES`] holds (the last may hold fewer).
    fn filled(&self) -> impl Iterator<Item = usize> {
        let n = self.states.len();
        (0..n.div_ceil(LANES)).map(move |b| (n - b * LANES).min(LANES))
    }

    /// The rail's displacement and velocity along `c` at the point whose sines are `s`.
    pub fn point(&self, s: &Sines, c: &[f64; R]) -> (f64, f64) {
        let pp = &self.pinned_state;
        let (mut x, mut v) = (0.0, 0.0);
        for (j, cj) in nonzero(c) {
            let (mut xj, mut vj) = (s.pinned * pp.x[j], s.pinned * pp.v[j]);
            for (acc, field) in [(&mut xj, &self.x_rail), (&mut vj, &self.v_rail)] {
                for ((f, (a, b)), len) in field.iter().zip(s.blocks()).zip(self.filled()) {
                    let t: Lanes =
                        std::array::from_fn(|q| a[q] * f[2 * j][q] + b[q] * f[2 * j + 1][q]);
                    add_in_order(acc, &t[..len]);
                }
            }
            x += cj * xj;
            v += cj * vj;
        }
        (x, v)
    }

    /// Copies the rail degrees of freedom's displacements and velocities into the blocks that
    /// [`Direction::point`] sweeps.
    fn mirror_rails(&mut self) {
        let dofs = self.dofs();
        for (k, st) in self.states.iter().enumerate() {
            let (xb, vb) = (&mut self.x_rail[k / LANES], &mut self.v_rail[k / LANES]);
            for (i, &d) in dofs.iter().enumerate() {
                xb[i][k % LANES] = st.x[d];
                vb[i][k % LANES] = st.v[d];
            }
        }
    }

    /// Starts a step: every system's free velocity change from its state.
    pub fn begin(&mut self) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked just above).
            return unsafe { self.begin_avx() };
        }
        self.begin_lanes();
    }

    /// [`Direction::begin`] compiled for AVX: the same operations in the same order (no
    /// FMA), so the same bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn begin_avx(&mut self) {
        self.begin_lanes();
    }

    /// `Δv = −Δt·inv·((K + B)·x + (C + Δt·B)·v)`, column by column (lanes along the rows).
    #[inline(always)]
    fn begin_lanes(&mut self) {
        let dofs = self.dofs();
        for (k, (st, sys)) in self.states.iter_mut().zip(&self.systems).enumerate() {
            let mut dv = [0.0; D];
            let columns = (sys.from_x.as_slice().chunks_exact(D))
                .zip(sys.from_v.as_slice().chunks_exact(D))
                .zip(st.x.iter().zip(st.v.iter()));
            for ((fx, fv), (x, v)) in columns {
                for ((d, a), b) in dv.iter_mut().zip(fx).zip(fv) {
                    *d += a * x + b * v;
                }
            }
            st.dv = SVector::from(dv);
            let block = &mut self.free_dv[k / LANES];
            for (slot, &d) in block.iter_mut().zip(&dofs) {
                slot[k % LANES] = st.dv[d];
            }
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
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked just above).
            return unsafe { self.free_avx(s, c, g) };
        }
        self.free_lanes(s, c, g)
    }

    /// [`Direction::free`] compiled for AVX: the same operations in the same order (no FMA),
    /// so the same bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn free_avx<const P: usize>(
        &self,
        s: &Sines,
        c: &[[f64; R]; P],
        g: f64,
    ) -> (SVector<f64, P>, SMatrix<f64, P, P>) {
        self.free_lanes(s, c, g)
    }

    #[inline(always)]
    fn free_lanes<const P: usize>(
        &self,
        s: &Sines,
        c: &[[f64; R]; P],
        g: f64,
    ) -> (SVector<f64, P>, SMatrix<f64, P, P>) {
        debug_assert_eq!(
            self.imp.len(),
            self.states.len().div_ceil(LANES),
            "factor() first"
        );
        // The fields any direction of `c` reads, each read once: its velocity change `u` and
        // the mobility `m` between each pair of them.
        let mut used = [false; R];
        for (j, _) in c.iter().flat_map(nonzero) {
            used[j] = true;
        }
        let (pp, pi) = (&self.pinned_state, &self.pinned.inv);
        let (mut u, mut m) = ([0.0; R], [[0.0; R]; R]);
        for j in (0..R).filter(|&j| used[j]) {
            u[j] = s.pinned * pp.dv[j];
            for l in (j..R).filter(|&l| used[l]) {
                m[j][l] = s.pinned * s.pinned * pi[(j, l)];
            }
        }
        // The fields read, in order.
        let mut list = [0; R];
        let mut len = 0;
        for j in (0..R).filter(|&j| used[j]) {
            list[len] = j;
            len += 1;
        }
        let list = &list[..len];
        // Four wavenumbers at a time: each one's numbers lane by lane, then its terms added in
        // the wavenumbers' order.
        let mut t = [0.0; LANES];
        let blocks = (self.imp.iter()).zip(&self.rail_inv).zip(&self.free_dv);
        for ((((imp, ri), free), (a, b)), len) in blocks.zip(s.blocks()).zip(self.filled()) {
            for (x, &j) in list.iter().enumerate() {
                let (r_lo, r_fo) = (&ri[2 * j], &ri[2 * j + 1]);
                // The rail slots' velocity change: the free one and the inverse's row times
                // the impulses (summed over the slots from −0.0, as `Iterator::sum`).
                let (mut lo, mut fo) = ([-0.0; LANES], [-0.0; LANES]);
                for ((rl, rf), i) in r_lo.iter().zip(r_fo).zip(imp) {
                    for q in 0..LANES {
                        lo[q] += rl[q] * i[q];
                        fo[q] += rf[q] * i[q];
                    }
                }
                let (free_lo, free_fo) = (&free[2 * j], &free[2 * j + 1]);
                for q in 0..LANES {
                    t[q] = a[q] * (free_lo[q] + lo[q]) + b[q] * (free_fo[q] + fo[q]);
                }
                add_in_order(&mut u[j], &t[..len]);
                for &l in &list[x..] {
                    for q in 0..LANES {
                        t[q] = a[q] * (a[q] * r_lo[2 * l][q] + b[q] * r_lo[2 * l + 1][q])
                            + b[q] * (a[q] * r_fo[2 * l][q] + b[q] * r_fo[2 * l + 1][q]);
                    }
                    add_in_order(&mut m[j][l], &t[..len]);
                }
            }
        }
        let (mut dv, mut w) = (SVector::<f64, P>::zeros(), SMatrix::<f64, P, P>::zeros());
        for p in 0..P {
            for (j, cj) in nonzero(&c[p]) {
                dv[p] += cj * u[j];
                for q in p..P {
                    for (l, cl) in nonzero(&c[q]) {
                        w[(p, q)] += g * cj * cl * m[j.min(l)][j.max(l)];
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
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked just above).
            return unsafe { self.impulse_avx(s, c, g) };
        }
        self.impulse_lanes(s, c, g);
    }

    /// [`Direction::impulse`] compiled for AVX: the same operations (no FMA), so the same
    /// bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn impulse_avx(&mut self, s: &Sines, c: &[f64; R], g: f64) {
        self.impulse_lanes(s, c, g);
    }

    #[inline(always)]
    fn impulse_lanes(&mut self, s: &Sines, c: &[f64; R], g: f64) {
        debug_assert_eq!(
            self.imp.len(),
            self.states.len().div_ceil(LANES),
            "factor() first"
        );
        for (j, cj) in nonzero(c) {
            self.pinned_state.dv += self.pinned.inv.column(j) * (g * cj * s.pinned);
            let gc = g * cj;
            for (imp, (a, b)) in self.imp.iter_mut().zip(s.blocks()) {
                for q in 0..LANES {
                    imp[2 * j][q] += gc * a[q];
                    imp[2 * j + 1][q] += gc * b[q];
                }
            }
        }
    }

    /// Ends the step: the impulses into the velocity changes, then velocities and
    /// displacements.
    pub fn end(&mut self, dt: f64) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            // SAFETY: the CPU has AVX (checked just above).
            return unsafe { self.end_avx(dt) };
        }
        self.end_lanes(dt);
    }

    /// [`Direction::end`] compiled for AVX: the same operations in the same order (no FMA),
    /// so the same bits.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx")]
    fn end_avx(&mut self, dt: f64) {
        self.end_lanes(dt);
    }

    #[inline(always)]
    fn end_lanes(&mut self, dt: f64) {
        let systems = self.states.iter_mut().zip(&self.cols).enumerate();
        for (k, (st, cols)) in systems {
            let mut acc = [0.0; D];
            for (i, col) in self.imp[k / LANES].iter().zip(cols) {
                let i = i[k % LANES];
                for (a, c) in acc.iter_mut().zip(col) {
                    *a += c * i;
                }
            }
            for (((x, v), dv), a) in (st.x.iter_mut().zip(st.v.iter_mut()))
                .zip(st.dv.iter_mut())
                .zip(acc)
            {
                *dv += a;
                *v += *dv;
                *x += *v * dt;
            }
        }
        self.imp.fill([[0.0; LANES]; S]);
        self.mirror_rails();
        let pp = &mut self.pinned_state;
        pp.v += pp.dv;
        pp.x += pp.v * dt;
    }

    /// Builds every system's step at `dt`.
    pub fn factor(&mut self, dt: f64) {
        self.systems.iter_mut().for_each(|s| s.factor(dt, FOLLOWED));
        // No pad reaches the pinned–pinned modes, so nothing else damps them.
        self.pinned.factor(dt, 0.0);
        let dofs = self.dofs();
        let blocks = self.systems.len().div_ceil(LANES);
        self.imp = vec![[[0.0; LANES]; S]; blocks];
        self.free_dv = vec![[[0.0; LANES]; S]; blocks];
        self.rail_inv = vec![[[[0.0; LANES]; S]; S]; blocks];
        for (k, sys) in self.systems.iter().enumerate() {
            for (r, row) in self.rail_inv[k / LANES].iter_mut().enumerate() {
                for (c, e) in row.iter_mut().enumerate() {
                    e[k % LANES] = sys.inv[(dofs[r], dofs[c])];
                }
            }
        }
        self.cols = (self.systems.iter())
            .map(|sys| dofs.map(|c| std::array::from_fn(|r| sys.inv[(r, c)])))
            .collect();
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
        self.mirror_rails();
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX twins of the step's parts give the portable code's bits.
    #[test]
    fn avx_and_portable_steps_agree_bit_for_bit() {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            let system = |k: f64| {
                let mut s = System::new(SVector::<f64, 3>::new(50.0, 120.0, 40.0));
                s.spring(SVector::<f64, 3>::new(1.0, -1.0, 0.0), 6.5e7 * k, 7.5e4);
                s.spring(SVector::<f64, 3>::new(0.0, 1.0, 0.0), 1.4e8, 5.8e4);
                s.spring(SVector::<f64, 3>::new(0.0, -1.0, 1.0), 6.5e7, 7.5e4);
                s.bend = SVector::<f64, 3>::new(3e6 * k, 0.0, 9e6 * k);
                s
            };
            let systems: Vec<System<3>> = (1..6).map(|k| system(k as f64)).collect();
            let mut pinned = System::new(SVector::<f64, 1>::new(30.0));
            pinned.bend[0] = 2e7;
            let mut a = Direction::<3, 1, 2>::new(systems, [(0, 2)], pinned);
            a.factor(1e-4);
            for (k, st) in a.states.iter_mut().enumerate() {
                st.x = SVector::from_fn(|r, _| 1e-4 * ((k * 3 + r) as f64).sin());
                st.v = SVector::from_fn(|r, _| 1e-2 * ((k * 5 + r) as f64).cos());
            }
            let sines = Sines {
                low: (1..6)
                    .map(|k| (0.3 * k as f64).sin())
                    .chain([0.0; 3])
                    .collect(),
                pinned: 0.7,
                high: (1..6)
                    .map(|k| (0.2 * k as f64).cos())
                    .chain([0.0; 3])
                    .collect(),
            };
            let mut b = a.clone();
            a.begin_lanes();
            // SAFETY: the CPU has AVX (checked above).
            unsafe { b.begin_avx() };
            for d in [&mut a, &mut b] {
                d.impulse(&sines, &[1.0], 0.04 * 35.0);
            }
            let fa = a.free_lanes(&sines, &[[1.0]], 0.04);
            // SAFETY: as above.
            let fb = unsafe { b.free_avx(&sines, &[[1.0]], 0.04) };
            assert_eq!(fa, fb);
            a.end_lanes(1e-4);
            // SAFETY: as above.
            unsafe { b.end_avx(1e-4) };
            for (sa, sb) in a.states.iter().zip(&b.states) {
                assert_eq!((sa.x, sa.v), (sb.x, sb.v));
            }
            assert!(a.states.iter().any(|st| st.v != SVector::<f64, 3>::zeros()));
            // A point reads the blocks as one system at a time would read the states.
            let pp = &a.pinned_state;
            let (mut x, mut v) = (sines.pinned * pp.x[0], sines.pinned * pp.v[0]);
            for ((p, q), st) in sines.low.iter().zip(&sines.high).zip(&a.states) {
                x += p * st.x[0] + q * st.x[2];
                v += p * st.v[0] + q * st.v[2];
            }
            assert_eq!(a.point(&sines, &[1.0]), (x, v));
        }
    }
}
