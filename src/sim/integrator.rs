//! One step of the bodies' motion: semi-implicit Euler with the wheel–rail damping taken
//! implicitly (linearly implicit, issue 37), the same with the contact's Hertz spring taken in
//! too (linearly implicit Hertz), plain semi-implicit Euler, or Heun's method.
//!
//! Creep acts on a wheelset as a damper of `c ≈ f/V` (Kalker's coefficients over the speed):
//! at 40–60 km/h its time constant is about a millisecond, so an explicit step must stay far
//! below it (the statistics of a 0.4 ms step are 21 % off at 40 km/h, `bench step`). The
//! linearly implicit step solves `(I + ½Δt·M⁻¹·D)·Δu = Δt·M⁻¹·F` for each wheelset's velocity
//! change `Δu = (Δv, Δω)`, with `D` the contact's damping linearised by Kalker's linear theory
//! at the law's saturation ([`crate::contact::patch_damping`]): the damping's share is taken at the
//! step's midpoint (the trapezoidal rule: second order in it and without numerical damping;
//! at ½ it was 2–3 times closer to the fine-step statistics than at 1, fully implicit). The
//! creep forces themselves stay the law's. With `D = 0` it is the explicit step.
//!
//! On a compliant track the same damper joins the wheel to its rail mass (the rail's velocity
//! enters the creepage): each wheelset and its two rail masses are solved together, 10
//! unknowns, with the shared damper at θ = ½ on both sides and the rails' support implicit.
//! Solved apart, at 0.6 ms and 40 km/h, the statistics were 3.2 % off against 0.16 %. The
//! contact's Hertz spring stays explicit on the rail as on the wheelset: taken implicitly
//! (backward Euler on the rail mass on the Hertz spring, about 400 Hz) it took that mode's
//! energy out every step, a first-order error of 0.64 / 1.31 / 2.56 % in the trailing wheels'
//! Y/Q rms at 0.1 / 0.2 / 0.4 ms (R 400 m, 80 km/h; 0.22 % at 0.4 ms explicit). Explicit, it
//! sets the step's limit: ω·Δt < 2 with ω = √((k_H + k_s)/m_rail) ≈ 2 500 rad/s, 0.79 ms
//! (runs at 0.8 ms diverge, measured).
//!
//! The contact's Hertz spring in the solve (`linearly-implicit-hertz`): explicit, the wheel and
//! its rail mass on the spring between them (about 2 840 rad/s) limit the step to ω·Δt < 2, and
//! the statistics fall off a cliff above 0.6 ms (28–38 % off at 5/7 ms, R 400 m at 100 km/h).
//! Taking `α·Δt²·K` into the solve beside `θ·Δt·D` (`K` the patches' normal stiffness at their
//! load centres, [`crate::contact::patch_stiffness`]) makes a linear spring's step
//! `M·Δv = Δt·F(x) − α·Δt²·K·Δv`: symplectic Euler on `ω̃² = ω²/(1 + α·ω²·Δt²)`, with no
//! numerical damping and a stability limit of ω·Δt < 2/√(1 − 4α). α = 1/12 is Fox and
//! Goodwin's share (Newmark's β = 1/12, γ = ½), whose frequency is right to fourth order (5 %
//! high at ω·Δt = 2, limit 2.45); α = 0.1, the default's, puts it right at the default step
//! with a wider margin (see [`ALPHA`]); α = ¼ (the average acceleration, unconditionally
//! stable) puts the mode 13 % low at 0.5 ms (tried earlier, without the surface's change
//! below: Q's standard deviation 1.1 % off at 0.5 ms). The share sees the rail masses'
//! motion, and it must see the rail surface's: the irregularity passing under the wheel is the
//! spring's other end, and a share that ignores its change over the step acts on the wheel's
//! following of it as an extra mass `θ·Δt·c_n + α·Δt²·k_n` (25 + 38 kg per wheel at 0.5 ms
//! and α = 0.1, against the wheel's 650; measured with α = 1/12, R 400 m at 100 km/h: Q's
//! standard deviation 0.53 → 0.29 % off at 0.5 ms and 1.07 → 0.62 % at 5/7 ms with the change
//! seen). The change is taken from the last step (one step behind, an estimate).
//!
//! The same integrator takes each wheelset's gyroscopic moment into the solve at θ = ½ (the
//! spin Ω = V/r₀ couples roll and yaw by `I_y·Ω`). Explicit, that coupling lags half a step,
//! a first-order error in the hunting threshold: the restrained wheelset's critical speed
//! (`validate dynamics`, Wickens; closed form 38.33 m/s) was 38.34 / 38.28 / 38.23 / 38.06 /
//! 37.95 / 37.89 m/s at 0.05 (semi-implicit) / 0.125 / 0.25 / 0.5 / 0.625 / 5/7 ms, the Hertz
//! share making no difference at 0.5 ms; with the moment in the solve, 38.34 m/s at 0.5 and
//! 5/7 ms alike (the bisection's resolution is 0.06 m/s).

