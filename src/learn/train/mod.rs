//! Training: networks by minibatch Adam on MSE with early stopping on the validation loss
//! (best weights restored), checkpoints every epoch that `--resume` continues from, and a JSON
//! lines log; classical models fitted once on (a strided subsample of) the training windows.

use super::classical::{Classical, ClassicalParams};
pub use super::gradient::{GradientEngine, Stepper};
use super::metrics::metrics;
use super::model::{Engine, Model, ModelKind, ModelMeta, read_weights, write_weights};
use super::neural::{Adam, NetConfig, Network};
use super::windows::{DataSpec, NoiseRefresher, WindowSet, prepare};
use crate::dataset::DataSet;
use crate::error::{Error, Result};
use crate::features::NoiseProtocol;
use rand::RngExt;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::path::Path;
use std::time::Instant;

mod options;
pub use options::{DEFAULT_QUANTILE_HEADS, TrainOptions};

/// One line of `train_log.jsonl`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EpochLog {
    /// Epoch (1-based).
    pub epoch: usize,
    /// Mean training loss (standardised MSE, dropout on).
    pub train_loss: f64,
    /// Validation MSE (standardised, mean over outputs).
    pub val_loss: f64,
    /// Validation R² per output.
    pub val_r2: Vec<f64>,
    /// Training windows per second this epoch.
    pub windows_per_s: f64,
    /// Wall time of the epoch, s.
    pub seconds: f64,
    /// Best epoch so far.
    pub best_epoch: usize,
    /// Learning rate of the epoch.
    #[serde(default)]
    pub lr: f32,
}

/// What the trainer reports while it works.
#[derive(Debug, Clone)]
pub enum Progress {
    /// Minibatch `done` of `total` in `epoch`.
    Batch {
        /// Epoch (1-based).
        epoch: usize,
        /// Batches done.
        done: usize,
        /// Batches this epoch.
        total: usize,
    },
    /// An epoch finished.
    Epoch(EpochLog),
    /// A classical fit advanced (trees or outputs).
    Fit {
        /// Units done.
        done: usize,
        /// Units in all.
        total: usize,
    },
}

#[derive(Debug, Clone, Serialize, Deserialize)]
struct Checkpoint {
    epoch: usize,
    best_val: f64,
    best_epoch: usize,
    bad_epochs: usize,
    adam_t: u64,
    fingerprint: String,
    /// Learning-rate halvings so far (reduce-on-plateau).
    #[serde(default)]
    lr_halvings: u32,
}

