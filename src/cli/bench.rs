//! `railforce bench …`: built-in benchmarks.

use anyhow::Result;
use clap::{Args, Subcommand};

#[derive(Debug, Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    what: What,
}

#[derive(Debug, Subcommand)]
enum What {
    /// One wheel's contact evaluation during a simulation step (table lookup + Hertz +
    /// creepages + Polach), against FASTSIM and a full rigid solve measured in the same run.
    /// Build with --release for meaningful numbers.
    Contact {
        /// Vehicle file whose wheel–rail pair is timed.
        #[arg(long, default_value = "vehicles/c80.toml")]
        vehicle: std::path::PathBuf,
        /// Evaluations timed.
        #[arg(long, default_value_t = 2_000_000)]
        iterations: usize,
    },
    /// The full C80 on tangent track with FRA class 5 irregularities and profile contact: wall
    /// time per integration step and real-time factor, physics only and with every channel
    /// filtered and sampled (one thread).
    Simulate {
        /// Vehicle file.
        #[arg(long, default_value = "vehicles/c80.toml")]
        vehicle: std::path::PathBuf,
        /// Track file.
        #[arg(long, default_value = "tracks/tangent.toml")]
        track: std::path::PathBuf,
        /// Speed, km/h.
        #[arg(long, default_value_t = 80.0)]
        speed_kmh: f64,
        /// Simulated seconds per measurement.
        #[arg(long, default_value_t = 20.0)]
        seconds: f64,
    },
}

pub fn run(args: BenchArgs) -> Result<()> {
    match args.what {
        What::Simulate {
            vehicle,
            track,
            speed_kmh,
            seconds,
        } => {
            if cfg!(debug_assertions) {
                eprintln!("warning: debug build; use `cargo run --release -- bench simulate`");
            }
            let v = railforce::vehicle::Vehicle::load(&vehicle)?;
            let t0 = std::time::Instant::now();
            v.contact.table();
            let table_s = t0.elapsed().as_secs_f64();
            let tr = railforce::track::Track::load(&track)?;
            let b = railforce::bench::simulate::run(&v, &tr, speed_kmh / 3.6, seconds)?;
            println!(
                "simulation benchmark: {} on {}, {speed_kmh} km/h, {seconds} s, step {} ms, one thread",
                v.name,
                tr.spec().name,
                b.dt * 1e3
            );
            println!(
                "  physics only:       {:>6.2} µs per step, {:>5.1}× real time",
                b.step_us, b.real_time_factor
            );
            println!(
                "  with all channels:  {:>6.2} µs per step, {:>5.1}× real time (recording costs {:.0} % of the physics)",
                b.step_recorded_us,
                b.real_time_factor_recorded,
                100.0 * (b.step_recorded_us / b.step_us - 1.0)
            );
            println!("  contact table (once per vehicle, all cores): {table_s:.2} s");
            Ok(())
        }
        What::Contact {
            vehicle,
            iterations,
        } => {
            if cfg!(debug_assertions) {
                eprintln!("warning: debug build; use `cargo run --release -- bench contact`");
            }
            let v = railforce::vehicle::Vehicle::load(&vehicle)?;
            let b = railforce::bench::contact::run(&v.contact.geometry, iterations);
            println!(
                "contact benchmark ({}: {} on {}, one thread, 122.6 kN, 60 km/h)",
                v.name,
                v.contact.geometry.wheel().name,
                v.contact.geometry.rail().name
            );
            println!(
                "  one wheel, table + Hertz + Polach: {:>10.1} ns  ({:.2}× the 1 µs budget)",
                b.wheel_polach_ns,
                b.wheel_polach_ns / 1000.0
            );
            println!(
                "  one wheel, table + Hertz + FASTSIM 60×60: {:>10.1} ns  (Polach is {:.0}× faster)",
                b.wheel_fastsim_ns,
                b.wheel_fastsim_ns / b.wheel_polach_ns
            );
            println!(
                "  rigid contact solve, both wheels:  {:>10.0} ns  (the table lookup path is {:.0}× faster)",
                b.rigid_solve_ns,
                b.rigid_solve_ns / b.wheel_polach_ns
            );
            println!(
                "  table build, ±15 mm every 0.1 mm:  {:>10.2} s",
                b.table_build_s
            );
            Ok(())
        }
    }
}
