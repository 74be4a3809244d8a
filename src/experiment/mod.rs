//! The paper's three experiments on railforce data (spec learning.md §4): model comparison,
//! generalisation over conditions (with leave-one-condition-out, which the paper never ran),
//! and robustness to noise under both noise protocols. Each writes Markdown and CSV tables,
//! SVG figures and its part of `index.html`, with seeds, data identity, versions and timings.

pub mod paper;

use crate::dataset::{Format, GenerateOptions, generate, noise_column};
use crate::error::{Error, Result};
use crate::features::{DataSet, LabelAt, NoiseProtocol, Split};
use crate::learn::evaluate::{EvalPart, PredictionRow, evaluate};
use crate::learn::metrics::{Metrics, metrics};
use crate::learn::model::{Model, ModelKind};
use crate::learn::train::{EpochLog, Progress, TrainOptions, train};
use crate::learn::windows::{DataSpec, prepare};
use crate::plan::Plan;
use crate::report::svg::{Chart, Series};
use crate::report::table::Table;
use crate::report::{Section, write_index};
use crate::sim::output::PAPER_CHANNELS;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Which experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Which {
    /// Eight models on one condition.
    Comparison,
    /// One CNN-BiLSTM over all conditions, and leave-one-condition-out.
    Generalization,
    /// SNR sweep.
    Robustness,
    /// All three.
    All,
}

/// Settings of a run of experiments.
#[derive(Debug, Clone)]
pub struct ExperimentOptions {
    /// Plan of conditions (simulated once, clean; noise is added per SNR in memory).
    pub plan: PathBuf,
    /// Output folder (data/, one folder per experiment, index.html).
    pub out: PathBuf,
    /// SNR of the comparison and generalisation, dB.
    pub snr_db: f64,
    /// Condition of the comparison and robustness experiments.
    pub condition: String,
    /// Models of the comparison.
    pub models: Vec<ModelKind>,
    /// Models of the robustness sweep.
    pub robustness_models: Vec<ModelKind>,
    /// SNRs of the sweep, dB.
    pub snrs: Vec<f64>,
    /// Conditions held out one at a time (empty: a curve, a tangent and a gradient case).
    pub loco: Vec<String>,
    /// Training settings (networks and classical).
    pub train: TrainOptions,
    /// Simulations in parallel.
    pub jobs: usize,
    /// Label position (the last step: causal, the default; the centre: as the paper reads).
    pub label_at: LabelAt,
    /// Window length, steps (the paper's 20 by default).
    pub window: usize,
    /// Networks trained at an SNR (matched protocol) draw new training-input noise every
    /// epoch instead of learning one fixed realisation (validation and test keep theirs).
    pub fresh_noise: bool,
}

impl ExperimentOptions {
    /// The full protocol of the paper's experiments.
    pub fn full(plan: PathBuf, out: PathBuf) -> Self {
        ExperimentOptions {
            plan,
            out,
            snr_db: 6.0,
            condition: "curve_r400_v60".into(),
            models: ModelKind::ALL.to_vec(),
            robustness_models: vec![
                ModelKind::Gbdt,
                ModelKind::BiLstm,
                ModelKind::Cnn,
                ModelKind::CnnBiLstm,
            ],
            snrs: vec![1000.0, 100.0, 60.0, 40.0, 30.0, 20.0, 10.0, 5.0, 3.0, 1.0],
            loco: Vec::new(),
            train: TrainOptions {
                epochs: 100,
                patience: 10,
                windows_per_epoch: Some(50_000),
                ..TrainOptions::default()
            },
            jobs: 2,
            label_at: LabelAt::Last,
            window: 20,
            fresh_noise: true,
        }
    }
}

