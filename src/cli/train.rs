//! `railforce train`: a thin shell over `learn::train` (and `learn::uncertainty` for an
//! ensemble).

use anyhow::{Context, Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use railforce::dataset::DataSet;
use railforce::features::{LabelAt, NoiseProtocol, Selection, Split, SplitRequest};
use railforce::learn::evaluate::target_name;
use railforce::learn::model::{Model, ModelKind};
use railforce::learn::train::{DEFAULT_QUANTILE_HEADS, GradientEngine, Progress, TrainOptions};
use railforce::learn::uncertainty::train_ensemble;
use railforce::learn::windows::{DataRequest, DataSpec};
use railforce::sensors::PAPER_CHANNELS;
use std::path::{Path, PathBuf};

/// Data and split options shared by `train` and the experiments.
#[derive(Debug, Args, Clone)]
pub struct DataArgs {
    /// Data set folder (written by `railforce generate`).
    #[arg(long)]
    pub data: PathBuf,
    /// Selection file from `railforce select` (channels, window, label position). Without it,
    /// all 21 paper channels, window 20, label at the centre step.
    #[arg(long)]
    pub selection: Option<PathBuf>,
    /// Targets, comma separated: FL (lateral force of the vehicle's label wheel, 1L for the
    /// C80), FQ (vertical), both, a wheel (`w1r` or `1R`: its Y and Q), or a channel name.
    /// `--target w1l,w1r` identifies both wheels of the leading wheelset: Y/Q of each and the
    /// wheelset's lateral force H.
    #[arg(long, default_value = "both")]
    pub target: String,
    /// Noise protocol: clean, train-clean-test-noisy, or matched (train and test on the
    /// `_noisy` inputs). Default: matched when the data set has `_noisy` columns, else clean.
    #[arg(long)]
    pub noise: Option<String>,
    /// How runs are split: `seeds` (whole runs by irregularity seed: the default when the
    /// data set has three or more seeds; the last tests, the one before validates, the rest
    /// train), `blocks` (70/15/15 % contiguous blocks of every run: the default with fewer
    /// seeds), `conditions` (with --test-conditions) or `shuffled` (stride-1 windows shuffled
    /// 70/15/15: leaky, for comparison only).
    #[arg(long, value_parser = railforce::features::SPLIT_KINDS)]
    pub split: Option<String>,
    /// Training seeds of the seed split (comma separated), instead of all but the last two.
    #[arg(long, value_delimiter = ',')]
    pub train_seeds: Vec<u64>,
    /// Validation seeds of the seed split, instead of the one before last.
    #[arg(long, value_delimiter = ',')]
    pub val_seeds: Vec<u64>,
    /// Test seeds of the seed split, instead of the last.
    #[arg(long, value_delimiter = ',')]
    pub test_seeds: Vec<u64>,
    /// Hold out whole conditions for the test (comma separated); validation then uses
    /// `--val-conditions`.
    #[arg(long, value_delimiter = ',')]
    pub test_conditions: Vec<String>,
    /// Conditions held out for validation (with --test-conditions).
    #[arg(long, value_delimiter = ',')]
    pub val_conditions: Vec<String>,
    /// Stride of the training windows (validation and test always use 1).
    #[arg(long, default_value_t = 1)]
    pub stride: usize,
    /// Where a window's label sits: `centre` (the paper's intermediate time point, the
    /// default, as Python's `windows()` and the experiments) or `last` (causal, usable on
    /// board in real time). Without it, the selection's position, or the centre.
    #[arg(long, value_parser = LabelAt::NAMES)]
    pub label: Option<String>,
    /// The former spelling of `--label centre`.
    #[arg(long, hide = true, conflicts_with = "label")]
    pub centre_label: bool,
    /// Window length, steps, instead of the selection's (or 20).
    #[arg(long)]
    pub window: Option<usize>,
}

#[derive(Debug, Args)]
pub struct TrainArgs {
    #[command(flatten)]
    data: DataArgs,
    /// Model: cnn-bilstm, cnn, bilstm, gru, svr, gbdt, xgboost or tree.
    #[arg(long, default_value = "cnn-bilstm")]
    model: String,
    /// Model directory to write (weights, model.json, train_log.jsonl, checkpoints).
    #[arg(long)]
    out: PathBuf,
    /// Epochs at most (networks).
    #[arg(long, default_value_t = 200)]
    epochs: usize,
    /// Early-stopping patience, epochs.
    #[arg(long, default_value_t = 20)]
    patience: usize,
    /// Minibatch size.
    #[arg(long, default_value_t = 64)]
    batch: usize,
    /// Adam learning rate.
    #[arg(long, default_value_t = 1e-3)]
    lr: f32,
    /// Halve the learning rate after this many epochs without a better validation loss
    /// (reduce-on-plateau; 0 keeps it constant).
    #[arg(long, default_value_t = 4)]
    lr_plateau: usize,
    /// Seed of weights, shuffling and dropout.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Training windows drawn per epoch at most (default: all).
    #[arg(long)]
    windows_per_epoch: Option<usize>,
    /// Training windows a classical model is fitted on at most (evenly strided).
    #[arg(long, default_value_t = 40_000)]
    classical_rows: usize,
    /// Validation windows scored each epoch at most (evenly strided; default: all). The
    /// experiments use 40 000.
    #[arg(long)]
    val_windows: Option<usize>,
    /// Continue from the checkpoint in --out (same data and settings).
    #[arg(long)]
    resume: bool,
    /// Members of a deep ensemble: N networks (or regressors) from seeds --seed, --seed+1, …;
    /// the model predicts their mean, and `identify` widens its bands where they disagree.
    /// Every model is calibrated by split conformal prediction on the validation runs, so
    /// `identify` writes intervals at --coverage with one member too.
    #[arg(long, default_value_t = 1)]
    ensemble: usize,
    /// Networks: the quantile heads' nominal coverage (default 0.9). A single network learns,
    /// beside the mean, the (1 − c)/2 and (1 + c)/2 quantiles with the pinball loss, and its
    /// intervals follow their width (conformalised on the validation runs like an ensemble's
    /// spread): the default, as well calibrated as a 5-member ensemble for one network's
    /// training time (assets/docs/learning.md §3.1). Not for an ensemble (its spread is the
    /// members' disagreement), classical models or the burn engine.
    #[arg(long, value_name = "COVERAGE", conflicts_with_all = ["ensemble", "no_quantile_heads"])]
    quantile_heads: Option<f64>,
    /// A plain network without quantile heads: one mean per target, intervals from the
    /// validation residuals and each window's difficulty alone.
    #[arg(long)]
    no_quantile_heads: bool,
    /// Train anew into an --out that already holds a model or a checkpoint (without it, and
    /// without --resume, such a folder is refused so that no finished training is lost).
    #[arg(long, conflicts_with = "resume")]
    force: bool,
    /// Networks, matched protocol: learn the data set's one fixed noise realisation instead of
    /// drawing new training-input noise every epoch at its SNR (the default, the protocol of
    /// assets/docs/learning.md §1.4 and the experiments; validation and test always keep the data set's noisy
    /// columns).
    #[arg(long)]
    fixed_noise: bool,
    /// Networks: what computes each minibatch's forward and backward pass. `fused`, the
    /// hand-fused engine, is the fast CPU path; `burn-cpu` runs the same network as burn
    /// modules with burn's autodiff (build with `--features burn`), `burn-gpu` on a GPU through wgpu
    /// and Vulkan (`--features burn-gpu`). Same weights, optimizer, dropout stream and model directory:
    /// a model or checkpoint of either engine loads and resumes in the other.
    #[arg(long, default_value = "fused", value_parser = ["fused", "burn-cpu", "burn-gpu"])]
    engine: String,
}

/// The data options as the library's request: the selection file's channels, window and
/// label position (or the paper's 21, 20, the centre), then the flags that override them.
pub fn data_spec(args: &DataArgs, ds: &DataSet) -> Result<DataSpec> {
    let (channels, window, label_at) = match &args.selection {
        Some(p) => {
            let s = Selection::load(p)?;
            (s.channels, s.window, s.label_at)
        }
        None => (
            PAPER_CHANNELS.iter().map(|c| c.to_string()).collect(),
            20,
            LabelAt::default(),
        ),
    };
    let noise = match args.noise.as_deref() {
        None => None,
        Some(o) => Some(NoiseProtocol::parse(o).ok_or_else(|| {
            anyhow::anyhow!("--noise {o}: expected clean, matched or train-clean-test-noisy")
        })?),
    };
    let req = DataRequest {
        channels,
        targets: args.target.clone(),
        window: args.window.unwrap_or(window),
        label_at: match (&args.label, args.centre_label) {
            (Some(name), _) => LabelAt::parse(name)?,
            (None, true) => LabelAt::Centre,
            (None, false) => label_at,
        },
        stride: args.stride,
        split: split(args, ds)?,
        noise,
    };
    super::with_flags(
        DataSpec::resolve(&req, ds),
        "--target, --window or --stride",
    )
}

/// The split flags resolved against the data set's seeds and conditions (the library's
/// [`Split::resolve`]); its errors get the flags to use.
pub fn split(args: &DataArgs, ds: &DataSet) -> Result<Split> {
    let req = SplitRequest {
        kind: args.split.clone(),
        train_seeds: args.train_seeds.clone(),
        val_seeds: args.val_seeds.clone(),
        test_seeds: args.test_seeds.clone(),
        val_conditions: args.val_conditions.clone(),
        test_conditions: args.test_conditions.clone(),
    };
    super::with_flags(
        Split::resolve(&req, ds),
        "--split, --test-conditions/--val-conditions or --train-seeds/--val-seeds/--test-seeds",
    )
}

/// `ds` with `<channel>_noisy` copies of every channel of `channels` that lacks one, drawn
/// with `noise` (seeded per run and channel name, as `generate` draws them); unchanged when
/// none is missing.
pub fn with_noisy_copies(
    ds: DataSet,
    channels: &[String],
    noise: Option<railforce::sensors::NoiseModel>,
) -> Result<DataSet> {
    let missing = channels
        .iter()
        .filter(|c| ds.channel(&railforce::sensors::noisy_name(c)).is_err())
        .count();
    if missing == 0 {
        return Ok(ds);
    }
    let noise = noise.with_context(|| {
        format!(
            "{} has no noisy copies of {missing} input channels and records no noise (generate with --snr-db)",
            ds.dir.display()
        )
    })?;
    eprintln!(
        "note: drawing the noisy copies of {missing} channels in memory: {}",
        noise.describe()
    );
    Ok(ds.with_noise(noise, channels)?)
}

pub fn run(args: TrainArgs) -> Result<()> {
    let kind = ModelKind::parse(&args.model)?;
    let ds = DataSet::load(&args.data.data)?;
    let spec = data_spec(&args.data, &ds)?;
    let ds = if spec.noise == NoiseProtocol::Clean {
        ds
    } else {
        let noise = ds.noise;
        with_noisy_copies(ds, &spec.channels, noise)?
    };
    let opts = TrainOptions {
        epochs: args.epochs,
        patience: args.patience,
        batch: args.batch,
        lr: args.lr,
        lr_plateau: args.lr_plateau,
        seed: args.seed,
        windows_per_epoch: args.windows_per_epoch,
        classical_rows: args.classical_rows,
        val_windows: args.val_windows,
        resume: args.resume,
        // Fresh noise applies to networks under the matched protocol when the data set
        // records its noise; otherwise the one realisation on disk is all there is.
        fresh_noise: if !args.fixed_noise
            && kind.architecture().is_some()
            && spec.noise == NoiseProtocol::Matched
        {
            ds.noise
        } else {
            None
        },
        engine: GradientEngine::from_name(&args.engine).unwrap_or_default(),
        quantile_heads: if args.no_quantile_heads {
            None
        } else {
            Some(args.quantile_heads.unwrap_or(DEFAULT_QUANTILE_HEADS))
        },
        ..TrainOptions::default()
    };
    if let Some(c) = args.quantile_heads
        && opts.heads_for(kind, args.ensemble).is_none()
    {
        bail!(
            "--quantile-heads {c}: quantile heads are a network's, trained with the fused engine; {} with --engine {} has none",
            kind.name(),
            args.engine
        );
    }
    let short = |t: &String| target_name(t, &ds.labels);
    println!(
        "training {} on {} ({} runs): {} channels × {} steps, label at the {} → {}",
        kind.name(),
        args.data.data.display(),
        ds.runs.len(),
        spec.channels.len(),
        spec.window,
        match spec.label_at {
            LabelAt::Centre => "centre step",
            LabelAt::Last => "last step",
        },
        spec.targets
            .iter()
            .map(short)
            .collect::<Vec<_>>()
            .join(" and "),
    );
    println!(
        "  noise: {}{}",
        spec.noise.describe(),
        spec.noise_model
            .map(|n| format!(", {}", n.describe()))
            .unwrap_or_default()
    );
    if kind.architecture().is_some() && spec.noise == NoiseProtocol::Matched {
        println!(
            "  training noise: {}",
            if opts.fresh_noise.is_some() {
                "a new draw every epoch (the default protocol; --fixed-noise to learn the data set's one realisation)"
            } else {
                "the data set's one fixed realisation"
            }
        );
    }
    println!("  split: {}", spec.split.describe());
    if kind.architecture().is_some() {
        println!(
            "  Adam lr {}{}, batch {}, at most {} epochs, patience {}, {} training windows per epoch; gradients by {}",
            opts.lr,
            if opts.lr_plateau > 0 {
                format!(
                    " (halved after {} epochs without improvement)",
                    opts.lr_plateau
                )
            } else {
                String::new()
            },
            opts.batch,
            opts.epochs,
            opts.patience,
            opts.windows_per_epoch
                .map(|w| w.to_string())
                .unwrap_or("all".into()),
            opts.engine.describe()
        );
    } else {
        println!(
            "  fitted on at most {} training windows (evenly strided)",
            opts.classical_rows
        );
    }
    if !args.resume && !args.force {
        for (file, what) in [
            ("model.json", "a trained model"),
            ("checkpoint.json", "a checkpoint"),
        ] {
            if args.out.join(file).exists() {
                bail!(
                    "{} already holds {what} ({file}): --resume continues it, --force trains anew over it, or give another --out",
                    args.out.display()
                );
            }
        }
    }
    let model = train_with_bar(&ds, &spec, kind, &opts, args.ensemble, &args.out)?;
    if let Some(c) = &model.meta.calibration {
        println!(
            "calibrated ({} score) on the {}; the 90 % half-width of a typical window: {}",
            c.score.name(),
            c.part,
            spec.targets
                .iter()
                .enumerate()
                .map(|(k, n)| format!(
                    "{} {:.2} kN",
                    short(n),
                    c.typical_half_width(k, 0.9) * model.meta.target_stats.std[k] * 1e-3
                ))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let t = &model.meta.training;
    let r2 = t["best_val_r2"]
        .as_array()
        .or(t["val_r2"].as_array())
        .map(|a| {
            spec.targets
                .iter()
                .zip(a)
                .map(|(n, v)| format!("{} {:.3}", short(n), v.as_f64().unwrap_or(f64::NAN)))
                .collect::<Vec<_>>()
                .join(", ")
        })
        .unwrap_or_default();
    let how = if kind.architecture().is_some() {
        format!(
            "best epoch {} of {}{}",
            t["best_epoch"],
            t["epochs_run"],
            if t["stopped_early"].as_bool() == Some(true) {
                " (stopped early)"
            } else {
                ""
            }
        )
    } else {
        format!("fitted on {} windows", t["fitted_rows"])
    };
    println!(
        "done in {:.0} s: {how}; validation R² {r2}. Model in {} (model.json holds every setting).",
        t["wall_seconds"].as_f64().unwrap_or(0.0),
        args.out.display()
    );
    println!(
        "next: railforce evaluate --model {} --data {}",
        args.out.display(),
        args.data.data.display()
    );
    Ok(())
}

/// Trains (`members` of an ensemble, one after the other) with a progress bar on standard
/// error and one line per epoch, then calibrates.
pub fn train_with_bar(
    ds: &DataSet,
    spec: &DataSpec,
    kind: ModelKind,
    opts: &TrainOptions,
    members: usize,
    out: &Path,
) -> Result<Model> {
    let bar = ProgressBar::new(1);
    bar.set_style(
        ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} {msg}").expect("template"),
    );
    bar.set_prefix(kind.name());
    let model = train_ensemble(
        ds,
        spec,
        kind,
        opts,
        members,
        out,
        &mut |member, p| match p {
            Progress::Batch { epoch, done, total } => {
                if members > 1 {
                    bar.set_prefix(format!("{} member {}/{members}", kind.name(), member + 1));
                }
                bar.set_length(total as u64);
                bar.set_position(done as u64);
                bar.set_message(format!("epoch {epoch} batches"));
            }
            Progress::Epoch(e) => {
                let r2: Vec<String> = e
                    .val_r2
                    .iter()
                    .zip(&spec.targets)
                    .map(|(r, t)| format!("{} {r:.3}", target_name(t, &ds.labels)))
                    .collect();
                bar.suspend(|| {
                eprintln!(
                    "epoch {:>3}: loss train {:.4}, val {:.4}; val R² {}; {:.0} windows/s; best epoch {}; lr {:.1e}",
                    e.epoch,
                    e.train_loss,
                    e.val_loss,
                    r2.join(", "),
                    e.windows_per_s,
                    e.best_epoch,
                    e.lr
                )
            });
            }
            Progress::Fit { done, total } => {
                bar.set_length(total as u64);
                bar.set_position(done as u64);
                bar.set_message("fitting");
            }
        },
    )?;
    bar.finish_and_clear();
    Ok(model)
}
