//! `railforce generate`: data sets per working condition.

use anyhow::Result;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use railforce::dataset::{self, Event, Format, GenerateOptions};
use railforce::plan::Plan;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct GenerateArgs {
    /// Plan file (TOML): vehicle, duration, seeds and [[condition]] tables; a built-in plan by
    /// name: `paper34` (the paper's 34 conditions), `paper34_varied` (the same with a fleet:
    /// every run draws its own wagon and track from the plan's `[vary]`) or `demo`. Required
    /// unless --merge is given.
    #[arg(long, required_unless_present = "merge")]
    plan: Option<PathBuf>,
    /// Output folder (one file per run plus manifest.json).
    #[arg(long)]
    out: PathBuf,
    /// File format: npz (NumPy), parquet (pandas, polars) or csv.
    #[arg(long, default_value = "npz")]
    format: String,
    /// Runs in parallel [default: the number of cores].
    #[arg(long)]
    jobs: Option<usize>,
    /// Only this shard of the plan, `i/N` (1-based), for batch schedulers: runs k with
    /// k mod N = i − 1; writes manifest.shard-i-of-N.json.
    #[arg(long, value_name = "i/N")]
    shard: Option<String>,
    /// Add noised copies (`<channel>_noisy`) of the 21 input channels at this signal-to-noise
    /// ratio, dB: white Gaussian noise with σ = std(clean channel over the run)·10^(−SNR/20).
    #[arg(long, allow_hyphen_values = true)]
    snr_db: Option<f64>,
    /// What the SNR is measured against: `std` (each channel's variation, the default; a
    /// constant offset such as gravity sets no noise level) or `rms` (offset included: a
    /// constant offset raises the noise level).
    #[arg(long, default_value = "std", value_parser = ["std", "rms"])]
    snr_reference: String,
    /// Settling time of each run, s (not written).
    #[arg(long, default_value_t = 3.0)]
    settle: f64,
    /// Integrator of every run (default: linearly-implicit-hertz): `linearly-implicit-hertz`
    /// (the wheel–rail damping and the contact's Hertz spring, each wheelset with its rail
    /// masses, implicit; see `railforce bench step`), `linearly-implicit` (the damping alone),
    /// `semi-implicit` (explicit in every force) or `heun` (second order, explicit, for small
    /// steps). Recorded in the manifest; a data set resumes only with the same choice.
    #[arg(long, value_parser = railforce::sim::Integrator::NAMES)]
    integrator: Option<String>,
    /// Integration step of every run, s (default: the integrator's own, 5/6 ms linearly
    /// implicit Hertz, 0.5 ms linearly implicit, 0.2 ms semi-implicit or Heun).
    #[arg(long)]
    dt: Option<f64>,
    /// Join the shard manifests in --out into manifest.json instead of generating.
    #[arg(long)]
    merge: bool,
}

