//! The paper's experiments on railforce data (assets/docs/learning.md §4), and two of ours: model
//! comparison, generalisation over conditions (with leave-one-condition-out, which the paper
//! never ran), robustness to noise under both noise protocols, the protocols side by side,
//! on-board sensor selection, wagons the models did not learn (mismatch), and the simulator's
//! form (lumped track against rails on sleepers). Defaults: the plan's seeds split by seed (independent test runs),
//! 6 dB with σ from each channel's standard deviation, window 20 with the centre label, fresh
//! training noise. Each writes Markdown and CSV tables, SVG figures and its part of
//! `index.html`, with seeds, data identity, protocol, noise definition, label position,
//! versions and timings.

mod assessment;
mod comparison;
mod fit;
use fit::{FitJob, earlier};
mod generalization;
mod index;
mod mismatch;
mod model_form;
mod options;
pub use options::ExperimentOptions;
mod paper;
mod protocols;
mod provenance;
use provenance::{cores, cpu_seconds, machine, source_commit, unix_now};
mod robustness;
mod sensors;
mod snapshot;
mod snapshot_merge;
pub use snapshot::{
    HEADLINE_BEGIN, HEADLINE_END, headline_block, quoted_headline, requote, utc_date_time,
    write_snapshot,
};

use crate::dataset::DataSet;
use crate::dataset::{Format, GenerateOptions, generate};
use crate::error::{Error, Result};
use crate::features::{NoiseProtocol, Split};
use crate::learn::metrics::{Metrics, metrics};
use crate::learn::model::Model;
use crate::learn::train::EpochLog;
use crate::learn::windows::{DataRequest, DataSpec, prepare};
use crate::plan::Plan;
use crate::sensors::{Candidates, PAPER_CHANNELS};
pub use index::{VIEW_FOLDER, write_report};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Which experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Which {
    /// Eight models on one condition, one model per target.
    Comparison,
    /// One CNN-BiLSTM over all conditions, and leave-one-condition-out.
    Generalization,
    /// SNR sweep.
    Robustness,
    /// The CNN-BiLSTM under the seed, block, condition and shuffled splits.
    Protocols,
    /// Filter–Wrapper over the on-board candidates against the paper's 21.
    Sensors,
    /// Nominal against fleet-trained models on wagons they did not learn.
    Mismatch,
    /// The CNN-BiLSTM trained on the lumped track and tested on rails on sleepers, and back.
    ModelForm,
    /// The paper's three (comparison, generalisation, robustness): the demo.
    Paper,
    /// All seven.
    All,
}

impl Which {
    /// The experiments this choice runs, in order.
    pub fn parts(self) -> Vec<Which> {
        use Which::*;
        match self {
            All => vec![
                Comparison,
                Generalization,
                Robustness,
                Protocols,
                Sensors,
                Mismatch,
                ModelForm,
            ],
            Paper => vec![Comparison, Generalization, Robustness],
            w => vec![w],
        }
    }

    /// Every experiment's folder, in report order.
    pub const FOLDERS: [&'static str; 7] = [
        "comparison",
        "generalization",
        "robustness",
        "protocols",
        "sensors",
        "mismatch",
        "model_form",
    ];

    fn folder(self) -> &'static str {
        match self {
            Which::Comparison => "comparison",
            Which::Generalization => "generalization",
            Which::Robustness => "robustness",
            Which::Protocols => "protocols",
            Which::Sensors => "sensors",
            Which::Mismatch => "mismatch",
            Which::ModelForm => "model_form",
            _ => "all",
        }
    }
}

/// The results snapshot every run writes into its folder.
pub const RESULTS_FILE: &str = "results.md";

/// Writes the snapshot of the finished run in `out` to `dest` and, with `readme`, replaces
/// the headline table that README quotes; returns `dest`. With `merge`, the parts `out` holds
/// replace theirs in the snapshot already at `dest` and the others stay as they were measured
/// ([`snapshot_merge`]: one part run again after a change that touched its data alone).
pub fn snapshot(out: &Path, dest: &Path, readme: Option<&Path>, merge: bool) -> Result<PathBuf> {
    let written = if merge {
        let old = crate::io::read_text(dest)?;
        let merged = snapshot_merge::merge(&old, &snapshot::render(out, dest)?);
        crate::io::write_atomic(dest, |w| w.write_all(merged.as_bytes()))?;
        dest.to_path_buf()
    } else {
        write_snapshot(out, dest)?
    };
    if let Some(readme) = readme {
        let snap = crate::io::read_text(&written)?;
        let text = crate::io::read_text(readme)?;
        let new = requote(&text, &snap, readme)?;
        crate::io::write_atomic(readme, |w| w.write_all(new.as_bytes()))?;
    }
    Ok(written)
}

