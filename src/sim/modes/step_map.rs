//! The step guard: a run's own step, linearised about its start, read for the modes it grows.
//!
//! An integrator is stable for a mode while `ω·Δt` stays below its limit: 2 for the
//! semi-implicit step's explicit springs, `2/√(1 − 4α)` for the Hertz spring taken at the
//! share `α` ([`crate::sim::Integrator`]). Which coupling is the stiffest, and which share of
//! it each solve takes, differs between the integrators, the vehicles and the tracks, so the
//! guard does not estimate one `ω`: it measures the step itself. From the run's start it takes
//! `x_{n+1} = Φ·x_n` by central differences ([`super::linear`]: every body's displacement,
//! rotation and their rates, the lumped rails, the haul's integral) and reads the eigenvalues
//! `μ` of `Φ`. A mode the step follows has `μ ≈ e^{λ·Δt}`; one it outruns leaves the unit
//! circle at a frequency no wagon's motion has, where `ω·Δt` nears the limit (the step's
//! flip-flop `μ ≈ −1`, a quarter of the step rate or above). A vehicle's own instabilities
//! (hunting) lie below 20 Hz and are left to the run: only modes above 100 Hz count
//! ([`HIGH_FREQUENCY`]).
//!
//! What it cannot see: stiffness that grows with the load (the Hertz spring, as `N^{1/3}`, in
//! flange contact) past the start's — the run's watch ends such bursts ([`crate::sim`]'s
//! chatter check) — and, on rails on sleepers, the beams' own modes, which the track's solve
//! takes implicitly (each step of the map starts the beams where the run's start has them).

use super::Mode;
use super::eigen::eigenvector;
use super::linear::Linear;
use crate::error::{Error, Result};
use crate::sim::{Integrator, SimConfig, Simulation};
use crate::track::Track;
use crate::vehicle::Vehicle;
use nalgebra::{Complex, DVector};

/// Growth per step above which a mode counts as growing (`|μ| − 1`). The map's own error,
/// from the central differences over along-track positions of kilometres, stays near 1e-7
/// (measured: the neutral modes, the drift along the track, read `|μ| = 1 ± 2e-7`).
const GROWTH_TOL: f64 = 1e-5;

/// Lowest frequency of a growing mode the guard refuses, Hz: above every mode of the
/// vehicle on its suspension (hunting, sway, bounce: below 20 Hz) and of the bolsters on their
/// friction elements (the bolster's yaw near 70 Hz, which a friction element at its stick–slip
/// edge at the start of a curve can make read as growing slowly), below the stiff couplings
/// that outrun a step (the side frames on their pads, 170–230 Hz; the wheel–rail mode, about
/// 480 Hz) and far below the step rate.
pub const HIGH_FREQUENCY: f64 = 100.0;

/// What the step does to the run's fastest-growing stiff mode.
#[derive(Debug, Clone)]
pub struct StepCheck {
    /// The step, s.
    pub dt: f64,
    /// Largest `|μ|` over the modes above [`HIGH_FREQUENCY`] (per step; ≤ 1 + tolerance:
    /// the step holds them).
    pub growth: f64,
    /// That mode's frequency as the step sees it, `|arg μ|/(2π·Δt)`, Hz (the step's
    /// Nyquist frequency, `1/(2Δt)`, for the flip-flop).
    pub frequency_hz: f64,
    /// That mode, named by where its energy lies (its `real`/`imag` are `ln μ / Δt`).
    pub mode: Mode,
}

impl StepCheck {
    /// Whether the step grows a mode it cannot follow.
    pub fn bursts(&self) -> bool {
        self.growth > 1.0 + GROWTH_TOL
    }

    /// Time over which the mode grows by `e`, s.
    pub fn e_fold(&self) -> f64 {
        self.dt / self.growth.ln()
    }
}

/// The step of `sim` (as it stands: a run's start) linearised, and its fastest-growing mode
/// above [`HIGH_FREQUENCY`].
pub fn check_step(sim: &Simulation) -> Result<StepCheck> {
    let dt = sim.cfg.dt;
    let mut lin = Linear::new(sim.clone());
    let phi = lin.step_matrix()?;
    let low = 2.0 * std::f64::consts::PI * HIGH_FREQUENCY * dt;
    // nalgebra's `complex_eigenvalues` asks for machine precision without an iteration
    // limit and does not return on this map (its neutral modes, μ = 1, repeat); a tolerance
    // relative to the map's largest entry does, in milliseconds.
    let scale = phi.amax().max(1.0);
    let eigenvalues = [1e-14, 1e-12, 1e-10]
        .iter()
        .find_map(|eps| nalgebra::linalg::Schur::try_new(phi.clone(), eps * scale, 10_000))
        .ok_or_else(|| Error::Domain("the step's map has no converged eigenvalues".into()))?
        .complex_eigenvalues();
    let worst = eigenvalues
        .iter()
        .copied()
        .filter(|m| m.arg().abs() >= low)
        .max_by(|a, b| a.norm().total_cmp(&b.norm()))
        .ok_or_else(|| Error::Domain("the step's map has no mode above 100 Hz".into()))?;
    let (q, h) = nalgebra::linalg::Hessenberg::new(phi).unpack();
    let shape = eigenvector(&q, &h, worst);
    let l = Complex::new(worst.norm().ln(), worst.arg()) / dt;
    let confirmed =
        worst.norm() <= 1.0 + GROWTH_TOL || grows_in_run(&mut lin, &shape, worst.norm())?;
    Ok(StepCheck {
        dt,
        growth: if confirmed { worst.norm() } else { 1.0 },
        frequency_hz: worst.arg().abs() / (2.0 * std::f64::consts::PI * dt),
        mode: lin.mode(l, &shape),
    })
}

