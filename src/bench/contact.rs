//! Speed of one wheel's contact evaluation during a simulation step.

use crate::contact::{CreepLaw, Material, Side, WheelsetGeometry, WheelsetMotion, wheel_force};
use std::hint::black_box;
use std::time::Instant;

/// Result of the contact benchmark.
#[derive(Debug, Clone, Copy)]
pub struct ContactBench {
    /// One wheel: table lookup + Hertz + creepages + Polach + force assembly, ns.
    pub wheel_polach_ns: f64,
    /// The same with FASTSIM (60 × 60) instead of Polach, ns: the reference.
    pub wheel_fastsim_ns: f64,
    /// One rigid contact solve of both wheels (what the table saves), ns.
    pub rigid_solve_ns: f64,
    /// Time to build the contact table (±15 mm every 0.1 mm), s.
    pub table_build_s: f64,
}

/// Runs the benchmark on a wheelset geometry (the vehicle file's), at 122.6 kN and 60 km/h.
pub fn run(geo: &WheelsetGeometry, iterations: usize) -> ContactBench {
    let t = Instant::now();
    let table = geo.table(15e-3, 1e-4);
    let table_build_s = t.elapsed().as_secs_f64();
    let mat = Material::STEEL;
    let motion = WheelsetMotion {
        lateral_velocity: 0.05,
        yaw_rate: 0.01,
        yaw: 1e-3,
        ..WheelsetMotion::rolling(16.7, geo.nominal_radius)
    };
    let time_wheel = |law: CreepLaw, n: usize| {
        let t = Instant::now();
        let mut acc = 0.0;
        for i in 0..n {
            // Sweep the lateral shift so the lookup is not a cache of one entry.
            let y = -6e-3 + 12e-3 * (i % 997) as f64 / 997.0;
            let s = table.lookup(black_box(y));
            let f = wheel_force(
                Side::Left,
                &s.wheels[0],
                [0.0, y, s.z],
                s.roll,
                &motion,
                black_box(122.6e3),
                0.3,
                &mat,
                law,
            );
            acc += f.force[1];
        }
        black_box(acc);
        t.elapsed().as_secs_f64() * 1e9 / n as f64
    };
    let wheel_polach_ns = time_wheel(CreepLaw::Polach, iterations);
    let wheel_fastsim_ns = time_wheel(CreepLaw::Fastsim { n: 60 }, (iterations / 200).max(10));
    let n_solve = (iterations / 5000).max(5);
    let t = Instant::now();
    for i in 0..n_solve {
        black_box(geo.solve(black_box(1e-3 * (i % 7) as f64), 0.0));
    }
    let rigid_solve_ns = t.elapsed().as_secs_f64() * 1e9 / n_solve as f64;
    ContactBench {
        wheel_polach_ns,
        wheel_fastsim_ns,
        rigid_solve_ns,
        table_build_s,
    }
}
