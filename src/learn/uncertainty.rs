//! Calibrated uncertainty of identified forces: a deep ensemble (N networks from
//! different seeds, Lakshminarayanan et al. 2017) whose spread says where the members disagree,
//! and split conformal prediction (Vovk et al. 2005; Lei et al. 2018) on the validation part's
//! whole runs, which turns residuals into intervals with a stated coverage.
//!
//! The conformity score of a validation window is `|y − ŷ|` (one model) or
//! `|y − ŷ| / (σ + β)` (an ensemble: σ its members' spread, β the median spread, which keeps
//! the score finite where the members agree), in standardised units per target. The interval at
//! coverage `c` is `ŷ ± q·(σ + β)` (or `ŷ ± q`) with `q` the `⌈(n+1)·c⌉`-th smallest of the `n`
//! scores: marginal coverage of at least `c` on data exchangeable with the validation runs.

pub use super::calibration::{CONTEXT_ROWS, Calibration, Context, Features, OOD_MARGIN, Score};
use super::difficulty::WindowContexts;
use super::model::Model;
use super::train::{Progress, TrainOptions, train};
use super::windows::{DataSpec, prepare};
use crate::dataset::DataSet;
use crate::error::{Error, Result};
use std::path::Path;

/// Windows predicted per batch while calibrating.
const BATCH: usize = 8192;

/// Calibrates `model` on the validation part of its own split of `ds`, with each window's
/// difficulty (the default: intervals follow the inputs' level, [`Calibration::difficulty`]).
pub fn calibrate(model: &mut Model, ds: &DataSet) -> Result<Calibration> {
    calibrate_with(model, ds, true)
}

/// [`calibrate`], with the window's difficulty or without it (one interval width everywhere,
/// but for an ensemble's spread).
pub fn calibrate_with(model: &mut Model, ds: &DataSet, difficulty: bool) -> Result<Calibration> {
    let spec = model.meta.data.clone();
    let stats = (
        model.meta.input_stats.clone(),
        model.meta.target_stats.clone(),
    );
    let prep = prepare(ds, &spec, Some((&stats.0, &stats.1)))?;
    let val = &prep.val;
    let o = val.outputs;
    let (mut y, mut mean, mut spread) = (Vec::new(), Vec::new(), Vec::new());
    let (mut xb, mut yb) = (Vec::new(), Vec::new());
    let c = val.channels;
    let mut features = Vec::new();
    // Each run's context, built once (a shuffled split's windows come in no run order).
    let place = |i: usize| (val.windows[i].run as usize, val.last_row(i));
    let inputs = |r: usize| val.inputs()[r].as_slice();
    let mut contexts = WindowContexts::new(val.len(), place, inputs, c, CONTEXT_ROWS);
    let mut runs_of: Vec<u32> = Vec::new();
    let idx: Vec<usize> = (0..val.len()).collect();
    for chunk in idx.chunks(BATCH) {
        val.gather(chunk, &mut xb, &mut yb);
        let len = xb.len() / chunk.len().max(1);
        let (m, s) = model.predict_spread(&xb, chunk.len());
        for ((w, p), &i) in xb.chunks(len.max(1)).zip(m.chunks(o)).zip(chunk) {
            runs_of.push(place(i).0 as u32);
            let ctx = contexts.at(i, place(i), inputs);
            features.extend(super::calibration::features(w, c, p, &ctx));
        }
        y.extend_from_slice(&yb);
        mean.extend(m);
        if let Some(s) = s {
            spread.extend(s);
        }
    }
    let runs: std::collections::BTreeSet<u32> = val.windows.iter().map(|w| w.run).collect();
    let envelope = envelope(&prep.train);
    let mut cal = Calibration::fit(
        &y,
        &mean,
        (!spread.is_empty()).then_some(spread.as_slice()),
        o,
        difficulty.then_some(Features {
            values: &features,
            d: super::calibration::feature_count(c, o, true),
            runs: &runs_of,
        }),
        format!(
            "validation part of the model's split: {} windows of {} whole runs",
            val.len(),
            runs.len()
        ),
    )?;
    cal.envelope = envelope;
    if !cal.difficulty.is_empty() {
        cal.context_rows = CONTEXT_ROWS;
    }
    Ok(cal)
}

/// Windows sampled (evenly strided) for the input envelope.
const ENVELOPE_WINDOWS: usize = 20_000;