use super::Simulation;
use super::wheel_rail::{RailCoupling, RailState};
use nalgebra::{Matrix2, Matrix3, Matrix6, SMatrix, UnitQuaternion, Vector2, Vector3, Vector6};

/// Share of the contact damping taken at the step's end, on the wheelset and its rails alike
/// (the trapezoidal rule; see the module's comment).
const THETA: f64 = 0.5;

/// Share of the contact's Hertz spring taken at the step's end with
/// [`Integrator::LinearlyImplicitHertz`]: `α` in `α·Δt²·K` (see the module's comment). The share
/// that puts the wheel–rail mode's frequency right at the default step is 0.104 (ω·Δt = 2.03 at
/// 5/7 ms), and 0.097 at 0.625 ms; 0.1 puts it within 1 % at both. Fox and Goodwin's 1/12
/// (the frequency right to fourth order in ω·Δt) has the smaller stability margin, ω·Δt < 2.45
/// against 2.58: the Hertz spring stiffens as N^{1/3}, so a load peak of 3.1 times the static
/// load takes 1/12 past its limit at 5/7 ms and 4.2 times takes 0.1. Measured on paper34's 34
/// conditions at 5/7 ms (`bench step`, 60 s): with 1/12 four conditions 1.0–1.7 % off in Q's
/// standard deviation (tangent at 60 km/h 1.2 %), with 0.1 every one within 0.67 %.
const ALPHA: f64 = 0.1;

/// How the linearly implicit solve takes the contact at step `dt`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Shares {
    /// `θ` of its damping.
    pub theta: f64,
    /// `α·Δt` of its normal stiffness (0: the Hertz spring explicit).
    pub alpha_dt: f64,
}

/// Mass, support stiffness and support damping of a rail mass, lateral and vertical.
fn rail_matrices(sup: &crate::track::RailSupport) -> (Matrix2<f64>, Matrix2<f64>, Matrix2<f64>) {
    (
        Matrix2::from_diagonal(&Vector2::new(sup.lateral.mass, sup.vertical.mass)),
        Matrix2::from_diagonal(&Vector2::new(sup.lateral.stiffness, sup.vertical.stiffness)),
        Matrix2::from_diagonal(&Vector2::new(sup.lateral.damping, sup.vertical.damping)),
    )
}

/// How the bodies are integrated over a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integrator {
    /// Semi-implicit (symplectic) Euler: velocities first, positions with the new velocities
    /// (the default until 2026-12-04, at 0.2 ms).
    SemiImplicit,
    /// Semi-implicit Euler with each wheelset's velocity change, and its rail masses', taken
    /// implicitly in the linearised wheel–rail damping (creep and normal), the contact's Hertz
    /// spring explicit: the default until 2026-12-04 (late), at 0.5 ms.
    LinearlyImplicit,
    /// The linearly implicit step with the contact's Hertz spring in the solve too (`α·Δt²·K`,
    /// α = 0.1: no numerical damping, the wheel–rail mode's frequency right at the step), the
    /// rail surface's passing under the wheel seen by that share: the default, at 5/7 ms (seven
    /// steps per 200 Hz sample).
    #[default]
    LinearlyImplicitHertz,
    /// Heun's method (explicit trapezoidal, second order): two force evaluations a step, the
    /// friction sliders and the haul's integral advanced at the accepted state only.
    Heun,
}

impl Integrator {
    /// Names as the command line takes them.
    pub const NAMES: [&'static str; 4] = [
        "semi-implicit",
        "linearly-implicit",
        "heun",
        "linearly-implicit-hertz",
    ];

