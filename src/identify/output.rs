//! What `identify` gives for one recording, in one place for the command line and Python:
//! the identified forces with their intervals, the track position where the input has it, the
//! safety indices with their exceedance reports, and the out-of-distribution flags.

use super::safety::{IndexReport, Limits, Monitor};
use super::{Bands, CheckedInput, Identified, OodSpan, at_labels, identify_with_bands};
use crate::learn::model::Model;

/// The identification of one recording.
#[derive(Debug, Clone)]
pub struct Output {
    /// Forces (N) per target at each label time.
    pub identified: Identified,
    /// The track position `s_m` at each label time, where the input has it.
    pub position: Option<Vec<f64>>,
    /// Interval bounds per estimate and target (a calibrated model only).
    pub bands: Option<Bands>,
    /// Names of the safety indices (ASCII), in [`Output::indices`]' order.
    pub index_names: Vec<String>,
    /// Per estimate, the safety indices' values.
    pub indices: Vec<Vec<f64>>,
    /// Each index's exceedance report.
    pub reports: Vec<IndexReport>,
    /// Per estimate, how many input channels lie beyond the training envelope (a model with
    /// an envelope only).
    pub ood_counts: Option<Vec<usize>>,
    /// The share of estimates flagged and the flagged stretches with their channels.
    pub ood_spans: Option<(f64, Vec<OodSpan>)>,
}

/// Identifies the forces of a checked recording with `model`, the intervals at `coverage`
/// where the model is calibrated, and judges them against `limits`.
pub fn run(model: &mut Model, input: &CheckedInput, limits: &Limits, coverage: f64) -> Output {
    let (identified, bands) = identify_with_bands(model, input, Some(coverage));
    let position = input.position.as_ref().map(|p| at_labels(model, p));
    let mut monitor = Monitor::new(&identified.targets, limits, false);
    let index_names = monitor.columns().iter().map(|s| s.to_string()).collect();
    let indices = identified
        .time
        .iter()
        .zip(&identified.values)
        .map(|(t, v)| monitor.push(*t, v))
        .collect();
    let ood = super::out_of_distribution(model, input);
    let ood_spans = ood.as_ref().map(|o| {
        (
            o.share(),
            o.spans(&identified.time, &model.meta.data.channels),
        )
    });
    Output {
        position,
        bands,
        index_names,
        indices,
        reports: monitor.finish(),
        ood_counts: ood.map(|o| o.channels.iter().map(|c| c.len()).collect()),
        ood_spans,
        identified,
    }
}

impl Output {
    /// Every series as a named column, in the order and with the names of `identify`'s CSV:
    /// `time_s`, `s_m`, per target `<target>_N` (with `<target>_lo_N`, `<target>_hi_N`), the
    /// indices, `ood_channels`.
    pub fn columns(&self) -> Vec<(String, Vec<f64>)> {
        let id = &self.identified;
        let mut cols = vec![("time_s".to_string(), id.time.clone())];
        if let Some(p) = &self.position {
            cols.push(("s_m".into(), p.clone()));
        }
        for (k, t) in id.targets.iter().enumerate() {
            cols.push((format!("{t}_N"), id.values.iter().map(|v| v[k]).collect()));
            if let Some(b) = &self.bands {
                cols.push((
                    format!("{t}_lo_N"),
                    b.bounds.iter().map(|r| r[k].0).collect(),
                ));
                cols.push((
                    format!("{t}_hi_N"),
                    b.bounds.iter().map(|r| r[k].1).collect(),
                ));
            }
        }
        for (k, name) in self.index_names.iter().enumerate() {
            cols.push((name.clone(), self.indices.iter().map(|r| r[k]).collect()));
        }
        if let Some(c) = &self.ood_counts {
            cols.push(("ood_channels".into(), c.iter().map(|&n| n as f64).collect()));
        }
        cols
    }
}
