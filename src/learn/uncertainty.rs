//! Calibrated uncertainty of identified forces (issue 36): a deep ensemble (N networks from
//! different seeds, Lakshminarayanan et al. 2017) whose spread says where the members disagree,
//! and split conformal prediction (Vovk et al. 2005; Lei et al. 2018) on the validation part's
//! whole runs, which turns residuals into intervals with a stated coverage.
//!
//! The conformity score of a validation window is `|y − ŷ|` (one model) or
//! `|y − ŷ| / (σ + β)` (an ensemble: σ its members' spread, β the median spread, which keeps
//! the score finite where the members agree), in standardised units per target. The interval at
//! coverage `c` is `ŷ ± q·(σ + β)` (or `ŷ ± q`) with `q` the `⌈(n+1)·c⌉`-th smallest of the `n`
//! scores: marginal coverage of at least `c` on data exchangeable with the validation runs.

use super::model::Model;
use super::train::{Progress, TrainOptions, train};
use super::windows::{DataSpec, prepare};
use crate::dataset::DataSet;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Quantile levels stored per target: `i / LEVELS` for `i = 0..=LEVELS`.
const LEVELS: usize = 1000;

/// Windows predicted per batch while calibrating.
const BATCH: usize = 8192;

/// The conformity score of a window.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Score {
    /// `|y − ŷ|`: one model.
    Absolute,
    /// `|y − ŷ| / (σ + β)`: an ensemble, σ its members' spread.
    Normalised,
}

impl Score {
    /// `absolute` or `normalised`, as `model.json` writes it.
    pub fn name(self) -> &'static str {
        match self {
            Score::Absolute => "absolute",
            Score::Normalised => "normalised",
        }
    }
}

/// A model's conformal calibration (in `model.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// The conformity score.
    pub score: Score,
    /// Per target, β of the normalised score (standardised units; 0 for `absolute`).
    pub beta: Vec<f64>,
    /// Per target, the conformal quantile of the score at each level `i/1000`.
    pub quantiles: Vec<Vec<f64>>,
    /// Windows calibrated on.
    pub windows: usize,
    /// What they were.
    pub part: String,
    /// Per input channel, the 0.1 % and 99.9 % quantiles of its standardised values over the
    /// training part: what the model has seen (`identify` flags inputs beyond it).
    #[serde(default)]
    pub envelope: Vec<[f64; 2]>,
}

impl Calibration {
    /// Calibrates on standardised labels `y[n × outputs]`, predictions `mean` and (an
    /// ensemble's) spread.
    pub fn fit(
        y: &[f32],
        mean: &[f32],
        spread: Option<&[f32]>,
        outputs: usize,
        part: String,
    ) -> Result<Self> {
        let n = y.len() / outputs.max(1);
        if n == 0 || mean.len() != y.len() || spread.is_some_and(|s| s.len() != y.len()) {
            return Err(Error::Domain(format!(
                "calibration needs windows with one prediction each ({part})"
            )));
        }
        let mut beta = vec![0.0; outputs];
        let mut quantiles = Vec::with_capacity(outputs);
        for k in 0..outputs {
            if let Some(s) = spread {
                let mut sk: Vec<f64> = (0..n).map(|i| s[i * outputs + k] as f64).collect();
                sk.sort_by(f64::total_cmp);
                beta[k] = sk[n / 2].max(1e-6);
            }
            let mut scores: Vec<f64> = (0..n)
                .map(|i| {
                    let r = (y[i * outputs + k] - mean[i * outputs + k]).abs() as f64;
                    match spread {
                        Some(s) => r / (s[i * outputs + k] as f64 + beta[k]),
                        None => r,
                    }
                })
                .collect();
            if scores.iter().any(|v| !v.is_finite()) {
                return Err(Error::Domain(format!(
                    "calibration on {part}: a prediction is not finite"
                )));
            }
            scores.sort_by(f64::total_cmp);
            quantiles.push(
                (0..=LEVELS)
                    .map(|i| {
                        let c = i as f64 / LEVELS as f64;
                        let rank = ((n + 1) as f64 * c).ceil() as usize;
                        scores[rank.clamp(1, n) - 1]
                    })
                    .collect(),
            );
        }
        Ok(Calibration {
            score: if spread.is_some() {
                Score::Normalised
            } else {
                Score::Absolute
            },
            beta,
            quantiles,
            windows: n,
            part,
            envelope: Vec::new(),
        })
    }

