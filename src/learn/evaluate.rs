//! Evaluation of a trained model on a data set's test windows (or on all of it): metrics and
//! the predicted force beside the true one.

use super::calibration::WindowContexts;
use super::metrics::{Metrics, metrics};
use super::model::Model;
use super::windows::prepare;
use crate::dataset::DataSet;
use crate::error::Result;
use crate::features::{Split, ZScore};
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
    /// Inference windows per second, on every core ([`crate::dataset::default_jobs`]).
    pub windows_per_s: f64,
    /// Rows of the prediction table: condition, seed, time, then (true, predicted) in N per target.
    pub rows: Vec<PredictionRow>,
    /// Per row and target, the half-width (N) of the model's interval at [`EVAL_COVERAGE`]
    /// (`None`: the model is not calibrated).
    pub half_widths: Option<Vec<Vec<f64>>>,
    /// Per row, whether an input left the training envelope (the rule `identify` flags by,
    /// [`crate::learn::uncertainty::OOD_MARGIN`]); `None`: the model has no envelope.
    pub outside: Option<Vec<bool>>,
}

/// The coverage at which `evaluate` scores the model's intervals.
pub const EVAL_COVERAGE: f64 = 0.9;

/// How a model's intervals did on one condition (or pooled), per target.
#[derive(Debug, Clone, PartialEq)]
pub struct CoverageRow {
    /// Condition (or `all (pooled)`).
    pub condition: String,
    /// Per target: the fraction of true forces inside the interval, and its mean width in kN.
    pub targets: Vec<(f64, f64)>,
    /// Per target: the standard error of that fraction by batch means over 1 s blocks of each
    /// run (neighbouring windows overlap and share their errors, so the windows are far from
    /// independent: the blocks are nearly so). What a coverage measured on these runs can
    /// resolve.
    pub se: Vec<f64>,
}

/// `FL` or `FQ` for a data set's two labels (lateral, vertical), else the channel's own name.
pub fn target_name(t: &str, labels: &[String]) -> String {
    match labels.iter().position(|l| l == t) {
        Some(0) => "FL".into(),
        Some(1) => "FQ".into(),
        _ => t.to_string(),
    }
}

impl CoverageRow {
    /// Writes rows (per condition, then pooled) as tidy CSV
    /// (`condition,target,coverage,coverage_se,mean_width_kn`), `names` per target.
    pub fn write_csv(rows: &[CoverageRow], names: &[String], path: &Path) -> Result<()> {
        let mut csv = String::from("condition,target,coverage,coverage_se,mean_width_kn\n");
        for r in rows {
            for ((n, (c, w)), se) in names.iter().zip(&r.targets).zip(&r.se) {
                let _ = writeln!(csv, "{},{n},{c:.4},{se:.4},{w:.3}", r.condition);
            }
        }
        crate::io::check_csv_finite(&csv, path)?;
        crate::io::write_atomic(path, |w| w.write_all(csv.as_bytes()))
    }

    /// One line per target: the pooled coverage, its range over the conditions, the median
    /// standard error of a condition's figure and the mean width. `rows` end with the pooled
    /// row, as [`Evaluation::coverage`] gives them.
    pub fn describe(rows: &[CoverageRow], names: &[String]) -> Vec<String> {
        let Some((pooled, per)) = rows.split_last() else {
            return Vec::new();
        };
        (0..names.len())
            .map(|k| {
                let (lo, hi) = per.iter().fold((1.0f64, 0.0f64), |a, r| {
                    (a.0.min(r.targets[k].0), a.1.max(r.targets[k].0))
                });
                let mut se: Vec<f64> = per.iter().map(|r| r.se[k]).collect();
                se.sort_by(f64::total_cmp);
                format!(
                    "{} {:.1} % pooled (conditions {:.1}–{:.1} %, each measured ± {:.1} % \
                     (median batch-means se)), mean width {:.2} kN",
                    names[k],
                    pooled.targets[k].0 * 100.0,
                    lo * 100.0,
                    hi * 100.0,
                    se.get(se.len() / 2).copied().unwrap_or(0.0) * 100.0,
                    pooled.targets[k].1
                )
            })
            .collect()
    }
}

