//! The linear model: the simulation held at its equilibrium, its state laid out, the state
//! derivative from the run's own forces, the equilibrium tightened, the numerical Jacobian,
//! and the modes of its eigenvalues.

use super::eigen::eigenvector;
use super::naming::family;
use super::{DOFS, Mode, ShapeEntry};
use crate::error::{Error, Result};
use crate::sim::{RailState, Simulation};
use nalgebra::{Complex, DMatrix, DVector, Matrix3, UnitQuaternion, Vector3};

/// The simulation held at its equilibrium, with the layout of the linear state.
pub(super) struct Linear<'a> {
    sim: Simulation<'a>,
    /// Reference rotation and angular velocity (world) of each body.
    rotations: Vec<UnitQuaternion<f64>>,
    omegas: Vec<Vector3<f64>>,
    /// Track axes of each body's reference place.
    axes: Vec<Matrix3<f64>>,
    positions: Vec<Vector3<f64>>,
    velocities: Vec<Vector3<f64>>,
    body_s: Vec<f64>,
    frames: Vec<crate::sim::TrackFrame>,
    memory: Vec<crate::vehicle::elements::Memory>,
    rails: Vec<RailState>,
    compliant: bool,
    hauled: bool,
}

impl<'a> Linear<'a> {
    pub(super) fn new(sim: Simulation<'a>) -> Self {
        let axes = sim.frames.iter().map(|f| f.axes).collect();
        Linear {
            rotations: sim.states.iter().map(|s| s.rotation).collect(),
            omegas: sim.states.iter().map(|s| s.angular_velocity).collect(),
            positions: sim.states.iter().map(|s| s.position).collect(),
            velocities: sim.states.iter().map(|s| s.velocity).collect(),
            body_s: sim.body_s.clone(),
            frames: sim.frames.clone(),
            memory: sim.memory.clone(),
            rails: sim.rails.clone(),
            compliant: sim.track.spec().rail_support.is_some(),
            hauled: sim.vehicle.hauling.is_some(),
            axes,
            sim,
        }
    }

    fn bodies(&self) -> usize {
        self.positions.len()
    }

    fn len(&self) -> usize {
        12 * self.bodies()
            + if self.compliant {
                4 * self.rails.len()
            } else {
                0
            }
            + 1
    }

    /// Puts the simulation at reference + `x` (every reference quantity restored first).
    fn set(&mut self, x: &DVector<f64>) {
        let last = self.len() - 1;
        let sim = &mut self.sim;
        for i in 0..self.positions.len() {
            let a = self.axes[i];
            let c = |k: usize| Vector3::new(x[12 * i + k], x[12 * i + k + 1], x[12 * i + k + 2]);
            sim.states[i].position = self.positions[i] + a * c(0);
            sim.states[i].rotation = UnitQuaternion::from_scaled_axis(a * c(3)) * self.rotations[i];
            sim.states[i].velocity = self.velocities[i] + a * c(6);
            sim.states[i].angular_velocity = self.omegas[i] + a * c(9);
        }
        sim.body_s.clone_from(&self.body_s);
        sim.frames.clone_from(&self.frames);
        sim.memory.clone_from(&self.memory);
        sim.rails.clone_from(&self.rails);
        let base = 12 * self.positions.len();
        if self.compliant {
            for (k, r) in sim.rails.iter_mut().enumerate() {
                r.y += x[base + 4 * k];
                r.vy += x[base + 4 * k + 1];
                r.z += x[base + 4 * k + 2];
                r.vz += x[base + 4 * k + 3];
            }
        }
        sim.hauling_integral = x[last];
    }

    /// Whether state `j` is a rate (a velocity), not a displacement.
    fn is_rate(&self, j: usize) -> bool {
        let base = 12 * self.bodies();
        if j < base {
            j % 12 >= 6
        } else {
            j + 1 < self.len() && (j - base) % 2 == 1
        }
    }

    /// The difference step of state `j` in the numerical derivatives.
    fn step_size(&self, j: usize) -> f64 {
        let base = 12 * self.bodies();
        match (j < base, j + 1 == self.len(), self.is_rate(j)) {
            (_, true, _) => 1e-4,
            (_, false, true) => 1e-5,
            (true, false, false) => 1e-6,
            (false, false, false) => 1e-7,
        }
    }

    /// Per state, the weight that makes a rate comparable with a displacement over a step `dt`
    /// (rates times `dt`).
    pub(super) fn rate_weights(&self, dt: f64) -> DVector<f64> {
        DVector::from_fn(self.len(), |j, _| if self.is_rate(j) { dt } else { 1.0 })
    }