    /// Parses `semi-implicit`, `linearly-implicit`, `heun` or `linearly-implicit-hertz`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "semi-implicit" => Some(Integrator::SemiImplicit),
            "linearly-implicit" => Some(Integrator::LinearlyImplicit),
            "heun" => Some(Integrator::Heun),
            "linearly-implicit-hertz" => Some(Integrator::LinearlyImplicitHertz),
            _ => None,
        }
    }

    /// The step a run takes with it when none is given, s: the largest whose statistics stay
    /// within 1 % of the semi-implicit step at 0.05 ms on every paper34 condition (`bench
    /// step`; README, "Speed"), and a whole number of steps per 200 Hz output sample.
    pub fn default_step(self) -> f64 {
        match self {
            Integrator::SemiImplicit | Integrator::Heun => 2e-4,
            Integrator::LinearlyImplicit => 5e-4,
            // Seven steps per 200 Hz output sample.
            Integrator::LinearlyImplicitHertz => 5e-3 / 7.0,
        }
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::SemiImplicit => Self::NAMES[0],
            Integrator::LinearlyImplicit => Self::NAMES[1],
            Integrator::Heun => Self::NAMES[2],
            Integrator::LinearlyImplicitHertz => Self::NAMES[3],
        }
    }

    /// Whether each wheelset is solved implicitly in its contact.
    pub fn implicit(self) -> bool {
        matches!(
            self,
            Integrator::LinearlyImplicit | Integrator::LinearlyImplicitHertz
        )
    }

    /// `α`, the share of the contact's Hertz spring the solve takes (`α·Δt²·K`; 0 where the
    /// spring is explicit).
    pub fn stiffness_share(self) -> f64 {
        match self {
            Integrator::LinearlyImplicitHertz => ALPHA,
            _ => 0.0,
        }
    }

    /// How the implicit solve takes the contact at step `dt` (none for the explicit steps).
    pub(super) fn shares(self, dt: f64) -> Option<Shares> {
        self.implicit().then(|| Shares {
            theta: THETA,
            alpha_dt: self.stiffness_share() * dt,
        })
    }
}

/// The integrator and its step, as a run or a data set chooses them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stepping {
    /// How the bodies are integrated.
    pub integrator: Integrator,
    /// Integration step, s.
    pub dt: f64,
}

impl Stepping {
    /// The integrator named (checked against [`Integrator::NAMES`]; the default where none or
    /// an unknown one is named) at step `dt`, or at the integrator's own step.
    pub fn chosen(integrator: Option<&str>, dt: Option<f64>) -> Self {
        let integrator = integrator.and_then(Integrator::parse).unwrap_or_default();
        Stepping {
            integrator,
            dt: dt.unwrap_or(integrator.default_step()),
        }
    }
}

impl Default for Stepping {
    /// The default run's: linearly implicit at 0.5 ms.
    fn default() -> Self {
        let cfg = super::SimConfig::default();
        Stepping {
            integrator: cfg.integrator,
            dt: cfg.dt,
        }
    }
}