/// Standard error of the mean of `inside` (0/1 per window) by batch means: windows grouped in
/// blocks (`block[i]`), se = sd(block means) / √blocks. Zero with fewer than two blocks.
fn batch_means_se<K: Ord + Copy>(inside: &[bool], block: &[K]) -> f64 {
    let mut sums: std::collections::BTreeMap<K, (f64, f64)> = Default::default();
    for (&b, &x) in block.iter().zip(inside) {
        let e = sums.entry(b).or_default();
        e.0 += f64::from(u8::from(x));
        e.1 += 1.0;
    }
    let means: Vec<f64> = sums.values().map(|(s, n)| s / n).collect();
    let n = means.len() as f64;
    if n < 2.0 {
        return 0.0;
    }
    let m = means.iter().sum::<f64>() / n;
    let var = means.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (var / n).sqrt()
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
    // Every core (the experiments evaluate after their trainings, the cores free).
    let (p, spread) = model.predict_spread_on(&x, prep.test.len(), crate::dataset::default_jobs());
    let windows_per_s = prep.test.len() as f64 / t0.elapsed().as_secs_f64().max(1e-9);
    let half_widths = model.meta.calibration.as_ref().map(|cal| {
        let o = prep.test.outputs;
        let c = prep.test.channels;
        let len = x.len() / prep.test.len().max(1);
        let test = &prep.test;
        let place = |i: usize| (test.windows[i].run as usize, test.last_row(i));
        let inputs = |r: usize| test.inputs()[r].as_slice();
        let mut contexts = (cal.reads_context())
            .then(|| WindowContexts::new(test.len(), place, inputs, c, cal.context_rows));
        (0..test.len())
            .map(|i| {
                let ctx = contexts.as_mut().map(|w| w.at(i, place(i), inputs));
                let level = cal.difficulty_with(
                    &x[i * len..(i + 1) * len],
                    c,
                    &p[i * o..(i + 1) * o],
                    ctx.as_deref(),
                );
                (0..o)
                    .map(|k| {
                        let sp = spread.as_ref().map_or(0.0, |s| s[i * o + k] as f64);
                        cal.half_width(k, EVAL_COVERAGE, sp, level[k]) * stats.1.std[k]
                    })
                    .collect()
            })
            .collect()
    });
    let outside = model
        .meta
        .calibration
        .as_ref()
        .filter(|cal| !cal.envelope.is_empty())
        .map(|cal| {
            let c = prep.test.channels;
            let len = x.len() / prep.test.len().max(1);
            x.chunks(len.max(1))
                .map(|w| !cal.outside(w, c).is_empty())
                .collect()
        });
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
        half_widths,
        outside,
    })
}

impl Evaluation {
    /// Empirical coverage and mean width of the intervals per condition (in order of first
    /// appearance), then pooled; `None` for a model without calibration.
    pub fn coverage(&self) -> Option<Vec<CoverageRow>> {
        let hw = self.half_widths.as_ref()?;
        let o = self.rows.first().map_or(0, |r| r.3.len());
        let mut order: Vec<&str> = Vec::new();
        for r in &self.rows {
            if !order.contains(&r.0.as_str()) {
                order.push(&r.0);
            }
        }
        let score = |pick: &dyn Fn(&str) -> bool, name: String| {
            let idx: Vec<usize> = (0..self.rows.len())
                .filter(|&i| pick(&self.rows[i].0))
                .collect();
            let n = idx.len().max(1) as f64;
            // 1 s blocks of each run (condition, seed, whole second).
            let block: Vec<(&str, u64, i64)> = idx
                .iter()
                .map(|&i| {
                    let r = &self.rows[i];
                    (r.0.as_str(), r.1, r.2.floor() as i64)
                })
                .collect();
            let inside = |k: usize| -> Vec<bool> {
                idx.iter()
                    .map(|&i| {
                        let (y, p) = self.rows[i].3[k];
                        (y - p).abs() <= hw[i][k]
                    })
                    .collect()
            };
            let (targets, se) = (0..o)
                .map(|k| {
                    let inside = inside(k);
                    let covered = inside.iter().filter(|&&x| x).count() as f64;
                    let width = idx.iter().map(|&i| 2.0 * hw[i][k]).sum::<f64>() / n;
                    ((covered / n, width * 1e-3), batch_means_se(&inside, &block))
                })
                .unzip();
            CoverageRow {
                condition: name,
                targets,
                se,
            }
        };
        let mut rows: Vec<CoverageRow> = order
            .iter()
            .map(|c| score(&|r: &str| r == *c, c.to_string()))
            .collect();
        rows.push(score(&|_| true, "all (pooled)".into()));
        Some(rows)
    }

    /// Metrics of every condition on its own (conditions in the order they first appear),
    /// from the prediction rows; `stats` are the model's target z-scores. Pooled back
    /// (`Σ n·mse / Σ n`) they give the pooled MSE.
    pub fn per_condition(&self, stats: &ZScore) -> Vec<(String, Vec<Metrics>)> {
        let mut order: Vec<&str> = Vec::new();
        for r in &self.rows {
            if order.last() != Some(&r.0.as_str()) && !order.contains(&r.0.as_str()) {
                order.push(&r.0);
            }
        }
        let o = stats.names.len();
        order
            .into_iter()
            .map(|c| {
                let (mut y, mut p) = (Vec::new(), Vec::new());
                for r in self.rows.iter().filter(|r| r.0 == c) {
                    for k in 0..o {
                        let z = |v: f64| ((v - stats.mean[k]) / stats.std[k]) as f32;
                        y.push(z(r.3[k].0));
                        p.push(z(r.3[k].1));
                    }
                }
                (c.to_string(), metrics(&y, &p, stats))
            })
            .collect()
    }

