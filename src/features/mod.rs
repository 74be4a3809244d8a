//! From data sets to learning: leak-free samples, mutual-information filter, wrapper
//! selection, and the selection file that training reads.

mod mutual_info;
mod samples;
mod split;
mod wrapper;

pub use samples::{Block, LabelAt, NoiseProtocol, Part, Samples, Split, Window, ZScore};
pub use split::{SPLIT_KINDS, SplitRequest};

use crate::dataset::DataSet;
use crate::error::{Error, Result};
use crate::sensors::{Candidates, noisy_name};
use serde::{Deserialize, Serialize};

/// One row of the selection table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SelectionRow {
    /// Channel name.
    pub channel: String,
    /// Mutual information with the target, nats.
    pub mi: f64,
    /// Validation R² gain when the wrapper added it (or would have, at its last step).
    pub wrapper_gain: Option<f64>,
    /// Kept in the final subset.
    pub kept: bool,
}

/// What `railforce select` writes and training reads.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Selection {
    /// Target channel.
    pub target: String,
    /// Selected input channels, in the order the wrapper added them.
    pub channels: Vec<String>,
    /// Z-score statistics of the selected inputs (training blocks only).
    pub input_stats: ZScore,
    /// Z-score statistics of the target (training blocks only).
    pub target_stats: ZScore,
    /// Window length, steps.
    pub window: usize,
    /// Label position.
    pub label_at: LabelAt,
    /// The ranked table.
    pub table: Vec<SelectionRow>,
    /// Filter threshold, nats.
    pub mi_threshold: f64,
    /// Wrapper stopping tolerance on R².
    pub tolerance: f64,
}

impl Selection {
    /// Reads a selection file written by `railforce select`; errors name the file.
    pub fn load(path: &std::path::Path) -> Result<Self> {
        let text = crate::io::read_text(path)?;
        let s: Self = serde_json::from_str(&text).map_err(|e| Error::Parse {
            file: path.to_path_buf(),
            message: format!("not a selection file: {e}"),
        })?;
        s.input_stats.check(path, "input_stats")?;
        s.target_stats.check(path, "target_stats")?;
        Ok(s)
    }
}

/// Settings of a selection.
#[derive(Debug, Clone)]
pub struct SelectOptions {
    /// Target: `FL`, `FQ` or a channel name.
    pub target: String,
    /// Use the `_noisy` copies of the inputs.
    pub noisy: bool,
    /// Drop channels whose MI is below this, nats.
    pub mi_threshold: f64,
    /// Stop the wrapper when the best gain is below this.
    pub tolerance: f64,
    /// Window length, steps.
    pub window: usize,
    /// Label position.
    pub label_at: LabelAt,
    /// Largest number of rows the MI estimator sees (evenly strided).
    pub mi_samples: usize,
    /// Largest number of training windows the wrapper's ridge sees (evenly strided; the
    /// validation windows at most half as many).
    pub max_windows: usize,
    /// The signals to choose from.
    pub candidates: Candidates,
}

impl Default for SelectOptions {
    fn default() -> Self {
        SelectOptions {
            target: "FQ".into(),
            noisy: false,
            mi_threshold: 0.01,
            tolerance: 0.002,
            window: 20,
            label_at: LabelAt::default(),
            mi_samples: 50_000,
            max_windows: 40_000,
            candidates: Candidates::Paper21,
        }
    }
}

/// Filter (MI of each candidate with the target over the training rows, assets/docs/learning.md §2),
/// then wrapper (forward selection by validation R² of ridge on flattened windows).
pub fn select(ds: &DataSet, split: &Split, opts: &SelectOptions) -> Result<Selection> {
    let target_name = ds.target_channel(&opts.target);
    let target = ds.channel(&target_name)?;
    let names: Vec<String> = ds
        .distinct_channels(&opts.candidates.among(&ds.names, &ds.labels))
        .iter()
        .map(|c| if opts.noisy { noisy_name(c) } else { c.clone() })
        .collect();
    if names.is_empty() {
        return Err(Error::Domain(format!(
            "{} has no {} candidate channels",
            ds.dir.display(),
            opts.candidates.name()
        )));
    }
    let inputs = names
        .iter()
        .map(|n| ds.channel(n))
        .collect::<Result<Vec<_>>>()?;
    let mut samples = Samples::build(ds, split, opts.window, 2, opts.label_at)?;
    for (part, cap) in [
        (&mut samples.train, opts.max_windows),
        (&mut samples.val, opts.max_windows / 2),
    ] {
        let step = part.len().div_ceil(cap.max(1)).max(1);
        *part = part.iter().step_by(step).copied().collect();
    }
    if samples.train.is_empty() || samples.val.is_empty() {
        return Err(Error::Domain(
            "the split leaves no training or validation windows".into(),
        ));
    }
    // Filter: MI on the same time step over the training rows.
    let rows: Vec<(usize, usize)> = samples
        .train_blocks
        .iter()
        .flat_map(|b| (b.from..b.to).map(move |r| (b.run, r)))
        .collect();
    let step = rows.len().div_ceil(opts.mi_samples.max(1)).max(1);
    let picked: Vec<(usize, usize)> = rows.into_iter().step_by(step).collect();
    let y: Vec<f64> = picked
        .iter()
        .map(|&(r, i)| ds.runs[r].columns[target][i])
        .collect();
    let mis: Vec<f64> = std::thread::scope(|scope| {
        let handles: Vec<_> = inputs
            .iter()
            .map(|&c| {
                let (picked, y) = (&picked, &y);
                scope.spawn(move || {
                    let x: Vec<f64> = picked
                        .iter()
                        .map(|&(r, i)| ds.runs[r].columns[c][i])
                        .collect();
                    mutual_info::mutual_information(&x, y, 3)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("MI thread"))
            .collect()
    });
    let survivors: Vec<usize> = (0..inputs.len())
        .filter(|&k| mis[k] >= opts.mi_threshold)
        .collect();
    let cand: Vec<usize> = survivors.iter().map(|&k| inputs[k]).collect();
    let zx = ZScore::fit(ds, &samples.train_blocks, &cand);
    let zt = ZScore::fit(ds, &samples.train_blocks, &[target]);
    let (steps, last) =
        wrapper::forward_selection(ds, &samples, &cand, &zx, target, &zt, opts.tolerance, 1e-3);
    let mut table: Vec<SelectionRow> = (0..inputs.len())
        .map(|k| {
            let pos = survivors.iter().position(|&s| s == k);
            let gain = pos.and_then(|p| {
                steps
                    .iter()
                    .find(|s| s.candidate == p)
                    .map(|s| s.gain)
                    .or_else(|| last.iter().find(|(c, _)| *c == p).map(|(_, g)| *g))
            });
            SelectionRow {
                channel: names[k].clone(),
                mi: mis[k],
                wrapper_gain: gain,
                kept: pos.is_some_and(|p| steps.iter().any(|s| s.candidate == p)),
            }
        })
        .collect();
    table.sort_by(|a, b| b.mi.total_cmp(&a.mi));
    let chosen: Vec<usize> = steps.iter().map(|s| cand[s.candidate]).collect();
    Ok(Selection {
        target: target_name,
        channels: chosen.iter().map(|&c| ds.names[c].clone()).collect(),
        input_stats: ZScore::fit(ds, &samples.train_blocks, &chosen),
        target_stats: zt,
        window: opts.window,
        label_at: opts.label_at,
        table,
        mi_threshold: opts.mi_threshold,
        tolerance: opts.tolerance,
    })
}
