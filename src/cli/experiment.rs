//! `railforce experiment …` and `railforce demo`: the paper's experiments and the one-command
//! demonstration, as thin shells over `railforce::experiment`.

use anyhow::Result;
use clap::{Args, ValueEnum};
use railforce::experiment::{self, ExperimentOptions, Which};
use railforce::features::Split;
use railforce::learn::train::TrainOptions;
use railforce::sensors::SnrReference;
use std::path::PathBuf;

#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum WhichArg {
    /// Eight models on one condition at 6 dB (paper Tables 2–3).
    Comparison,
    /// One CNN-BiLSTM over all conditions, plus leave-one-condition-out (Tables 4–5).
    Generalization,
    /// SNR sweep of GBDT, BiLSTM, CNN and CNN-BiLSTM under both noise protocols (Fig. 8).
    Robustness,
    /// The CNN-BiLSTM under the seed, block, condition and shuffled splits, side by side.
    Protocols,
    /// Filter–Wrapper over the on-board candidates for FL and FQ; the CNN-BiLSTM on the
    /// selected set against the paper's 21 at 6 and 1 dB.
    Sensors,
    /// Wagons the models did not learn: the nominal CNN-BiLSTM (paper's 21 and the on-board
    /// selection) against the same trained on a fleet (--fleet), on the fleet's held-out
    /// wagons and four named extremes (half payload, wet rail, highest conicity, class 4).
    Mismatch,
    /// The simulator's form: the CNN-BiLSTM (paper's 21) trained on the lumped track and
    /// tested on rails on sleepers (every run simulated again on them), and the other way
    /// round, both also on the test runs with CNOSSOS rail roughness; the labels' spread on
    /// the three per condition.
    ModelForm,
    /// The paper's three: comparison, generalization, robustness.
    Paper,
    /// All seven.
    All,
    /// Run nothing: rewrite the results snapshot of the finished run in --out into
    /// --results (and the headline table --readme quotes).
    Snapshot,
}

#[derive(Debug, Args)]
pub struct ExperimentArgs {
    /// Which experiments, comma separated (e.g. `generalization,protocols`), in this order.
    #[arg(value_enum, value_delimiter = ',', required = true)]
    which: Vec<WhichArg>,
    /// Plan of conditions (simulated once, clean; noise is added per SNR).
    #[arg(long, default_value = "tracks/paper34.plan.toml")]
    plan: PathBuf,
    /// The fleet of the mismatch experiment: a plan whose conditions, by name, give each of
    /// --plan's conditions its [vary] (wagons and tracks drawn per run).
    #[arg(long, default_value = "tracks/paper34_varied.plan.toml")]
    fleet: PathBuf,
    /// Output folder: data/, one folder per experiment, index.html, meta.json.
    #[arg(long, default_value = "experiments")]
    out: PathBuf,
    /// Condition of the comparison and robustness experiments.
    #[arg(long, default_value = "curve_r400_v60")]
    condition: String,
    /// SNR of the comparison, generalisation, protocols and sensors, dB.
    #[arg(long, default_value_t = 6.0)]
    snr_db: f64,
    /// What the SNR is measured against: `std` (each channel's variation, the default) or
    /// `rms` (offset included: a constant offset raises the noise level).
    #[arg(long, default_value = "std", value_parser = ["std", "rms"])]
    snr_reference: String,
    /// Training seeds (comma separated) instead of all of the plan's but the last two.
    #[arg(long, value_delimiter = ',')]
    train_seeds: Vec<u64>,
    /// Validation seeds instead of the plan's one before last.
    #[arg(long, value_delimiter = ',')]
    val_seeds: Vec<u64>,
    /// Test seeds instead of the plan's last.
    #[arg(long, value_delimiter = ',')]
    test_seeds: Vec<u64>,
    /// Epochs at most per network.
    #[arg(long, default_value_t = 100)]
    epochs: usize,
    /// Early-stopping patience.
    #[arg(long, default_value_t = 10)]
    patience: usize,
    /// Halve each network's learning rate after this many epochs without a better
    /// validation loss (0: constant).
    #[arg(long, default_value_t = 4)]
    lr_plateau: usize,
    /// Training windows drawn per epoch (0: all).
    #[arg(long, default_value_t = 50_000)]
    windows_per_epoch: usize,
    /// Seed of every training.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Simulations, and trainings, in parallel (each training runs on one thread; the models
    /// do not depend on how many run at once).
    #[arg(long, default_value_t = 2)]
    jobs: usize,
    /// Where a window's label sits: `centre` (the paper's, the default, as `train` and
    /// Python's `windows()`) or `last` (causal, usable on board in real time).
    #[arg(long, default_value = "centre", value_parser = railforce::features::LabelAt::NAMES)]
    label: String,
    /// The former spelling of `--label last`.
    #[arg(long, hide = true, conflicts_with = "label")]
    last_label: bool,
    /// Window length, steps (the paper's 20 at 200 Hz = 0.1 s; longer windows average more
    /// noise out and cost proportionally more time).
    #[arg(long, default_value_t = 20)]
    window: usize,
    /// Window length of the mismatch experiment's models, steps (default 40 = 0.2 s: the
    /// paper's 21 + mass read held-out wagons' FL better with it; its nominal models are then
    /// trained again rather than reused from the other parts).
    #[arg(long)]
    mismatch_window: Option<usize>,
    /// Networks in each of the mismatch experiment's fleet-trained models with the weighed
    /// mass, from seeds seed, seed + 1, …, joined into one ensemble (its mean averages out the
    /// training seed; each member costs one more training). 1 to 32.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u16).range(1..=32))]
    mismatch_members: u16,
    /// Also write the results snapshot here (it is always written to --out/results.md): the
    /// date, commit, version, protocol, wall and CPU time of each part, a headline table and every
    /// table and figure, from the run's own files; figures are copied beside it under
    /// results/. The project's is assets/docs/results.md.
    #[arg(long)]
    results: Option<PathBuf>,
    /// With snapshot: replace in the existing --results file only the parts --out holds (their
    /// sections, headline rows, wall and CPU times and commits), keeping the others as they were
    /// measured; for one part run again after a change that touched its data alone.
    #[arg(long)]
    merge: bool,
    /// Replace the headline table this README quotes (between its results:headline markers)
    /// with the snapshot's.
    #[arg(long)]
    readme: Option<PathBuf>,
    /// Train the networks on the one fixed noisy copy of the inputs instead of drawing new
    /// noise every epoch (the default draws fresh noise at the same SNR; validation and test
    /// keep their fixed noise either way).
    #[arg(long)]
    fixed_noise: bool,
}