    /// The condition with the lowest R² of target `k`, and that R².
    pub fn worst_condition(
        per_condition: &[(String, Vec<Metrics>)],
        k: usize,
    ) -> Option<(&str, f64)> {
        per_condition
            .iter()
            .filter_map(|(c, m)| m.get(k).map(|m| (c.as_str(), m.r2)))
            .filter(|(_, r2)| r2.is_finite())
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Writes per-condition metrics as tidy CSV: one row per condition and target, then the
    /// pooled rows (`condition` = `all`).
    pub fn write_condition_csv(
        &self,
        path: &Path,
        per_condition: &[(String, Vec<Metrics>)],
    ) -> Result<()> {
        let mut s = String::from("condition,target,n,mse,r2,var_y,rmse_kn,mae_kn\n");
        let all = [("all".to_string(), self.metrics.clone())];
        for (c, ms) in per_condition.iter().chain(all.iter()) {
            for m in ms {
                // R² is undefined where the test labels do not vary (`metrics`): an empty cell.
                let r2 = if m.r2.is_finite() {
                    format!("{:.6}", m.r2)
                } else {
                    String::new()
                };
                let _ = writeln!(
                    s,
                    "{c},{},{},{:.6},{r2},{:.6},{:.4},{:.4}",
                    m.target, m.n, m.mse, m.var_y, m.rmse_kn, m.mae_kn
                );
            }
        }
        crate::io::check_csv_finite(&s, path)?;
        crate::io::write_atomic(path, |w| w.write_all(s.as_bytes()))
    }

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
        crate::io::check_csv_finite(&s, path)?;
        crate::io::write_atomic(path, |w| w.write_all(s.as_bytes()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn per_condition_metrics_pool_back_to_the_pooled_figure() {
        let stats = ZScore {
            names: vec!["w1l_force_y".into(), "w1l_force_z".into()],
            mean: vec![5e3, 110e3],
            std: vec![8e3, 15e3],
        };
        let (mut y, mut p, mut rows) = (Vec::new(), Vec::new(), Vec::new());
        for i in 0..300 {
            let c = ["tangent", "curve", "grade"][i % 3];
            let x = i as f64 * 0.37;
            let pairs: Vec<(f64, f64)> = (0..2)
                .map(|k| {
                    let t = stats.mean[k] + stats.std[k] * x.sin() * (1.0 + (i % 3) as f64);
                    (t, t + stats.std[k] * 0.3 * (x * 1.7).cos())
                })
                .collect();
            for (k, (t, q)) in pairs.iter().enumerate() {
                y.push(((t - stats.mean[k]) / stats.std[k]) as f32);
                p.push(((q - stats.mean[k]) / stats.std[k]) as f32);
            }
            rows.push((c.to_string(), 1, i as f64 * 0.005, pairs));
        }
        let ev = Evaluation {
            half_widths: None,
            outside: None,
            metrics: metrics(&y, &p, &stats),
            windows_per_s: 0.0,
            rows,
        };
        let per = ev.per_condition(&stats);
        assert_eq!(
            per.iter().map(|c| c.0.as_str()).collect::<Vec<_>>(),
            ["tangent", "curve", "grade"]
        );
        for k in 0..2 {
            let n: usize = per.iter().map(|c| c.1[k].n).sum();
            let sse: f64 = per.iter().map(|c| c.1[k].n as f64 * c.1[k].mse).sum();
            assert_eq!(n, ev.metrics[k].n);
            assert!((sse / n as f64 - ev.metrics[k].mse).abs() < 1e-6 * ev.metrics[k].mse);
        }
        // The tangent has the smallest spread, so the lowest R² for the same error.
        let worst = Evaluation::worst_condition(&per, 0).unwrap();
        assert_eq!(worst.0, "tangent");
    }

    /// Whole blocks in or out: the blocks are the samples. Nine of ten 1 s blocks covered,
    /// one not: sd of the block means √0.1, se √0.1/√10 = 0.1, however many windows a block
    /// holds. Every block covered 90 % alike: no spread between blocks, se 0.
    #[test]
    fn batch_means_count_blocks_not_windows() {
        let block: Vec<u32> = (0..10).flat_map(|b| [b; 200]).collect();
        let whole: Vec<bool> = block.iter().map(|&b| b != 3).collect();
        assert!((batch_means_se(&whole, &block) - 0.1).abs() < 1e-12);
        let even: Vec<bool> = (0..2000).map(|i| i % 10 != 0).collect();
        assert!(batch_means_se(&even, &block).abs() < 1e-12);
        assert_eq!(batch_means_se(&even[..200], &block[..200]), 0.0);
    }
}