impl Simulation<'_> {
    /// Advances every body by one step under the wrenches of the current state.
    pub(super) fn integrate(&mut self) {
        let dt = self.cfg.dt;
        let wheelsets = &self.vehicle.contact.wheelsets;
        let support = self.track.spec().rail_support;
        let (rails, coupling, rail_force) =
            (&mut self.rails, &self.rail_coupling, &self.rail_force);
        let (inputs, last_rates) = (&self.inputs, &mut self.surface_rates);
        let implicit = self.cfg.integrator.implicit();
        let follow_surface = self
            .cfg
            .integrator
            .shares(dt)
            .is_some_and(|s| s.alpha_dt > 0.0);
        for (i, (st, w)) in self.states.iter_mut().zip(&self.wrenches).enumerate() {
            let b = &self.vehicle.bodies[i];
            let (acc, wb, dwb) = body_rates(b, st, w);
            let rot = st.rotation;
            let wheelset = if implicit {
                wheelsets.iter().position(|&ws| ws == i)
            } else {
                None
            };
            let damping = wheelset.map(|k| &self.contact_damping[k]);
            let Some(d) = damping else {
                self.accelerations[i] = acc;
                st.velocity += acc * dt;
                st.position += st.velocity * dt;
                let wb = wb + dwb * dt;
                st.angular_velocity = rot * wb;
                st.rotation = rot * UnitQuaternion::from_scaled_axis(wb * dt);
                continue;
            };
            // The explicit change, then (I + ½Δt·M⁻¹·D)·Δu = Δu_explicit, with the wheelset's
            // two rail masses in the same solve on a compliant track.
            let dw_explicit = rot * (wb + dwb * dt) - st.angular_velocity;
            let r = rot.to_rotation_matrix().into_inner();
            let inv_inertia =
                r * Matrix3::from_diagonal(&b.inertia.map(|x| 1.0 / x)) * r.transpose();
            let du = Vector6::new(
                acc.x * dt,
                acc.y * dt,
                acc.z * dt,
                dw_explicit.x,
                dw_explicit.y,
                dw_explicit.z,
            );
            let k = wheelset.expect("a damped body is a wheelset");
            let gyroscopic = if follow_surface {
                // The gyroscopic moment in the solve at θ (its slope in ω:
                // ∂(ω × I·ω)/∂ω = [ω]×·I − [I·ω]×): explicit, the spin's coupling of roll and
                // yaw lags half a step, a first-order error in the hunting threshold (module
                // comment).
                let iw = r * Matrix3::from_diagonal(&b.inertia) * r.transpose();
                let w = st.angular_velocity;
                inv_inertia * (w.cross_matrix() * iw - (iw * w).cross_matrix()) * (THETA * dt)
            } else {
                Matrix3::zeros()
            };
            let body = Inverse {
                mass: b.mass,
                inertia: inv_inertia,
                gyroscopic,
            };
            // The rail surface's rate under each wheel changes over the step as the wheel rolls
            // on (the irregularity's curvature): the normal law's share in the solve sees that
            // change as it sees a rail mass's, else it acts on the wheel's following of the
            // irregularity as a mass of θ·Δt·c_n + α·Δt²·k_n (tens of kg at 0.5 ms). The
            // change is the last step's, an estimate one step behind.
            let pair = 2 * k..2 * k + 2;
            let mut surface = [Vector2::zeros(); 2];
            let du = if follow_surface {
                let mut push = SMatrix::<f64, 6, 1>::zeros();
                for (side, idx) in pair.clone().enumerate() {
                    let now = Vector2::from(inputs[idx].surface_rate);
                    let change = last_rates[idx].map_or(Vector2::zeros(), |last| now - last);
                    last_rates[idx] = Some(now);
                    surface[side] = change * dt;
                    push += coupling[idx].from_surface * surface[side];
                }
                body.apply(&mut push);
                du + push
            } else {
                du
            };
            let du = match support {
                None => {
                    let mut a = d * (THETA * dt);
                    body.apply(&mut a);
                    let mut g = a.fixed_view_mut::<3, 3>(3, 3);
                    g += body.gyroscopic;
                    (Matrix6::identity() + a).lu().solve(&du).unwrap_or(du)
                }
                Some(sup) => with_rails(
                    &body,
                    d,
                    du,
                    dt,
                    &mut rails[pair.clone()],
                    &coupling[pair.clone()],
                    &rail_force[pair],
                    &surface,
                    &sup,
                ),
            };
            let dv = du.fixed_rows::<3>(0).into_owned();
            self.accelerations[i] = dv / dt;
            st.velocity += dv;
            st.position += st.velocity * dt;
            st.angular_velocity += du.fixed_rows::<3>(3).into_owned();
            let wb = rot.inverse() * st.angular_velocity;
            st.rotation = rot * UnitQuaternion::from_scaled_axis(wb * dt);
        }
    }
}

/// A wheelset's inverse mass: its mass and its inverse inertia tensor in world axes.
struct Inverse {
    mass: f64,
    inertia: Matrix3<f64>,
    /// `θ·Δt·I⁻¹·∂(ω × I·ω)/∂ω`, world axes (zero where the gyroscopic moment stays explicit).
    gyroscopic: Matrix3<f64>,
}

impl Inverse {
    /// `M⁻¹` applied to every column of `m`, whose rows are a wrench's (force, moment).
    fn apply<const C: usize>(&self, m: &mut SMatrix<f64, 6, C>) {
        for col in 0..C {
            let f = m.fixed_view::<3, 1>(0, col) / self.mass;
            let t = self.inertia * m.fixed_view::<3, 1>(3, col);
            m.fixed_view_mut::<3, 1>(0, col).copy_from(&f);
            m.fixed_view_mut::<3, 1>(3, col).copy_from(&t);
        }
    }
}

