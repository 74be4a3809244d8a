//! Command-line parsing and dispatch. Each subcommand lives in its own file and only turns
//! arguments into library calls and library results into text.

mod track;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// railforce: railway vehicle dynamics and wheel–rail force identification.
///
/// Simulates a C80 heavy-haul wagon on tracks with FRA irregularities, writes virtual sensor
/// data sets, and identifies wheel–rail forces from them.
#[derive(Debug, Parser)]
#[command(name = "railforce", version, about, long_about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Inspect a track file: summary, geometry and irregularity export, PSD check.
    ///
    /// Without options, prints the sections (with balance speeds of curves), the vertical
    /// profile and the irregularity settings. `--out` writes the geometry and both rails'
    /// irregular offsets every `--step` metres as CSV; `--psd` compares the synthesised
    /// irregularities with the FRA PSD formula (RMS table, Welch PSD to CSV).
    Track(track::TrackArgs),
}

/// Parses the command line, runs the subcommand and turns errors into a message and exit 1.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Track(args) => track::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