/// The columns the experiments keep (inputs, labels, time): the rest of a run is dropped.
fn slim(ds: &DataSet) -> Result<DataSet> {
    let mut keep: Vec<&str> = vec!["time_s", "w1l_force_y", "w1l_force_z"];
    keep.extend(PAPER_CHANNELS.iter().copied());
    let idx = keep
        .iter()
        .map(|n| ds.channel(n))
        .collect::<Result<Vec<_>>>()?;
    Ok(DataSet {
        dir: ds.dir.clone(),
        names: keep.iter().map(|s| s.to_string()).collect(),
        runs: ds
            .runs
            .iter()
            .map(|r| crate::features::Run {
                condition: r.condition.clone(),
                seed: r.seed,
                columns: idx.iter().map(|&i| r.columns[i].clone()).collect(),
            })
            .collect(),
    })
}

/// A copy with `_noisy` inputs at `snr` dB (replacing any), seeded by run seed and channel.
pub fn with_noise(ds: &DataSet, snr: f64) -> DataSet {
    let mut out = ds.clone();
    let base: Vec<usize> = PAPER_CHANNELS
        .iter()
        .filter_map(|c| ds.channel(c).ok())
        .collect();
    let noisy_names: Vec<String> = PAPER_CHANNELS
        .iter()
        .map(|c| format!("{c}_noisy"))
        .collect();
    let keep: Vec<usize> = (0..ds.names.len())
        .filter(|&i| !ds.names[i].ends_with("_noisy"))
        .collect();
    out.names = keep
        .iter()
        .map(|&i| ds.names[i].clone())
        .chain(noisy_names)
        .collect();
    for (r, run) in out.runs.iter_mut().enumerate() {
        let src = &ds.runs[r];
        let mut cols: Vec<Vec<f64>> = keep.iter().map(|&i| src.columns[i].clone()).collect();
        for (k, &c) in base.iter().enumerate() {
            cols.push(noise_column(&src.columns[c], snr, src.seed, k));
        }
        run.columns = cols;
    }
    out
}

fn subset(ds: &DataSet, conditions: &[String]) -> DataSet {
    DataSet {
        dir: ds.dir.clone(),
        names: ds.names.clone(),
        runs: ds
            .runs
            .iter()
            .filter(|r| conditions.contains(&r.condition))
            .cloned()
            .collect(),
    }
}

fn spec(opts: &ExperimentOptions, noise: NoiseProtocol, split: Split) -> DataSpec {
    DataSpec {
        channels: PAPER_CHANNELS.iter().map(|c| c.to_string()).collect(),
        targets: vec!["w1l_force_y".into(), "w1l_force_z".into()],
        window: opts.window,
        label_at: opts.label_at,
        stride: 1,
        split,
        noise,
    }
}

struct Ctx<'a> {
    opts: &'a ExperimentOptions,
    log: &'a mut dyn FnMut(String),
}

impl Ctx<'_> {
    /// Trains `kind`; with the matched protocol at `snr` dB, networks draw fresh training
    /// noise every epoch when the options say so ([`ExperimentOptions::fresh_noise`]).
    fn fit(
        &mut self,
        ds: &DataSet,
        spec: &DataSpec,
        kind: ModelKind,
        dir: &Path,
        snr: Option<f64>,
    ) -> Result<(Model, f64)> {
        let t0 = Instant::now();
        let name = format!("{} → {}", kind.name(), dir.display());
        (self.log)(format!("training {name}"));
        let log = &mut self.log;
        let opts = TrainOptions {
            fresh_noise_snr_db: snr
                .filter(|_| self.opts.fresh_noise && spec.noise == NoiseProtocol::Matched),
            ..self.opts.train.clone()
        };
        let model = train(ds, spec, kind, &opts, dir, &mut |p| {
            if let Progress::Epoch(e) = p
                && (e.epoch % 10 == 0 || e.epoch == 1)
            {
                log(format!(
                    "  epoch {:>3}: val {:.4}, best epoch {}, {:.0} windows/s",
                    e.epoch, e.val_loss, e.best_epoch, e.windows_per_s
                ));
            }
        })?;
        let secs = t0.elapsed().as_secs_f64();
        (self.log)(format!("  done in {secs:.1} s"));
        Ok((model, secs))
    }
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

