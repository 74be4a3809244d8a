//! Speed of the full wagon simulation: profile contact, class 5 irregularities, 11 bodies.

use railforce::error::Result;
use railforce::sim::{SimConfig, Simulation, output::Recorder};
use railforce::track::Track;
use railforce::vehicle::Vehicle;
use std::time::Instant;

/// Result of the simulation benchmark.
#[derive(Debug, Clone)]
pub struct SimulateBench {
    /// Integration step, s.
    pub dt: f64,
    /// Wall time per integration step, physics only, µs (the fastest of the repeats).
    pub step_us: f64,
    /// Wall time per step with all channels filtered and sampled, µs (the fastest).
    pub step_recorded_us: f64,
    /// The slowest repeat's physics-only and recorded µs per step (the spread a shared
    /// machine adds; equal to the fastest with one repeat).
    pub slowest_us: (f64, f64),
    /// Simulated over wall time, physics only.
    pub real_time_factor: f64,
    /// Simulated over wall time, with recording.
    pub real_time_factor_recorded: f64,
    /// Where a recorded step's time goes (a third run, profiled): part, µs per step, calls
    /// per step; the clock's own cost taken off.
    pub profile: Vec<(String, f64, f64)>,
    /// µs per step of that profiled run (clock included).
    pub profiled_step_us: f64,
    /// Per element kind: count and ns per `apply` (measured apart, on the run's last state).
    pub elements: Vec<(&'static str, usize, f64)>,
}

/// One measurement of each kind: `steps` steps physics only, then with the recorder; wall
/// seconds of each.
fn measure(vehicle: &Vehicle, track: &Track, cfg: &SimConfig, steps: usize) -> Result<(f64, f64)> {
    let mut sim = Simulation::new(vehicle, track, cfg.clone())?;
    let t = Instant::now();
    for _ in 0..steps {
        sim.step()?;
    }
    let plain = t.elapsed().as_secs_f64();
    let mut sim = Simulation::new(vehicle, track, cfg.clone())?;
    let mut rec = Recorder::new(&sim);
    let mut acc = 0.0;
    let t = Instant::now();
    for _ in 0..steps {
        sim.step()?;
        if let Some(row) = rec.sample(&mut sim) {
            acc += row[2];
        }
    }
    std::hint::black_box(acc);
    Ok((plain, t.elapsed().as_secs_f64()))
}

/// The configuration of a timed run (`base`'s stepping at `speed`, `seconds` long, no
/// settling) and its number of steps.
fn timed_run(base: &SimConfig, speed: f64, seconds: f64) -> (SimConfig, usize) {
    let cfg = SimConfig {
        speed,
        duration: seconds,
        settle: 0.0,
        ..base.clone()
    };
    let steps = railforce::bounds::to_count((seconds / cfg.dt).round().max(1.0));
    (cfg, steps)
}

/// Real-time factors (simulated over wall seconds) physics only and with all channels, one
/// measurement of each (the A/B rounds of `bench simulate --against`).
pub fn once(
    vehicle: &Vehicle,
    track: &Track,
    speed: f64,
    seconds: f64,
    base: &SimConfig,
) -> Result<(f64, f64)> {
    let (cfg, steps) = timed_run(base, speed, seconds);
    let (p, r) = measure(vehicle, track, &cfg, steps)?;
    let simulated = steps as f64 * cfg.dt;
    Ok((simulated / p, simulated / r))
}

/// Runs `seconds` of simulated time physics only, then with the recorder, `repeats` times in
/// turn at `speed` on `track`, with the step and integrator of `base`; the fastest of each
/// counts (a run only ever gets slower from what else the machine does).
pub fn run(
    vehicle: &Vehicle,
    track: &Track,
    speed: f64,
    seconds: f64,
    repeats: usize,
    base: &SimConfig,
) -> Result<SimulateBench> {
    let (cfg, steps) = timed_run(base, speed, seconds);
    let dt = cfg.dt;
    let (mut plain, mut recorded) = (Vec::new(), Vec::new());
    for _ in 0..repeats.max(1) {
        let (p, r) = measure(vehicle, track, &cfg, steps)?;
        plain.push(p);
        recorded.push(r);
    }
    let fastest = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let slowest = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    let per_step = |s: f64| s * 1e6 / steps as f64;
    let (plain_s, recorded_s) = (fastest(&plain), fastest(&recorded));
    // Profiled: the same run with the clock read around every part of the step, and around
    // the recorder.
    let clock = railforce::sim::profile::clock_cost_ns();
    let mut sim = Simulation::new(vehicle, track, cfg.clone())?;
    let mut rec = Recorder::new(&sim);
    sim.set_profiling(true);
    rec.set_profiling(true);
    let (mut rec_time, mut acc) = (std::time::Duration::ZERO, 0.0);
    let t = Instant::now();
    for _ in 0..steps {
        sim.step()?;
        let t0 = Instant::now();
        if let Some(row) = rec.sample(&mut sim) {
            acc += row[2];
        }
        rec_time += t0.elapsed();
    }
    std::hint::black_box(acc);
    let profiled = t.elapsed().as_secs_f64();
    let mut profile = sim.profile().map(|p| p.per_step(clock)).unwrap_or_default();
    profile.push((
        "recording (every channel computed and filtered each step)".into(),
        // Its own clock pair and the recorder's four readings inside it (two pairs).
        (rec_time.as_secs_f64() * 1e9 - 3.0 * clock * steps as f64).max(0.0) * 1e-3 / steps as f64,
        1.0,
    ));
    // The recorder's parts: one reading (half a pair) each.
    for (part, us, calls) in rec.profile(0.5 * clock) {
        profile.push((format!("  of which {part}"), us, calls));
    }
    let elements = sim.element_costs(20_000);
    Ok(SimulateBench {
        elements,
        profile,
        profiled_step_us: profiled * 1e6 / steps as f64,
        dt,
        step_us: per_step(plain_s),
        step_recorded_us: per_step(recorded_s),
        slowest_us: (per_step(slowest(&plain)), per_step(slowest(&recorded))),
        real_time_factor: seconds / plain_s,
        real_time_factor_recorded: seconds / recorded_s,
    })
}