    /// `a − b` of two copies of the run in the linear state's coordinates: the track axes of
    /// each body's reference place, rotations as the rotation vector of `R_a·R_b⁻¹`.
    pub(super) fn difference(&self, a: &Simulation, b: &Simulation) -> DVector<f64> {
        let n = self.len();
        let mut x = DVector::zeros(n);
        for i in 0..self.bodies() {
            let at = self.axes[i].transpose();
            let (p, q) = (&a.states[i], &b.states[i]);
            let blocks = [
                at * (p.position - q.position),
                at * (p.rotation * q.rotation.inverse()).scaled_axis(),
                at * (p.velocity - q.velocity),
                at * (p.angular_velocity - q.angular_velocity),
            ];
            for (k, v) in blocks.iter().enumerate() {
                for j in 0..3 {
                    x[12 * i + 3 * k + j] = v[j];
                }
            }
        }
        let base = 12 * self.bodies();
        if self.compliant {
            for (k, (r, r0)) in a.rails.iter().zip(&b.rails).enumerate() {
                x[base + 4 * k] = r.y - r0.y;
                x[base + 4 * k + 1] = r.vy - r0.vy;
                x[base + 4 * k + 2] = r.z - r0.z;
                x[base + 4 * k + 3] = r.vz - r0.vz;
            }
        }
        x[n - 1] = a.hauling_integral - b.hauling_integral;
        x
    }

