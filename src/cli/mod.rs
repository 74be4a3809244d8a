//! Command-line parsing and dispatch. Each subcommand lives in its own file and only turns
//! arguments into library calls and library results into text.

mod assess;
mod bench;
mod builtin;
mod calibrate;
mod channels;
mod contact;
mod evaluate;
mod experiment;
mod export;
mod generate;
mod identify;
mod modes;
mod select;
mod sensitivity;
mod simulate;
mod track;
mod train;
mod validate;
mod view;

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
    #[command(
        after_help = "Examples:\n  railforce track curve_r400\n  railforce track tracks/curve_r400.toml --out r400.csv --step 0.5\n  railforce track tracks/tangent.toml --psd"
    )]
    Track(track::TrackArgs),
    /// Contact of both wheels of a wheelset in a given state: contact points, angles,
    /// ellipses, creepages and forces.
    ///
    /// The same evaluation a simulation step runs (elastic strip contact: one or two patches
    /// per wheel, Hertz ellipse, creepages, creep law), at the wheelset height where each
    /// wheel carries the given load. Forces are those of the rail on the wheel: Fx, Fy in the
    /// contact plane; Y (+ left) and Q (+ up) in the track frame. By default the wheelset
    /// rolls at the mean rolling radius of its two wheels at the shift; `--sweep-y` and
    /// `--sweep-yaw` write a table of states.
    #[command(
        after_help = "Examples:\n  railforce contact --vehicle c80 --y-mm 6 --yaw-mrad 2\n  railforce contact --vehicle c80 --sweep-y -10:10:0.5 --out sweep.csv"
    )]
    Contact(contact::ContactArgs),
    /// The channels a run records: every column's name, unit and meaning, in file order.
    ///
    /// The recorder's own list for the vehicle: time and track position, the paper's 21
    /// inputs, every wheel's forces and contact and its rail's deflection, every body's motion, every suspension
    /// element's deflection and the wagon's mass. `--markdown` prints the table of
    /// assets/docs/channels.md.
    #[command(
        after_help = "Examples:\n  railforce channels\n  railforce channels --vehicle c80_empty --markdown"
    )]
    Channels(channels::ChannelsArgs),
    /// Linear stability against speed: the whole model linearised about its centred
    /// equilibrium on smooth tangent track, eigenvalues (root locus), damping, named modes
    /// and each family's linear critical speed.
    ///
    /// The linearisation calls the run's own force evaluation (elements, contact, rails,
    /// hauling) and differentiates it numerically; the contact enters at an amplitude (its
    /// secant over ± --amplitude-mm: the equivalent conicity with the contact-angle and
    /// gravitational terms) with linear Kalker creep; friction elements stuck and sliding give
    /// two loci. Modes are named by where their kinetic energy lies (wheelset hunting, bogie
    /// hunting, carbody lower and upper sway, yaw …).
    #[command(
        after_help = "Examples:\n  railforce modes --vehicle c80 --speeds 20:200:10 --out modes_c80\n  railforce modes --vehicle c80_empty --flange-back-change-mm 7 --friction stuck --out modes_empty_1360\n  railforce modes --vehicle c80 --pairs --out pairs_c80"
    )]
    Modes(modes::ModesArgs),
    /// Simulate a vehicle on a track and record the 21 sensor channels, the forces of every
    /// wheel and the motion of every body at 200 Hz.
    ///
    /// The run starts from static equilibrium, settles (not recorded), then records. A step
    /// its integrator cannot hold (a stiff mode growing from step to step at the start) is
    /// refused before the first step, naming the mode and the longest step that holds it. A
    /// diverging run or a derailment (flange climb, or |Y/Q| above Nadal's limit for more
    /// than 50 ms) stops with a message naming the time and the wheel or body; nothing
    /// non-finite is ever written, and the CSV appears only when complete.
    #[command(
        after_help = "Examples:\n  railforce simulate --track curve_r400 --speed-kmh 60 --duration 5 --out run.csv\n  railforce simulate --vehicle c80_empty --track tangent --speed-kmh 80 --duration 5 --out empty.csv"
    )]
    Simulate(simulate::SimulateArgs),
    /// Generate a data set: every condition and seed of a plan, in parallel, one file per run
    /// (npz, parquet or csv) plus manifest.json; resumable, shardable (`--shard i/N`, then `--merge`).
    ///
    /// A rerun skips the runs the manifest lists as done with the same definition and redoes
    /// the rest; files are written atomically. `--snr-db X` adds `<channel>_noisy` copies of
    /// the 21 input channels (white Gaussian noise at X dB, seeded); labels are never noised.
    /// The plan file's keys (per-condition vehicle, class, seeds, start; [dataset] channel
    /// subset and float32) are listed in assets/docs/file-formats.md, "Plan files".
    #[command(
        after_help = "Examples:\n  railforce generate --plan demo --out data/demo --snr-db 6\n  (the paper's 34 conditions, 136 runs: railforce generate --plan paper34 --out data/paper34 --snr-db 6)"
    )]
    Generate(generate::GenerateArgs),
    /// What the labels depend on: Morris screening (every estimate of an estimates file over
    /// its stated range, ranked by μ*) and Sobol first and total indices (the top few), on the
    /// labels' mean, std, 99.85 % percentile and band std per condition.
    ///
    /// The study is a plan: each condition of the base plan is copied per design point (each
    /// copy sharing its base's irregularities), generated like `generate` (jobs, `--shard`,
    /// resume after an interruption), then read back into ranked tables and tornado charts
    /// (`OUT/index.html`). Every range is tried on the files' loaders before any run: a range
    /// outside an element's bounds, or an estimate without a range or a source, is refused
    /// naming the file and key.
    #[command(
        after_help = "Examples:\n  railforce sensitivity --out sensitivity                  (Morris, 10 trajectories)\n  railforce sensitivity --out sensitivity --method sobol   (the screening's top 5)\n  railforce sensitivity --shard 1/4 …, then --merge        (on a cluster)"
    )]
    Sensitivity(sensitivity::SensitivityArgs),
    /// Feature selection on a data set: mutual information of each of the 21 inputs with the
    /// target (Kraskov k = 3), then forward selection by validation R² of ridge regression on
    /// flattened windows; writes the selected channels and their z-score statistics.
    ///
    /// The split is leak-free: by seed when the data set has three or more (whole runs on
    /// other irregularities validate), else contiguous 70/15/15 % blocks of each run; all
    /// statistics come from the training part.
    #[command(
        after_help = "Examples:\n  railforce select --data data/demo --target FQ --out selection_fq.json"
    )]
    Select(select::SelectArgs),
    /// Train a model (cnn-bilstm, cnn, bilstm, gru, svr, gbdt, xgboost, tree) on a data set.
    ///
    /// Leak-free windows (whole runs by seed, contiguous blocks, or whole conditions held
    /// out), z-scores from the training part only. Networks: Adam, MSE, batch 64, fresh input
    /// noise every epoch, early stopping on the validation loss (patience 20) with the best
    /// weights restored, a checkpoint every epoch (`--resume`), train_log.jsonl. Classical
    /// models: fitted on up to 40 000 training windows. The model directory holds everything
    /// `evaluate` and `identify` need.
    #[command(
        after_help = "Examples:\n  railforce train --data data/demo --model gru --epochs 3 --out models/demo\n  railforce train --data data/demo --model tree --target w1l,w1r --out models/wheels"
    )]
    Train(train::TrainArgs),
    /// Score a trained model on a data set: MSE and R² on standardised targets with
    /// Var(y_test), RMSE and MAE in kN, per condition and pooled; predictions and
    /// per-condition metrics to CSV.
    #[command(after_help = "Examples:\n  railforce evaluate --model models/demo --data data/demo")]
    Evaluate(evaluate::EvaluateArgs),
    /// Calibrate a trained model's intervals again, on the validation runs of a data set,
    /// without training: split conformal prediction (assets/docs/learning.md §3.1), by default
    /// with intervals that follow each window's difficulty; writes model.json.
    #[command(
        after_help = "Examples:\n  railforce calibrate --model models/demo --data data/demo\n  railforce calibrate --model models/demo --data data/demo --uniform"
    )]
    Calibrate(calibrate::CalibrateArgs),
    /// Identify wheel–rail forces from a sensor recording with a trained model, with safety
    /// indices (|Y|/Q, wheel unloading ΔQ/Q̄, wheelset lateral force) and an exceedance report.
    ///
    /// The input (CSV, NPZ or Parquet with a `time_s` column) is checked first: every channel
    /// the model needs, 200 Hz without gaps (`--resample` interpolates), no NaN — the error
    /// names the column and row. `--input -` streams CSV lines from standard input and writes
    /// each estimate (forces, track position, safety indices) as soon as its window is
    /// complete, and the exceedance report at the end of the stream.
    #[command(
        after_help = "Examples:\n  railforce identify --model models/demo --input data/demo/curve_r400_v60_seed4.npz --out identified.csv\n  railforce identify --model models/wheels --input run.csv --out wheels.csv\n  railforce identify --model models/demo --input - --out streamed.csv < run.csv"
    )]
    Identify(identify::IdentifyArgs),
    /// Rerun the paper's experiments: model comparison, generalisation over conditions
    /// (with leave-one-condition-out) and robustness to noise, and four of ours: the protocols
    /// side by side, on-board sensor selection, wagons the models did not learn (mismatch:
    /// nominal against fleet-trained) and the simulator's own form (model-form: lumped track
    /// against rails on sleepers). Defaults: split by seed (independent test runs), 6 dB with
    /// σ from each channel's std, centre label. Writes tables (Markdown, CSV), SVG figures and
    /// index.html with the paper's numbers beside ours, and prints each part's wall time and
    /// CPU time at the end. A run of all seven writes results.md, the snapshot of what it
    /// measured (date, commit, protocol, the wall and CPU time of each part, every table);
    /// `experiment snapshot` rewrites it from a finished folder. The full protocol on the
    /// paper's 34 conditions takes hours on two cores, most of it training (results.md
    /// records each part's wall and CPU time).
    #[command(
        after_help = "Examples:\n  railforce experiment comparison --plan demo --out experiments --epochs 2 --windows-per-epoch 2000"
    )]
    Experiment(experiment::ExperimentArgs),
    /// The whole chain in a few minutes: simulate three short conditions, train a CNN-BiLSTM
    /// and GBDT, sweep two SNRs, and write the report (demo/index.html).
    Demo(experiment::DemoArgs),
    /// Check railforce against reference solutions and in closed loop (`validate contact`,
    /// `validate dynamics`, `validate track`, `validate identify`).
    #[command(
        after_help = "Examples:\n  railforce validate contact\n  railforce validate identify --model models/demo --plan demo"
    )]
    Validate(validate::ValidateArgs),
    /// Assess a run as acceptance engineers do: forces filtered at 20 Hz, (Y/Q)2m and (ΣY)2m
    /// as sliding means over 2 m of track with their 99.85 % percentiles, Q's 99.85 %,
    /// quasi-static Yqst and Qqst over curves, and the Chinese derailment criteria with
    /// their 50 ms time criterion — per wheel and per section of track, each against a limit
    /// that cites its source (vehicles/assessment.toml; --criteria for your own).
    ///
    /// Works on simulated runs and on identify output alike, so the true and the identified
    /// forces of a run are judged by the same statistics.
    #[command(
        after_help = "Examples:\n  railforce assess run.csv --track curve_r400\n  railforce assess identified.csv --out identified_assessment"
    )]
    Assess(assess::AssessArgs),
    /// Replay a run in one self-contained HTML page for a class or a review: the leading
    /// wheelset's wheels on their rails from the real profiles (contact points, two-point
    /// contact, Y and Q arrows), a plan view of the wagon on the track (yaw and lateral shift
    /// exaggerated, by factors the page states), and the label wheel's Y, Q and Y/Q with the
    /// identified forces and the limits, all following a time slider with play and speed.
    ///
    /// The page needs no network (script and data inline) and opens from disk in any current
    /// browser; a 60 s run makes 1.8 MB at the default 100 frames per second.
    #[command(
        after_help = "Examples:\n  railforce view run.csv\n  (run.csv from: railforce simulate --track curve_r400 --duration 20 --out run.csv)\n  railforce view data/demo/curve_r400_v60_seed4.npz --identified identified.csv --out view.html"
    )]
    View(view::ViewArgs),
    /// Export a network's weights for Python: safetensors with the names and layouts of the
    /// PyTorch module in assets/python/railforce_nets.py (the same layers), the inputs' and
    /// targets' z-score statistics included, so the module reads physical inputs and returns
    /// forces in N as `identify` does.
    #[command(
        after_help = "Examples:\n  railforce export --model models/demo\n  (then in Python: import railforce_nets; net = railforce_nets.load(\"models/demo/model.safetensors\"))"
    )]
    Export(export::ExportArgs),
    /// Built-in benchmarks with same-run references (`bench contact`, `bench simulate`,
    /// `bench learn`, `bench step`).
    Bench(bench::BenchArgs),
    /// Write the built-in vehicles, tracks and plans (the C80 loaded and empty, the paper's 34
    /// conditions, the demo plan) into DIR to edit them.
    ///
    /// railforce carries these files: a command given a path that does not exist but names a
    /// built-in file (e.g. `vehicles/c80.toml`, `tracks/demo.plan.toml`) uses the built-in
    /// copy, so the defaults work from any folder after `cargo install`; files you give always
    /// take precedence.
    #[command(after_help = "Examples:\n  railforce init my_project")]
    Init(InitArgs),
}

