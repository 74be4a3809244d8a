//! Speed of the full wagon simulation: profile contact, class 5 irregularities, 11 bodies.

use railforce::error::Result;
use railforce::sim::{SimConfig, Simulation, output::Recorder};
use railforce::track::Track;
use railforce::vehicle::Vehicle;
use std::time::Instant;

/// Result of the simulation benchmark.
#[derive(Debug, Clone, Copy)]
pub struct SimulateBench {
    /// Integration step, s.
    pub dt: f64,
    /// Wall time per integration step, physics only, µs.
    pub step_us: f64,
    /// Wall time per step with all channels filtered and sampled, µs.
    pub step_recorded_us: f64,
    /// Simulated over wall time, physics only.
    pub real_time_factor: f64,
    /// Simulated over wall time, with recording.
    pub real_time_factor_recorded: f64,
}

/// Runs `seconds` of simulated time twice (physics only, then with the recorder) at `speed` on
/// `track`.
pub fn run(vehicle: &Vehicle, track: &Track, speed: f64, seconds: f64) -> Result<SimulateBench> {
    let cfg = SimConfig {
        speed,
        duration: seconds,
        settle: 0.0,
        ..SimConfig::default()
    };
    let dt = cfg.dt;
    let steps = (seconds / dt).round() as usize;
    let mut sim = Simulation::new(vehicle, track, cfg.clone())?;
    let t = Instant::now();
    for _ in 0..steps {
        sim.step()?;
    }
    let plain = t.elapsed().as_secs_f64();
    let mut sim = Simulation::new(vehicle, track, cfg)?;
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
    let recorded = t.elapsed().as_secs_f64();
    Ok(SimulateBench {
        dt,
        step_us: plain * 1e6 / steps as f64,
        step_recorded_us: recorded * 1e6 / steps as f64,
        real_time_factor: seconds / plain,
        real_time_factor_recorded: seconds / recorded,
    })
}
