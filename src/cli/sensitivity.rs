//! `railforce sensitivity`: what the labels depend on.

use anyhow::Result;
use clap::Args;
use railforce::dataset::{self, Format, GenerateOptions};
use railforce::plan::Plan;
use railforce::sensitivity::{Estimates, Method, Study};
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct SensitivityArgs {
    /// Estimates file: each estimated parameter of the vehicle and track files with its range
    /// (`uniform = [lo, hi]`, `scale = true` for a factor) and the `source` of that range.
    #[arg(long, default_value = "vehicles/c80.estimates.toml")]
    estimates: PathBuf,
    /// Base plan: the conditions the study copies (built in: `sensitivity`, a tangent at
    /// 80 km/h, R 400 m at 60 km/h and the 20 ‰ grade in its train, 30 s each, one seed).
    #[arg(long, default_value = "tracks/sensitivity.plan.toml")]
    plan: PathBuf,
    /// `morris` (screening: every estimate, r·(k + 1) + 1 runs per condition, the nominal one
    /// included) or `sobol` (first and total indices of a few estimates, N·(k + 2) + 1 runs per
    /// condition, the nominal one included).
    #[arg(long, default_value = "morris", value_parser = ["morris", "sobol"])]
    method: String,
    /// Morris trajectories (r).
    #[arg(long, default_value_t = 10)]
    trajectories: usize,
    /// Sobol base rows (N).
    #[arg(long, default_value_t = 64)]
    rows: usize,
    /// Sobol: the estimates to sample, comma separated keys [default: the --top best ranked
    /// by the Morris screening already in --out].
    #[arg(long, value_delimiter = ',')]
    parameters: Vec<String>,
    /// Sobol: how many of the screening's best to sample when --parameters is not given.
    #[arg(long, default_value_t = 5)]
    top: usize,
    /// A trained model (`railforce train`'s folder) whose identification R² on each run
    /// (clean inputs, FL and FQ) becomes two more outputs: how far each estimate moves what
    /// the model can identify.
    #[arg(long)]
    model: Option<PathBuf>,
    /// Seed of the design (the same seed, the same points and the same bytes).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output folder: `<method>/data` (the runs), `<method>/` (tables, tornado charts) and
    /// index.html.
    #[arg(long, default_value = "sensitivity")]
    out: PathBuf,
    /// Runs in parallel [default: the number of cores].
    #[arg(long)]
    jobs: Option<usize>,
    /// Only this shard of the study's runs, `i/N`, for batch schedulers; then run once with
    /// --merge to join the shards and write the report.
    #[arg(long, value_name = "i/N")]
    shard: Option<String>,
    /// Join the shard manifests of the study's runs and write the report.
    #[arg(long)]
    merge: bool,
    /// Settling time of each run, s (not written).
    #[arg(long, default_value_t = 3.0)]
    settle: f64,
}

pub fn run(args: SensitivityArgs) -> Result<()> {
    let plan = Plan::load(&super::builtin::resolve(&args.plan)?)?;
    let estimates = Estimates::load(&super::builtin::resolve(&args.estimates)?)?;
    let method = match args.method.as_str() {
        "sobol" => {
            let keys = if args.parameters.is_empty() {
                super::with_flags(
                    railforce::sensitivity::top_of_screening(&args.out, args.top),
                    "--out, --top (or name them with --parameters)",
                )?
            } else {
                args.parameters.clone()
            };
            let parameters = keys
                .iter()
                .map(|k| super::with_flags(estimates.index_of(k), "--parameters"))
                .collect::<Result<Vec<_>>>()?;
            Method::Sobol {
                rows: args.rows,
                parameters,
            }
        }
        _ => Method::Morris {
            trajectories: args.trajectories,
        },
    };
    let mut study = Study::new(plan, estimates, method, args.seed)?;
    study.model = args.model.clone();
    let data = args.out.join(study.method.folder()).join("data");
    let runs = dataset::runs(&study.plan).len();
    if args.merge {
        dataset::merge(&data)?;
    } else {
        let shard = args
            .shard
            .as_deref()
            .map(|s| super::with_flags(dataset::parse_shard(s), "--shard"))
            .transpose()?;
        let opts = GenerateOptions {
            out: data.clone(),
            format: Format::Npz,
            jobs: args.jobs.unwrap_or_else(dataset::default_jobs),
            shard,
            noise: None,
            settle: args.settle,
            stepping: railforce::sim::Stepping::chosen(None, None),
        };
        eprintln!(
            "{}: {runs} runs ({} estimates, {} condition(s)) into {}",
            study.plan.name,
            study.sampled().len(),
            study.base.conditions.len(),
            data.display()
        );
        let (_, generated, skipped) = super::generate::with_progress(&study.plan, &opts)?;
        eprintln!("{generated} generated, {skipped} already done");
        if let Some((i, n)) = shard {
            println!(
                "shard {i}/{n} done; when every shard is, join them and write the report: railforce sensitivity … --merge (the same options, without --shard)"
            );
            return Ok(());
        }
    }
    let results = study.analyse(&data)?;
    railforce::sensitivity::write(&study, &results, &args.out)?;
    let sampled = study.sampled();
    for r in &results {
        println!("{}: most influential", r.condition);
        for (p, score) in r.ranking().iter().take(5) {
            println!(
                "  {:<50} {:>5.0} % of the label's std ({})",
                sampled[*p].variation.key,
                score,
                sampled[*p].describe_range()
            );
        }
    }
    println!("report: {}", args.out.join("index.html").display());
    Ok(())
}