pub fn run(args: GenerateArgs) -> Result<()> {
    if args.merge {
        let m = dataset::merge(&args.out)?;
        println!(
            "merged {} shard manifests: {} runs in {}",
            m.merged_from.as_ref().map_or(0, |a| a.len()),
            m.runs.len(),
            args.out.join("manifest.json").display()
        );
        return Ok(());
    }
    let plan_path =
        super::builtin::resolve(&args.plan.expect("clap requires --plan without --merge"))?;
    let plan = Plan::load(&plan_path)?;
    let format = Format::parse(&args.format).ok_or_else(|| {
        anyhow::anyhow!("--format must be npz, parquet or csv, got {}", args.format)
    })?;
    let shard = args
        .shard
        .as_deref()
        .map(|s| super::with_flags(dataset::parse_shard(s), "--shard"))
        .transpose()?;
    let jobs = args.jobs.unwrap_or_else(dataset::default_jobs);
    let opts = GenerateOptions {
        out: args.out.clone(),
        format,
        jobs,
        shard,
        noise: match args.snr_db {
            None => None,
            Some(snr) => Some(railforce::sensors::NoiseModel::new(
                snr,
                railforce::sensors::SnrReference::parse(&args.snr_reference).ok_or_else(|| {
                    anyhow::anyhow!("--snr-reference {}: std or rms", args.snr_reference)
                })?,
            )),
        },
        settle: args.settle,
        stepping: railforce::sim::Stepping::chosen(args.integrator.as_deref(), args.dt),
    };
    let t0 = std::time::Instant::now();
    let (manifest, generated, skipped) = with_progress(&plan, &opts)?;
    let runs = manifest.runs.len();
    if generated == 0 && skipped > 0 {
        println!(
            "nothing to do: all {skipped} runs are already in {} with the same settings (delete a run file to redo it)",
            args.out.display()
        );
    } else {
        let dropped = manifest.dropped.len();
        let dropped_text = if dropped > 0 {
            format!(" ({dropped} of them derailed and dropped: the manifest lists where)")
        } else {
            String::new()
        };
        println!(
            "{runs} runs in {} ({} format): {generated} generated{dropped_text}, {skipped} skipped (already done), {:.1} s with {jobs} jobs; manifest: {}",
            args.out.display(),
            format.ext(),
            t0.elapsed().as_secs_f64(),
            dataset::manifest_path(&opts).display()
        );
    }
    Ok(())
}

/// Generates `plan` with a progress bar on a terminal, or one plain line per run in a log
/// (Slurm, nohup, CI) with the count, elapsed time and an estimate of what is left. Returns
/// the manifest and how many runs were generated and skipped.
pub(super) fn with_progress(
    plan: &Plan,
    opts: &GenerateOptions,
) -> Result<(dataset::Manifest, usize, usize)> {
    let shard = opts.shard;
    let total = dataset::runs(plan)
        .iter()
        .filter(|r| shard.is_none_or(|(i, n)| r.index % n == i - 1))
        .count();
    let bar = ProgressBar::new(total as u64);
    bar.set_style(
        ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} runs, eta {eta} {msg}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_prefix(format!("generating {}", plan.name));
    let t0 = std::time::Instant::now();
    // On a terminal a progress bar; in a log (Slurm, nohup, CI) one plain line per run with
    // the count, elapsed time and an estimate of what is left.
    let tty = std::io::IsTerminal::is_terminal(&std::io::stderr());
    let state = std::sync::Mutex::new((Vec::<String>::new(), 0usize, 0usize));
    let on_event = |e: Event| {
        let mut st = state.lock().expect("lock");
        let line = match e {
            Event::Started(f) => {
                st.0.push(f);
                None
            }
            Event::Skipped(f) => {
                st.2 += 1;
                Some(format!("skip {f} (already done)"))
            }
            Event::Finished(f, wall) => {
                st.0.retain(|x| *x != f);
                st.1 += 1;
                Some(format!("done {f} in {wall:.1} s"))
            }
            Event::Dropped(f, why) => {
                st.0.retain(|x| *x != f);
                st.1 += 1;
                Some(format!("dropped {f}: {why}"))
            }
        };
        let Some(line) = line else {
            bar.set_message(st.0.join(" "));
            return;
        };
        if tty {
            bar.println(line);
            bar.inc(1);
            bar.set_message(st.0.join(" "));
        } else {
            let (done, elapsed) = (st.1 + st.2, t0.elapsed().as_secs_f64());
            let eta = if st.1 > 0 {
                format!(
                    ", about {:.0} s left",
                    elapsed / st.1 as f64 * (total - done) as f64
                )
            } else {
                String::new()
            };
            eprintln!("[{done}/{total}] {line} ({elapsed:.0} s{eta})");
        }
    };
    if !tty {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let result = dataset::generate(plan, opts, &on_event);
    bar.finish_and_clear();
    let manifest = result?;
    let (_, generated, skipped) = *state.lock().expect("lock");
    Ok((manifest, generated, skipped))
}
