//! Evaluation of a trained model on a data set's test windows (or on all of it): metrics and
//! the predicted force beside the true one.

use super::metrics::{Metrics, metrics};
use super::model::Model;
use super::windows::prepare;
use crate::error::Result;
use crate::features::{DataSet, Split};
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// Which windows to score.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EvalPart {
    /// The test blocks of the model's own split.
    Test,
    /// Every window of every run (data the model never saw: other seeds or conditions).
    All,
}

/// One row of the prediction table: condition, seed, time (s), then (true, predicted) in N per
/// target.
pub type PredictionRow = (String, u64, f64, Vec<(f64, f64)>);

/// Metrics, predictions and speed.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// Per target.
    pub metrics: Vec<Metrics>,
    /// Inference windows per second.
    pub windows_per_s: f64,
    /// Rows of the prediction table: condition, seed, time, then (true, predicted) in N per target.
    pub rows: Vec<PredictionRow>,
}

/// Scores `model` on `ds`.
pub fn evaluate(model: &mut Model, ds: &DataSet, part: EvalPart) -> Result<Evaluation> {
    let mut spec = model.meta.data.clone();
    if part == EvalPart::All {
        spec.split = Split::Runs {
            val: Vec::new(),
            test: (0..ds.runs.len()).collect(),
        };
    }
    let stats = (
        model.meta.input_stats.clone(),
        model.meta.target_stats.clone(),
    );
    let prep = prepare(ds, &spec, Some((&stats.0, &stats.1)))?;
    let (x, y) = prep.test.all();
    let t0 = Instant::now();
    let p = model.predict(&x, prep.test.len());
    let windows_per_s = prep.test.len() as f64 / t0.elapsed().as_secs_f64().max(1e-9);
    let m = metrics(&y, &p, &stats.1);
    let time = ds.channel("time_s").ok();
    let o = prep.test.outputs;
    let rows = (0..prep.test.len())
        .map(|i| {
            let (run, row) = prep.test.label_row(i);
            let r = &ds.runs[run];
            let t = time
                .map(|c| r.columns[c][row])
                .unwrap_or(row as f64 / 200.0);
            let pairs = (0..o)
                .map(|k| {
                    let de = |v: f32| v as f64 * stats.1.std[k] + stats.1.mean[k];
                    (de(y[i * o + k]), de(p[i * o + k]))
                })
                .collect();
            (r.condition.clone(), r.seed, t, pairs)
        })
        .collect();
    Ok(Evaluation {
        metrics: m,
        windows_per_s,
        rows,
    })
}

impl Evaluation {
    /// Writes the predictions as CSV (`condition,seed,time_s,<target>_true_N,<target>_pred_N…`).
    pub fn write_csv(&self, path: &Path, targets: &[String]) -> Result<()> {
        let mut s = String::from("condition,seed,time_s");
        for t in targets {
            let _ = write!(s, ",{t}_true_N,{t}_pred_N");
        }
        s.push('\n');
        for (c, seed, t, pairs) in &self.rows {
            let _ = write!(s, "{c},{seed},{t:.3}");
            for (a, b) in pairs {
                let _ = write!(s, ",{a:.2},{b:.2}");
            }
            s.push('\n');
        }
        crate::io::write_atomic(path, |w| w.write_all(s.as_bytes()))
    }
}