fn run_with(which: &[Which], opts: &ExperimentOptions) -> Result<()> {
    let t0 = std::time::Instant::now();
    let index = experiment::run(which, opts, &|line| {
        eprintln!("[{:>6.0} s] {line}", t0.elapsed().as_secs_f64())
    })?;
    println!(
        "report: {} ({:.0} s); results: {}",
        index.display(),
        t0.elapsed().as_secs_f64(),
        opts.out.join(experiment::RESULTS_FILE).display()
    );
    Ok(())
}

pub fn run(args: ExperimentArgs) -> Result<()> {
    if args.which.iter().any(|w| matches!(w, WhichArg::Snapshot)) {
        if args.which.len() > 1 {
            anyhow::bail!("snapshot runs nothing: give it alone");
        }
        let dest = args
            .results
            .clone()
            .unwrap_or_else(|| args.out.join(experiment::RESULTS_FILE));
        let written = experiment::snapshot(&args.out, &dest, args.readme.as_deref(), args.merge)?;
        println!("results: {}", written.display());
        return Ok(());
    }
    let which: Vec<Which> = args
        .which
        .iter()
        .map(|w| match w {
            WhichArg::Comparison => Which::Comparison,
            WhichArg::Generalization => Which::Generalization,
            WhichArg::Robustness => Which::Robustness,
            WhichArg::Protocols => Which::Protocols,
            WhichArg::Sensors => Which::Sensors,
            WhichArg::Mismatch => Which::Mismatch,
            WhichArg::ModelForm => Which::ModelForm,
            WhichArg::Paper => Which::Paper,
            WhichArg::All | WhichArg::Snapshot => Which::All,
        })
        .collect();
    let mut opts = ExperimentOptions::full(super::builtin::resolve(&args.plan)?, args.out);
    if which.iter().any(|w| w.parts().contains(&Which::Mismatch)) {
        opts.fleet = Some(super::builtin::resolve(&args.fleet)?);
    }
    opts.results = args.results;
    opts.readme = args.readme;
    opts.condition = args.condition;
    opts.snr_db = args.snr_db;
    opts.jobs = args.jobs;
    opts.fresh_noise = !args.fixed_noise;
    opts.window = args.window;
    if let Some(w) = args.mismatch_window {
        opts.mismatch_window = w;
    }
    opts.mismatch_members = args.mismatch_members.into();
    opts.label_at = if args.last_label {
        railforce::features::LabelAt::Last
    } else {
        railforce::features::LabelAt::parse(&args.label)?
    };
    opts.snr_reference = SnrReference::parse(&args.snr_reference)
        .ok_or_else(|| anyhow::anyhow!("--snr-reference {}: std or rms", args.snr_reference))?;
    if !(args.train_seeds.is_empty() && args.val_seeds.is_empty() && args.test_seeds.is_empty()) {
        if args.train_seeds.is_empty() || args.test_seeds.is_empty() {
            anyhow::bail!("give --train-seeds and --test-seeds (and --val-seeds) together");
        }
        opts.split = Some(Split::Seeds {
            train: args.train_seeds,
            val: args.val_seeds,
            test: args.test_seeds,
        });
    }
    opts.train = TrainOptions {
        epochs: args.epochs,
        patience: args.patience,
        lr_plateau: args.lr_plateau,
        seed: args.seed,
        windows_per_epoch: (args.windows_per_epoch > 0).then_some(args.windows_per_epoch),
        ..opts.train
    };
    run_with(&which, &opts)
}

#[derive(Debug, Args)]
pub struct DemoArgs {
    /// Output folder of the demo report.
    #[arg(long, default_value = "demo")]
    out: PathBuf,
    /// Plan (three short conditions).
    #[arg(long, default_value = "tracks/demo.plan.toml")]
    plan: PathBuf,
}

pub fn demo(args: DemoArgs) -> Result<()> {
    if cfg!(debug_assertions) {
        eprintln!("warning: debug build; `cargo run --release -- demo` is many times faster");
    }
    eprintln!(
        "railforce demo: simulate 3 short conditions, train a CNN-BiLSTM and GBDT, sweep 2 SNRs, write the report"
    );
    let opts = ExperimentOptions::demo(super::builtin::resolve(&args.plan)?, args.out.clone());
    run_with(&[Which::Paper], &opts)?;
    super::view::write_demo_view(&args.out)?;
    let index = experiment::write_report(&args.out)?;
    println!("report with the viewer linked: {}", index.display());
    Ok(())
}