    /// Half-width of target `k`'s interval at `coverage` (0–1) where the ensemble's spread is
    /// `spread`, standardised units (the stored level at or above `coverage`).
    pub fn half_width(&self, k: usize, coverage: f64, spread: f64) -> f64 {
        let i = ((coverage.clamp(0.0, 1.0) * LEVELS as f64) - 1e-9).ceil() as usize;
        let q = self.quantiles[k][i.min(LEVELS)];
        if self.score == Score::Normalised {
            q * (spread + self.beta[k])
        } else {
            q
        }
    }
}

/// Calibrates `model` on the validation part of its own split of `ds`.
pub fn calibrate(model: &mut Model, ds: &DataSet) -> Result<Calibration> {
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
    let idx: Vec<usize> = (0..val.len()).collect();
    for chunk in idx.chunks(BATCH) {
        val.gather(chunk, &mut xb, &mut yb);
        let (m, s) = model.predict_spread(&xb, chunk.len());
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
        format!(
            "validation part of the model's split: {} windows of {} whole runs",
            val.len(),
            runs.len()
        ),
    )?;
    cal.envelope = envelope;
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
            let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
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
    let mut model: Option<Model> = None;
    let mut summaries = Vec::new();
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
        let m = train(ds, spec, kind, &o, &dir, &mut |p| progress(k, p))?;
        summaries.push(m.meta.training.clone());
        match &mut model {
            None => model = Some(m),
            Some(first) => first.members.push(m.engine),
        }
    }
    let mut model = model.expect("at least one member");
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

#[cfg(test)]
mod tests {
    use super::*;
    use rand_chacha::ChaCha8Rng;
    use rand_chacha::rand_core::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// On a planted Gaussian problem (y = f + ε, ε ~ N(0, σ(x)²) with σ varying 4×) the split
    /// conformal interval covers new points at the nominal rate within ±2 %, with the absolute
    /// score and with the normalised one fed the true σ as its "spread"; the normalised
    /// intervals are narrower where σ is small.
    #[test]
    fn conformal_coverage_on_a_planted_gaussian_problem() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let unit = Normal::new(0.0, 1.0).unwrap();
        let mut draw = |n: usize| {
            let (mut y, mut p, mut s) = (Vec::new(), Vec::new(), Vec::new());
            for i in 0..n {
                let sigma = 0.25 + 0.75 * ((i % 100) as f64 / 99.0);
                let f = (i as f64 * 0.01).sin();
                y.push((f + sigma * unit.sample(&mut rng)) as f32);
                p.push(f as f32);
                s.push(sigma as f32);
            }
            (y, p, s)
        };
        let (yc, pc, sc) = draw(5_000);
        let (yt, pt, st) = draw(20_000);
        for normalised in [false, true] {
            let cal = Calibration::fit(
                &yc,
                &pc,
                normalised.then_some(sc.as_slice()),
                1,
                "planted".into(),
            )
            .unwrap();
            for coverage in [0.8, 0.9, 0.95] {
                let inside = (0..yt.len())
                    .filter(|&i| {
                        let h = cal.half_width(0, coverage, st[i] as f64);
                        ((yt[i] - pt[i]).abs() as f64) <= h
                    })
                    .count() as f64
                    / yt.len() as f64;
                assert!(
                    (inside - coverage).abs() < 0.02,
                    "{} at {coverage}: {inside}",
                    cal.score.name()
                );
            }
            if normalised {
                assert!(cal.half_width(0, 0.9, 0.25) < 0.6 * cal.half_width(0, 0.9, 1.0));
            }
        }
    }

    /// Mismatched lengths and non-finite predictions are refused, not calibrated on.
    #[test]
    fn calibration_refuses_bad_input() {
        assert!(Calibration::fit(&[1.0, 2.0], &[1.0], None, 1, "x".into()).is_err());
        assert!(Calibration::fit(&[1.0], &[f32::NAN], None, 1, "x".into()).is_err());
        assert!(Calibration::fit(&[], &[], None, 1, "x".into()).is_err());
    }
}