    /// A copy of the run after `steps` of its own steps from reference + `x`; the reference
    /// stays as it was.
    pub(super) fn stepped(&mut self, x: &DVector<f64>, steps: usize) -> Result<Simulation<'a>> {
        let start = self.sim.clone();
        self.set(x);
        let mut out = Ok(());
        for _ in 0..steps {
            out = self.sim.step();
            if out.is_err() {
                break;
            }
        }
        let end = std::mem::replace(&mut self.sim, start);
        out.map(|_| end)
    }

    /// The run's own step as a linear map `x_{n+1} = Φ·x_n` about the reference, by central
    /// differences: each column is the difference of two steps from the reference stepped by
    /// ± a small amount, each read against the reference's own step (rotations included, so
    /// the wheelsets' spin over the step mixes nothing). Every step starts from a copy of the
    /// whole simulation (friction sliders, rails on sleepers, the train); the states outside
    /// `x` (the beams' modes, the sliders) start each step where the reference has them.
    pub(super) fn step_matrix(&mut self) -> Result<DMatrix<f64>> {
        let n = self.len();
        let reference = self.stepped(&DVector::zeros(n), 1)?;
        let mut phi = DMatrix::zeros(n, n);
        for j in 0..n {
            let h = self.step_size(j);
            let mut x = DVector::zeros(n);
            x[j] = h;
            let plus = self.stepped(&x, 1)?;
            let minus = self.stepped(&(-x), 1)?;
            let column = (self.difference(&plus, &reference) - self.difference(&minus, &reference))
                / (2.0 * h);
            phi.set_column(j, &column);
        }
        if phi.iter().any(|v| !v.is_finite()) {
            return Err(Error::Domain(
                "the step's linearisation gave a non-finite entry".into(),
            ));
        }
        Ok(phi)
    }

    /// The state derivative at reference + `x`.
    fn derivative(&mut self, x: &DVector<f64>) -> Result<DVector<f64>> {
        self.set(x);
        self.sim.forces(false)?;
        let sim = &self.sim;
        let n = self.len();
        let mut dx = DVector::zeros(n);
        for i in 0..self.positions.len() {
            let a = self.axes[i];
            let st = &sim.states[i];
            let body = &sim.vehicle.bodies[i];
            let w = &sim.wrenches[i];
            let phi = Vector3::new(x[12 * i + 3], x[12 * i + 4], x[12 * i + 5]);
            let w0 = a.transpose() * self.omegas[i];
            let rates = Vector3::new(x[12 * i + 9], x[12 * i + 10], x[12 * i + 11]);
            // Euler's equations in body axes, as the integrator (world ω̇ = R·ω̇_body).
            let rot = st.rotation;
            let wb = rot.inverse() * st.angular_velocity;
            let tb = rot.inverse() * w.torque;
            let dwb =
                (tb - wb.cross(&body.inertia.component_mul(&wb))).component_div(&body.inertia);
            let blocks = [
                Vector3::new(x[12 * i + 6], x[12 * i + 7], x[12 * i + 8]),
                rates - phi.cross(&w0),
                a.transpose() * (w.force / body.mass),
                a.transpose() * (rot * dwb),
            ];
            for (k, b) in blocks.iter().enumerate() {
                for j in 0..3 {
                    dx[12 * i + 3 * k + j] = b[j];
                }
            }
        }
        let base = 12 * self.positions.len();
        if self.compliant
            && let Some(sup) = sim.track.spec().rail_support
        {
            for (k, (r, f)) in sim.rails.iter().zip(&sim.rail_force).enumerate() {
                dx[base + 4 * k] = r.vy;
                dx[base + 4 * k + 1] =
                    (f[0] - sup.lateral.stiffness * r.y - sup.lateral.damping * r.vy)
                        / sup.lateral.mass;
                dx[base + 4 * k + 2] = r.vz;
                dx[base + 4 * k + 3] =
                    (f[1] - sup.vertical.stiffness * r.z - sup.vertical.damping * r.vz)
                        / sup.vertical.mass;
            }
        }
        if let Some(h) = sim.vehicle.hauling {
            let along = sim.frames[h.body].axes.column(0).into_owned();
            dx[n - 1] = sim.cfg.speed - sim.states[h.body].velocity.dot(&along);
        }
        Ok(dx)
    }

    /// Brings the reference to equilibrium where the run's start leaves a residual: each
    /// wheelset's spin to its elastic contact's rolling radius (no longitudinal creep), each
    /// rail mass to its static deflection under the wheel. A few Newton steps on those
    /// states alone.
    pub(super) fn equilibrate(&mut self) {
        let base = 12 * self.positions.len();
        // (state to move, derivative that must vanish)
        let mut pairs: Vec<(usize, usize)> = self
            .sim
            .vehicle
            .contact
            .wheelsets
            .iter()
            .map(|&w| (12 * w + 10, 12 * w + 10))
            .collect();
        if self.compliant {
            for k in 0..self.rails.len() {
                pairs.push((base + 4 * k, base + 4 * k + 1));
                pairs.push((base + 4 * k + 2, base + 4 * k + 3));
            }
        }
        let n = self.len();
        let m = pairs.len();
        for _ in 0..3 {
            let zero = DVector::zeros(n);
            let Ok(d0) = self.derivative(&zero) else {
                return;
            };
            let mut jac = DMatrix::zeros(m, m);
            for (c, &(state, _)) in pairs.iter().enumerate() {
                let h = if state < base { 1e-4 } else { 1e-7 };
                let mut x = DVector::zeros(n);
                x[state] = h;
                let Ok(d) = self.derivative(&x) else {
                    return;
                };
                for (r, &(_, res)) in pairs.iter().enumerate() {
                    jac[(r, c)] = (d[res] - d0[res]) / h;
                }
            }
            let rhs = DVector::from_iterator(m, pairs.iter().map(|&(_, res)| -d0[res]));
            let Some(step) = jac.lu().solve(&rhs) else {
                return;
            };
            for (&(state, _), &dx) in pairs.iter().zip(step.iter()) {
                if state < base {
                    let w = state / 12;
                    self.omegas[w] += self.axes[w] * Vector3::new(0.0, dx, 0.0);
                } else {
                    let (k, c) = ((state - base) / 4, (state - base) % 4);
                    if c == 0 {
                        self.rails[k].y += dx;
                    } else {
                        self.rails[k].z += dx;
                    }
                }
            }
        }
    }

    /// Largest acceleration at the reference state, m/s².
    pub(super) fn residual(&mut self) -> f64 {
        let x = DVector::zeros(self.len());
        match self.derivative(&x) {
            Ok(d) => (0..self.positions.len())
                .flat_map(|i| (6..9).map(move |k| 12 * i + k))
                .map(|j| d[j].abs())
                .fold(0.0, f64::max),
            Err(_) => f64::NAN,
        }
    }

    /// The numerical Jacobian by central differences. Each wheelset's lateral position is
    /// the contact's quasi-linearisation: its column is the secant over ± `amplitude` along
    /// the contact's kinematic path — the wheelset shifted with the roll and height its rigid
    /// contact takes there (from the contact table), so both wheels stay on their rails — less
    /// the parts of that roll and height, which their own columns carry. Every other state is
    /// stepped by a small amount.
    pub(super) fn jacobian(&mut self, amplitude: f64) -> Result<DMatrix<f64>> {
        let n = self.len();
        let wheelsets = self.sim.vehicle.contact.wheelsets.clone();
        let mut a = DMatrix::zeros(n, n);
        let base = 12 * self.positions.len();
        let column = |lin: &mut Self, x: &DVector<f64>, h: f64| -> Result<DVector<f64>> {
            let plus = lin.derivative(x)?;
            let minus = lin.derivative(&(-x))?;
            Ok((plus - minus) / (2.0 * h))
        };
        for j in 0..n {
            if j < base && j % 12 == 1 && wheelsets.contains(&(j / 12)) {
                continue; // below, once the roll and height columns are known
            }
            let h = self.step_size(j);
            let mut x = DVector::zeros(n);
            x[j] = h;
            let c = column(self, &x, h)?;
            a.set_column(j, &c);
        }
        let table = self.sim.table;
        let (r0, z0) = {
            let c = table.lookup(0.0);
            (c.roll, c.z)
        };
        let (rp, rm) = (table.lookup(amplitude), table.lookup(-amplitude));
        let c_roll = (rp.roll - rm.roll) / (2.0 * amplitude);
        let c_z = (rp.z - rm.z) / (2.0 * amplitude);
        for &w in &wheelsets {
            let j = 12 * w + 1;
            let mut x = DVector::zeros(n);
            x[j] = amplitude;
            x[12 * w + 3] = rp.roll - r0;
            x[12 * w + 2] = rp.z - z0;
            let plus = self.derivative(&x)?;
            x[j] = -amplitude;
            x[12 * w + 3] = rm.roll - r0;
            x[12 * w + 2] = rm.z - z0;
            let minus = self.derivative(&x)?;
            let along = (plus - minus) / (2.0 * amplitude);
            let col = along - a.column(12 * w + 3) * c_roll - a.column(12 * w + 2) * c_z;
            a.set_column(j, &col);
        }
        if !self.hauled {
            // No controller: its integral is a dead state; leave it decoupled.
            a[(n - 1, n - 1)] = 0.0;
        }
        if a.iter().any(|v| !v.is_finite()) {
            return Err(Error::Domain(
                "the linearisation gave a non-finite derivative".into(),
            ));
        }
        Ok(a)
    }

    /// The first harmonic of the wrench `element` (the vehicle's element `index`) puts on every
    /// body (force, torque per body, world axes) while the state moves through
    /// `Re(scale·shape·e^{iθ})`: a first cycle from the reference's memory brings its sliders
    /// onto the steady hysteresis loop, the second is measured (`F̂ = (1/π)∫F·e^{−iθ}dθ`).
    pub(super) fn element_harmonic(
        &mut self,
        element: &crate::vehicle::Element,
        index: usize,
        shape: &DVector<Complex<f64>>,
        scale: f64,
    ) -> DVector<Complex<f64>> {
        const STEPS: usize = 128;
        let nb = self.bodies();
        let mut memory = self.memory[index];
        let mut h = DVector::zeros(6 * nb);
        for k in 0..2 * STEPS {
            let turn =
                Complex::from_polar(scale, 2.0 * std::f64::consts::PI * k as f64 / STEPS as f64);
            let x = shape.map(|v| (v * turn).re);
            self.set(&x);
            let mut wrenches = vec![crate::vehicle::Wrench::default(); nb];
            element.apply(
                &self.sim.states,
                &mut memory,
                &mut wrenches,
                self.sim.cfg.dt,
            );
            if k >= STEPS {
                let e = harmonic_weight(k, STEPS);
                for (i, w) in wrenches.iter().enumerate() {
                    for j in 0..3 {
                        h[6 * i + j] += e * w.force[j];
                        h[6 * i + 3 + j] += e * w.torque[j];
                    }
                }
            }
        }
        h
    }

    /// The eigenvalue of `a` below `max_frequency` with the least damping ratio, and its
    /// eigenvector.
    pub(super) fn least_damped(
        &self,
        a: &DMatrix<f64>,
        max_frequency: f64,
    ) -> Option<(Complex<f64>, DVector<Complex<f64>>)> {
        let wmax = 2.0 * std::f64::consts::PI * max_frequency;
        let l = a
            .clone()
            .complex_eigenvalues()
            .iter()
            .copied()
            .filter(|l| l.im > 1e-3 && l.im <= wmax && l.norm() > 1e-6)
            .max_by(|a, b| (a.re / a.norm()).total_cmp(&(b.re / b.norm())))?;
        let (q, h) = nalgebra::linalg::Hessenberg::new(a.clone()).unpack();
        Some((l, eigenvector(&q, &h, l)))
    }

    /// Index of the lateral displacement of the vehicle's first wheelset in the state.
    pub(super) fn leading_lateral(&self) -> usize {
        12 * self.sim.vehicle.contact.wheelsets[0] + 1
    }

    /// Eigenvalues and named modes of `a` below `max_frequency`.
    pub(super) fn analyse(&self, a: &DMatrix<f64>, max_frequency: f64) -> Vec<Mode> {
        let eig = a.clone().complex_eigenvalues();
        let hess = nalgebra::linalg::Hessenberg::new(a.clone());
        let (q, h) = hess.unpack();
        let wmax = 2.0 * std::f64::consts::PI * max_frequency;
        let mut modes: Vec<Mode> = eig
            .iter()
            .filter(|l| l.im > 1e-3 && l.im <= wmax && l.norm() > 1e-6)
            .map(|&l| {
                let v = eigenvector(&q, &h, l);
                self.mode(l, &v)
            })
            .collect();
        modes.sort_by(|a, b| a.damping_ratio.total_cmp(&b.damping_ratio));
        modes
    }

    /// A mode from its eigenvalue and eigenvector: energy shares, name, shape.
    pub(super) fn mode(&self, l: Complex<f64>, v: &DVector<Complex<f64>>) -> Mode {
        let vehicle = self.sim.vehicle;
        // Kinetic energy of each degree of freedom from its displacement's rate λ·q (the
        // rates of the rotation coordinates, not the spinning wheelsets' angular velocity).
        let mut entries: Vec<(String, &'static str, f64, Complex<f64>)> = Vec::new();
        for (i, b) in vehicle.bodies.iter().enumerate() {
            for k in 0..6 {
                let weight = if k < 3 { b.mass } else { b.inertia[k - 3] };
                let disp = v[12 * i + k];
                entries.push((
                    b.name.clone(),
                    DOFS[k],
                    weight * (l * disp).norm_sqr(),
                    disp,
                ));
            }
        }
        let base = 12 * self.positions.len();
        if self.compliant
            && let Some(sup) = self.sim.track.spec().rail_support
        {
            for k in 0..self.rails.len() {
                let name = format!("rail {}", crate::sim::wheel_name(k));
                for (d, dof, m) in [
                    (0, "lateral", sup.lateral.mass),
                    (2, "vertical", sup.vertical.mass),
                ] {
                    let disp = v[base + 4 * k + d];
                    entries.push((name.clone(), dof, m * (l * disp).norm_sqr(), disp));
                }
            }
        }
        let total: f64 = entries.iter().map(|e| e.2).sum::<f64>().max(1e-300);
        let biggest = entries
            .iter()
            .map(|e| e.3)
            .max_by(|a, b| a.norm().total_cmp(&b.norm()))
            .unwrap_or(Complex::new(1.0, 0.0));
        let mut shape: Vec<ShapeEntry> = entries
            .iter()
            .map(|(body, dof, e, d)| ShapeEntry {
                body: body.clone(),
                dof,
                share: e / total,
                amplitude: d.norm() / biggest.norm().max(1e-300),
                phase_deg: (d / biggest).arg().to_degrees(),
            })
            .collect();
        shape.sort_by(|a, b| b.share.total_cmp(&a.share));
        let dominant = shape
            .first()
            .map(|s| (s.body.clone(), s.dof, s.share))
            .unwrap_or_default();
        let wheelsets: Vec<&str> = vehicle
            .contact
            .wheelsets
            .iter()
            .map(|&w| vehicle.bodies[w].name.as_str())
            .collect();
        let carbody = vehicle
            .sensors
            .as_ref()
            .map(|s| vehicle.bodies[s.carbody].name.as_str());
        let name = family(&shape, &wheelsets, carbody);
        shape.retain(|s| s.share >= 0.05);
        Mode {
            real: l.re,
            imag: l.im,
            frequency_hz: l.im / (2.0 * std::f64::consts::PI),
            damping_ratio: -l.re / l.norm(),
            name,
            dominant,
            shape,
        }
    }
}

/// The weight of sample `k` of `steps` per cycle in the first harmonic `(1/π)∫F·e^{−iθ}dθ`.
pub(super) fn harmonic_weight(k: usize, steps: usize) -> Complex<f64> {
    let theta = 2.0 * std::f64::consts::PI * k as f64 / steps as f64;
    Complex::from_polar(2.0 / steps as f64, -theta)
}