/// Shared state of a run of experiments.
struct Ctx<'a> {
    opts: &'a ExperimentOptions,
    log: &'a (dyn Fn(String) + Sync),
    /// All conditions, clean, with the paper's inputs, the labels and time.
    ds: DataSet,
    /// The split every experiment uses unless it studies splits.
    split: Split,
    /// Plan order of the conditions.
    conditions: Vec<String>,
    /// Pooled test metrics of the all-condition CNN-BiLSTM on the paper's 21 at the
    /// experiments' SNR under the default split, once trained (generalisation): the same model
    /// the protocols and sensors experiments would train again, so they reuse it.
    pooled: Option<Vec<Metrics>>,
    /// Models trained (and calibrated) on the nominal data at the experiments' SNR that a later
    /// part reuses: [`PAPER21`] (generalisation) and [`SELECTED`] (sensors), by folder.
    trained: Vec<(&'static str, PathBuf)>,
    /// The on-board selection (union for FL and FQ) once the sensors experiment made it.
    selected: Option<Vec<String>>,
    /// Identity of the data (`data_fnv1a`): a model an earlier run left on the same data may
    /// be reused.
    data_hash: String,
}

/// [`Ctx::trained`]: the all-condition CNN-BiLSTM on the paper's 21.
const PAPER21: &str = "paper21";
/// [`Ctx::trained`]: the all-condition CNN-BiLSTM on the on-board selection.
const SELECTED: &str = "selected";

impl Ctx<'_> {
    /// Data spec of a model over `channels` predicting `targets` on `ds` (the one
    /// [`DataSpec::resolve`]: its noise model is the one `ds` was noised with).
    fn spec(
        &self,
        ds: &DataSet,
        channels: &[String],
        targets: &[String],
        noise: NoiseProtocol,
        split: Split,
    ) -> Result<DataSpec> {
        self.spec_windowed(ds, channels, targets, noise, split, self.opts.window)
    }

    /// [`Self::spec`] with windows of `window` steps.
    fn spec_windowed(
        &self,
        ds: &DataSet,
        channels: &[String],
        targets: &[String],
        noise: NoiseProtocol,
        split: Split,
        window: usize,
    ) -> Result<DataSpec> {
        let req = DataRequest {
            channels: channels.to_vec(),
            targets: targets.join(","),
            window,
            label_at: self.opts.label_at,
            stride: 1,
            split,
            noise: Some(noise),
        };
        DataSpec::resolve(&req, ds)
    }

    /// Simulates `plan` into `dir` (resumable), saying so first.
    fn simulate_runs(&self, plan: &Plan, dir: &Path) -> Result<()> {
        (self.log)(format!(
            "simulating {} runs of {} into {} (resumable) …",
            plan.conditions.iter().map(|c| c.seeds.len()).sum::<usize>(),
            plan.name,
            dir.display()
        ));
        simulate(plan, dir, self.opts.jobs)
    }

    /// The paper's 21 inputs.
    fn paper21() -> Vec<String> {
        PAPER_CHANNELS.iter().map(|c| c.to_string()).collect()
    }

    /// Both labels.
    fn labels(&self) -> Vec<String> {
        self.ds.labels.to_vec()
    }

    /// A copy of `ds` with the inputs of `channels` noised at `snr`.
    fn noisy(&self, ds: &DataSet, snr: f64, channels: &[String]) -> Result<DataSet> {
        ds.with_noise(self.opts.noise(snr), channels)
    }

    /// The protocol paragraph every section carries.
    fn protocol(&self, split: &Split, snr: Option<f64>) -> String {
        self.protocol_windowed(split, snr, self.opts.window)
    }

    /// [`Self::protocol`] for models reading windows of `window` steps.
    fn protocol_windowed(&self, split: &Split, snr: Option<f64>, window: usize) -> String {
        format!(
            "Protocol: {}; z-scores from the training part only; windows of {} steps, label at the {}; noise: {}. MSE and R² on standardised targets, Var(y_test) beside them.",
            split.describe(),
            window,
            self.opts.label_words(),
            snr.map(|s| self.opts.noise(s).describe())
                .unwrap_or_else(|| "none (clean inputs)".into())
        )
    }
}

