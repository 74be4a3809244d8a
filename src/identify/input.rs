//! A recording checked against a model before any work: its channels present, a 200 Hz time
//! base without gaps (or resampled onto one), every value finite and within reach of the
//! training data.

use super::{RATE_HZ, SensorTable, resolve_channels};
use crate::error::{Error, Result};
use crate::learn::model::Model;

/// Whether a time step is one 200 Hz sample interval (within 1 %).
pub fn is_regular_step(step: f64) -> bool {
    (step - 1.0 / RATE_HZ).abs() <= 0.01 / RATE_HZ
}

/// The model inputs found in a table, in model order, validated.
#[derive(Debug, Clone)]
pub struct CheckedInput {
    /// Column names used (the model's channel or its `_noisy` copy).
    pub used: Vec<String>,
    /// Times, s (200 Hz).
    pub time: Vec<f64>,
    /// Columns in model order.
    pub columns: Vec<Vec<f64>>,
    /// The track position `s_m` where the table has it (resampled with the rest).
    pub position: Option<Vec<f64>>,
}

/// Checks a table against a model: every channel present (the `_noisy` copy where the model's
/// test inputs are noisy and the table has one), a 200 Hz time base without gaps (or resampled
/// linearly onto 200 Hz when `resample`), no NaN or infinity. Errors name the column and row
/// (rows count from 1 after the header).
pub fn check(table: &SensorTable, model: &Model, resample: bool) -> Result<CheckedInput> {
    let spec = &model.meta.data;
    let names: Vec<&str> = table.columns.iter().map(|(n, _)| n.as_str()).collect();
    let used: Vec<String> = resolve_channels(&names, model, &table.source)?
        .into_iter()
        .map(|k| names[k].to_string())
        .collect();
    let t = &table.time;
    if t.len() < spec.window {
        return Err(Error::Domain(format!(
            "{}: {} rows, fewer than one window ({} steps)",
            table.source,
            t.len(),
            spec.window
        )));
    }
    let mut columns: Vec<Vec<f64>> = Vec::new();
    let stats = &model.meta.input_stats;
    for (k, name) in used.iter().enumerate() {
        let v = table.column(name).expect("checked above");
        if let Some(r) = v.iter().position(|x| !x.is_finite()) {
            return Err(not_finite(&table.source, name, r + 1, v[r]));
        }
        // A value a million standard deviations from the training data is no measurement (a
        // unit slip or a corrupt cell), and would overflow the network into NaN. A channel
        // constant in training (a vehicle's mass) keeps a rounding-sized std: its scale is at
        // least a thousandth of its mean.
        if let (Some(&m), Some(&sd)) = (stats.mean.get(k), stats.std.get(k))
            && let sd = sd.max(1e-3 * m.abs())
            && let Some(r) = v.iter().position(|x| ((x - m) / sd).abs() > MAX_DEVIATIONS)
        {
            return Err(Error::Domain(format!(
                "{}: column {name}, row {}: value {} lies {:.1e} standard deviations from what the model was trained on (mean {m:.4e}, std {sd:.4e}): a unit slip or a corrupt cell",
                table.source,
                r + 1,
                v[r],
                ((v[r] - m) / sd).abs()
            )));
        }
        columns.push(v.to_vec());
    }
    if let Some(r) = t.iter().position(|x| !x.is_finite()) {
        return Err(Error::Domain(format!(
            "{}: time column, row {}: not a finite number",
            table.source,
            r + 1
        )));
    }
    let position = table.column("s_m").map(<[f64]>::to_vec);
    if let Some(r) = position
        .as_ref()
        .and_then(|p| p.iter().position(|x| !x.is_finite()))
    {
        return Err(Error::Domain(format!(
            "{}: column s_m, row {}: value is not a finite number",
            table.source,
            r + 1
        )));
    }
    let dt = 1.0 / RATE_HZ;
    let bad = t.windows(2).position(|w| !is_regular_step(w[1] - w[0]));
    match bad {
        None => Ok(CheckedInput {
            used,
            time: t.clone(),
            columns,
            position,
        }),
        Some(r) if !resample => Err(irregular_step(
            &table.source,
            r + 1,
            t[r + 1] - t[r],
            " (resampling interpolates it onto 200 Hz)",
        )),
        Some(_) => {
            if let Some(r) = t.windows(2).position(|w| w[1] <= w[0]) {
                return Err(Error::Domain(format!(
                    "{}: time column, row {}: time does not increase; cannot resample",
                    table.source,
                    r + 2
                )));
            }
            let n = crate::bounds::count_of(
                ((t[t.len() - 1] - t[0]) / dt).floor(),
                "resampled rows of the sensor file",
            )? + 1;
            let new_t: Vec<f64> = (0..n).map(|i| t[0] + i as f64 * dt).collect();
            let columns = columns.iter().map(|c| interpolate(t, c, &new_t)).collect();
            let position = position.map(|p| interpolate(t, &p, &new_t));
            Ok(CheckedInput {
                used,
                time: new_t,
                columns,
                position,
            })
        }
    }
}

/// Farthest an input may lie from the training data's mean, in its standard deviations,
/// before it is refused as no measurement (a choice: the training data's own extremes lie
/// within tens).
const MAX_DEVIATIONS: f64 = 1e6;

/// A value that is not finite, named by source, column and row (from 1 after the header): the
/// batch check's and the stream's one wording.
pub(super) fn not_finite(source: &str, column: &str, row: usize, value: f64) -> Error {
    Error::Domain(format!(
        "{source}: column {column}, row {row}: value {value} is not a finite number"
    ))
}

/// A time step other than one 200 Hz interval between `row` and the next (from 1 after the
/// header), with `hint` appended.
pub(super) fn irregular_step(source: &str, row: usize, step: f64, hint: &str) -> Error {
    if step <= 0.0 {
        return Error::Domain(format!(
            "{source}: time column, rows {row}–{}: time does not increase (step {step:.6} s)",
            row + 1
        ));
    }
    let rate = 1.0 / step;
    Error::Domain(format!(
        "{source}: time column, rows {row}–{}: step {step:.6} s ({rate:.1} Hz); the model needs {RATE_HZ} Hz without gaps{hint}",
        row + 1
    ))
}

/// Linear interpolation of `(t, v)` at `at` (ascending, inside the range).
fn interpolate(t: &[f64], v: &[f64], at: &[f64]) -> Vec<f64> {
    let mut k = 0;
    at.iter()
        .map(|&x| {
            while k + 2 < t.len() && t[k + 1] < x {
                k += 1;
            }
            let (t0, t1) = (t[k], t[k + 1]);
            let w = ((x - t0) / (t1 - t0)).clamp(0.0, 1.0);
            v[k] + w * (v[k + 1] - v[k])
        })
        .collect()
}
