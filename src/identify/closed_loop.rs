//! Closed-loop check of a trained model: simulate fresh runs (seeds never used in training),
//! identify the forces from their sensor channels, and compare with the simulator's truth —
//! R², RMSE, peak error and whether the safety verdicts agree.

use super::safety::{Limits, indices};
use super::{Identified, SensorTable, check, identify};
use crate::dataset::{Format, GenerateOptions, generate};
use crate::error::{Error, Result};
use crate::features::{DataSet, NoiseProtocol};
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
    /// Per safety index: (name, true max, identified max, verdicts agree).
    pub safety: Vec<(String, f64, f64, bool)>,
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
pub fn validate(
    model: &mut Model,
    plan: &Plan,
    seed: u64,
    work: &Path,
    jobs: usize,
    limits: &Limits,
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
        c.seeds = vec![seed];
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
        let table =
            SensorTable::from_columns(format!("{} seed {}", run.condition, run.seed), cols)?;
        let input = check(&table, model, false)?;
        let id = identify(model, &input);
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
                TargetCheck {
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
        let (ti, ii) = (indices(&truth, limits), indices(&id, limits));
        let safety = ti
            .iter()
            .zip(&ii)
            .map(|(a, b)| {
                (
                    a.name.clone(),
                    a.max,
                    b.max,
                    a.exceedances.is_empty() == b.exceedances.is_empty(),
                )
            })
            .collect();
        out.push(RunCheck {
            condition: run.condition.clone(),
            seed: run.seed,
            targets,
            safety,
        });
    }
    Ok(out)
}
