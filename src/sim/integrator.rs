//! One step of the bodies' motion: semi-implicit Euler with the wheel–rail damping taken
//! implicitly (linearly implicit), the same with the contact's Hertz spring taken in
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
//! sets the step's limit: ω·Δt < 2 with ω = √((k_H + k_s)/m_rail) (an estimate: the wheel and rail
//! masses on the Hertz spring, about 2 990 rad/s, `railforce modes`), which with the side
//! frames on their pads keeps an explicit step below 0.8 ms (runs at 0.8 ms diverge, measured).
//!
//! The contact's Hertz spring and the gyroscopic moment in the solve
//! (`linearly-implicit-hertz`, the default): [`super::wheelset_solve`]. The same integrator
//! also solves each side frame in its pads' damping ([`super::element_solve`]): the side frame's pitch
//! and bounce on its two 200 MN/m pads (230 and 170 Hz, damping ratio 0.3–0.4) put the explicit
//! step's limit `ω²Δt² + 4ζωΔt < 4` near 0.8 ms (a run at 5/6 ms derailed within 0.1 s);
//! with the damping at θ = ½ it is `ω·Δt < 2`, 1.3 ms. The side frame is solved with the axle
//! held, and the axle takes the reaction of the damping's share in the same step, so the pair's
//! momentum balances.
//!
//! In a curve each body's velocity vectors turn with the track, `Δu = Δt·Ω × u` at a steady
//! state, `Ω = V·κ` about the vertical. That turning changes no creepage and no deflection,
//! but a share taken on the world velocities reads it as one: `θ·D·Δu` from the creep and
//! normal damping, `α·Δt·K·Δu` from the Hertz spring, acting on the spinning wheelset's axle as
//! it turns (`Ω_spin·Ω·Δt` about x). Measured on R 400 m at 100 km/h: the outer wheels' quasi-
//! static load 0.09 / 0.24 / 0.42 / 0.55 kN too high at 0.25 / 0.5 / 5/7 / 5/6 ms (Q's
//! standard deviation 1.03 % off at 5/6 ms), every step but the semi-implicit one's. The
//! Hertz integrator solves for the change relative to that turning (`Δu = Δu' + Δt·Ω × u`):
//! −0.02 kN at 5/7 and 5/6 ms, Q's standard deviation 0.14 / 0.38 % off. The `linearly-implicit`
//! integrator keeps the bias (its output stays what it was).

use super::Simulation;
use super::wheelset_solve::{ALPHA, Inverse, Shares, THETA, with_rails};
use nalgebra::{Matrix3, Matrix6, SMatrix, UnitQuaternion, Vector2, Vector3, Vector6};

