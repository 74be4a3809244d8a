//! The experiments' trainings: one model per job, as many at a time as the options allow, an
//! ensemble's members as jobs of their own; and the reuse of a model an earlier run left on the
//! same data and protocol.

use super::Ctx;
use crate::dataset::DataSet;
use crate::error::{Error, Result};
use crate::features::NoiseProtocol;
use crate::learn::model::{Model, ModelKind};
use crate::learn::train::{Progress, TrainOptions, train};
use crate::learn::uncertainty::{calibrate, join};
use crate::learn::windows::DataSpec;
use std::path::{Path, PathBuf};
use std::time::Instant;

impl Ctx<'_> {
    /// Trains `kind`; with the matched protocol, networks draw fresh training noise every
    /// epoch when the options say so ([`ExperimentOptions::fresh_noise`]).
    pub(super) fn fit(
        &self,
        ds: &DataSet,
        spec: &DataSpec,
        kind: ModelKind,
        dir: &Path,
        windows_per_epoch: Option<usize>,
        seed_offset: u64,
    ) -> Result<(Model, f64)> {
        let t0 = Instant::now();
        let name = dir
            .strip_prefix(&self.opts.out)
            .unwrap_or(dir)
            .display()
            .to_string();
        (self.log)(format!("training {} → {name}", kind.name()));
        let opts = TrainOptions {
            fresh_noise: spec
                .noise_model
                .filter(|_| self.opts.fresh_noise && spec.noise == NoiseProtocol::Matched),
            windows_per_epoch: windows_per_epoch.or(self.opts.train.windows_per_epoch),
            // An ensemble's members from seeds seed, seed + 1, … (as `train --ensemble`), a
            // job's own offset added (a second seed of the same model).
            seed: self.opts.train.seed + seed_offset,
            ..self.opts.train.clone()
        };
        let mut model = train(ds, spec, kind, &opts, dir, &mut |p| {
            if let Progress::Epoch(e) = p
                && (e.epoch % 10 == 0 || e.epoch == 1)
            {
                let lr = if e.lr < opts.lr {
                    format!(", lr {:.1e}", e.lr)
                } else {
                    String::new()
                };
                (self.log)(format!(
                    "  {name}: epoch {:>3}: val {:.4}, best epoch {}, {:.0} windows/s{lr}",
                    e.epoch, e.val_loss, e.best_epoch, e.windows_per_s
                ));
            }
        })?;
        // Split conformal on the validation part, and the training envelope: every model of
        // the experiments reports its intervals' coverage and flags what it never saw.
        match calibrate(&mut model, ds) {
            Ok(cal) => {
                model.meta.calibration = Some(cal);
                model.save(dir)?;
            }
            Err(e) => (self.log)(format!("  {name}: not calibrated: {e}")),
        }
        let secs = t0.elapsed().as_secs_f64();
        (self.log)(format!("  {name}: done in {secs:.1} s"));
        Ok((model, secs))
    }

    /// Trains every job, [`ExperimentOptions::jobs`] at a time (each training runs on one
    /// thread and is seeded on its own, so the models do not depend on the order; an
    /// ensemble's members train as jobs of their own, member k in `dir/member<k>`, and are
    /// joined and calibrated at the end), and returns the models in the order of the jobs
    /// with their wall time, s (an ensemble's: its members' sum).
    pub(super) fn fit_all(&self, jobs: &[FitJob]) -> Result<Vec<(Model, f64)>> {
        let tasks: Vec<(usize, usize)> = jobs
            .iter()
            .enumerate()
            .flat_map(|(j, job)| (0..job.members.max(1)).map(move |k| (j, k)))
            .collect();
        let next = std::sync::atomic::AtomicUsize::new(0);
        let done: std::sync::Mutex<Vec<Option<Fitted>>> =
            std::sync::Mutex::new((0..tasks.len()).map(|_| None).collect());
        std::thread::scope(|scope| {
            for _ in 0..self.opts.jobs.max(1).min(tasks.len()) {
                scope.spawn(|| {
                    loop {
                        let t = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                        let Some(&(j, k)) = tasks.get(t) else { return };
                        let job = &jobs[j];
                        let dir = if k == 0 {
                            job.dir.clone()
                        } else {
                            job.dir.join(format!("member{}", k + 1))
                        };
                        let r = self.fit(
                            job.ds,
                            &job.spec,
                            job.kind,
                            &dir,
                            job.windows,
                            job.seed_offset + k as u64,
                        );
                        let failed = r.is_err();
                        done.lock().expect("results lock")[t] = Some(r);
                        if failed {
                            // Stop handing out work: the first error ends the experiment.
                            next.store(tasks.len(), std::sync::atomic::Ordering::SeqCst);
                            return;
                        }
                    }
                });
            }
        });
        let mut fitted = done.into_inner().expect("results lock").into_iter();
        let mut out = Vec::with_capacity(jobs.len());
        for job in jobs {
            let mut members = Vec::new();
            let mut secs = 0.0;
            for _ in 0..job.members.max(1) {
                let (m, s) = fitted.next().flatten().ok_or_else(|| {
                    Error::Domain("a training was not run after another failed".into())
                })??;
                members.push(m);
                secs += s;
            }
            if members.len() == 1 {
                out.push((members.pop().expect("one member"), secs));
            } else {
                out.push((join(members, job.ds, &job.dir)?, secs));
            }
        }
        Ok(out)
    }
}

/// A trained model and its wall time, s, or why it failed.
type Fitted = Result<(Model, f64)>;

/// One training of [`Ctx::fit_all`].
pub(super) struct FitJob<'d> {
    pub(super) ds: &'d DataSet,
    pub(super) spec: DataSpec,
    pub(super) kind: ModelKind,
    pub(super) dir: PathBuf,
    pub(super) windows: Option<usize>,
    /// Networks from seeds seed, seed + 1, … joined into one ensemble (1: one network).
    pub(super) members: usize,
    /// Added to the training seed (0: the experiments' seed; 1: a second training of the
    /// same model, for the spread over seeds).
    pub(super) seed_offset: u64,
}

/// The model an earlier run of the experiments left in `dir` (the generalisation's or the
/// sensors' CNN-BiLSTM), when it was trained on the same data under the same protocol
/// (`channels`, or its own; windows of `window` steps) and calibrated with its envelope:
/// reused, not trained again.
pub(super) fn earlier(
    ctx: &Ctx,
    dir: &Path,
    ds: &DataSet,
    channels: Option<&[String]>,
    window: usize,
) -> Option<Model> {
    let m = Model::load(dir).ok()?;
    let channels = channels.map_or_else(|| m.meta.data.channels.clone(), |c| c.to_vec());
    let mut spec = ctx
        .spec_windowed(
            ds,
            &channels,
            &ctx.labels(),
            NoiseProtocol::Matched,
            ctx.split.clone(),
            window,
        )
        .ok()?;
    // The noise the experiments train with (`ds` may be the clean data).
    spec.noise_model = Some(ctx.opts.noise(ctx.opts.snr_db));
    let same = m.meta.kind == ModelKind::CnnBiLstm
        && m.meta.data == spec
        && m.meta.data_identity["data_fnv1a"].as_str() == Some(ctx.data_hash.as_str())
        && m.meta
            .calibration
            .as_ref()
            .is_some_and(|c| !c.envelope.is_empty());
    same.then_some(m)
}
