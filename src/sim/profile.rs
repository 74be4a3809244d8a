//! Where a step's time goes: a simulation with profiling on times each part of its
//! step — every force element by kind, the track frames, the track springs, the contact
//! (wheel placement and the patch solve apart), the rails, the hauling, the integration and
//! the checks — with the clock read around each part. Off by default: the step then pays one
//! branch per part.

use std::time::{Duration, Instant};

/// The vector instructions this build's step runs on, in words (for benchmarks: the same
/// code is 12 % fewer instructions a step when the compiler may use AVX2 throughout, with the
/// same output to the bit, since Rust never fuses a multiply and an add on its own).
pub fn vector_build() -> &'static str {
    if cfg!(target_feature = "avx2") {
        "AVX2 throughout (built with -C target-cpu=x86-64-v3 or native)"
    } else if cfg!(target_arch = "x86_64") {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            return "portable x86-64 (SSE2), the strip sums and the filter bank in AVX (detected at run time)";
        }
        "portable x86-64 (SSE2)"
    } else {
        std::env::consts::ARCH
    }
}

/// Accumulated time of each part of a step.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StepProfile {
    /// Part name, total time and calls, in order of first appearance.
    pub parts: Vec<(String, Duration, u64)>,
    /// Steps profiled.
    pub steps: u64,
}

impl StepProfile {
    /// Adds `elapsed` to `part`.
    pub fn add(&mut self, part: &str, elapsed: Duration) {
        match self.parts.iter_mut().find(|p| p.0 == part) {
            Some(p) => {
                p.1 += elapsed;
                p.2 += 1;
            }
            None => self.parts.push((part.to_string(), elapsed, 1)),
        }
    }

    /// Per part: name, mean µs per step with the clock's own cost per reading (`clock_ns`)
    /// taken off, and calls per step.
    pub fn per_step(&self, clock_ns: f64) -> Vec<(String, f64, f64)> {
        let n = self.steps.max(1) as f64;
        self.parts
            .iter()
            .map(|(name, d, calls)| {
                let us = (d.as_secs_f64() * 1e9 - clock_ns * *calls as f64).max(0.0) * 1e-3;
                (name.clone(), us / n, *calls as f64 / n)
            })
            .collect()
    }
}

impl super::Simulation<'_> {
    /// Per element kind, in the vehicle's order: how many elements, and the time of one
    /// `apply`, ns, on the current state (each kind applied `reps` times over, on copies of
    /// the wrenches and the sliders' memory, so the run is not disturbed): the split of
    /// [`StepProfile`]'s "force elements" part without a clock read per element.
    pub fn element_costs(&self, reps: usize) -> Vec<(&'static str, usize, f64)> {
        let mut kinds: Vec<&'static str> = Vec::new();
        for e in &self.vehicle.elements {
            if !kinds.contains(&e.kind()) {
                kinds.push(e.kind());
            }
        }
        kinds
            .into_iter()
            .map(|kind| {
                let idx: Vec<usize> = (0..self.vehicle.elements.len())
                    .filter(|&i| self.vehicle.elements[i].kind() == kind)
                    .collect();
                let mut memory = self.memory.clone();
                let mut wrenches = self.wrenches.clone();
                let t = Instant::now();
                for _ in 0..reps {
                    for &i in &idx {
                        self.vehicle.elements[i].apply(
                            &self.states,
                            &mut memory[i],
                            &mut wrenches,
                            self.cfg.dt,
                        );
                    }
                }
                std::hint::black_box(&wrenches);
                let ns = t.elapsed().as_secs_f64() * 1e9 / (reps * idx.len()).max(1) as f64;
                (kind, idx.len(), ns)
            })
            .collect()
    }
}

/// The cost of one clock reading as the profiler takes it (`Instant::now` and `elapsed`), ns.
pub fn clock_cost_ns() -> f64 {
    let n = 200_000;
    let t = Instant::now();
    let mut acc = Duration::ZERO;
    for _ in 0..n {
        let t0 = Instant::now();
        acc += t0.elapsed();
    }
    std::hint::black_box(acc);
    t.elapsed().as_secs_f64() * 1e9 / n as f64
}

/// Runs `$body`, adding its wall time to part `$name` of `$sim.profile` when profiling is on.
macro_rules! timed {
    ($profile:expr, $name:expr, $body:expr) => {{
        let t0 = $profile.is_some().then(std::time::Instant::now);
        let r = $body;
        if let (Some(t0), Some(p)) = (t0, $profile.as_deref_mut()) {
            p.add($name, t0.elapsed());
        }
        r
    }};
}
pub(crate) use timed;
