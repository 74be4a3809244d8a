//! Closed-loop check of a trained model: simulate fresh runs (seeds never used in training),
//! identify the forces from their sensor channels, and compare with the simulator's truth —
//! R², RMSE, peak error and whether the safety verdicts agree.

use super::channel_map::ChannelMap;
use super::safety::{Limits, indices};
use super::{Identified, SensorTable, check, identify_with_bands};
use crate::dataset::DataSet;
use crate::dataset::{Format, GenerateOptions, generate};
use crate::error::{Error, Result};
use crate::features::NoiseProtocol;
use crate::learn::model::Model;
use crate::learn::windows::label_offset;
use crate::plan::Plan;
use serde::Serialize;
use std::path::Path;

/// Result for one target of one run.
#[derive(Debug, Clone, Serialize)]
pub struct TargetCheck {
    /// Label channel.
    pub target: String,
    /// Coefficient of determination against the truth.
    pub r2: f64,
    /// RMSE, kN.
    pub rmse_kn: f64,
    /// Largest absolute error, kN.
    pub peak_error_kn: f64,
    /// Share of the true forces inside the model's interval at
    /// [`crate::learn::evaluate::EVAL_COVERAGE`] (`None`: the model is not calibrated).
    pub coverage: Option<f64>,
    /// Mean width of that interval, kN.
    pub width_kn: Option<f64>,
}

/// One safety index of one wheel (or wheelset) of a run: the identified value against the
/// true one, by its peak and by its 99.85 % percentile (the statistic acceptance uses).
#[derive(Debug, Clone, Serialize)]
pub struct IndexCheck {
    /// Index: `Y/Q`, `ΔQ/Q̄` or `H (kN)`.
    pub index: String,
    /// Wheel (`w1l`) or wheelset (`wheelset 1`).
    pub place: String,
    /// Limit of the index.
    pub limit: f64,
    /// Largest true value.
    pub true_peak: f64,
    /// Largest identified value.
    pub identified_peak: f64,
    /// `identified_peak / true_peak` (`None` where the true peak is not positive).
    pub peak_ratio: Option<f64>,
    /// 99.85 % percentile of the true series.
    pub true_p99_85: f64,
    /// 99.85 % percentile of the identified series.
    pub identified_p99_85: f64,
    /// `identified_p99_85 / true_p99_85` (`None` where the true value is not positive).
    pub p99_85_ratio: Option<f64>,
    /// The true series exceeds the limit somewhere.
    pub true_exceeds: bool,
    /// The identified series exceeds the limit somewhere.
    pub identified_exceeds: bool,
    /// Both say the same (exceeds or not).
    pub verdicts_agree: bool,
    /// A ratio is below `1 − margin`: the identification under-reads this index.
    pub underestimated: bool,
}

/// Result for one run.
#[derive(Debug, Clone, Serialize)]
pub struct RunCheck {
    /// Condition.
    pub condition: String,
    /// Seed (never one of the training seeds).
    pub seed: u64,
    /// Per target.
    pub targets: Vec<TargetCheck>,
    /// Per safety index and wheel.
    pub safety: Vec<IndexCheck>,
    /// The acceptance statistics (`railforce assess`) of the identified forces against the
    /// true ones, per section of the condition's track.
    pub assessment: Vec<crate::assess::StatCheck>,
    /// The simulator's forces at the label times.
    #[serde(skip)]
    pub truth: Identified,
    /// The identified forces.
    #[serde(skip)]
    pub identified: Identified,
}

/// Default margin of [`IndexCheck::underestimated`]: an identified statistic more than 20 %
/// below the true one.
pub const UNDER_MARGIN: f64 = 0.2;

/// Compares the safety indices of the truth and the identification.
pub fn compare_indices(
    truth: &Identified,
    identified: &Identified,
    limits: &Limits,
    margin: f64,
) -> Vec<IndexCheck> {
    let p = |r: &super::safety::IndexReport| crate::dsp::percentile(&r.series, 99.85);
    let ratio = |a: f64, b: f64| (b > 1e-9 && a.is_finite()).then(|| a / b);
    indices(truth, limits)
        .iter()
        .zip(&indices(identified, limits))
        .map(|(t, i)| {
            let (tp, ip) = (p(t), p(i));
            let (peak_ratio, p99_85_ratio) = (ratio(i.max, t.max), ratio(ip, tp));
            let under = |r: Option<f64>| r.is_some_and(|r| r < 1.0 - margin);
            IndexCheck {
                index: t.index.clone(),
                place: t.place.clone(),
                limit: t.limit,
                true_peak: t.max,
                identified_peak: i.max,
                peak_ratio,
                true_p99_85: tp,
                identified_p99_85: ip,
                p99_85_ratio,
                true_exceeds: !t.exceedances.is_empty(),
                identified_exceeds: !i.exceedances.is_empty(),
                verdicts_agree: t.exceedances.is_empty() == i.exceedances.is_empty(),
                underestimated: under(peak_ratio) || under(p99_85_ratio),
            }
        })
        .collect()
}

