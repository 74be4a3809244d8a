//! Acceptance statistics of identified forces with their intervals: each statistic
//! recomputed with every wheel's Y and Q at the bounds of its identified interval, and the
//! probability that its limit is exceeded.
//!
//! The model: the identification errors of one run move together (a comonotone shift within
//! each force's interval: the errors of neighbouring windows are strongly correlated, and a
//! statistic over a section reads many of them). The statistic's interval is then the
//! smallest and largest value over the four corners (Y low or high × Q low or high), with the
//! identified value. Every limit is an upper one, so the probability of exceeding it is read
//! from the upper side, with the statistic's error taken as normal with its central
//! `coverage` interval reaching the upper bound: `P = 1 − Φ((limit − value) / σ)`,
//! `σ = (hi − value) / z`, `z = Φ⁻¹((1 + coverage) / 2)`. An estimate: the conformal bounds
//! hold marginally per window, not jointly over a section.

use super::{Assessment, RunForces, Span, WheelSeries, assess};
pub use crate::dsp::{normal_cdf, normal_quantile};
use crate::error::{Error, Result};
use serde::Serialize;

/// The interval of each wheel's Y and Q around the identified forces, N, in the order of
/// [`RunForces::wheels`].
#[derive(Debug, Clone, PartialEq)]
pub struct WheelBand {
    /// Y: lower and upper bound.
    pub y: [Vec<f64>; 2],
    /// Q: lower and upper bound.
    pub q: [Vec<f64>; 2],
}

/// A statistic's interval and the probability its limit is exceeded.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RowInterval {
    /// Lower end.
    pub low: f64,
    /// Upper end.
    pub high: f64,
    /// Probability that the true statistic exceeds its limit, 0–1.
    pub exceedance: f64,
}

/// The bounds `identify` writes (`w1l_force_y_lo_N`, `w1l_force_y_hi_N`, …) for every wheel
/// of `run`; `None` when the columns carry none; an error names a wheel with only some of
/// them, or a bound that is not finite or not around its value.
pub fn bands_from_columns(
    source: &str,
    cols: &[(String, Vec<f64>)],
    run: &RunForces,
) -> Result<Option<Vec<WheelBand>>> {
    let find = |name: &str| {
        cols.iter()
            .find(|(n, _)| n == name || n.strip_suffix("_N") == Some(name))
            .map(|(_, v)| v)
    };
    let mut bands = Vec::new();
    for w in &run.wheels {
        let get = |force: &str, value: &[f64]| -> Result<Option<[Vec<f64>; 2]>> {
            let name = format!("{}_force_{force}", w.wheel);
            let (lo, hi) = (find(&format!("{name}_lo")), find(&format!("{name}_hi")));
            let (lo, hi) = match (lo, hi) {
                (None, None) => return Ok(None),
                (Some(lo), Some(hi)) => (lo, hi),
                _ => {
                    return Err(Error::Domain(format!(
                        "{source}: {name} has only one of {name}_lo_N and {name}_hi_N"
                    )));
                }
            };
            if let Some(r) = (0..value.len()).find(|&r| {
                !(lo[r].is_finite() && hi[r].is_finite() && lo[r] <= value[r] + 1e-3)
                    || hi[r] < value[r] - 1e-3
            }) {
                return Err(Error::Domain(format!(
                    "{source}: {name}_lo_N / _hi_N, row {}: bounds must be finite around the value",
                    r + 1
                )));
            }
            Ok(Some([lo.clone(), hi.clone()]))
        };
        match (get("y", &w.y)?, get("z", &w.q)?) {
            (Some(y), Some(q)) => bands.push(WheelBand { y, q }),
            (None, None) if bands.is_empty() => continue,
            _ => {
                return Err(Error::Domain(format!(
                    "{source}: wheel {} lacks the interval of its Y or Q while others have them",
                    w.wheel
                )));
            }
        }
    }
    Ok((bands.len() == run.wheels.len()).then_some(bands))
}

/// [`assess`] of `run`, with per row ([`Assessment::intervals`]) the statistic's interval
/// from the four corners of the wheels' `bands` and the probability its limit is exceeded at
/// the bands' `coverage`.
pub fn assess_with_bands(
    run: &RunForces,
    bands: &[WheelBand],
    spans: &[Span],
    criteria: &super::Criteria,
    q0_kn: f64,
    coverage: f64,
) -> Result<Assessment> {
    if bands.len() != run.wheels.len() {
        return Err(Error::Domain(format!(
            "{} wheels but {} intervals",
            run.wheels.len(),
            bands.len()
        )));
    }
    if !(coverage > 0.0 && coverage < 1.0) {
        return Err(Error::Domain(format!(
            "coverage {coverage}: give a fraction between 0 and 1"
        )));
    }
    let mut central = assess(run, spans, criteria, q0_kn)?;
    let mut low: Vec<f64> = central.rows.iter().map(|r| r.value).collect();
    let mut high = low.clone();
    for (yi, qi) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
        let corner = RunForces {
            wheels: run
                .wheels
                .iter()
                .zip(bands)
                .map(|(w, b)| WheelSeries {
                    wheel: w.wheel.clone(),
                    y: b.y[yi].clone(),
                    q: b.q[qi].clone(),
                })
                .collect(),
            ..run.clone()
        };
        let a = assess(&corner, spans, criteria, q0_kn)?;
        if a.rows.len() != central.rows.len() {
            return Err(Error::Domain(
                "the bounds' assessment has other rows than the value's".into(),
            ));
        }
        for (i, r) in a.rows.iter().enumerate() {
            low[i] = low[i].min(r.value);
            high[i] = high[i].max(r.value);
        }
    }
    let z = normal_quantile((1.0 + coverage) / 2.0);
    central.coverage = Some(coverage);
    central.intervals = central
        .rows
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let sigma = (high[i] - r.value) / z;
            let exceedance = if sigma > 1e-12 {
                1.0 - normal_cdf((r.limit - r.value) / sigma)
            } else if r.value > r.limit {
                1.0
            } else {
                0.0
            };
            RowInterval {
                low: low[i],
                high: high[i],
                exceedance,
            }
        })
        .collect();
    Ok(central)
}