fn read_log(dir: &Path) -> Vec<EpochLog> {
    crate::io::read_text(&dir.join("train_log.jsonl"))
        .map(|t| {
            t.lines()
                .filter_map(|l| serde_json::from_str(l).ok())
                .collect()
        })
        .unwrap_or_default()
}

/// Runs the experiments; returns the path of `index.html`.
pub fn run(which: Which, opts: &ExperimentOptions, log: &mut dyn FnMut(String)) -> Result<PathBuf> {
    let t0 = Instant::now();
    let plan = Plan::load(&opts.plan)?;
    let data_dir = opts.out.join("data");
    log(format!(
        "simulating {} condition(s) of {} into {} (resumable) …",
        plan.conditions.len(),
        plan.name,
        data_dir.display()
    ));
    let gopts = GenerateOptions {
        out: data_dir.clone(),
        format: Format::Npz,
        jobs: opts.jobs.max(1),
        shard: None,
        snr_db: None,
        settle: 3.0,
    };
    generate(&plan, &gopts, &|_| {})?;
    let ds = slim(&DataSet::load(&data_dir)?)?;
    let manifest_hash = crate::dataset::file_hash(&data_dir.join("manifest.json"))?;
    let mut ctx = Ctx { opts, log };
    let mut sections: Vec<(String, Section)> = Vec::new();
    let mut timings = serde_json::Map::new();
    let conditions: Vec<String> = plan.conditions.iter().map(|c| c.name.clone()).collect();
    if matches!(which, Which::Comparison | Which::Robustness | Which::All)
        && !conditions.contains(&opts.condition)
    {
        return Err(Error::Domain(format!(
            "condition {} is not in the plan {}",
            opts.condition,
            opts.plan.display()
        )));
    }
    for (part, folder) in [
        (Which::Comparison, "comparison"),
        (Which::Generalization, "generalization"),
        (Which::Robustness, "robustness"),
    ] {
        if which != part && which != Which::All {
            continue;
        }
        let ts = Instant::now();
        let sec = match part {
            Which::Comparison => comparison(&mut ctx, &ds)?,
            Which::Generalization => generalization(&mut ctx, &ds, &conditions)?,
            _ => robustness(&mut ctx, &ds)?,
        };
        sec.write_files(&opts.out.join(folder))?;
        sections.push((folder.into(), sec));
        timings.insert(format!("{folder}_s"), json!(ts.elapsed().as_secs_f64()));
    }
    let wall = t0.elapsed().as_secs_f64();
    let meta = json!({
        "plan": opts.plan.display().to_string(),
        "plan_name": plan.name,
        "data_manifest_fnv1a": manifest_hash,
        "runs": ds.runs.len(),
        "snr_db": opts.snr_db,
        "condition": opts.condition,
        "training": opts.train,
        "label_at": format!("{:?}", opts.label_at),
        "window": opts.window,
        "fresh_noise_every_epoch": opts.fresh_noise,
        "railforce_version": env!("CARGO_PKG_VERSION"),
        "wall_seconds": wall,
        "timings": timings,
        "protocol": format!("70/15/15 % contiguous blocks per run (or whole conditions held out), z-scores from training blocks, window {} × 21 channels, FL and FQ as two outputs of one model", opts.window),
    });
    let mj = serde_json::to_string_pretty(&meta).expect("meta serialises");
    crate::io::write_atomic(&opts.out.join("meta.json"), |w| w.write_all(mj.as_bytes()))?;
    let intro = vec![
        format!(
            "railforce {} — plan {} ({} runs, data manifest {}), seed {}, wall time {:.0} s.",
            env!("CARGO_PKG_VERSION"),
            plan.name,
            ds.runs.len(),
            manifest_hash,
            opts.train.seed,
            wall
        ),
        format!(
            "Protocol: each run cut into contiguous 70/15/15 % train/validation/test blocks before windowing (no window crosses a block), z-scores from the training blocks only, windows of {} steps × 21 channels, label at the {} step, FL (w1l_force_y) and FQ (w1l_force_z) as the two outputs of one model. MSE and R² on standardised targets; Var(y_test) shown beside them. Paper numbers come from another simulator and unknown splits: a bar, not a target to match digit for digit.",
            opts.window,
            if opts.label_at == LabelAt::Last {
                "last (causal)"
            } else {
                "centre (non-causal)"
            }
        ),
        format!(
            "Training: Adam lr {}, batch {}, at most {} epochs, early stopping patience {}, {} training windows drawn per epoch{}; classical models on at most {} windows.",
            opts.train.lr,
            opts.train.batch,
            opts.train.epochs,
            opts.train.patience,
            opts.train
                .windows_per_epoch
                .map(|w| w.to_string())
                .unwrap_or("all".into()),
            if opts.fresh_noise {
                "; networks trained at an SNR draw new input noise every epoch (validation and test keep one fixed, seeded realisation)"
            } else {
                "; networks trained on one fixed noise realisation"
            },
            opts.train.classical_rows
        ),
    ];
    write_index(
        &opts.out,
        "railforce: wheel–rail force identification experiments",
        &intro,
        &sections,
    )?;
    Ok(opts.out.join("index.html"))
}