/// Per channel, the 0.1 % and 99.9 % quantiles of the standardised inputs over (evenly strided
/// windows of) `train`.
fn envelope(train: &super::windows::WindowSet) -> Vec<[f64; 2]> {
    let c = train.channels;
    let step = train.len().div_ceil(ENVELOPE_WINDOWS).max(1);
    let idx: Vec<usize> = (0..train.len()).step_by(step).collect();
    let (mut x, mut y) = (Vec::new(), Vec::new());
    train.gather(&idx, &mut x, &mut y);
    (0..c)
        .map(|k| {
            let mut v: Vec<f64> = x.iter().skip(k).step_by(c).map(|&v| v as f64).collect();
            if v.is_empty() {
                return [f64::NEG_INFINITY, f64::INFINITY];
            }
            v.sort_by(f64::total_cmp);
            let q = |p: f64| {
                v[crate::bounds::cell_clamped(((v.len() - 1) as f64 * p).round(), v.len())]
            };
            [q(0.001), q(0.999)]
        })
        .collect()
}

/// Trains `members` networks (or regressors) from seeds `opts.seed`, `opts.seed + 1`, …
/// (members 2… in `out/member<k>`), joins them into one model whose prediction is their mean,
/// calibrates it on the validation part and saves it in `out`. One member is a plain model
/// with its calibration.
pub fn train_ensemble(
    ds: &DataSet,
    spec: &DataSpec,
    kind: super::model::ModelKind,
    opts: &TrainOptions,
    members: usize,
    out: &Path,
    progress: &mut dyn FnMut(usize, Progress),
) -> Result<Model> {
    if !(1..=32).contains(&members) {
        return Err(Error::Domain(format!(
            "an ensemble has 1 to 32 members, got {members}"
        )));
    }
    if let Some(c) = opts.quantile_heads
        && !(c > 0.0 && c < 1.0)
    {
        return Err(Error::Domain(format!(
            "the quantile heads' coverage must lie between 0 and 1, got {c}"
        )));
    }
    // Heads for one network; an ensemble's spread is its members' disagreement.
    let opts = &TrainOptions {
        quantile_heads: opts.heads_for(kind, members),
        ..opts.clone()
    };
    let mut trained = Vec::with_capacity(members);
    for k in 0..members {
        let o = TrainOptions {
            seed: opts.seed + k as u64,
            ..opts.clone()
        };
        let dir = if k == 0 {
            out.to_path_buf()
        } else {
            out.join(format!("member{}", k + 1))
        };
        trained.push(train(ds, spec, kind, &o, &dir, &mut |p| progress(k, p))?);
    }
    join(trained, ds, out)
}

/// Joins separately trained `members` (the same kind, data spec and statistics; member 1's
/// weights in `out`, the others' beside them) into one model whose prediction is their mean
/// and whose spread is their total variance ([`Model::predict_spread`]), calibrates it on the
/// validation part of `ds` and saves it in `out`. One member is returned calibrated as it is.
pub fn join(members: Vec<Model>, ds: &DataSet, out: &Path) -> Result<Model> {
    let mut it = members.into_iter();
    let mut model = it
        .next()
        .ok_or_else(|| Error::Domain("an ensemble needs at least one member".into()))?;
    let mut summaries = vec![model.meta.training.clone()];
    for m in it {
        let same = m.meta.kind == model.meta.kind
            && m.meta.data == model.meta.data
            && m.meta.input_stats == model.meta.input_stats
            && m.meta.target_stats == model.meta.target_stats
            && m.meta
                .net
                .as_ref()
                .map(|n| (n.window, n.channels, n.outputs, n.quantiles))
                == model
                    .meta
                    .net
                    .as_ref()
                    .map(|n| (n.window, n.channels, n.outputs, n.quantiles));
        if !same {
            return Err(Error::Domain(
                "ensemble members differ in kind, data, statistics or shape: they cannot be joined"
                    .into(),
            ));
        }
        summaries.push(m.meta.training.clone());
        model.members.push(m.engine);
    }
    let members = summaries.len();
    if members > 32 {
        return Err(Error::Domain(format!(
            "an ensemble has 1 to 32 members, got {members}"
        )));
    }
    model.meta.members = members;
    if members > 1
        && let Some(obj) = model.meta.training.as_object_mut()
    {
        obj.insert("ensemble".into(), serde_json::json!(summaries));
    }
    model.meta.calibration = Some(calibrate(&mut model, ds)?);
    model.save(out)?;
    Ok(model)
}