/// One linearly implicit step of a wheelset (velocity change `du` explicit, damping `d` in
/// world axes) and its two rail masses solved together; moves the rails and returns the
/// wheelset's velocity change. Wheelset rows: `(I + θΔt·M⁻¹·D)·Δu − θΔt·M⁻¹·Σ D_k·P·Δr_k =
/// Δu_explicit`. Rail rows, implicit in their support and in the damper they share with the
/// wheel (θ on both sides, so the damper's impulses are equal and opposite):
/// `(M_r + Δt·(θ·C_c + C_s) + Δt²·K_s)·Δr_k − θΔt·Pᵀ·D_k·Δu = Δt·(R_k − K_s·(x + Δt·v) − C_s·v)`.
#[allow(clippy::too_many_arguments)]
fn with_rails(
    body: &Inverse,
    d: &Matrix6<f64>,
    du: Vector6<f64>,
    dt: f64,
    rails: &mut [RailState],
    coupling: &[RailCoupling],
    rail_force: &[[f64; 2]],
    surface: &[Vector2<f64>; 2],
    sup: &crate::track::RailSupport,
) -> Vector6<f64> {
    let (m, ks, cs) = rail_matrices(sup);
    let mut a = d * (THETA * dt);
    body.apply(&mut a);
    let mut g = a.fixed_view_mut::<3, 3>(3, 3);
    g += body.gyroscopic;
    // The rails' rows eliminated (a Schur complement: each rail's block is 2×2), so the
    // solve is the wheelset's 6×6: Δr_k = L_k⁻¹·(r_k − Y_k·Δu),
    // (I + A − Σ X_k·L_k⁻¹·Y_k)·Δu = Δu_explicit − Σ X_k·L_k⁻¹·r_k.
    let mut lhs6 = Matrix6::identity() + a;
    let mut rhs6 = du;
    let mut parts = [(
        Matrix2::zeros(),
        SMatrix::<f64, 2, 6>::zeros(),
        Vector2::zeros(),
    ); 2];
    for side in 0..2 {
        let (rail, c, f) = (&rails[side], &coupling[side], rail_force[side]);
        let mut x = -c.from_rail * (THETA * dt);
        body.apply(&mut x);
        let y = -c.to_rail * (THETA * dt);
        let (xv, vv) = (Vector2::new(rail.y, rail.z), Vector2::new(rail.vy, rail.vz));
        let l = m + (c.damping * THETA + cs) * dt + ks * (dt * dt);
        let mut r = (Vector2::from(f) - ks * (xv + vv * dt) - cs * vv) * dt;
        if surface[side] != Vector2::zeros() {
            r -= c.surface_on_rail * surface[side];
        }
        let l_inv = l.try_inverse().unwrap_or_else(Matrix2::zeros);
        lhs6 -= x * (l_inv * y);
        rhs6 -= x * (l_inv * r);
        parts[side] = (l_inv, y, r);
    }
    let du = lhs6.lu().solve(&rhs6).unwrap_or(rhs6);
    for (rail, (l_inv, y, r)) in rails.iter_mut().zip(parts) {
        let dv = l_inv * (r - y * du);
        rail.vy += dv.x;
        rail.vz += dv.y;
        rail.y += rail.vy * dt;
        rail.z += rail.vz * dt;
    }
    du
}

/// A body's rates under its wrench: linear acceleration (world), angular velocity and angular
/// acceleration in body axes (Euler's equations, principal axes).
#[inline]
fn body_rates(
    b: &crate::vehicle::Body,
    st: &crate::vehicle::BodyState,
    w: &crate::vehicle::Wrench,
) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let inv = st.rotation.inverse();
    let wb = inv * st.angular_velocity;
    let tb = inv * w.torque;
    let dwb = (tb - wb.cross(&b.inertia.component_mul(&wb))).component_div(&b.inertia);
    (w.force / b.mass, wb, dwb)
}