#[derive(Debug, clap::Args)]
struct InitArgs {
    /// Folder to write into (vehicles/ and tracks/ are created inside).
    #[arg(default_value = ".")]
    dir: std::path::PathBuf,
    /// Overwrite files that exist.
    #[arg(long)]
    force: bool,
}

fn init(args: InitArgs) -> anyhow::Result<()> {
    let written = builtin::write_all(&args.dir, args.force)?;
    println!(
        "wrote {} files under {} (vehicles/, tracks/)",
        written.len(),
        args.dir.display()
    );
    Ok(())
}

/// Parses the command line, runs the subcommand and turns errors into a message and exit 1.
/// A library error with the flags that set what it names: `<what is wrong> (set by <flags>)`.
/// The library says what is wrong in its own words; the command line adds where to change it.
/// A number flag that must be finite: clap reads `nan` and `inf` as numbers.
pub fn finite(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(format!("{v} is not a finite number")),
        Err(e) => Err(e.to_string()),
    }
}

pub fn with_flags<T>(r: railforce::Result<T>, flags: &str) -> anyhow::Result<T> {
    r.map_err(|e| anyhow::anyhow!("{e} (set by {flags})"))
}

pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Track(args) => track::run(args),
        Command::Contact(args) => contact::run(args),
        Command::Channels(args) => channels::run(args),
        Command::Modes(args) => modes::run(args),
        Command::Simulate(args) => simulate::run(args),
        Command::Generate(args) => generate::run(args),
        Command::Sensitivity(args) => sensitivity::run(args),
        Command::Select(args) => select::run(args),
        Command::Train(args) => train::run(args),
        Command::Evaluate(args) => evaluate::run(args),
        Command::Calibrate(args) => calibrate::run(args),
        Command::Identify(args) => identify::run(args),
        Command::Experiment(args) => experiment::run(args),
        Command::Demo(args) => experiment::demo(args),
        Command::Validate(args) => validate::run(args),
        Command::Assess(args) => assess::run(args),
        Command::View(args) => view::run(args),
        Command::Export(args) => export::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Init(args) => init(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