fn comparison(ctx: &mut Ctx, ds: &DataSet) -> Result<Section> {
    let opts = ctx.opts;
    let dsc = with_noise(
        &subset(ds, std::slice::from_ref(&opts.condition)),
        opts.snr_db,
    );
    let sp = spec(opts, NoiseProtocol::Matched, Split::default());
    let dir = opts.out.join("comparison");
    let mut tables: [Table; 2] = std::array::from_fn(|_| {
        Table::new(&[
            "model",
            "train MSE",
            "train R²",
            "test MSE",
            "test R²",
            "Var(y_test)",
            "test RMSE kN",
            "fit s",
            "paper train MSE / R²",
            "paper test MSE / R²",
        ])
    });
    let mut curves = Vec::new();
    let mut traces: Option<Vec<PredictionRow>> = None;
    for &kind in &opts.models {
        let mdir = dir.join("models").join(kind.name());
        let (mut model, secs) = ctx.fit(&dsc, &sp, kind, &mdir, Some(opts.snr_db))?;
        let tr = train_metrics(&mut model, &dsc)?;
        let te = evaluate(&mut model, &dsc, EvalPart::Test)?;
        let paper = paper::COMPARISON
            .iter()
            .find(|(n, _)| *n == kind.name())
            .map(|(_, v)| *v);
        for k in 0..2 {
            let p = paper.map(|v| {
                (
                    format!("{} / {}", v[4 * k], v[4 * k + 1]),
                    format!("{} / {}", v[4 * k + 2], v[4 * k + 3]),
                )
            });
            let (pa, pb) = p.unwrap_or_default();
            let m = &te.metrics[k];
            tables[k].push(vec![
                kind.name().into(),
                f4(tr[k].mse),
                f4(tr[k].r2),
                f4(m.mse),
                f4(m.r2),
                f4(m.var_y),
                format!("{:.2}", m.rmse_kn),
                format!("{secs:.1}"),
                pa,
                pb,
            ]);
        }
        if kind.architecture().is_some() {
            let l = read_log(&mdir);
            curves.push(Series {
                label: kind.name().into(),
                points: l.iter().map(|e| (e.epoch as f64, e.val_loss)).collect(),
            });
        }
        if kind == ModelKind::CnnBiLstm
            || (traces.is_none() && kind == *opts.models.last().expect("models"))
        {
            traces = Some(te.rows.clone());
        }
    }
    let [fl, fq] = tables;
    let mut sec = Section {
        title: format!(
            "1. Model comparison: {} at {} dB (paper Tables 2–3)",
            opts.condition, opts.snr_db
        ),
        text: vec![format!(
            "{} models on {} with every input noised at {} dB, trained and tested on the noisy inputs (matched protocol). Train metrics on up to 20 000 training windows; test metrics on every test window.",
            opts.models.len(),
            opts.condition,
            opts.snr_db
        )],
        tables: vec![
            (
                "Lateral force FL (w1l_force_y)".into(),
                fl,
                "comparison_fl".into(),
            ),
            (
                "Vertical force FQ (w1l_force_z)".into(),
                fq,
                "comparison_fq".into(),
            ),
        ],
        figures: Vec::new(),
    };
    if !curves.is_empty() {
        sec.figures.push((
            "Training curves: validation MSE per epoch".into(),
            Chart {
                title: "Validation loss".into(),
                x_label: "epoch".into(),
                y_label: "MSE (standardised)".into(),
                log_x: false,
                y_range: None,
                series: curves,
            },
            "training_curves.svg".into(),
        ));
    }
    if let Some(rows) = traces {
        let first = rows.first().map(|r| (r.0.clone(), r.1));
        let pts: Vec<&PredictionRow> = rows
            .iter()
            .filter(|r| Some((r.0.clone(), r.1)) == first)
            .take(800)
            .collect();
        for (k, name) in [(0, "FL"), (1, "FQ")] {
            let series = vec![
                Series {
                    label: "true".into(),
                    points: pts.iter().map(|r| (r.2, r.3[k].0 / 1000.0)).collect(),
                },
                Series {
                    label: "identified".into(),
                    points: pts.iter().map(|r| (r.2, r.3[k].1 / 1000.0)).collect(),
                },
            ];
            sec.figures.push((
                format!("{name}: identified against true force on the test block (first 4 s)"),
                Chart {
                    title: format!("{name}, test block"),
                    x_label: "time (s)".into(),
                    y_label: "force (kN)".into(),
                    log_x: false,
                    y_range: None,
                    series,
                },
                format!("trace_{}.svg", name.to_lowercase()),
            ));
        }
    }
    Ok(sec)
}