/// Trains `kind` on `ds` and writes the model directory `out`.
///
/// ```no_run
/// use railforce::dataset::DataSet;
/// use railforce::features::{LabelAt, Split};
/// use railforce::learn::model::ModelKind;
/// use railforce::learn::train::{TrainOptions, train};
/// use railforce::learn::windows::{DataRequest, DataSpec};
/// let ds = DataSet::load("data/demo".as_ref())?; // written by `railforce generate`
/// let req = DataRequest {
///     channels: railforce::sensors::PAPER_CHANNELS.iter().map(|c| c.to_string()).collect(),
///     targets: "both".into(),
///     window: 20,
///     label_at: LabelAt::Centre,
///     stride: 1,
///     split: Split::standard(&ds),
///     noise: None,
/// };
/// let spec = DataSpec::resolve(&req, &ds)?;
/// let opts = TrainOptions::default();
/// let model = train(&ds, &spec, ModelKind::CnnBiLstm, &opts, "models/demo".as_ref(), &mut |_| {})?;
/// # Ok::<(), railforce::Error>(())
/// ```
pub fn train(
    ds: &DataSet,
    spec: &DataSpec,
    kind: ModelKind,
    opts: &TrainOptions,
    out: &Path,
    progress: &mut dyn FnMut(Progress),
) -> Result<Model> {
    if opts.batch == 0
        || opts.epochs == 0
        || opts.lr.is_nan()
        || opts.lr <= 0.0
        || !(0.0..1.0).contains(&opts.dropout)
    {
        return Err(Error::Domain(
            "batch and epochs must be ≥ 1, lr > 0 and 0 ≤ dropout < 1".into(),
        ));
    }
    if opts.val_windows == Some(0) || opts.windows_per_epoch == Some(0) {
        return Err(Error::Domain(
            "validation windows and training windows per epoch must be ≥ 1 when given".into(),
        ));
    }
    if let Some(a) = kind.architecture()
        && spec.window < a.min_window()
    {
        return Err(Error::Domain(format!(
            "a window of {} step(s) is too short for a {}: its convolutional stem reads at least {}",
            spec.window,
            a.name(),
            a.min_window()
        )));
    }
    let t0 = Instant::now();
    let mut prep = prepare(ds, spec, None)?;
    if let Some(cap) = opts.val_windows {
        let step = prep.val.len().div_ceil(cap.max(1)).max(1);
        prep.val.windows = prep.val.windows.iter().step_by(step).copied().collect();
    }
    if prep.train.is_empty() || prep.val.is_empty() {
        return Err(Error::Domain(format!(
            "the split leaves {} training and {} validation windows: need both",
            prep.train.len(),
            prep.val.len()
        )));
    }
    let refresher = match &opts.fresh_noise {
        Some(noise) if kind.architecture().is_some() => {
            if spec.noise != NoiseProtocol::Matched {
                return Err(Error::Domain(format!(
                    "fresh noise every epoch needs the matched noise protocol (train and test at the same SNR), not {:?}",
                    spec.noise
                )));
            }
            Some(NoiseRefresher::new(ds, spec, &prep.input_stats, noise)?)
        }
        _ => None,
    };
    let identity = json!({
        "folder": ds.dir.display().to_string(),
        "data_fnv1a": crate::dataset::data_identity(&ds.dir).ok(),
        "runs": ds.runs.len(),
        "seeds": ds.runs.iter().map(|r| r.seed).collect::<std::collections::BTreeSet<_>>(),
        "conditions": ds.runs.iter().map(|r| r.condition.clone()).collect::<std::collections::BTreeSet<_>>(),
        "snr_db": ds.snr_db(),
        "split": spec.split.describe(),
    });
    std::fs::create_dir_all(out).map_err(|e| Error::io(out, e))?;
    let mut meta = ModelMeta {
        kind,
        data: DataSpec {
            // The noise the model met: the data set's (noisy columns) or the fresh draws.
            noise_model: spec.noise_model.or(match spec.noise {
                NoiseProtocol::Clean => None,
                _ => opts.fresh_noise.or(ds.noise),
            }),
            ..spec.clone()
        },
        input_stats: prep.input_stats.clone(),
        target_stats: prep.target_stats.clone(),
        net: None,
        slots: None,
        data_identity: identity,
        training: json!({}),
        version: env!("CARGO_PKG_VERSION").to_string(),
        members: 1,
        calibration: None,
    };
    let heads = opts.heads_for(kind, 1);
    let engine = match kind.architecture() {
        Some(architecture) => {
            let config = NetConfig {
                architecture,
                window: spec.window,
                channels: spec.channels.len(),
                outputs: spec.targets.len() * if heads.is_some() { 3 } else { 1 },
                quantiles: heads,
                dropout: opts.dropout,
                seed: opts.seed,
            };
            let job = NetJob {
                config: config.clone(),
                train: &prep.train,
                refresher: refresher.as_ref(),
                val: &prep.val,
                opts,
                out,
                meta: &meta,
            };
            let (net, summary) = train_network(&job, progress)?;
            meta.slots = Some(net.params.slots.clone());
            meta.net = Some(config);
            meta.training = summary;
            Engine::Net(Box::new(net))
        }
        None => {
            let params = match kind {
                ModelKind::Svr => ClassicalParams::svr(),
                ModelKind::Gbdt => ClassicalParams::gbdt(),
                ModelKind::Xgboost => ClassicalParams::xgboost(),
                _ => ClassicalParams::tree(),
            };
            let step = prep.train.len().div_ceil(opts.classical_rows.max(1)).max(1);
            let idx: Vec<usize> = (0..prep.train.len()).step_by(step).collect();
            let (mut x, mut y) = (Vec::new(), Vec::new());
            prep.train.gather(&idx, &mut x, &mut y);
            let tf = Instant::now();
            let model = Classical::fit(
                params,
                &x,
                prep.train.features(),
                &y,
                prep.train.outputs,
                &mut |done, total| progress(Progress::Fit { done, total }),
            );
            let fit_s = tf.elapsed().as_secs_f64();
            let (vx, vy) = prep.val.all();
            let vp = model.predict(&vx, prep.val.len());
            let vm = metrics(&vy, &vp, &prep.target_stats);
            meta.training = json!({
                "params": params,
                "fitted_rows": model.fitted_rows,
                "training_windows": prep.train.len(),
                "features": prep.train.features(),
                "fit_seconds": fit_s,
                "val_loss": vm.iter().map(|m| m.mse).sum::<f64>() / vm.len() as f64,
                "val_r2": vm.iter().map(|m| m.r2).collect::<Vec<_>>(),
            });
            Engine::Classical(Box::new(model))
        }
    };
    let is_net = kind.architecture().is_some();
    if let Some(obj) = meta.training.as_object_mut() {
        obj.insert("wall_seconds".into(), json!(t0.elapsed().as_secs_f64()));
        // The settings that applied: a tree has no epochs, batch or learning rate.
        let settings = if is_net {
            serde_json::to_value(opts).expect("options serialise")
        } else {
            json!({ "classical_rows": opts.classical_rows, "seed": opts.seed })
        };
        obj.insert("options".into(), settings);
    }
    let model = Model {
        meta,
        engine,
        members: Vec::new(),
    };
    model.save(out)?;
    Ok(model)
}

