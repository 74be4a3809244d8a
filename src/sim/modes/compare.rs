//! One wagon on one wheel–rail pair in all three views: the equivalent conicity, the first
//! mode to lose its damping with friction stuck and sliding (linear), and the critical speeds
//! of kink-and-coast and the run-down with their limit cycles' frequencies (nonlinear). The
//! table of `validate dynamics` and the pair sweep of `railforce modes --pairs` are rows of it.

use super::{Critical, FrictionLimit, ModesOptions, critical_speeds, modes};
use crate::error::Result;
use crate::sim::fidelity::{CriticalSpeed, critical_speed, run_down};
use crate::track::Track;
use crate::vehicle::Vehicle;
use serde::Serialize;

/// Seconds at the start of a nonlinear run left out of its running-stability criterion: the
/// kink and the kick (at 0.5 s) and their first response.
const TRANSIENT_S: f64 = 3.0;

/// A nonlinear method's verdict.
#[derive(Debug, Clone, Serialize)]
pub struct Nonlinear {
    /// Lowest speed at which the hunting cycle survived, km/h (`None`: no hunting).
    pub critical_kmh: Option<f64>,
    /// Frequency of the limit cycle at the lowest speed where it held its amplitude, Hz
    /// ([`CriticalSpeed::cycle_frequency`]).
    pub frequency_hz: Option<f64>,
    /// That speed, km/h.
    pub cycle_kmh: Option<f64>,
    /// Per second after the first two: speed (km/h), half peak-to-peak amplitude of the
    /// leading wheelset (mm) and its frequency over the 3 s ending there (Hz).
    pub blocks: Vec<(f64, f64, f64)>,
    /// The EN 14363-style running-stability criterion on the run (`assess`: ΣY of each
    /// wheelset band-passed around its dominant frequency, the largest sliding rms over 100 m,
    /// against its share of the track-shifting limit), after the first 3 s: the worst
    /// wheelset's value and limit, kN (`None` when the run is shorter than the criterion's
    /// window).
    pub running_stability_kn: Option<(f64, f64)>,
    /// The run derailed (a verdict of its own, as a hunting cycle that climbs the flange):
    /// the simulation's message; the fields above are then empty.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub derailed: Option<String>,
}

impl Nonlinear {
    /// The verdict of one method's run, with the running-stability criterion on its forces
    /// for the static wheel load `q0_kn`.
    fn of(c: &CriticalSpeed, q0_kn: f64) -> Self {
        let criteria = crate::assess::Criteria::builtin();
        // The kink's and the kick's own transient (the first 3 s) is not the running.
        let f = &c.forces;
        let from = f
            .time
            .iter()
            .position(|&t| t >= TRANSIENT_S)
            .unwrap_or(f.time.len());
        let running = crate::assess::RunForces {
            time: f.time[from..].to_vec(),
            s: f.s[from..].to_vec(),
            wheels: f
                .wheels
                .iter()
                .map(|w| crate::assess::WheelSeries {
                    wheel: w.wheel.clone(),
                    y: w.y[from..].to_vec(),
                    q: w.q[from..].to_vec(),
                })
                .collect(),
            carbody: None,
            couplers: None,
        };
        let running_stability_kn = crate::assess::assess(&running, &[], &criteria, q0_kn)
            .ok()
            .and_then(|a| {
                a.rows
                    .into_iter()
                    .filter(|r| r.criterion == "stability")
                    .max_by(|x, y| (x.value / x.limit).total_cmp(&(y.value / y.limit)))
                    .map(|r| (r.value, r.limit))
            });
        Nonlinear {
            running_stability_kn,
            derailed: None,
            critical_kmh: c.critical.map(|v| v * 3.6),
            frequency_hz: c.cycle_frequency().map(|c| c.1),
            cycle_kmh: c.cycle_frequency().map(|c| c.0 * 3.6),
            blocks: c
                .blocks
                .iter()
                .zip(&c.frequencies)
                .skip(2)
                .map(|((v, a), f)| (v * 3.6, a * 1e3, *f))
                .collect(),
        }
    }
}

