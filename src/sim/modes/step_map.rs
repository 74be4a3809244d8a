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
    /// `|μ|` of the fastest-growing mode above [`HIGH_FREQUENCY`] that the run confirms, per
    /// step; where none grows, the least damped one's (≤ 1: the step holds them).
    pub growth: f64,
    /// That mode's rate as the step sees it, `|ln μ|/(2π·Δt)`, Hz (near the step's Nyquist
    /// frequency, `1/(2Δt)`, for the flip-flop).
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

/// `ln μ`: the mode's rate and turn over one step.
fn step_log(m: Complex<f64>) -> Complex<f64> {
    Complex::new(m.norm().ln(), m.arg())
}

/// The step of `sim` (as it stands: a run's start) linearised, and its fastest-growing mode
/// above [`HIGH_FREQUENCY`] that the run confirms (else the least damped one there).
pub fn check_step(sim: &Simulation) -> Result<StepCheck> {
    let dt = sim.cfg.dt;
    let mut lin = Linear::new(sim.clone());
    let phi = lin.step_matrix()?;
    // A mode counts when its rate or turn over a step, |ln μ|, is that of 100 Hz or more: the
    // step's flip-flop (μ < −1), a turning pair, and a real μ > 1 alike (Heun's step on a
    // stiff damped mode).
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
    let mut stiff: Vec<Complex<f64>> = eigenvalues
        .iter()
        .copied()
        .filter(|m| m.im >= 0.0 && step_log(*m).norm() >= low)
        .collect();
    stiff.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    let (q, h) = nalgebra::linalg::Hessenberg::new(phi).unpack();
    let report = |lin: &Linear, m: Complex<f64>, growth: f64| {
        let shape = eigenvector(&q, &h, m);
        StepCheck {
            dt,
            growth,
            frequency_hz: step_log(m).norm() / (2.0 * std::f64::consts::PI * dt),
            mode: lin.mode(step_log(m) / dt, &shape),
        }
    };
    // The growing ones, fastest first, until the run confirms one: a jump the differences
    // straddle must not hide a slower mode that does grow.
    for &m in stiff.iter().take_while(|m| m.norm() > 1.0 + GROWTH_TOL) {
        let shape = eigenvector(&q, &h, m);
        if grows_in_run(&mut lin, &shape, m.norm(), dt)? {
            return Ok(report(&lin, m, m.norm()));
        }
    }
    let held = stiff
        .iter()
        .copied()
        .find(|m| m.norm() <= 1.0 + GROWTH_TOL)
        .or(stiff.first().copied())
        .ok_or_else(|| {
            Error::Domain(format!(
                "the step's map has no mode above {HIGH_FREQUENCY} Hz"
            ))
        })?;
    Ok(report(&lin, held, held.norm().min(1.0)))
}

/// Steps over which a fast-growing mode of the map is confirmed in the run itself.
const CONFIRM_STEPS: usize = 20;
/// Growth over [`CONFIRM_STEPS`] from which the run must confirm the map: a jump straddled
/// at the start of a curve on sleepers read as 16 % a step (20-fold over 20 steps, a real
/// `μ`, wheelset yaw), and the run did not grow it.
const CONFIRM_GROWTH: f64 = 4.0;

/// Whether the mode `shape` of the map, growing by `growth` a step, grows in the run itself.
/// The map is central differences; where the contact sits at a jump (a wheel between tread and
/// flange at the start of a curve) a difference straddles it and reads the jump as a stiffness
/// growing the mode by up to several times a step. So a mode the map grows [`CONFIRM_GROWTH`]
/// fold or more within [`CONFIRM_STEPS`] steps must do so in the run: the runs from the start displaced along the
/// mode's real and imaginary parts (10⁻⁶ of its largest entry) against the run from the start
/// must part, together and with rates weighed by the step, by at least the square root of the
/// map's growth over those steps. Slower growth is the map's word: it is where a step just past
/// its limit lies (Heun's step at 0.36 ms, growing slowly by the map, makes the C80 jump off
/// its rail 0.8 s into settling), and a run cannot show it in a few steps.
fn grows_in_run(
    lin: &mut Linear,
    shape: &DVector<Complex<f64>>,
    growth: f64,
    dt: f64,
) -> Result<bool> {
    if growth.powf(CONFIRM_STEPS as f64) < CONFIRM_GROWTH {
        return Ok(true);
    }
    let big = shape.iter().map(|c| c.norm()).fold(0.0, f64::max);
    if big == 0.0 {
        return Ok(true);
    }
    let w = lin.rate_weights(dt);
    let norm = |x: &DVector<f64>| x.component_mul(&w).norm();
    let Ok(reference) = lin.stepped(&DVector::zeros(shape.len()), CONFIRM_STEPS) else {
        // The run itself breaks down within those steps: the watch's, not the map's.
        return Ok(false);
    };
    let (mut parted, mut start) = (0.0, 0.0);
    for part in [shape.map(|c| c.re), shape.map(|c| c.im)] {
        let x0 = part * (1e-6 / big);
        if norm(&x0) == 0.0 {
            continue;
        }
        start += norm(&x0).powi(2);
        match lin.stepped(&x0, CONFIRM_STEPS) {
            Ok(moved) => parted += norm(&lin.difference(&moved, &reference)).powi(2),
            // The displaced run breaking down where the reference does not is growth.
            Err(_) => return Ok(true),
        }
    }
    let parted = (parted / start.max(1e-300)).sqrt();
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
/// bytes do not depend on it: it works on copies). Where the map itself cannot be read (a
/// step of the run failing from its start, eigenvalues that do not converge) it gives no
/// verdict and the run goes on: its first step and the watch then say what is wrong.
pub fn guard(sim: &Simulation) -> Result<()> {
    let Ok(check) = check_step(sim) else {
        return Ok(());
    };
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
    let advice = match longest_step(sim).ok().flatten() {
        Some(dt) => format!(
            "the longest step that holds it here is {:.3} ms: run with a --dt below it",
            dt * 1e3
        ),
        None => "a quarter of this step does not hold it either (or the shorter steps could not be read): the vehicle file's stiffest element or the integrator is at fault".into(),
    };
    Err(Error::Domain(format!(
        "the {:.3} ms step cannot follow the run's stiffest coupling: over one step the {} integrator grows a mode at {:.0} Hz (as the step sees it) by {:.3} % (an e-fold every {:.1} ms), its energy in {}; {advice}",
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