/// What one network training needs.
struct NetJob<'a> {
    config: NetConfig,
    train: &'a WindowSet,
    refresher: Option<&'a NoiseRefresher>,
    val: &'a WindowSet,
    opts: &'a TrainOptions,
    out: &'a Path,
    meta: &'a ModelMeta,
}

/// Where a network's training stands: weights, optimiser, the best weights so far, the
/// early-stopping counters and the epoch log — exactly what a checkpoint holds.
struct Trainer {
    net: Network,
    stepper: Stepper,
    adam: Adam,
    best: Vec<f32>,
    best_val: f64,
    best_epoch: usize,
    bad: usize,
    start: usize,
    log: Vec<EpochLog>,
    /// The learning rate's halvings so far, and the rate it started at.
    lr_halvings: u32,
    lr0: f32,
}

impl Trainer {
    fn new(config: &NetConfig, opts: &TrainOptions) -> Result<Self> {
        let net = Network::new(config.clone());
        let stepper = Stepper::new(opts.engine, config)?;
        let adam = Adam::new(net.params.value.len(), opts.lr);
        let best = net.params.value.clone();
        Ok(Trainer {
            net,
            stepper,
            adam,
            best,
            best_val: f64::INFINITY,
            best_epoch: 0,
            bad: 0,
            start: 0,
            log: Vec::new(),
            lr_halvings: 0,
            lr0: opts.lr,
        })
    }

    /// Identifies the model, data and settings a checkpoint belongs to.
    fn fingerprint(job: &NetJob) -> String {
        let opts = job.opts;
        let mut key = serde_json::to_string(&(
            &job.config,
            &job.meta.data,
            &job.meta.data_identity,
            opts.batch,
            opts.lr,
            opts.windows_per_epoch,
            opts.fresh_noise,
        ))
        .expect("serialises");
        // A constant rate keeps the key it had before the schedule existed.
        if opts.lr_plateau > 0 {
            key.push_str(&format!(" lr_plateau {}", opts.lr_plateau));
        }
        crate::dataset::fnv1a(key.as_bytes())
    }