fn per_condition(rows: &[PredictionRow], model: &Model, condition: &str) -> Vec<(f64, f64, f64)> {
    let ts = &model.meta.target_stats;
    (0..2)
        .map(|k| {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.0 == condition)
                .map(|r| {
                    (
                        (r.3[k].0 - ts.mean[k]) / ts.std[k],
                        (r.3[k].1 - ts.mean[k]) / ts.std[k],
                    )
                })
                .collect();
            let n = pts.len().max(1) as f64;
            let mean = pts.iter().map(|p| p.0).sum::<f64>() / n;
            let sst: f64 = pts.iter().map(|p| (p.0 - mean).powi(2)).sum();
            let sse: f64 = pts.iter().map(|p| (p.0 - p.1).powi(2)).sum();
            (sse / n, 1.0 - sse / sst, sst / n)
        })
        .collect()
}

fn generalization(ctx: &mut Ctx, ds: &DataSet, conditions: &[String]) -> Result<Section> {
    let opts = ctx.opts;
    let dsn = with_noise(ds, opts.snr_db);
    let dir = opts.out.join("generalization");
    let (mut model, secs) = ctx.fit(
        &dsn,
        &spec(opts, NoiseProtocol::Matched, Split::default()),
        ModelKind::CnnBiLstm,
        &dir.join("models/all_conditions"),
        Some(opts.snr_db),
    )?;
    let ev = evaluate(&mut model, &dsn, EvalPart::Test)?;
    let mut t = Table::new(&[
        "condition",
        "FL MSE",
        "FL R²",
        "FQ MSE",
        "FQ R²",
        "Var(FQ_test)",
        "paper FQ MSE / R²",
    ]);
    let (mut fl_pts, mut fq_pts, mut paper_pts) = (Vec::new(), Vec::new(), Vec::new());
    let mut in_dist = std::collections::HashMap::new();
    for (i, c) in conditions.iter().enumerate() {
        let m = per_condition(&ev.rows, &model, c);
        let p = paper::generalization(c);
        t.push(vec![
            c.clone(),
            f4(m[0].0),
            f4(m[0].1),
            f4(m[1].0),
            f4(m[1].1),
            f4(m[1].2),
            p.map(|(a, b)| format!("{a} / {b}")).unwrap_or("—".into()),
        ]);
        fl_pts.push((i as f64 + 1.0, m[0].1));
        fq_pts.push((i as f64 + 1.0, m[1].1));
        if let Some((_, r2)) = p {
            paper_pts.push((i as f64 + 1.0, r2));
        }
        in_dist.insert(c.clone(), (m[0].1, m[1].1));
    }
    let all = &ev.metrics;
    t.push(vec![
        "all (pooled)".into(),
        f4(all[0].mse),
        f4(all[0].r2),
        f4(all[1].mse),
        f4(all[1].r2),
        f4(all[1].var_y),
        "—".into(),
    ]);
    // Leave one condition out.
    let loco: Vec<String> = if opts.loco.is_empty() {
        ["curve_r400_v60", "tangent_v80", "grade20_L50_v60"]
            .iter()
            .map(|s| s.to_string())
            .filter(|c| conditions.contains(c))
            .collect()
    } else {
        opts.loco.clone()
    };
    let mut lt = Table::new(&[
        "held-out condition",
        "validation condition",
        "FL R² unseen",
        "FQ R² unseen",
        "FL R² seen",
        "FQ R² seen",
    ]);
    for c in &loco {
        let pos = conditions.iter().position(|x| x == c).ok_or_else(|| {
            Error::Domain(format!("leave-one-out condition {c} is not in the plan"))
        })?;
        let val = conditions[(pos + 1) % conditions.len()].clone();
        if conditions.len() < 3 {
            return Err(Error::Domain(
                "leave-one-condition-out needs at least three conditions".into(),
            ));
        }
        let sp = spec(
            opts,
            NoiseProtocol::Matched,
            Split::Conditions {
                val: vec![val.clone()],
                test: vec![c.clone()],
            },
        );
        let (mut m, _) = ctx.fit(
            &dsn,
            &sp,
            ModelKind::CnnBiLstm,
            &dir.join(format!("models/without_{c}")),
            Some(opts.snr_db),
        )?;
        let e = evaluate(&mut m, &dsn, EvalPart::Test)?;
        let seen = in_dist.get(c).copied().unwrap_or((f64::NAN, f64::NAN));
        lt.push(vec![
            c.clone(),
            val,
            f4(e.metrics[0].r2),
            f4(e.metrics[1].r2),
            f4(seen.0),
            f4(seen.1),
        ]);
    }
    let series = vec![
        Series {
            label: "FL (ours)".into(),
            points: fl_pts,
        },
        Series {
            label: "FQ (ours)".into(),
            points: fq_pts,
        },
        Series {
            label: "FQ (paper)".into(),
            points: paper_pts,
        },
    ];
    Ok(Section {
        title: "2. Generalisation over conditions (paper Tables 4–5)".into(),
        text: vec![
            format!("One CNN-BiLSTM trained on the training blocks of all {} conditions at {} dB ({secs:.0} s), scored on each condition's test block.", conditions.len(), opts.snr_db),
            "Leave-one-condition-out (not in the paper): the model is trained without the held-out condition (and without the validation condition used for early stopping) and tested on all of the held-out run — transfer to an unseen condition.".into(),
        ],
        tables: vec![
            ("Per-condition test metrics".into(), t, "per_condition".into()),
            ("Leave one condition out".into(), lt, "leave_one_out".into()),
        ],
        figures: vec![(
            "Test R² per condition (numbered in plan order)".into(),
            Chart { title: "R² per condition".into(), x_label: "condition (plan order)".into(), y_label: "test R²".into(), log_x: false, y_range: None, series },
            "r2_per_condition.svg".into(),
        )],
    })
}