/// The seed a closed-loop check uses by default: one above every training seed.
pub fn fresh_seed(model: &Model) -> u64 {
    model.meta.data_identity["seeds"]
        .as_array()
        .and_then(|a| a.iter().filter_map(|v| v.as_u64()).max())
        .unwrap_or(0)
        + 1000
}

/// Runs the check on every condition of `plan` with `seed`, writing the fresh data to `work`.
#[allow(clippy::too_many_arguments)]
pub fn validate(
    model: &mut Model,
    plan: &Plan,
    seed: u64,
    work: &Path,
    jobs: usize,
    limits: &Limits,
    margin: f64,
    map: Option<&ChannelMap>,
) -> Result<Vec<RunCheck>> {
    let used: Vec<u64> = model.meta.data_identity["seeds"]
        .as_array()
        .map(|a| a.iter().filter_map(|v| v.as_u64()).collect())
        .unwrap_or_default();
    if used.contains(&seed) {
        return Err(Error::Domain(format!(
            "seed {seed} was used in training (seeds {used:?}): pick another"
        )));
    }
    let mut plan = plan.clone();
    for c in &mut plan.conditions {
        c.only_seeds(&[seed]);
    }
    // The inputs at the noise the model was trained and tested with (its SNR and reference),
    // clean for a clean model.
    let noise = match model.meta.data.noise {
        NoiseProtocol::Clean => None,
        _ => model.meta.data.noise_model,
    };
    let opts = GenerateOptions {
        out: work.to_path_buf(),
        format: Format::Npz,
        jobs: jobs.max(1),
        shard: None,
        noise,
        settle: 3.0,
        stepping: Default::default(),
    };
    generate(&plan, &opts, &|_| {})?;
    let ds = DataSet::load(work)?;
    let off = label_offset(model.meta.data.window, model.meta.data.label_at);
    let mut out = Vec::new();
    for run in &ds.runs {
        let cols: Vec<(String, Vec<f64>)> = ds
            .names
            .iter()
            .cloned()
            .zip(run.columns.iter().cloned())
            .collect();
        let mut table =
            SensorTable::from_columns(format!("{} seed {}", run.condition, run.seed), cols)?;
        if let Some(map) = map {
            // Through the field's conventions: written as the map's recorder would write it
            // (columns, units, signs), read back as `identify --channel-map` reads a recording.
            let field = map.record(&table, &model.meta.data.channels)?;
            let path = work.join(format!("{}_seed{}.field.csv", run.condition, run.seed));
            write_columns(&path, &field)?;
            table = map.read(&path, &model.meta.data.channels)?;
        }
        let input = check(&table, model, false)?;
        let (id, bands) =
            identify_with_bands(model, &input, Some(crate::learn::evaluate::EVAL_COVERAGE));
        let truth_cols = model
            .meta
            .data
            .targets
            .iter()
            .map(|t| ds.channel(t).map(|c| &run.columns[c]))
            .collect::<Result<Vec<_>>>()?;
        let truth = Identified {
            targets: id.targets.clone(),
            time: id.time.clone(),
            values: (0..id.time.len())
                .map(|s| truth_cols.iter().map(|c| c[s + off]).collect())
                .collect(),
        };
        let targets = id
            .targets
            .iter()
            .enumerate()
            .map(|(k, t)| {
                let y: Vec<f64> = truth.values.iter().map(|v| v[k]).collect();
                let p: Vec<f64> = id.values.iter().map(|v| v[k]).collect();
                let mean = y.iter().sum::<f64>() / y.len() as f64;
                let sst: f64 = y.iter().map(|v| (v - mean).powi(2)).sum();
                let sse: f64 = y.iter().zip(&p).map(|(a, b)| (a - b).powi(2)).sum();
                let (coverage, width_kn) = match &bands {
                    Some(b) => {
                        let inside = y
                            .iter()
                            .zip(&b.bounds)
                            .filter(|(v, bd)| bd[k].0 <= **v && **v <= bd[k].1)
                            .count();
                        let width = b.bounds.iter().map(|bd| bd[k].1 - bd[k].0).sum::<f64>()
                            / b.bounds.len().max(1) as f64;
                        (
                            Some(inside as f64 / y.len().max(1) as f64),
                            Some(width / 1000.0),
                        )
                    }
                    None => (None, None),
                };
                TargetCheck {
                    coverage,
                    width_kn,
                    target: t.clone(),
                    r2: 1.0 - sse / sst,
                    rmse_kn: (sse / y.len() as f64).sqrt() / 1000.0,
                    peak_error_kn: y
                        .iter()
                        .zip(&p)
                        .map(|(a, b)| (a - b).abs())
                        .fold(0.0, f64::max)
                        / 1000.0,
                }
            })
            .collect();
        let safety = compare_indices(&truth, &id, limits, margin);
        // Acceptance statistics over the track's sections, true against identified.
        let s_col = ds.channel("s_m")?;
        let s: Vec<f64> = (0..id.time.len())
            .map(|k| run.columns[s_col][k + off])
            .collect();
        let spans = plan
            .conditions
            .iter()
            .find(|c| c.name == run.condition)
            .map(|c| crate::track::TrackSpec::load(&c.track).map(|t| crate::assess::spans(&t)))
            .transpose()?
            .unwrap_or_default();
        let criteria = crate::assess::Criteria::builtin();
        let q0 = limits.static_wheel_load_kn;
        let judge = |f: &Identified| {
            crate::assess::RunForces::from_identified(f, s.clone())
                .and_then(|r| crate::assess::assess(&r, &spans, &criteria, q0))
        };
        let assessment = match (judge(&truth), judge(&id)) {
            (Ok(a), Ok(b)) => crate::assess::compare(&a, &b),
            // Too short a run for a 2 m window, or no wheel with both forces: nothing to compare.
            _ => Vec::new(),
        };
        out.push(RunCheck {
            condition: run.condition.clone(),
            seed: run.seed,
            targets,
            safety,
            assessment,
            truth,
            identified: id,
        });
    }
    Ok(out)
}