    /// Continues from the checkpoint in `out` (refused if it belongs to something else).
    fn resume(&mut self, out: &Path, fingerprint: &str) -> Result<()> {
        let ck_path = out.join("checkpoint.json");
        let ck: Checkpoint = crate::io::read_json(&ck_path)?;
        if ck.fingerprint != fingerprint {
            return Err(Error::config(
                &ck_path,
                "fingerprint",
                "the checkpoint belongs to another model, data set or setting; train anew (not resuming) or into another folder",
            ));
        }
        self.net.params.value = read_weights(&out.join("checkpoint_weights.bin"))?;
        self.best = read_weights(&out.join("checkpoint_best.bin"))?;
        let mv = read_weights(&out.join("checkpoint_adam.bin"))?;
        let n = self.net.params.value.len();
        if self.best.len() != n || mv.len() != 2 * n {
            return Err(Error::config(
                &ck_path,
                "weights",
                "checkpoint files do not match the network",
            ));
        }
        self.adam.m = mv[..n].to_vec();
        self.adam.v = mv[n..].to_vec();
        self.adam.t = ck.adam_t;
        (self.best_val, self.best_epoch, self.bad, self.start) =
            (ck.best_val, ck.best_epoch, ck.bad_epochs, ck.epoch);
        self.set_halvings(ck.lr_halvings);
        self.log = crate::io::read_text(&out.join("train_log.jsonl"))?
            .lines()
            .filter_map(|l| serde_json::from_str::<EpochLog>(l).ok())
            .filter(|e| e.epoch <= self.start)
            .collect();
        Ok(())
    }

    /// One pass over this epoch's shuffled (and capped) training windows, with fresh input
    /// noise where asked; returns the mean training loss and the number of windows.
    fn epoch(
        &mut self,
        epoch: usize,
        job: &NetJob,
        buffers: &mut (Vec<f32>, Vec<f32>, Vec<f32>),
        progress: &mut dyn FnMut(Progress),
    ) -> Result<(f64, usize)> {
        let opts = job.opts;
        let batch = opts.batch;
        let mut order: Vec<usize> = (0..job.train.len()).collect();
        let mut rng =
            ChaCha8Rng::seed_from_u64(opts.seed.wrapping_mul(1_000_003).wrapping_add(epoch as u64));
        for i in (1..order.len()).rev() {
            let j = rng.random_range(0..=i);
            order.swap(i, j);
        }
        if let Some(cap) = opts.windows_per_epoch {
            order.truncate(cap.max(batch));
        }
        self.net
            .reseed_dropout(opts.seed ^ (epoch as u64).wrapping_mul(0x9E37_79B9));
        let fresh = job.refresher.map(|r| {
            job.train
                .with_inputs(r.draw(opts.seed.wrapping_mul(7_919).wrapping_add(epoch as u64)))
        });
        let train = fresh.as_ref().unwrap_or(job.train);
        let (x, y, dout) = buffers;
        let batches = order.len().div_ceil(batch);
        let mut loss_sum = 0.0f64;
        for (bi, chunk) in order.chunks(batch).enumerate() {
            train.gather(chunk, x, y);
            let l = self.stepper.step(&mut self.net, x, y, chunk.len(), dout)?;
            if !l.is_finite() {
                return Err(Error::Domain(format!(
                    "training diverged at epoch {epoch}, batch {} (loss {l}); lower the learning rate",
                    bi + 1
                )));
            }
            loss_sum += l * chunk.len() as f64;
            self.adam.step(&mut self.net.params);
            if bi % 16 == 0 || bi + 1 == batches {
                progress(Progress::Batch {
                    epoch,
                    done: bi + 1,
                    total: batches,
                });
            }
        }
        Ok((loss_sum / order.len() as f64, order.len()))
    }

    /// Validation loss and R² per output; keeps the best weights and counts the epochs
    /// without improvement (early stopping).
    fn validate(
        &mut self,
        epoch: usize,
        job: &NetJob,
        vx: &[f32],
        vy: &[f32],
    ) -> Result<(f64, Vec<f64>)> {
        let vp = self.net.predict(vx, job.val.len());
        let vm = metrics(vy, &vp, &job.meta.target_stats);
        let val_loss = vm.iter().map(|m| m.mse).sum::<f64>() / vm.len() as f64;
        if !val_loss.is_finite() {
            return Err(Error::Domain(format!(
                "validation loss is {val_loss} at epoch {epoch}; lower the learning rate"
            )));
        }
        if val_loss < self.best_val {
            self.best_val = val_loss;
            self.best_epoch = epoch;
            self.best.clone_from(&self.net.params.value);
            self.bad = 0;
        } else {
            self.bad += 1;
            let plateau = job.opts.lr_plateau;
            if plateau > 0 && self.bad.is_multiple_of(plateau) {
                self.set_halvings(self.lr_halvings + 1);
            }
        }
        Ok((val_loss, vm.iter().map(|m| m.r2).collect()))
    }