/// Simulates `plan` (clean, NPZ, 3 s settling) into `dir`, resuming what is there.
fn simulate(plan: &Plan, dir: &Path, jobs: usize) -> Result<()> {
    let gopts = GenerateOptions {
        out: dir.to_path_buf(),
        format: Format::Npz,
        jobs: jobs.max(1),
        shard: None,
        noise: None,
        settle: 3.0,
        stepping: Default::default(),
    };
    generate(plan, &gopts, &|_| {})?;
    Ok(())
}

/// The columns the experiments keep (time, labels, the candidates): the rest is dropped.
fn slim(ds: &DataSet, candidates: Candidates) -> Result<DataSet> {
    let mut keep: Vec<String> = vec!["time_s".into()];
    // The track position: the acceptance statistics are sliding means over distance.
    if ds.channel("s_m").is_ok() {
        keep.push("s_m".into());
    }
    // The weighed mass: no sensor, never a selection candidate, but a model may take it.
    if ds.channel(crate::sensors::VEHICLE_MASS).is_ok() {
        keep.push(crate::sensors::VEHICLE_MASS.into());
    }
    keep.extend(ds.labels.iter().cloned());
    keep.extend(candidates.among(&ds.names, &ds.labels));
    ds.subset(None, Some(&keep))
}

/// Metrics on (at most 20 000 evenly strided) training windows.
fn train_metrics(model: &mut Model, ds: &DataSet) -> Result<Vec<Metrics>> {
    let stats = (
        model.meta.input_stats.clone(),
        model.meta.target_stats.clone(),
    );
    let prep = prepare(ds, &model.meta.data, Some((&stats.0, &stats.1)))?;
    let step = prep.train.len().div_ceil(20_000).max(1);
    let idx: Vec<usize> = (0..prep.train.len()).step_by(step).collect();
    let (mut x, mut y) = (Vec::new(), Vec::new());
    prep.train.gather(&idx, &mut x, &mut y);
    let p = model.predict(&x, idx.len());
    Ok(metrics(&y, &p, &stats.1))
}

fn f4(v: f64) -> String {
    format!("{v:.4}")
}

/// Two runs' figures as `mean ± half range` to `digits` decimals (a spread over two seeds).
fn mean_half_range(u: f64, v: f64, digits: usize) -> String {
    format!(
        "{:.*} ± {:.*}",
        digits,
        0.5 * (u + v),
        digits,
        0.5 * (u - v).abs()
    )
}

fn read_log(dir: &Path) -> Vec<EpochLog> {
    crate::io::read_text(&dir.join("train_log.jsonl"))
        .map(|t| {
            t.lines()
                .filter_map(|l| serde_json::from_str(l).ok())
                .collect()
        })
        .unwrap_or_default()
}