/// One wagon on one pair.
#[derive(Debug, Clone, Serialize)]
pub struct Comparison {
    /// Vehicle name.
    pub vehicle: String,
    /// Flange back-to-back distance, m.
    pub flange_back_m: f64,
    /// Equivalent conicity at 3 mm (EN 15302).
    pub conicity: Option<f64>,
    /// The first family to lose its damping, friction stuck (`None`: all damped).
    pub stuck: Option<Critical>,
    /// The same, friction sliding.
    pub sliding: Option<Critical>,
    /// Kink-and-coast (6 mm kink, 2 m/s²), when run.
    pub kink_and_coast: Option<Nonlinear>,
    /// The run-down (kicked at the top speed, 1.5 m/s²), when run.
    pub run_down: Option<Nonlinear>,
}

/// The three views of `vehicle` on the smooth tangent `track` over `speeds` (m/s, ascending;
/// the nonlinear runs coast from the highest to the lowest, at least 50 km/h) — the nonlinear
/// ones only when `nonlinear`.
pub fn compare(
    vehicle: &Vehicle,
    track: &Track,
    speeds: &[f64],
    nonlinear: bool,
) -> Result<Comparison> {
    let first = |limit| -> Result<Option<Critical>> {
        let sweep = modes(
            vehicle,
            track,
            &ModesOptions {
                speeds: speeds.to_vec(),
                friction: limit,
                ..ModesOptions::default()
            },
        )?;
        Ok(critical_speeds(&sweep)
            .into_iter()
            .filter(|c| c.speed_kmh.is_some())
            .min_by(|a, b| {
                a.speed_kmh
                    .unwrap_or(f64::INFINITY)
                    .total_cmp(&b.speed_kmh.unwrap_or(f64::INFINITY))
            }))
    };
    let (kink, down) = if nonlinear {
        let [k, d] = nonlinear_views(vehicle, track, speeds)?;
        (Some(k), Some(d))
    } else {
        (None, None)
    };
    Ok(Comparison {
        vehicle: vehicle.name.clone(),
        flange_back_m: vehicle.contact.geometry.flange_back,
        conicity: vehicle.contact.table().equivalent_conicity(3e-3),
        stuck: first(FrictionLimit::Stuck)?,
        sliding: first(FrictionLimit::Sliding)?,
        kink_and_coast: kink,
        run_down: down,
    })
}

/// Kink-and-coast (6 mm kink, 2 m/s²) and the run-down (kicked at the top speed, 1.5 m/s²) of
/// `vehicle` on the smooth `track`, from the highest of `speeds` (m/s) down to the lowest, at
/// least 50 km/h: the two branches of the bifurcation.
pub fn nonlinear_views(vehicle: &Vehicle, track: &Track, speeds: &[f64]) -> Result<[Nonlinear; 2]> {
    let from = speeds.last().copied().unwrap_or(200.0 / 3.6);
    let to = speeds
        .first()
        .copied()
        .unwrap_or(50.0 / 3.6)
        .max(50.0 / 3.6);
    let q0 = vehicle.static_wheel_load_kn();
    // A derailment is this method's verdict on this pair, not a failure of the sweep.
    let verdict = |r: Result<CriticalSpeed>| match r {
        Ok(c) => Ok(Nonlinear::of(&c, q0)),
        Err(crate::error::Error::Derailment(m)) => Ok(Nonlinear {
            critical_kmh: None,
            frequency_hz: None,
            cycle_kmh: None,
            blocks: Vec::new(),
            running_stability_kn: None,
            derailed: Some(m),
        }),
        Err(e) => Err(e),
    };
    Ok([
        verdict(critical_speed(vehicle, track, from, to, 2.0))?,
        verdict(run_down(vehicle, track, from, to, 1.5))?,
    ])
}