    /// The learning rate after `n` halvings of the starting one.
    fn set_halvings(&mut self, n: u32) {
        self.lr_halvings = n;
        self.adam.lr = self.lr0 * 0.5f32.powi(n as i32);
    }

    /// Checkpoint: weights, best weights, Adam moments, counters, log.
    fn checkpoint(&self, out: &Path, epoch: usize, fingerprint: &str) -> Result<()> {
        write_weights(&out.join("checkpoint_weights.bin"), &self.net.params.value)?;
        write_weights(&out.join("checkpoint_best.bin"), &self.best)?;
        let mut mv = self.adam.m.clone();
        mv.extend_from_slice(&self.adam.v);
        write_weights(&out.join("checkpoint_adam.bin"), &mv)?;
        let log_path = out.join("train_log.jsonl");
        let lines: String = self
            .log
            .iter()
            .map(|e| crate::io::to_json(e, &log_path).map(|l| l + "\n"))
            .collect::<Result<_>>()?;
        crate::io::write_atomic(&out.join("train_log.jsonl"), |w| {
            w.write_all(lines.as_bytes())
        })?;
        let ck = Checkpoint {
            epoch,
            best_val: self.best_val,
            best_epoch: self.best_epoch,
            bad_epochs: self.bad,
            adam_t: self.adam.t,
            fingerprint: fingerprint.to_string(),
            lr_halvings: self.lr_halvings,
        };
        let ckj = crate::io::to_json_pretty(&ck, &out.join("checkpoint.json"))?;
        crate::io::write_atomic(&out.join("checkpoint.json"), |w| {
            w.write_all(ckj.as_bytes())
        })
    }
}

/// Trains a network: resume if asked, then epochs (train, validate, checkpoint) until the
/// epoch limit or early stopping; the best weights are restored.
fn train_network(
    job: &NetJob,
    progress: &mut dyn FnMut(Progress),
) -> Result<(Network, serde_json::Value)> {
    let opts = job.opts;
    let mut t = Trainer::new(&job.config, opts)?;
    let fingerprint = Trainer::fingerprint(job);
    if opts.resume && job.out.join("checkpoint.json").exists() {
        t.resume(job.out, &fingerprint)?;
    }
    let mut buffers = (Vec::new(), Vec::new(), Vec::new());
    let (vx, vy) = job.val.all();
    let mut stopped_early = false;
    for epoch in t.start + 1..=opts.epochs {
        if t.bad >= opts.patience {
            stopped_early = true;
            break;
        }
        let te = Instant::now();
        let lr = t.adam.lr;
        let (train_loss, windows) = t.epoch(epoch, job, &mut buffers, progress)?;
        let train_s = te.elapsed().as_secs_f64();
        let (val_loss, val_r2) = t.validate(epoch, job, &vx, &vy)?;
        let entry = EpochLog {
            epoch,
            train_loss,
            val_loss,
            val_r2,
            windows_per_s: windows as f64 / train_s,
            seconds: te.elapsed().as_secs_f64(),
            best_epoch: t.best_epoch,
            lr,
        };
        t.log.push(entry.clone());
        t.checkpoint(job.out, epoch, &fingerprint)?;
        progress(Progress::Epoch(entry));
    }
    let mut net = t.net;
    net.params.value = t.best;
    let log = &t.log;
    let mean_rate = log.iter().map(|e| e.windows_per_s).sum::<f64>() / log.len().max(1) as f64;
    let summary = json!({
        "epochs_run": log.len(),
        "best_epoch": t.best_epoch,
        "best_val_loss": t.best_val,
        "best_val_r2": log.iter().find(|e| e.epoch == t.best_epoch).map(|e| e.val_r2.clone()),
        "stopped_early": stopped_early || t.bad >= opts.patience,
        "training_windows": job.train.len(),
        "validation_windows": job.val.len(),
        "parameters": net.params.trainable_count(),
        "mean_windows_per_s": mean_rate,
    });
    Ok((net, summary))
}
