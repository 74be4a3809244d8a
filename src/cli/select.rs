//! `railforce select`: mutual-information filter, then wrapper, on a data set.

use anyhow::Result;
use clap::Args;
use railforce::dataset::DataSet;
use railforce::features::{self, LabelAt, SelectOptions, Split};
use railforce::sensors::Candidates;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct SelectArgs {
    /// Data set folder (written by `railforce generate`).
    #[arg(long)]
    data: PathBuf,
    /// Target: FL (lateral force on wheel 1L), FQ (vertical) or a channel name.
    #[arg(long, default_value = "FQ")]
    target: String,
    /// Drop channels whose mutual information with the target is below this, nats.
    #[arg(long, default_value_t = 0.01)]
    mi_threshold: f64,
    /// Stop the wrapper when the best validation-R² gain is below this.
    #[arg(long, default_value_t = 0.002)]
    tolerance: f64,
    /// Select among the `_noisy` copies of the candidates. The data set must be noised
    /// (generate --snr-db); copies it lacks (the on-board candidates: generate noises the
    /// paper's 21) are drawn in memory with its noise model.
    #[arg(long)]
    noisy: bool,
    /// Window length, steps.
    #[arg(long, default_value_t = 20)]
    window: usize,
    /// Where a window's label sits: `centre` (the paper's, the default) or `last` (causal);
    /// `train` with this selection uses the same.
    #[arg(long, default_value = "centre", value_parser = LabelAt::NAMES)]
    label: String,
    /// The former spelling of `--label centre`.
    #[arg(long, hide = true, conflicts_with = "label")]
    centre_label: bool,
    /// The signals to choose from: `paper21` (the paper's 21) or `onboard` (every on-board
    /// measurable signal: body accelerations, angular rates, track-relative displacements
    /// and angles, suspension deflections).
    #[arg(long, default_value = "paper21", value_parser = ["paper21", "onboard"])]
    candidates: String,
    /// Rows the mutual-information estimator sees at most (evenly strided over the
    /// training runs).
    #[arg(long, default_value_t = 50_000)]
    mi_samples: usize,
    /// Where to write the selection (channels and z-score statistics).
    #[arg(long, default_value = "selection.json")]
    out: PathBuf,
}

pub fn run(args: SelectArgs) -> Result<()> {
    let t0 = std::time::Instant::now();
    let mut ds = DataSet::load(&args.data)?;
    let candidates = Candidates::parse(&args.candidates).unwrap_or(Candidates::Paper21);
    if args.noisy {
        let wanted = candidates.among(&ds.names, &ds.labels);
        let noise = ds.noise;
        ds = super::train::with_noisy_copies(ds, &wanted, noise)?;
    }
    let opts = SelectOptions {
        target: args.target.clone(),
        noisy: args.noisy,
        mi_threshold: args.mi_threshold,
        tolerance: args.tolerance,
        window: args.window,
        label_at: if args.centre_label {
            LabelAt::Centre
        } else {
            LabelAt::parse(&args.label)?
        },
        candidates,
        mi_samples: args.mi_samples,
        ..SelectOptions::default()
    };
    let split = Split::standard(&ds);
    let sel = features::select(&ds, &split, &opts)?;
    println!(
        "target {} ({}), {} runs, {} candidates, split {}, window {}, MI on at most {} training rows:",
        args.target,
        sel.target,
        ds.runs.len(),
        sel.table.len(),
        split.describe(),
        sel.window,
        opts.mi_samples
    );
    println!(
        "  {:<22} {:>8} {:>13} {:>5}",
        "channel", "MI nats", "wrapper gain", "kept"
    );
    for r in &sel.table {
        println!(
            "  {:<22} {:>8.4} {:>13} {:>5}",
            r.channel,
            r.mi,
            r.wrapper_gain
                .map(|g| format!("{g:+.4}"))
                .unwrap_or_else(|| "filtered".into()),
            if r.kept { "yes" } else { "" }
        );
    }
    railforce::io::check_json_finite(&sel, &args.out)?;
    railforce::io::write_atomic(&args.out, |w| {
        serde_json::to_writer_pretty(&mut *w, &sel).map_err(std::io::Error::other)?;
        w.write_all(b"\n")
    })?;
    println!(
        "kept {} of {} channels; wrote {} in {:.1} s",
        sel.channels.len(),
        sel.table.len(),
        args.out.display(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}
