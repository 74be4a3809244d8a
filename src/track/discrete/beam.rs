//! One rail's bending in one direction: an Euler–Bernoulli beam pinned at the window's ends,
//! in its modes `φ_k(x) = √(2/(m·L))·sin(kπx/L)`, k = 1 … N−1 for N bays (mass-normalised:
//! `∫ m·φ_k·φ_l dx = δ_kl`), each `q̈_k + ω_k²·q_k = Σ φ_k(x_i)·F_i` with
//! `ω_k² = EI·(kπ/L)⁴/m`.
//!
//! The step is linearly implicit in each mode's own stiffness and damping (the beam's and the
//! pads', diagonal in the modes at evenly spaced fasteners: `Σ_j φ_k(x_j)·φ_l(x_j) = δ_kl/(m·s)`):
//! `(1 + Δt·c̃_k + Δt²·k̃_k)·Δv_k = Δt·(f_k − k̃_k·(q_k + Δt·v_k) − c̃_k·v_k)`, stable at any
//! step (the modes above the step's band are damped, not resolved), the sleepers' side of the
//! pads explicit. Point impulses (the wheels) add `φ_k(x)·I/(1 + Δt·c̃_k + Δt²·k̃_k)`.

/// One rail beam's modal state in the window.
#[derive(Debug, Clone, PartialEq)]
pub struct Beam {
    /// Window length, m.
    length: f64,
    /// `√(2/(m·L))`.
    scale: f64,
    /// Per mode: `k̃_k = ω_k² + k_pad/(m·s)`, 1/s².
    stiffness: Vec<f64>,
    /// Per mode: `c̃_k = c_pad/(m·s)`, 1/s.
    damping: Vec<f64>,
    /// Modal displacements and velocities.
    pub(super) q: Vec<f64>,
    pub(super) v: Vec<f64>,
    /// The step's velocity change so far, and each mode's `1 + Δt·c̃ + Δt²·k̃`.
    dv: Vec<f64>,
    lhs: Vec<f64>,
}

impl Beam {
    /// A beam at rest: `bays` bays of `spacing` m, mass `mass` kg/m, bending stiffness `ei`
    /// N·m², a pad of `pad_k` N/m and `pad_c` N·s/m at each interior node.
    pub fn new(bays: usize, spacing: f64, mass: f64, ei: f64, pad_k: f64, pad_c: f64) -> Self {
        let length = bays as f64 * spacing;
        let n = bays - 1;
        let stiffness = (1..=n)
            .map(|k| {
                let kappa = k as f64 * std::f64::consts::PI / length;
                ei * kappa.powi(4) / mass + pad_k / (mass * spacing)
            })
            .collect();
        Beam {
            length,
            scale: (2.0 / (mass * length)).sqrt(),
            stiffness,
            damping: vec![pad_c / (mass * spacing); n],
            q: vec![0.0; n],
            v: vec![0.0; n],
            dv: vec![0.0; n],
            lhs: vec![1.0; n],
        }
    }

    /// Number of modes.
    pub fn modes(&self) -> usize {
        self.q.len()
    }

    /// The mode shapes at `x` (m from the window's start) into `phi` (`sin(kπx/L)` by the
    /// Chebyshev recurrence, scaled).
    pub fn shapes(&self, x: f64, phi: &mut [f64]) {
        let a = std::f64::consts::PI * x / self.length;
        let (s1, c2) = (a.sin(), 2.0 * a.cos());
        let (mut prev, mut cur) = (0.0, s1);
        for p in phi.iter_mut() {
            *p = self.scale * cur;
            let next = c2 * cur - prev;
            prev = cur;
            cur = next;
        }
    }

    /// Displacement and velocity at `x`, m and m/s.
    pub fn point(&self, x: f64, phi: &mut [f64]) -> (f64, f64) {
        self.shapes(x, phi);
        let mut w = 0.0;
        let mut v = 0.0;
        for ((p, q), u) in phi.iter().zip(&self.q).zip(&self.v) {
            w += p * q;
            v += p * u;
        }
        (w, v)
    }

    /// Starts a step of `dt` s: each mode's velocity change under its own springs and
    /// dampers and the modal forces `f` (N/√kg, the pads' sleeper side and any load held
    /// over the step).
    pub fn begin(&mut self, dt: f64, f: &[f64]) {
        let state = self.q.iter().zip(&self.v).zip(f);
        let coefficients = self.stiffness.iter().zip(&self.damping);
        let out = self.lhs.iter_mut().zip(&mut self.dv);
        for (((q, v), f), ((kk, ck), (l, dv))) in state.zip(coefficients.zip(out)) {
            *l = 1.0 + dt * ck + dt * dt * kk;
            *dv = dt * (f - kk * (q + dt * v) - ck * v) / *l;
        }
    }

    /// The velocity change at `x` so far in the step, and how much an impulse (N·s) at `x`
    /// adds to it (the step's mobility, m/s per N·s).
    pub fn free(&self, x: f64, phi: &mut [f64]) -> (f64, f64) {
        self.shapes(x, phi);
        let mut dv = 0.0;
        let mut w = 0.0;
        for ((p, d), l) in phi.iter().zip(&self.dv).zip(&self.lhs) {
            dv += p * d;
            w += p * p / l;
        }
        (dv, w)
    }

    /// An impulse `i` (N·s) at `x` in the step.
    pub fn impulse(&mut self, x: f64, i: f64, phi: &mut [f64]) {
        self.shapes(x, phi);
        for ((d, p), l) in self.dv.iter_mut().zip(phi.iter()).zip(&self.lhs) {
            *d += p * i / l;
        }
    }

    /// Ends the step: velocities take their change, displacements move with them.
    pub fn end(&mut self, dt: f64) {
        for ((q, v), d) in self.q.iter_mut().zip(&mut self.v).zip(&mut self.dv) {
            *v += *d;
            *q += dt * *v;
            *d = 0.0;
        }
    }

    /// Modal coordinates from values at the interior nodes (the inverse DST-I):
    /// `q_k = 2/(N·scale)·Σ_j sin(kπj/N)·w_j`, `sines[k·(N−1) + j]` = `sin((k+1)π(j+1)/N)`.
    pub(super) fn modes_from_nodes(&self, nodes: &[f64], sines: &[f64], out: &mut [f64]) {
        let n = nodes.len();
        let c = 2.0 / ((n + 1) as f64 * self.scale);
        for (k, o) in out.iter_mut().enumerate() {
            *o = c * dot(&sines[k * n..(k + 1) * n], nodes);
        }
    }

    /// Values at the interior nodes from modal coordinates `m` (the DST-I).
    pub(super) fn nodes_from_modes(&self, m: &[f64], sines: &[f64], out: &mut [f64]) {
        let n = m.len();
        for (j, o) in out.iter_mut().enumerate() {
            *o = self.scale * dot(&sines[j * n..(j + 1) * n], m);
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