/// Steps over which a fast-growing mode of the map is confirmed in the run itself.
const CONFIRM_STEPS: i32 = 20;

/// Whether the mode `shape` of the map, growing by `growth` a step, grows in the run itself.
/// The map is central differences; where the contact sits at a jump (a wheel between tread and
/// flange at the start of a curve) a difference straddles it and reads the jump as a stiffness
/// growing the mode several times a step. So a mode the map grows a hundredfold within
/// [`CONFIRM_STEPS`] steps must do so in the run: the run from its start displaced along the
/// mode (10⁻⁶ of its largest entry) against the run from the start must part by at least the
/// square root of the map's growth over those steps. Slower growth is the map's word: it is
/// where a step just past its limit lies (Heun's step at 0.36 ms, growing slowly by the map,
/// makes the C80 jump off its rail 0.8 s into settling), and a run cannot show it in a few
/// steps.
fn grows_in_run(lin: &mut Linear, shape: &DVector<Complex<f64>>, growth: f64) -> Result<bool> {
    if growth.powi(CONFIRM_STEPS) < 100.0 {
        return Ok(true);
    }
    let big = shape
        .iter()
        .copied()
        .max_by(|a, b| a.norm().total_cmp(&b.norm()))
        .unwrap_or(Complex::new(1.0, 0.0));
    let x0: DVector<f64> = shape.map(|c| (c * big.conj() / big.norm()).re * 1e-6 / big.norm());
    let steps = CONFIRM_STEPS as usize;
    let Ok(reference) = lin.run_from(&DVector::zeros(x0.len()), steps) else {
        // The run itself breaks down within those steps: the watch's, not the map's.
        return Ok(false);
    };
    let moved = match lin.run_from(&x0, steps) {
        Ok(x) => x,
        // The displaced run breaking down where the reference does not is growth.
        Err(_) => return Ok(true),
    };
    let parted = (moved - reference).norm() / x0.norm();
    Ok(parted.ln() >= 0.5 * CONFIRM_STEPS as f64 * growth.ln())
}

/// The longest step of `sim`'s integrator that holds every stiff mode at its start, within
/// 1 %, by bisection below `sim`'s own step (which bursts); `None` when even a quarter of it
/// bursts.
pub fn longest_step(sim: &Simulation) -> Result<Option<f64>> {
    let at = |dt: f64| -> Result<bool> {
        let cfg = SimConfig {
            dt,
            ..sim.cfg.clone()
        };
        let s = Simulation::new(sim.vehicle, sim.track, cfg)?;
        Ok(!check_step(&s)?.bursts())
    };
    let (mut lo, mut hi) = (0.25 * sim.cfg.dt, sim.cfg.dt);
    if !at(lo)? {
        return Ok(None);
    }
    while hi - lo > 0.01 * lo {
        let mid = 0.5 * (lo + hi);
        if at(mid)? {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(Some(lo))
}

/// Refuses a run whose step grows a stiff mode at its start, naming the mode, how fast it
/// grows and the longest step that holds it; passes every other run untouched (the run's
/// bytes do not depend on it: it works on copies).
pub fn guard(sim: &Simulation) -> Result<()> {
    let check = check_step(sim)?;
    if !check.bursts() {
        return Ok(());
    }
    let parts: Vec<String> = check
        .mode
        .shape
        .iter()
        .take(3)
        .map(|s| format!("{} {} {:.0} %", s.body, s.dof, 100.0 * s.share))
        .collect();
    let advice = match longest_step(sim)? {
        Some(dt) => format!(
            "the longest step that holds it here is {:.3} ms: run with a --dt below it",
            dt * 1e3
        ),
        None => "a quarter of this step does not hold it either: the vehicle file's stiffest element or the integrator is at fault".into(),
    };
    Err(Error::Domain(format!(
        "the {:.3} ms step cannot follow the run's stiffest coupling: over one step the {} integrator grows a mode at {:.0} Hz (as the step sees it) by {:.3} % (an e-fold every {:.0} ms), its energy in {}; {advice}",
        check.dt * 1e3,
        sim.cfg.integrator.name(),
        check.frequency_hz,
        100.0 * (check.growth - 1.0),
        check.e_fold() * 1e3,
        parts.join(", "),
    )))
}

/// One integrator's own step against the longest step the guard finds for it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepLimit {
    /// The integrator.
    pub integrator: Integrator,
    /// Its own step, s.
    pub own: f64,
    /// The longest step that holds every stiff mode at the run's start, s (`None`: not even
    /// a quarter of a millisecond).
    pub longest: Option<f64>,
}

impl StepLimit {
    /// Whether the integrator's own step lies inside its limit.
    pub fn holds(&self) -> bool {
        self.longest.is_some_and(|l| l > self.own)
    }
}

/// Every integrator's longest step for `vehicle` starting on `track` at `speed` (m/s), by
/// bisection below 1 ms: what a vehicle file's stiffest element leaves of each default.
pub fn step_limits(vehicle: &Vehicle, track: &Track, speed: f64) -> Result<Vec<StepLimit>> {
    Integrator::NAMES
        .iter()
        .filter_map(|n| Integrator::parse(n))
        .map(|integrator| {
            let cfg = SimConfig {
                speed,
                dt: 1e-3,
                integrator,
                duration: 0.0,
                settle: 0.0,
                ..SimConfig::default()
            };
            let sim = Simulation::new(vehicle, track, cfg)?;
            let own = integrator.default_step();
            let longest = if check_step(&sim)?.bursts() {
                longest_step(&sim)?
            } else {
                Some(1e-3)
            };
            Ok(StepLimit {
                integrator,
                own,
                longest,
            })
        })
        .collect()
}