impl Simulation<'_> {
    /// One step of Heun's method: the rates at the state (stage 1), an Euler predictor, the
    /// rates there (stage 2), and the mean of the two. The wheels' results, the accelerations
    /// and the rail forces a step reports are stage 1's (the state at the step's start, as
    /// the other integrators report them); the sliders' memory and the haul's integral move
    /// with stage 1 only, so stage 2 is a pure function of the predicted state.
    pub(super) fn step_heun(&mut self) -> crate::error::Result<()> {
        let dt = self.cfg.dt;
        let start = self.states.clone();
        let rails0 = self.rails.clone();
        self.forces(true)?;
        let rates: Vec<_> = (0..start.len())
            .map(|i| body_rates(&self.vehicle.bodies[i], &start[i], &self.wrenches[i]))
            .collect();
        let support = self.track.spec().rail_support;
        let rail_rates: Vec<[f64; 2]> = match support {
            Some(sup) => rails0
                .iter()
                .zip(&self.rail_force)
                .map(|(r, f)| {
                    [
                        sup.lateral.acceleration(r.y, r.vy, f[0]),
                        sup.vertical.acceleration(r.z, r.vz, f[1]),
                    ]
                })
                .collect(),
            None => Vec::new(),
        };
        let (wheels, rail_force, inputs) = (
            self.wheels.clone(),
            self.rail_force.clone(),
            self.inputs.clone(),
        );
        for (i, (st, &(acc, wb, dwb))) in self.states.iter_mut().zip(&rates).enumerate() {
            self.accelerations[i] = acc;
            st.position += st.velocity * dt;
            st.velocity += acc * dt;
            st.rotation *= UnitQuaternion::from_scaled_axis(wb * dt);
            st.angular_velocity = st.rotation * (wb + dwb * dt);
        }
        for (r, a) in self.rails.iter_mut().zip(&rail_rates) {
            r.y += r.vy * dt;
            r.z += r.vz * dt;
            r.vy += a[0] * dt;
            r.vz += a[1] * dt;
        }
        let memory = self.memory.clone();
        self.forces(false)?;
        self.memory = memory;
        let h = 0.5 * dt;
        for (i, (st, (s0, &(acc1, wb1, dwb1)))) in self
            .states
            .iter_mut()
            .zip(start.iter().zip(&rates))
            .enumerate()
        {
            let (acc2, wb2, dwb2) = body_rates(&self.vehicle.bodies[i], st, &self.wrenches[i]);
            st.position = s0.position + (s0.velocity + st.velocity) * h;
            st.velocity = s0.velocity + (acc1 + acc2) * h;
            st.rotation = s0.rotation * UnitQuaternion::from_scaled_axis((wb1 + wb2) * h);
            st.angular_velocity = st.rotation * (wb1 + (dwb1 + dwb2) * h);
        }
        if let Some(sup) = support {
            for (((r, r0), a1), f) in self
                .rails
                .iter_mut()
                .zip(&rails0)
                .zip(&rail_rates)
                .zip(&self.rail_force)
            {
                let a2 = [
                    sup.lateral.acceleration(r.y, r.vy, f[0]),
                    sup.vertical.acceleration(r.z, r.vz, f[1]),
                ];
                r.y = r0.y + (r0.vy + r.vy) * h;
                r.z = r0.z + (r0.vz + r.vz) * h;
                r.vy = r0.vy + (a1[0] + a2[0]) * h;
                r.vz = r0.vz + (a1[1] + a2[1]) * h;
            }
        }
        (self.wheels, self.rail_force, self.inputs) = (wheels, rail_force, inputs);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::track::{RailSupport, Support};

    /// A damper at point `p` (wheelset axes = track axes here rotated by `a`), damping `c`
    /// along track x, y, z: `D = [C, −C·[p]×; [p]×·C, −[p]×·C·[p]×]` in track axes.
    fn point_damper(p: Vector3<f64>, c: Vector3<f64>) -> Matrix6<f64> {
        let (c, px) = (Matrix3::from_diagonal(&c), p.cross_matrix());
        let mut d = Matrix6::zeros();
        d.fixed_view_mut::<3, 3>(0, 0).copy_from(&c);
        d.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-c * px));
        d.fixed_view_mut::<3, 3>(3, 0).copy_from(&(px * c));
        d.fixed_view_mut::<3, 3>(3, 3).copy_from(&(-(px * c * px)));
        d
    }

    /// The damper a wheel shares with its rail moves momentum between them and creates none:
    /// with no other force (rails free, no support), a wheelset sliding sideways over its
    /// rails on a canted, turned track gives them exactly the lateral and vertical momentum it
    /// loses at every step, the energy never rises, and it settles near a perfectly
    /// inelastic collision's.
    #[test]
    fn the_shared_damper_conserves_momentum_and_dissipates() {
        let a = (nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), 0.3)
            * nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), 0.1))
        .into_inner();
        let free = Support {
            mass: 250.0,
            stiffness: 0.0,
            damping: 0.0,
        };
        let sup = RailSupport {
            lateral: free,
            vertical: free,
        };
        let (mass, dt) = (1200.0, 5e-4);
        let body = Inverse {
            mass,
            inertia: Matrix3::from_diagonal(&Vector3::new(700.0, 100.0, 700.0).map(|x| 1.0 / x)),
            gyroscopic: Matrix3::zeros(),
        };
        let dampers = [
            point_damper(Vector3::new(0.0, 0.75, -0.42), Vector3::new(4e5, 3e5, 2e5)),
            point_damper(Vector3::new(0.0, -0.75, -0.42), Vector3::new(4e5, 5e5, 2e5)),
        ];
        let coupling = dampers.map(|d| RailCoupling::new(&d, &a));
        let mut d = Matrix6::zeros();
        for dk in &dampers {
            let mut w = Matrix6::zeros();
            for (r, c) in [(0, 0), (0, 3), (3, 0), (3, 3)] {
                let blk = dk.fixed_view::<3, 3>(r, c).into_owned();
                w.fixed_view_mut::<3, 3>(r, c)
                    .copy_from(&(a * blk * a.transpose()));
            }
            d += w;
        }
        // The wheelset slides 0.1 m/s sideways (track y) and sinks 0.01 m/s; rails at rest.
        let v0 = a * Vector3::new(0.0, 0.1, -0.01);
        let mut u = Vector6::new(v0.x, v0.y, v0.z, 0.0, 0.0, 0.0);
        let mut rails = [RailState::default(); 2];
        let inertia = Matrix3::from_diagonal(&Vector3::new(700.0, 100.0, 700.0));
        let energy = |u: &Vector6<f64>, rails: &[RailState; 2]| {
            let (v, w) = (u.fixed_rows::<3>(0), u.fixed_rows::<3>(3));
            0.5 * mass * v.norm_squared()
                + 0.5 * w.dot(&(inertia * w))
                + rails
                    .iter()
                    .map(|r| 0.5 * 250.0 * (r.vy * r.vy + r.vz * r.vz))
                    .sum::<f64>()
        };
        let e0 = energy(&u, &rails);
        let mut e = e0;
        for _ in 0..20 {
            // The law's forces at the step's start: the same damper, linear.
            let r = |k: usize| Vector2::new(rails[k].vy, rails[k].vz);
            let mut du_exp =
                (-d * u + coupling[0].from_rail * r(0) + coupling[1].from_rail * r(1)) * dt;
            body.apply(&mut du_exp);
            let force = [0, 1].map(|k| {
                let f = coupling[k].to_rail * u - coupling[k].damping * r(k);
                [f.x, f.y]
            });
            let before = rails;
            let du = with_rails(
                &body,
                &d,
                du_exp,
                dt,
                &mut rails,
                &coupling,
                &force,
                &[Vector2::zeros(); 2],
                &sup,
            );
            // Wheelset's momentum change along track y and z against the rails'.
            let dp = a.transpose() * (du.fixed_rows::<3>(0) * mass);
            let rails_dp: f64 = (0..2).map(|k| (rails[k].vy - before[k].vy) * 250.0).sum();
            let rails_dz: f64 = (0..2).map(|k| (rails[k].vz - before[k].vz) * 250.0).sum();
            assert!(
                (dp.y + rails_dp).abs() < 1e-9 * dp.y.abs().max(1.0),
                "{dp} {rails_dp}"
            );
            assert!(
                (dp.z + rails_dz).abs() < 1e-9 * dp.z.abs().max(1.0),
                "{dp} {rails_dz}"
            );
            u += du;
            // A damper only dissipates.
            let now = energy(&u, &rails);
            assert!(now <= e * (1.0 + 1e-12), "energy rose: {e} → {now}");
            e = now;
        }
        // The rails were dragged along the slide, and the sliding's energy went: within 10 ms
        // close to a perfectly inelastic collision's, never below it (the least energy the
        // conserved momentum allows: m_w/(m_w + 2·m_r) of the start's).
        assert!(rails.iter().all(|r| r.vy > 0.01), "{rails:?}");
        let least = e0 * mass / (mass + 500.0);
        assert!(
            e >= least && e < 1.05 * least,
            "{e0} → {e}, at least {least}"
        );
    }

    /// The contact's Hertz spring in the solve against the closed form (issue 37's stiff
    /// spring–mass at the new step): a wheelset on two free rail masses (250 kg each) on
    /// vertical springs of 1.5 GN/m at its wheels, their relative mode at ω = 2 880 rad/s, so
    /// ω·Δt = 2.06 at 5/7 ms, past the explicit step's limit of 2. With the share α the step is
    /// symplectic Euler on `Ω² = ω²/(1 + α·ω²·Δt²)`: its period is `2π·Δt / (2·asin(Ω·Δt/2))`
    /// (within 0.5 %; measured 4·10⁻⁶ off), its amplitude neither grows nor decays (the largest swing of
    /// the last cycles within 2 % of the first's), the momentum stays; explicit (α = 0) it grows
    /// without bound.
    #[test]
    fn the_hertz_share_keeps_the_stiff_mode_at_its_closed_form() {
        let free = Support {
            mass: 250.0,
            stiffness: 0.0,
            damping: 0.0,
        };
        let sup = RailSupport {
            lateral: free,
            vertical: free,
        };
        let (mass, k, dt) = (1300.0, 1.5e9, 5e-3 / 7.0);
        let body = Inverse {
            mass,
            inertia: Matrix3::from_diagonal(&Vector3::new(700.0, 100.0, 700.0).map(|x| 1.0 / x)),
            gyroscopic: Matrix3::zeros(),
        };
        let springs = [0.75, -0.75]
            .map(|y| point_damper(Vector3::new(0.0, y, -0.45), Vector3::new(0.0, 0.0, k)));
        let omega = (2.0 * k * (1.0 / mass + 1.0 / 500.0)).sqrt();
        let run = |alpha: f64| {
            let d_eff = springs.map(|s| s * (alpha * dt / THETA));
            let coupling = d_eff.map(|d| RailCoupling::new(&d, &Matrix3::identity()));
            let d: Matrix6<f64> = d_eff.iter().sum();
            let (mut u, mut x) = (Vector6::zeros(), Vector6::zeros());
            // The wheelset 10 µm into its rails, everything at rest.
            x[2] = -1e-5;
            let mut rails = [RailState::default(); 2];
            let mut rel = Vec::new();
            for _ in 0..3000 {
                let r = |k: usize| Vector6::new(0.0, rails[k].y, rails[k].z, 0.0, 0.0, 0.0);
                let f = [0, 1].map(|j| -(springs[j] * (x - r(j))));
                let mut du_exp = (f[0] + f[1]) * dt;
                body.apply(&mut du_exp);
                let force = f.map(|f| [-f[1], -f[2]]);
                let du = with_rails(
                    &body,
                    &d,
                    du_exp,
                    dt,
                    &mut rails,
                    &coupling,
                    &force,
                    &[Vector2::zeros(); 2],
                    &sup,
                );
                u += du;
                x += u * dt;
                rel.push(x[2] - 0.5 * (rails[0].z + rails[1].z));
                if rel[rel.len() - 1].abs() > 1e-3 {
                    break; // a hundred times the start: diverging
                }
                let momentum = mass * u[2] + 250.0 * (rails[0].vz + rails[1].vz);
                let scale = mass * u[2].abs() + 250.0 * (rails[0].vz.abs() + rails[1].vz.abs());
                assert!(momentum.abs() <= 1e-12 * scale.max(1.0), "{momentum}");
            }
            rel
        };
        let rel = run(ALPHA);
        assert_eq!(rel.len(), 3000);
        let up: Vec<f64> = (1..rel.len())
            .filter(|&i| rel[i - 1] < 0.0 && rel[i] >= 0.0)
            .map(|i| (i as f64 - rel[i] / (rel[i] - rel[i - 1])) * dt)
            .collect();
        let period = (up[up.len() - 1] - up[0]) / (up.len() - 1) as f64;
        let big = omega / (1.0 + ALPHA * (omega * dt).powi(2)).sqrt();
        let closed = std::f64::consts::TAU * dt / (2.0 * (big * dt / 2.0).asin());
        assert!(
            (period / closed - 1.0).abs() < 0.005,
            "period {period:e} s against {closed:e} s (ω·Δt {:.3})",
            omega * dt
        );
        let swing = |r: &[f64]| r.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let (first, last) = (swing(&rel[..300]), swing(&rel[rel.len() - 300..]));
        assert!((last / first - 1.0).abs() < 0.02, "{first:e} → {last:e}");
        let explicit = run(0.0);
        assert!(
            swing(&explicit) > 50.0 * first,
            "the explicit step at ω·Δt {:.2} should not hold",
            omega * dt
        );
    }
}