fn robustness(ctx: &mut Ctx, ds: &DataSet) -> Result<Section> {
    let opts = ctx.opts;
    let base = subset(ds, std::slice::from_ref(&opts.condition));
    let dir = opts.out.join("robustness");
    let mut t = Table::new(&[
        "protocol",
        "SNR dB",
        "model",
        "FL MSE",
        "FL R²",
        "FQ MSE",
        "FQ R²",
        "paper R² at 1 dB",
    ]);
    let mut charts = Vec::new();
    for (proto, label) in [
        (
            NoiseProtocol::TrainCleanTestNoisy,
            "train clean, test noisy",
        ),
        (NoiseProtocol::Matched, "train and test at the SNR"),
    ] {
        let mut series = Vec::new();
        for &kind in &opts.robustness_models {
            let mut pts = Vec::new();
            let clean_model = if proto == NoiseProtocol::TrainCleanTestNoisy {
                let (mut m, _) = ctx.fit(
                    &base,
                    &spec(opts, NoiseProtocol::Clean, Split::default()),
                    kind,
                    &dir.join(format!("models/clean_{}", kind.name())),
                    None,
                )?;
                m.meta.data.noise = NoiseProtocol::TrainCleanTestNoisy;
                Some(m)
            } else {
                None
            };
            let mut clean_model = clean_model;
            for &snr in &opts.snrs {
                let dsn = with_noise(&base, snr);
                let ev = match clean_model.as_mut() {
                    Some(m) => evaluate(m, &dsn, EvalPart::Test)?,
                    None => {
                        let (mut m, _) = ctx.fit(
                            &dsn,
                            &spec(opts, NoiseProtocol::Matched, Split::default()),
                            kind,
                            &dir.join(format!("models/matched_{}_{snr}dB", kind.name())),
                            Some(snr),
                        )?;
                        evaluate(&mut m, &dsn, EvalPart::Test)?
                    }
                };
                let m = &ev.metrics;
                let paper = if snr == 1.0 && proto == NoiseProtocol::Matched {
                    paper::ROBUSTNESS_1DB
                        .iter()
                        .find(|(n, _)| *n == kind.name())
                        .map(|(_, v)| v.to_string())
                        .unwrap_or_default()
                } else {
                    String::new()
                };
                t.push(vec![
                    label.into(),
                    format!("{snr}"),
                    kind.name().into(),
                    f4(m[0].mse),
                    f4(m[0].r2),
                    f4(m[1].mse),
                    f4(m[1].r2),
                    paper,
                ]);
                pts.push((snr, 0.5 * (m[0].r2 + m[1].r2)));
            }
            series.push(Series {
                label: kind.name().into(),
                points: pts,
            });
        }
        let stem = if proto == NoiseProtocol::Matched {
            "r2_vs_snr_matched.svg"
        } else {
            "r2_vs_snr_train_clean.svg"
        };
        charts.push((
            format!("Mean test R² of FL and FQ against SNR ({label})"),
            Chart {
                title: format!("R² vs SNR: {label}"),
                x_label: "SNR (dB, log scale)".into(),
                y_label: "test R² (mean of FL, FQ)".into(),
                log_x: true,
                y_range: None,
                series,
            },
            stem.to_string(),
        ));
    }
    Ok(Section {
        title: format!("3. Robustness to noise on {} (paper Fig. 8)", opts.condition),
        text: vec![
            "White Gaussian noise per input channel, σ = rms·10^(−SNR/20), seeded; labels never noised. Two protocols: (i) trained on clean inputs, tested on noisy ones; (ii) trained and tested at the same SNR (the paper's reading). The paper's R² at 1 dB is shown beside protocol (ii).".into(),
        ],
        tables: vec![("Test metrics against SNR".into(), t, "robustness".into())],
        figures: charts,
    })
}
