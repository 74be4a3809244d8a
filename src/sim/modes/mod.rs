//! Linear stability: the whole model linearised about its centred equilibrium on smooth tangent
//! track, as multibody codes show it — eigenvalues against speed (root locus), each mode named
//! by where its energy lies, and each family's linear critical speed.
//!
//! The linearisation is the run's own physics: the state derivative is the simulation's force
//! evaluation ([`Simulation`]'s elements, contact, rails and hauling), differentiated
//! numerically by central differences. The contact is quasi-linearised at an amplitude: the
//! lateral position of each wheelset and of each rail is stepped by ± that amplitude, so its
//! column is the secant of the contact's nonlinear geometry (rolling-radius difference, contact
//! angles, gravitational stiffness) over the amplitude — the equivalent-conicity idea of
//! EN 15302 applied to the whole contact — while creep uses the linear Kalker law. Friction
//! elements enter in two limits: stuck (their stick springs, the sliders held) and sliding
//! (no friction force at all).
//!
//! State per body (track axes of its reference place): displacement x, y, z; rotation roll,
//! pitch, yaw; their rates. Per wheel on a compliant track: the rail mass's lateral and vertical
//! displacement and rate. And the hauling controller's integral.

use super::{SimConfig, Simulation};
use crate::contact::CreepLaw;
use crate::error::{Error, Result};
use crate::track::Track;
use crate::vehicle::Vehicle;
use nalgebra::DMatrix;
use serde::Serialize;

/// How friction elements (wedges, centre plates, side bearers) enter the linear model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FrictionLimit {
    /// The sliders held: each friction element is its stick spring and damper.
    Stuck,
    /// Friction sliding: no friction force (its friction coefficients set to zero).
    Sliding,
    /// Each friction element by its describing function over the least damped mode's cycle at
    /// the contact's amplitude: the stiffness and damping of its first harmonic, between the
    /// two limits (`sim/modes/describing.rs`).
    Equivalent,
}

impl FrictionLimit {
    /// `stuck` or `sliding`.
    pub fn name(self) -> &'static str {
        match self {
            FrictionLimit::Stuck => "stuck",
            FrictionLimit::Sliding => "sliding",
            FrictionLimit::Equivalent => "equivalent",
        }
    }
}

/// What to linearise and how.
#[derive(Debug, Clone)]
pub struct ModesOptions {
    /// Speeds, m/s (ascending).
    pub speeds: Vec<f64>,
    /// Amplitude of the contact's quasi-linearisation, m.
    pub amplitude: f64,
    /// Friction limit.
    pub friction: FrictionLimit,
    /// Highest frequency of the modes reported, Hz (the vehicle's modes lie below it; the
    /// contact and rail modes above).
    pub max_frequency: f64,
}

impl Default for ModesOptions {
    fn default() -> Self {
        ModesOptions {
            speeds: (4..=40).map(|k| k as f64 * 5.0 / 3.6).collect(),
            amplitude: 3e-3,
            friction: FrictionLimit::Stuck,
            max_frequency: 20.0,
        }
    }
}

/// The six degrees of freedom of a body, in its track axes.
pub const DOFS: [&str; 6] = [
    "longitudinal",
    "lateral",
    "vertical",
    "roll",
    "pitch",
    "yaw",
];

/// One degree of freedom's part of a mode.
#[derive(Debug, Clone, Serialize)]
pub struct ShapeEntry {
    /// Body (or `rail 1L` …).
    pub body: String,
    /// Degree of freedom.
    pub dof: &'static str,
    /// Share of the mode's kinetic energy, 0–1.
    pub share: f64,
    /// Amplitude relative to the largest displacement (m/m or rad/m) of the mode.
    pub amplitude: f64,
    /// Phase relative to the largest entry, degrees.
    pub phase_deg: f64,
}

/// One mode at one speed.
#[derive(Debug, Clone, Serialize)]
pub struct Mode {
    /// Real part of the eigenvalue, 1/s (positive: unstable).
    pub real: f64,
    /// Imaginary part, rad/s (≥ 0: one of each conjugate pair).
    pub imag: f64,
    /// Damped frequency, Hz.
    pub frequency_hz: f64,
    /// Damping ratio `−Re λ / |λ|`.
    pub damping_ratio: f64,
    /// Family name from the energy shares (`wheelset hunting`, `bogie hunting`, `carbody
    /// lower sway` …).
    pub name: String,
    /// The body and degree of freedom holding the largest energy share, and that share.
    pub dominant: (String, &'static str, f64),
    /// Entries holding at least 5 % of the energy, largest first.
    pub shape: Vec<ShapeEntry>,
}

/// The modes at one speed.
#[derive(Debug, Clone, Serialize)]
pub struct SpeedModes {
    /// Speed, km/h.
    pub speed_kmh: f64,
    /// Largest residual acceleration of the equilibrium, m/s² (its quality).
    pub residual: f64,
    /// Modes up to the frequency limit, least damped first.
    pub modes: Vec<Mode>,
}

/// A family's linear critical speed: the lowest speed at which its least damped mode's
/// damping ratio falls through zero.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Critical {
    /// Mode family.
    pub name: String,
    /// Critical speed, km/h (`None`: stable over the speeds swept).
    pub speed_kmh: Option<f64>,
    /// Frequency at the crossing (or at the least damped speed), Hz.
    pub frequency_hz: f64,
    /// Smallest damping ratio over the sweep.
    pub min_damping: f64,
}