/// Writes columns as CSV (shortest round-trip decimals), atomically.
fn write_columns(path: &Path, cols: &[(String, Vec<f64>)]) -> Result<()> {
    let n = cols.first().map_or(0, |c| c.1.len());
    crate::io::write_atomic(path, |w| {
        let head: Vec<&str> = cols.iter().map(|c| c.0.as_str()).collect();
        writeln!(w, "{}", head.join(","))?;
        let mut line = String::new();
        for i in 0..n {
            line.clear();
            for (k, (_, v)) in cols.iter().enumerate() {
                if k > 0 {
                    line.push(',');
                }
                line.push_str(&v[i].to_string());
            }
            writeln!(w, "{line}")?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A planted 40 % under-identification of the lateral force is flagged on Y/Q, and the
    /// vertical force identified exactly is not.
    #[test]
    fn a_planted_under_identification_warns() {
        let n = 400;
        let time: Vec<f64> = (0..n).map(|i| i as f64 * 0.005).collect();
        let truth = Identified {
            targets: vec!["w1l_force_y".into(), "w1l_force_z".into()],
            time: time.clone(),
            values: (0..n)
                .map(|i| {
                    let y = 40e3 + 30e3 * (i as f64 * 0.05).sin();
                    vec![y, 110e3 - 20e3 * (i as f64 * 0.03).cos()]
                })
                .collect(),
        };
        let mut id = truth.clone();
        for v in &mut id.values {
            v[0] *= 0.6;
        }
        let checks = compare_indices(&truth, &id, &Limits::default(), UNDER_MARGIN);
        let yq = checks.iter().find(|c| c.index == "Y/Q").unwrap();
        assert!(yq.underestimated);
        assert!((yq.peak_ratio.unwrap() - 0.6).abs() < 1e-9);
        assert!((yq.p99_85_ratio.unwrap() - 0.6).abs() < 1e-9);
        let dq = checks.iter().find(|c| c.index != "Y/Q").unwrap();
        assert!(!dq.underestimated && dq.verdicts_agree);
        assert!((dq.peak_ratio.unwrap() - 1.0).abs() < 1e-12);
        // 10 % low stays within a 20 % margin.
        for v in &mut id.values {
            v[0] *= 0.9 / 0.6;
        }
        let checks = compare_indices(&truth, &id, &Limits::default(), UNDER_MARGIN);
        assert!(checks.iter().all(|c| !c.underestimated));
    }
}