/// Runs the experiments `which` (each expanded by [`Which::parts`], in order, without
/// repeats); returns the path of `index.html`.
pub fn run(
    which: &[Which],
    opts: &ExperimentOptions,
    log: &(dyn Fn(String) + Sync),
) -> Result<PathBuf> {
    let (t0, cpu0) = (Instant::now(), cpu_seconds());
    let plan = Plan::load(&opts.plan)?;
    let data_dir = opts.out.join("data");
    let mut parts: Vec<Which> = Vec::new();
    for p in which.iter().flat_map(|w| w.parts()) {
        if !parts.contains(&p) {
            parts.push(p);
        }
    }
    if parts.contains(&Which::Mismatch) {
        mismatch::fleet_plan(opts, &plan)?;
    }
    log(format!(
        "simulating {} condition(s) of {} into {} (resumable) …",
        plan.conditions.len(),
        plan.name,
        data_dir.display()
    ));
    simulate(&plan, &data_dir, opts.jobs)?;
    let candidates = if parts.contains(&Which::Sensors) || parts.contains(&Which::Mismatch) {
        Candidates::Onboard
    } else {
        Candidates::Paper21
    };
    let ds = slim(&DataSet::load(&data_dir)?, candidates)?;
    let split = opts.split.clone().unwrap_or_else(|| Split::standard(&ds));
    split.check()?;
    if !matches!(split, Split::Seeds { .. }) {
        log(format!(
            "note: the plan has {} seed(s); testing on independent runs needs three or more (split: {})",
            ds.seeds().len(),
            split.describe()
        ));
    }
    let data_hash = crate::dataset::data_identity(&data_dir)?;
    let conditions: Vec<String> = plan.conditions.iter().map(|c| c.name.clone()).collect();
    if parts
        .iter()
        .any(|p| matches!(p, Which::Comparison | Which::Robustness))
        && !conditions.contains(&opts.condition)
    {
        return Err(Error::Domain(format!(
            "condition {} is not in the plan {}",
            opts.condition,
            opts.plan.display()
        )));
    }
    let runs = ds.runs.len();
    let mut ctx = Ctx {
        opts,
        log,
        ds,
        split: split.clone(),
        conditions,
        pooled: None,
        trained: Vec::new(),
        selected: None,
        data_hash: data_hash.clone(),
    };
    let mut timings = serde_json::Map::new();
    let common = json!({
        "plan": opts.plan.display().to_string(),
        "plan_name": plan.name,
        "data_fnv1a": data_hash,
        "runs": runs,
        "snr_db": opts.snr_db,
        "noise": opts.noise(opts.snr_db),
        "noise_definition": opts.noise(opts.snr_db).describe(),
        "split": split,
        "split_description": split.describe(),
        "condition": opts.condition,
        "training": opts.train,
        "condition_windows_per_epoch": opts.condition_windows_per_epoch,
        "label_at": format!("{:?}", opts.label_at),
        "window": opts.window,
        "mismatch_window": opts.mismatch_window,
        "mismatch_members": opts.mismatch_members,
        "fresh_noise_every_epoch": opts.fresh_noise,
        "railforce_version": env!("CARGO_PKG_VERSION"),
        "commit": source_commit(),
        "started_unix": unix_now(),
        "cores": cores(),
        "machine": machine(),
    });
    let mut took: Vec<(&str, f64, Option<f64>)> = Vec::new();
    let cpu_since = |c: Option<f64>| Some(cpu_seconds()? - c?);
    for part in parts.clone() {
        let (ts, cs) = (Instant::now(), cpu_seconds());
        let mut sec = match part {
            Which::Comparison => comparison::run(&mut ctx)?,
            Which::Generalization => generalization::run(&mut ctx)?,
            Which::Robustness => robustness::run(&mut ctx)?,
            Which::Protocols => protocols::run(&mut ctx)?,
            Which::Sensors => sensors::run(&mut ctx)?,
            Which::ModelForm => model_form::run(&mut ctx)?,
            _ => mismatch::run(&mut ctx)?,
        };
        let (secs, cpu) = (ts.elapsed().as_secs_f64(), cpu_since(cs));
        let folder = part.folder();
        // Each part says where it comes from: parts run at different times into one folder
        // keep their own provenance.
        sec.text.insert(
            0,
            format!(
                "railforce {}, plan {} ({} runs, data {}), training seed {}; this part took {:.0} s.",
                env!("CARGO_PKG_VERSION"),
                plan.name,
                runs,
                data_hash,
                opts.train.seed,
                secs
            ),
        );
        sec.write_files(&opts.out.join(folder))?;
        let mut pm = common.clone();
        pm["wall_seconds"] = json!(secs);
        pm["cpu_seconds"] = json!(cpu);
        let pj = serde_json::to_string_pretty(&pm).expect("meta serialises");
        crate::io::write_atomic(&opts.out.join(folder).join("meta.json"), |w| {
            w.write_all(pj.as_bytes())
        })?;
        timings.insert(format!("{folder}_s"), json!(secs));
        took.push((folder, secs, cpu));
    }
    let (wall, cpu) = (t0.elapsed().as_secs_f64(), cpu_since(cpu0));
    log(format!(
        "wall time of each part, and the CPU time its threads used ({} cores):",
        cores()
    ));
    for (folder, secs, cpu) in &took {
        log(format!("  {folder:<15} {}", snapshot::busy(*secs, *cpu)));
    }
    log(format!(
        "  {:<15} {} (simulating the plan's data and the rest)",
        "in all",
        snapshot::busy(wall, cpu)
    ));
    let mut meta = common.clone();
    meta["wall_seconds"] = json!(wall);
    meta["cpu_seconds"] = json!(cpu);
    meta["finished_unix"] = json!(unix_now());
    meta["timings"] = json!(timings);
    let mj = serde_json::to_string_pretty(&meta).expect("meta serialises");
    crate::io::write_atomic(&opts.out.join("meta.json"), |w| w.write_all(mj.as_bytes()))?;
    write_report(&opts.out)?;
    // The snapshot of what this folder holds: only a run of every part is a whole one.
    if parts.len() == Which::FOLDERS.len() {
        write_snapshot(&opts.out, &opts.out.join(RESULTS_FILE))?;
        if let Some(dest) = &opts.results {
            snapshot(&opts.out, dest, opts.readme.as_deref(), false)?;
        }
    }
    Ok(opts.out.join("index.html"))
}
