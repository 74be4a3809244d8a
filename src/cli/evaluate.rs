//! `railforce evaluate`: a thin shell over `learn::evaluate`.

use super::train::with_noisy_copies;
use anyhow::Result;
use clap::Args;
use railforce::dataset::DataSet;
use railforce::features::NoiseProtocol;
use railforce::learn::evaluate::{
    CoverageRow, EVAL_COVERAGE, EvalPart, Evaluation, evaluate, target_name,
};
use railforce::learn::model::Model;
use std::path::PathBuf;

/// `railforce evaluate`'s options.
#[derive(Debug, Args)]
pub struct EvaluateArgs {
    /// Model directory written by `railforce train`.
    #[arg(long)]
    model: PathBuf,
    /// Data set folder.
    #[arg(long)]
    data: PathBuf,
    /// Score every window of every run (data never used in training) instead of the test
    /// blocks of the model's own split.
    #[arg(long)]
    all: bool,
    /// Predictions CSV (default: MODEL/predictions.csv).
    #[arg(long)]
    predictions: Option<PathBuf>,
    /// Per-condition metrics CSV, one row per condition and target, then the pooled rows
    /// (default: MODEL/metrics_per_condition.csv).
    #[arg(long)]
    metrics: Option<PathBuf>,
    /// Interval coverage CSV, per condition and pooled, for a calibrated model
    /// (default: MODEL/coverage_per_condition.csv).
    #[arg(long)]
    coverage: Option<PathBuf>,
}

/// Scores a model on a data set: metrics per condition, predictions, interval coverage.
pub fn run(args: EvaluateArgs) -> Result<()> {
    let mut model = Model::load(&args.model)?;
    let mut ds = DataSet::load(&args.data)?;
    // A model that reads noisy inputs, on a data set without them: noise it as the model was
    // noised (its recorded SNR and reference), seeded per run and channel as `generate` does.
    if model.meta.data.noise != NoiseProtocol::Clean {
        ds = with_noisy_copies(ds, &model.meta.data.channels, model.meta.data.noise_model)?;
    }
    let part = if args.all {
        EvalPart::All
    } else {
        EvalPart::Test
    };
    let ev = evaluate(&mut model, &ds, part)?;
    println!(
        "{} on {} ({}; {}), {} windows, {:.0} windows/s:",
        model.meta.kind.name(),
        args.data.display(),
        if args.all {
            "all windows".to_string()
        } else {
            format!("test part: {}", model.meta.data.split.describe())
        },
        model.meta.data.noise.describe(),
        ev.metrics.first().map(|m| m.n).unwrap_or(0),
        ev.windows_per_s
    );
    let per = ev.per_condition(&model.meta.target_stats);
    println!(
        "{:<24} {:<14} {:>8} {:>9} {:>9} {:>9} {:>10} {:>9}",
        "condition", "target", "windows", "MSE", "R²", "Var(y)", "RMSE kN", "MAE kN"
    );
    let all = ("all (pooled)".to_string(), ev.metrics.clone());
    for (c, ms) in per.iter().chain(std::iter::once(&all)) {
        for m in ms {
            println!(
                "{:<24} {:<14} {:>8} {:>9.4} {:>9.4} {:>9.4} {:>10.3} {:>9.3}",
                c, m.target, m.n, m.mse, m.r2, m.var_y, m.rmse_kn, m.mae_kn
            );
        }
    }
    let summary: Vec<String> = ev
        .metrics
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let worst = Evaluation::worst_condition(&per, k)
                .map(|(c, r2)| format!(", worst {c} {r2:.3}"))
                .unwrap_or_default();
            format!("{} R² {:.3} pooled{worst}", m.target, m.r2)
        })
        .collect();
    println!(
        "summary over {} condition(s): {}",
        per.len(),
        summary.join("; ")
    );
    let metrics_csv = args
        .metrics
        .unwrap_or_else(|| args.model.join("metrics_per_condition.csv"));
    ev.write_condition_csv(&metrics_csv, &per)?;
    println!("per-condition metrics: {}", metrics_csv.display());
    let out = args
        .predictions
        .unwrap_or_else(|| args.model.join("predictions.csv"));
    ev.write_csv(&out, &model.meta.data.targets)?;
    println!("predictions: {}", out.display());
    match ev.coverage() {
        None => println!(
            "no intervals: the model has no calibration (trained by a version without intervals; `railforce calibrate` adds them)"
        ),
        Some(rows) => {
            let names: Vec<String> = model
                .meta
                .data
                .targets
                .iter()
                .map(|t| target_name(t, &ds.labels))
                .collect();
            let path = args
                .coverage
                .clone()
                .unwrap_or_else(|| args.model.join("coverage_per_condition.csv"));
            CoverageRow::write_csv(&rows, &names, &path)?;
            println!(
                "intervals at {:.0} % nominal coverage: {}; per condition: {}",
                EVAL_COVERAGE * 100.0,
                CoverageRow::describe(&rows, &names).join("; "),
                path.display()
            );
        }
    }
    Ok(())
}
