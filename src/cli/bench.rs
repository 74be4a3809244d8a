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
        /// Evaluations timed.
        #[arg(long, default_value_t = 2_000_000)]
        iterations: usize,
    },
}

pub fn run(args: BenchArgs) -> Result<()> {
    match args.what {
        What::Contact { iterations } => {
            if cfg!(debug_assertions) {
                eprintln!("warning: debug build; use `cargo run --release -- bench contact`");
            }
            let b = railforce::bench::contact::run(iterations);
            println!("contact benchmark (one thread, S1002 on 60 kg/m at 1:40, 122.6 kN, 60 km/h)");
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
