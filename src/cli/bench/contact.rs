//! Speed of one wheel's contact evaluation during a simulation step: the same function a run
//! executes ([`railforce::contact::evaluate`]), on the vehicle's own contact table.

use railforce::contact::{CreepLaw, Side, WheelOnRail, evaluate, height_for_load};
use railforce::vehicle::Vehicle;
use std::hint::black_box;
use std::time::Instant;

/// Result of the contact benchmark.
#[derive(Debug, Clone, Copy)]
pub struct ContactBench {
    /// One wheel: strip contact + Hertz + creepages + Polach + force assembly, ns.
    pub wheel_polach_ns: f64,
    /// The same with FASTSIM (60 × 60) instead of Polach, ns: the reference.
    pub wheel_fastsim_ns: f64,
    /// One rigid contact solve of both wheels (what the table saves), ns.
    pub rigid_solve_ns: f64,
    /// Time to build the vehicle's contact table with its strips, s.
    pub table_build_s: f64,
}

/// Runs the benchmark on a vehicle's contact (its table and settings), at 122.6 kN and
/// 60 km/h, sweeping the lateral shift over ±6 mm.
pub fn run(vehicle: &Vehicle, iterations: usize) -> ContactBench {
    let cs = &vehicle.contact;
    let t = Instant::now();
    let table = cs.table();
    let table_build_s = t.elapsed().as_secs_f64();
    let geo = &cs.geometry;
    let mass = 0.5 * vehicle.bodies[cs.wheelsets[0]].mass;
    let mut base = WheelOnRail::rolling(Side::Left, 16.7, geo.nominal_radius, 0.0, mass);
    base.velocity[1] = 0.05;
    base.angular_velocity[2] = 0.01;
    base.yaw = 1e-3;
    let time_wheel = |law: CreepLaw, n: usize| {
        let model = railforce::contact::ContactModel { law, ..cs.model() };
        // Heights that carry the load, every 0.12 mm of shift (not timed).
        let heights: Vec<f64> = (0..100)
            .map(|i| {
                let w = WheelOnRail {
                    y: -6e-3 + 12e-3 * i as f64 / 100.0,
                    ..base
                };
                height_for_load(table, &model, &w, 122.6e3)
            })
            .collect();
        let t = Instant::now();
        let mut acc = 0.0;
        for i in 0..n {
            let j = i % 100;
            let w = WheelOnRail {
                y: black_box(-6e-3 + 12e-3 * j as f64 / 100.0),
                height: heights[j],
                ..base
            };
            acc += evaluate(table, &model, &w).force[1];
        }
        black_box(acc);
        t.elapsed().as_secs_f64() * 1e9 / n as f64
    };
    let wheel_polach_ns = time_wheel(CreepLaw::default(), iterations);
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