/// Linearises `vehicle` on the smooth tangent `track` at every speed of `opts`.
pub fn modes(vehicle: &Vehicle, track: &Track, opts: &ModesOptions) -> Result<Vec<SpeedModes>> {
    if !(opts.amplitude > 0.0 && opts.amplitude < 0.02) {
        return Err(Error::Domain(format!(
            "the contact amplitude must lie in (0, 20) mm, got {} mm",
            opts.amplitude * 1e3
        )));
    }
    let v = linear_vehicle(vehicle, opts.friction);
    opts.speeds
        .iter()
        .map(|&speed| {
            if !(speed > 0.0 && speed.is_finite()) {
                return Err(Error::Domain(format!(
                    "speed must be positive, got {speed}"
                )));
            }
            let sim = Simulation::new(&v, track, linear_config(speed))?;
            let mut lin = Linear::new(sim);
            lin.equilibrate();
            let residual = lin.residual();
            let a = if opts.friction == FrictionLimit::Equivalent {
                describing::equivalent_matrix(
                    &mut lin,
                    &v,
                    track,
                    speed,
                    opts.amplitude,
                    opts.max_frequency,
                )?
            } else {
                lin.jacobian(opts.amplitude)?
            };
            let modes = lin.analyse(&a, opts.max_frequency);
            Ok(SpeedModes {
                speed_kmh: speed * 3.6,
                residual,
                modes,
            })
        })
        .collect()
}

/// The linear state matrix `A` (ẋ = A·x) of `vehicle` on the smooth tangent `track` at
/// `speed` (m/s): the same model [`modes`] analyses. The state of body `i` occupies
/// `12·i + k`, `k` = 0–2 displacement (longitudinal, lateral, vertical), 3–5 rotation (roll,
/// pitch, yaw), 6–8 and 9–11 their rates, all in the track axes of its reference place; then
/// four per wheel for the rail masses on a compliant track (lateral, its rate, vertical, its
/// rate), then the hauling integral.
pub fn linearise(
    vehicle: &Vehicle,
    track: &Track,
    speed: f64,
    amplitude: f64,
    friction: FrictionLimit,
) -> Result<DMatrix<f64>> {
    let v = linear_vehicle(vehicle, friction);
    let sim = Simulation::new(&v, track, linear_config(speed))?;
    let mut lin = Linear::new(sim);
    lin.equilibrate();
    lin.jacobian(amplitude)
}

/// The vehicle as the linearisation sees it: linear Kalker creep, friction per `limit`.
fn linear_vehicle(vehicle: &Vehicle, limit: FrictionLimit) -> Vehicle {
    let mut v = vehicle.clone();
    v.contact.law = CreepLaw::Linear;
    if limit == FrictionLimit::Sliding {
        v = v.without_friction();
    }
    v
}

/// A run that starts and stops at its static equilibrium at `speed`.
fn linear_config(speed: f64) -> SimConfig {
    SimConfig {
        speed,
        duration: 0.0,
        settle: 0.0,
        ..SimConfig::default()
    }
}

/// Each family's linear critical speed over a sweep (families in order of first appearance).
pub fn critical_speeds(sweep: &[SpeedModes]) -> Vec<Critical> {
    let mut names: Vec<String> = Vec::new();
    for s in sweep {
        for m in &s.modes {
            if !names.contains(&m.name) {
                names.push(m.name.clone());
            }
        }
    }
    names
        .into_iter()
        .map(|name| {
            // The family's least damped mode at each speed.
            let pts: Vec<(f64, f64, f64)> = sweep
                .iter()
                .filter_map(|s| {
                    s.modes
                        .iter()
                        .filter(|m| m.name == name)
                        .min_by(|a, b| a.damping_ratio.total_cmp(&b.damping_ratio))
                        .map(|m| (s.speed_kmh, m.damping_ratio, m.frequency_hz))
                })
                .collect();
            let mut crit = None;
            for w in pts.windows(2) {
                let ((v0, z0, f0), (v1, z1, f1)) = (w[0], w[1]);
                if z0 >= 0.0 && z1 < 0.0 {
                    let t = z0 / (z0 - z1);
                    crit = Some((v0 + t * (v1 - v0), f0 + t * (f1 - f0)));
                    break;
                }
            }
            if crit.is_none()
                && let Some(&(v0, z0, f0)) = pts.first()
                && z0 < 0.0
            {
                crit = Some((v0, f0));
            }
            let least = pts
                .iter()
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .copied()
                .unwrap_or((f64::NAN, f64::NAN, f64::NAN));
            Critical {
                name,
                speed_kmh: crit.map(|c| c.0),
                frequency_hz: crit.map_or(least.2, |c| c.1),
                min_damping: least.1,
            }
        })
        .collect()
}

mod compare;
mod describing;
mod eigen;
mod linear;
mod naming;
mod step_map;

pub use compare::{Comparison, Nonlinear, compare, nonlinear_views};
pub use step_map::{
    HIGH_FREQUENCY, StepCheck, StepLimit, check_step, guard, longest_step, step_limits,
};

use linear::Linear;