/// How the bodies are integrated over a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integrator {
    /// Semi-implicit (symplectic) Euler: velocities first, positions with the new velocities
    /// (0.2 ms on its own; at 0.05 ms, the reference the implicit steps are measured against).
    SemiImplicit,
    /// Semi-implicit Euler with each wheelset's velocity change, and its rail masses', taken
    /// implicitly in the linearised wheel–rail damping (creep and normal), the contact's Hertz
    /// spring explicit, at 0.5 ms: for data sets made with it (their manifest names it) and as
    /// the Hertz variant without its additions.
    LinearlyImplicit,
    /// The linearly implicit step with the contact's Hertz spring in the solve too (`α·Δt²·K`,
    /// α = 0.15: no numerical damping, the wheel–rail mode's frequency 10 % low at the step),
    /// the rail surface's passing under the wheel seen by that share, each wheelset's gyroscopic
    /// moment in the solve at the step's midpoint, the side frames solved in their pads'
    /// damping, and every implicit share acting on the velocities relative to the turning
    /// track frame: the default, at 5/6 ms (six steps per 200 Hz sample).
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
    /// step`), and a whole number of steps per 200 Hz output sample.
    pub fn default_step(self) -> f64 {
        match self {
            Integrator::SemiImplicit | Integrator::Heun => 2e-4,
            Integrator::LinearlyImplicit => 5e-4,
            // Six steps per 200 Hz output sample.
            Integrator::LinearlyImplicitHertz => 5e-3 / 6.0,
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

    /// Whether the step takes the Hertz variant's additions beside the contact's Hertz share:
    /// the rail surface's passing, the wheelsets' gyroscopic moment, the side frames in their
    /// pads' damping and the shares relative to the turning track.
    pub(super) fn solves_bogie(self) -> bool {
        self == Integrator::LinearlyImplicitHertz
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

/// The integrator and its step, as a run or a data set chooses them (two are equal when their
/// integrator and step are, given or not).
#[derive(Debug, Clone, Copy)]
pub struct Stepping {
    /// How the bodies are integrated.
    pub integrator: Integrator,
    /// Integration step, s.
    pub dt: f64,
    /// Whether the step was given (else it is the integrator's own).
    pub given: bool,
}

/// The longest step a run on rails on sleepers takes ([`crate::track::discrete`]) unless
/// told otherwise, at or below 60 km/h; faster, the step shortens with the speed
/// ([`MAX_TRAVEL_ON_BEAMS`]). At 5/6 ms the rail under a flanging wheel (a bay's rail mass,
/// 36 kg, against the flange's Hertz stiffness) is not followed: on R 400 m at 100 km/h the run
/// chatters. Against the same model at 0.025 ms on R 400 m at 60 km/h, 0.1 ms holds every
/// wheel's Y/Q rms within 0.84 %, Q's and FL's standard deviation within 0.14 and 0.06 % and
/// FQ's 0–20 / 20–50 / 50–100 Hz bands within 0.03 / 0.28 / 1.64 %; 0.2 ms is 1.39 % off in
/// Y/Q (physics.md §3.3; `railforce bench step --rail-support discrete --reference 2.5e-5
/// --reference-integrator linearly-implicit-hertz`).
pub const MAX_STEP_ON_BEAMS: f64 = 1e-4;

/// The wagon's travel a step on rails on sleepers, m: 0.1 ms at 60 km/h. What a fixed step
/// leaves (the coupling's error, first order in the step: physics.md §3.3) grows with the speed,
/// as the excitation's frequencies and the sleepers' passing do: on R 400 m a fixed 0.1 ms is
/// 1.25 % off in the trailing wheels' Y/Q at 80 km/h and 6.3 % in FQ's 50–100 Hz band at
/// 100 km/h against 0.025 ms; at this travel a step (0.0746 and 0.0595 ms) Y/Q is 0.66 and
/// 0.29 % off and the band 1.71 and 0.79 % (physics.md §3.3).
pub const MAX_TRAVEL_ON_BEAMS: f64 = MAX_STEP_ON_BEAMS * 60.0 / 3.6;

/// The step on rails on sleepers at `speed` (m/s): [`MAX_STEP_ON_BEAMS`] up to 60 km/h, above
/// it [`MAX_TRAVEL_ON_BEAMS`] of travel a step at most, a whole fraction of the 5 ms sample.
pub fn step_on_beams(speed: f64) -> f64 {
    whole_fraction(MAX_STEP_ON_BEAMS.min(MAX_TRAVEL_ON_BEAMS / speed.abs().max(1e-9)))
}

/// The longest whole fraction of the 5 ms sample at most `wanted` (a step that a rounding
/// error leaves a hair above a whole fraction is taken as that fraction).
fn whole_fraction(wanted: f64) -> f64 {
    SAMPLE_INTERVAL / (SAMPLE_INTERVAL / wanted - 1e-9).ceil()
}

impl PartialEq for Stepping {
    fn eq(&self, other: &Self) -> bool {
        self.integrator == other.integrator && self.dt == other.dt
    }
}

/// The longest step a run over short waves takes (rail roughness, weld dips:
/// [`crate::track::short_wave`]), 80 per 5 ms sample. The engine's error in the label
/// wheel's FQ falls with the step's first power in the 20–50 and 50–100 Hz bands that short
/// waves excite: against a step ten times finer, 5/6 ms reads them 6 % and 22 % off on a
/// CNOSSOS-rough tangent at 100 km/h, 0.1 ms 0.8 % and 3.6 %, this step within 3 % (physics.md
/// §3.4; `railforce bench step` on such a track).
pub const MAX_STEP_SHORT_WAVES: f64 = 6.25e-5;

/// Steps per period of the shortest wave's passing frequency `V/λ` at least, so a wave
/// shorter than the default 0.1 m is followed too (ω·Δt ≤ 2π/20).
pub const STEPS_PER_SHORTEST_WAVE: f64 = 20.0;

/// The output's sample interval the steps divide, s (200 Hz).
const SAMPLE_INTERVAL: f64 = 5e-3;

impl Stepping {
    /// The longest step a run of `vehicle` on the track `spec` at `speed` (m/s) may take and
    /// why: at most [`step_on_beams`] on rails on sleepers; over short waves (the track's
    /// roughness and welds, the wheels' flats and polygons) at most [`MAX_STEP_SHORT_WAVES`]
    /// and [`STEPS_PER_SHORTEST_WAVE`] steps per passing of the shortest wave, a whole fraction
    /// of the 5 ms sample. None on any other run.
    pub fn limit_on(
        spec: &crate::track::TrackSpec,
        vehicle: &crate::vehicle::Vehicle,
        speed: f64,
    ) -> Option<(f64, String)> {
        let mut limit: Option<(f64, String)> = spec.discrete_rails.map(|_| {
            let dt = step_on_beams(speed);
            (
                dt,
                format!(
                    "rails on sleepers are followed at {:.4} ms ({:.2} mm of travel a step at most, 0.1 ms at most)",
                    dt * 1e3,
                    MAX_TRAVEL_ON_BEAMS * 1e3
                ),
            )
        });
        let track = spec.short_waves.map(|w| w.shortest_wavelength());
        let wheels = vehicle.shortest_wave();
        if track.is_some() || wheels.is_some() {
            let lambda = track
                .unwrap_or(f64::INFINITY)
                .min(wheels.unwrap_or(f64::INFINITY));
            let f = speed.abs() / lambda;
            let wanted = MAX_STEP_SHORT_WAVES.min(1.0 / (STEPS_PER_SHORTEST_WAVE * f.max(1e-9)));
            let dt = whole_fraction(wanted);
            if limit.as_ref().is_none_or(|(l, _)| dt < *l) {
                limit = Some((
                    dt,
                    format!(
                        "short waves (down to {:.0} mm, {f:.0} Hz at {:.0} km/h) excite FQ up to 100 Hz and beyond, which a step of at most {:.4} ms follows",
                        lambda * 1e3,
                        speed * 3.6,
                        dt * 1e3
                    ),
                ));
            }
        }
        limit
    }

    /// The step a run of `vehicle` on the track `spec` at `speed` (m/s) takes: the
    /// integrator's own, at most [`Stepping::limit_on`]'s; a given step as given, refused where
    /// short waves need a finer one (a run never reads their bands silently wrong).
    pub fn step_on(
        &self,
        spec: &crate::track::TrackSpec,
        vehicle: &crate::vehicle::Vehicle,
        speed: f64,
    ) -> crate::error::Result<f64> {
        let Some((limit, why)) = Self::limit_on(spec, vehicle, speed) else {
            return Ok(self.dt);
        };
        if !self.given {
            return Ok(self.dt.min(limit));
        }
        let short = spec.short_waves.is_some() || vehicle.shortest_wave().is_some();
        if short && self.dt > limit * (1.0 + 1e-9) {
            return Err(crate::error::Error::Domain(format!(
                "a step of {:.4} ms is too coarse for {} on track '{}': {why}; give at most that step, or none",
                self.dt * 1e3,
                vehicle.name,
                spec.name
            )));
        }
        Ok(self.dt)
    }

    /// The integrator named (checked against [`Integrator::NAMES`]; the default where none or
    /// an unknown one is named) at step `dt`, or at the integrator's own step.
    pub fn chosen(integrator: Option<&str>, dt: Option<f64>) -> Self {
        let integrator = integrator.and_then(Integrator::parse).unwrap_or_default();
        Stepping {
            integrator,
            dt: dt.unwrap_or(integrator.default_step()),
            given: dt.is_some(),
        }
    }
}

impl Default for Stepping {
    /// The default run's: the default integrator at its own step (`SimConfig::default`).
    fn default() -> Self {
        let cfg = super::SimConfig::default();
        Stepping {
            integrator: cfg.integrator,
            dt: cfg.dt,
            given: false,
        }
    }
}

impl Simulation<'_> {
    /// Advances every body by one step under the wrenches of the current state.
    pub(super) fn integrate(&mut self) {
        // The bodies solved in their stiff elements' damping first (the Hertz integrator's side
        // frames, `element_solve`), so the bodies beneath take the reaction in the same step.
        self.kicks.fill(Vector6::zeros());
        for first in [true, false] {
            for i in 0..self.states.len() {
                if self.damped.iter().any(|d| d.body == i) == first {
                    self.advance(i);
                }
            }
        }
    }

    /// Advances body `i` by one step.
    fn advance(&mut self, i: usize) {
        let dt = self.cfg.dt;
        let b = &self.vehicle.bodies[i];
        let st = &mut self.states[i];
        let (acc, wb, dwb) = body_rates(b, st, &self.wrenches[i]);
        let rot = st.rotation;
        let wheelset = if self.cfg.integrator.implicit() {
            self.vehicle
                .contact
                .wheelsets
                .iter()
                .position(|&ws| ws == i)
        } else {
            None
        };
        let damped = self.damped.iter().position(|d| d.body == i);
        // The reaction of the damping the bodies above took in their solve (an impulse, world).
        let mut kick = self.kicks[i];
        let kicked = kick != Vector6::zeros();
        if let Some(k) = damped {
            // In the body's own axes, where its elements' damping is constant: the explicit
            // change is `(Rᵀ·a·Δt, ω̇_body·Δt)`, less the track's turning.
            let r = rot.to_rotation_matrix().into_inner();
            let turn = self.turning(i);
            let (tv, tw) = (turn.fixed_rows::<3>(0), turn.fixed_rows::<3>(3));
            let (v, w) = (
                r.transpose() * (acc * dt - tv),
                dwb * dt - r.transpose() * tw,
            );
            let du = self.damped[k].change(
                &r,
                &Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z),
                &mut self.kicks,
            ) + turn;
            self.finish(i, rot, du);
            return;
        }
        if wheelset.is_none() && !kicked {
            self.accelerations[i] = acc;
            st.velocity += acc * dt;
            st.position += st.velocity * dt;
            let wb = wb + dwb * dt;
            st.angular_velocity = rot * wb;
            st.rotation = rot * UnitQuaternion::from_scaled_axis(wb * dt);
            return;
        }
        // The explicit change, then (I + θΔt·M⁻¹·D)·Δu = Δu_explicit, with a wheelset's two
        // rail masses in the same solve on a compliant track.
        let dw_explicit = rot * (wb + dwb * dt) - st.angular_velocity;
        let r = rot.to_rotation_matrix().into_inner();
        let inv_inertia = r * Matrix3::from_diagonal(&b.inertia.map(|x| 1.0 / x)) * r.transpose();
        let mut du = Vector6::new(
            acc.x * dt,
            acc.y * dt,
            acc.z * dt,
            dw_explicit.x,
            dw_explicit.y,
            dw_explicit.z,
        );
        let hertz = self.cfg.integrator.solves_bogie();
        let gyroscopic = if hertz && wheelset.is_some() {
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
        if kicked {
            body.apply(&mut kick);
            du += kick;
        }
        // The implicit shares act on the change of the velocities relative to the track, not
        // on the turning of the velocity vectors that following a curve is (module comment).
        let turn = if hertz {
            self.turning(i)
        } else {
            Vector6::zeros()
        };
        du -= turn;
        let du = if let Some(k) = wheelset {
            self.wheelset_change(k, &body, du)
        } else {
            du
        } + turn;
        self.finish(i, rot, du);
    }

    /// Moves body `i` (at rotation `rot` at the step's start) by its velocity change `du`
    /// (world).
    fn finish(&mut self, i: usize, rot: UnitQuaternion<f64>, du: Vector6<f64>) {
        let dt = self.cfg.dt;
        let st = &mut self.states[i];
        let dv = du.fixed_rows::<3>(0).into_owned();
        self.accelerations[i] = dv / dt;
        st.velocity += dv;
        st.position += st.velocity * dt;
        st.angular_velocity += du.fixed_rows::<3>(3).into_owned();
        let wb = rot.inverse() * st.angular_velocity;
        st.rotation = rot * UnitQuaternion::from_scaled_axis(wb * dt);
    }

    /// How body `i`'s velocities `(v, ω)` (world) turn over a step as the track frame under
    /// it turns, `Δt·(Ω × v, Ω × ω)`, with `Ω = V·(κ·z − κ_v·y_track)` the frame's rate at the
    /// body's speed `V` along the track (heading and gradient; the cant's rate in transitions
    /// left out). In a curve at a steady state this is a body's whole velocity change: the
    /// creepages and the springs' deflections do not change, and neither must the implicit
    /// shares' forces.
    fn turning(&self, i: usize) -> Vector6<f64> {
        let (st, f) = (&self.states[i], &self.frames[i]);
        let speed = f.axes.column(0).dot(&st.velocity);
        let rate = (Vector3::z() * f.point.curvature
            - f.axes.column(1) * f.point.vertical_curvature)
            * (speed * self.cfg.dt);
        let (v, w) = (rate.cross(&st.velocity), rate.cross(&st.angular_velocity));
        Vector6::new(v.x, v.y, v.z, w.x, w.y, w.z)
    }

    /// Wheelset `k`'s velocity change in its linearly implicit solve (its rail masses moved
    /// with it on a compliant track), from the explicit change `du`.
    fn wheelset_change(&mut self, k: usize, body: &Inverse, du: Vector6<f64>) -> Vector6<f64> {
        let dt = self.cfg.dt;
        let d = &self.contact_damping[k];
        let hertz = self.cfg.integrator.solves_bogie();
        // The rail surface's rate under each wheel changes over the step as the wheel rolls
        // on (the irregularity's curvature): the normal law's share in the solve sees that
        // change as it sees a rail mass's, else it acts on the wheel's following of the
        // irregularity as a mass of θ·Δt·c_n + α·Δt²·k_n (tens of kg at 0.5 ms). The
        // change is the last step's, an estimate one step behind.
        let pair = 2 * k..2 * k + 2;
        let mut surface = [Vector2::zeros(); 2];
        let du = if hertz {
            let mut push = SMatrix::<f64, 6, 1>::zeros();
            for (side, idx) in pair.clone().enumerate() {
                let now = Vector2::from(self.inputs[idx].surface_rate);
                let change = self.surface_rates[idx].map_or(Vector2::zeros(), |last| now - last);
                self.surface_rates[idx] = Some(now);
                surface[side] = change * dt;
                push += self.rail_coupling[idx].from_surface * surface[side];
            }
            body.apply(&mut push);
            du + push
        } else {
            du
        };
        if self.beams.is_some() {
            let d = *d;
            return self.wheelset_on_beams(k, body, &d, du, &surface);
        }
        match self.track.spec().rail_support {
            None => {
                let mut a = d * (THETA * dt);
                body.apply(&mut a);
                let mut g = a.fixed_view_mut::<3, 3>(3, 3);
                g += body.gyroscopic;
                (Matrix6::identity() + a).lu().solve(&du).unwrap_or(du)
            }
            Some(sup) => with_rails(
                body,
                d,
                du,
                dt,
                &mut self.rails[pair.clone()],
                &self.rail_coupling[pair.clone()],
                &self.rail_force[pair],
                &surface,
                &sup,
            ),
        }
    }
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
