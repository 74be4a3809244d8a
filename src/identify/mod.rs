//! Identification of wheel–rail forces from sensor recordings with a trained model: the input
//! is checked before any work (channels, rate, gaps, NaN), standardised with the model's own
//! statistics, windowed like training, and turned into force time series; [`safety`] derives
//! Y/Q, wheel unloading and wheelset lateral force with an exceedance report. [`Streamer`]
//! does the same one sample at a time.

pub mod channel_map;
pub mod check_report;
pub mod closed_loop;
mod input;
pub mod output;
mod stream;
/// The safety indices live in [`crate::assess::safety`] (assess judges any force series);
/// re-exported here, where the streaming identification uses them.
pub use crate::assess::safety;
pub use channel_map::ChannelMap;
pub use input::{CheckedInput, check, is_regular_step};
use input::{irregular_step, not_finite};
pub use stream::SensorRows;

use crate::error::{Error, Result};
use crate::features::{LabelAt, Part};
use crate::learn::model::Model;
use crate::learn::uncertainty::Context;
use crate::learn::windows::label_offset;
use std::path::Path;

/// Sampling rate the models are trained at, Hz (the sensor contract's).
pub use crate::sensors::RATE_HZ;

/// Names accepted for the time column.
pub const TIME_COLUMNS: [&str; 3] = ["time_s", "time", "t"];

/// A sensor recording: named columns and a time column.
#[derive(Debug, Clone)]
pub struct SensorTable {
    /// Where it came from (for messages).
    pub source: String,
    /// Times, s.
    pub time: Vec<f64>,
    /// Named columns.
    pub columns: Vec<(String, Vec<f64>)>,
}

impl SensorTable {
    /// Reads a CSV, NPZ or Parquet file with a time column.
    pub fn read(path: &Path) -> Result<Self> {
        let cols = crate::dataset::read_table(path)?;
        Self::from_columns(path.display().to_string(), cols)
    }

    /// Builds a table from columns, taking out the time column.
    pub fn from_columns(source: String, mut cols: Vec<(String, Vec<f64>)>) -> Result<Self> {
        let Some(k) = cols
            .iter()
            .position(|(n, _)| TIME_COLUMNS.contains(&n.as_str()))
        else {
            return Err(Error::Domain(format!(
                "{source}: no time column (expected one of {})",
                TIME_COLUMNS.join(", ")
            )));
        };
        let (name, time) = cols.remove(k);
        if let Some(row) = time.iter().position(|t| !t.is_finite()) {
            return Err(Error::Domain(format!(
                "{source}: column {name}, row {}: the time is {} (every time must be a finite number)",
                row + 1,
                time[row]
            )));
        }
        Ok(SensorTable {
            source,
            time,
            columns: cols,
        })
    }

    /// The column `name`, if the table has it.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }
}

/// For each model channel, the position in `names` of the column to read: its `_noisy` copy
/// where the model was tested on noisy inputs and the names have one, else the clean name.
/// The error lists every missing channel.
pub fn resolve_channels(names: &[&str], model: &Model, source: &str) -> Result<Vec<usize>> {
    let spec = &model.meta.data;
    let mut found = Vec::new();
    let mut missing = Vec::new();
    for c in &spec.channels {
        let preferred = spec.noise.column(c, Part::Test);
        match names
            .iter()
            .position(|n| *n == preferred)
            .or_else(|| names.iter().position(|n| n == c))
        {
            Some(k) => found.push(k),
            None => missing.push(c.as_str()),
        }
    }
    if missing.is_empty() {
        Ok(found)
    } else {
        Err(Error::Domain(format!(
            "{source}: missing channel(s) {} required by the model",
            missing.join(", ")
        )))
    }
}

/// Identified forces: the label time and one series per model target, in N (the force series
/// that [`crate::assess`] judges).
pub type Identified = crate::assess::ForceSeries;

/// Identifies forces over a whole checked recording (one estimate per complete window).
///
/// ```no_run
/// use railforce::identify::{SensorTable, check, identify};
/// use railforce::learn::model::Model;
/// let mut model = Model::load("models/demo".as_ref())?;
/// let table = SensorTable::read("run.csv".as_ref())?;
/// let input = check(&table, &model, false)?; // channels, rate, gaps, NaN
/// let forces = identify(&mut model, &input);
/// println!("{} estimates of {:?}", forces.time.len(), forces.targets);
/// # Ok::<(), railforce::Error>(())
/// ```
pub fn identify(model: &mut Model, input: &CheckedInput) -> Identified {
    identify_with_bands(model, input, None).0
}

/// How far beyond the training envelope an input may go before its estimate is flagged
/// (the calibration's rule: [`crate::learn::uncertainty::OOD_MARGIN`]).
pub use crate::learn::uncertainty::OOD_MARGIN;

/// The checked input as the model reads it: rows `[time × channel]`, z-scored with the
/// model's own statistics.
fn standardised(model: &Model, input: &CheckedInput) -> Vec<f32> {
    let (n, c) = (input.time.len(), input.columns.len());
    let z = &model.meta.input_stats;
    let mut rows = vec![0.0f32; n * c];
    for (k, col) in input.columns.iter().enumerate() {
        for (i, v) in col.iter().enumerate() {
            rows[i * c + k] = z.apply(k, *v) as f32;
        }
    }
    rows
}

/// Estimates whose inputs left what the model was trained on: per estimate, the input channels
/// (model order) outside the training envelope.
#[derive(Debug, Clone, PartialEq)]
pub struct OutOfDistribution {
    /// Per estimate, the channels outside (empty: in distribution).
    pub channels: Vec<Vec<usize>>,
}

/// One stretch of flagged estimates.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct OodSpan {
    /// First and last label time, s.
    pub from_s: f64,
    /// See `from_s`.
    pub to_s: f64,
    /// The channels outside somewhere in it.
    pub channels: Vec<String>,
}

impl OutOfDistribution {
    /// Contiguous stretches of flagged estimates with their channels' names.
    pub fn spans(&self, time: &[f64], names: &[String]) -> Vec<OodSpan> {
        let mut out: Vec<OodSpan> = Vec::new();
        let mut open = false;
        for (i, ch) in self.channels.iter().enumerate() {
            if ch.is_empty() {
                open = false;
                continue;
            }
            if !open {
                out.push(OodSpan {
                    from_s: time[i],
                    to_s: time[i],
                    channels: Vec::new(),
                });
                open = true;
            }
            let span = out.last_mut().expect("opened");
            span.to_s = time[i];
            for &k in ch {
                if !span.channels.contains(&names[k]) {
                    span.channels.push(names[k].clone());
                }
            }
        }
        out
    }

    /// Share of estimates flagged.
    pub fn share(&self) -> f64 {
        self.channels.iter().filter(|c| !c.is_empty()).count() as f64
            / self.channels.len().max(1) as f64
    }
}

/// The out-of-distribution check of a whole recording against the model's training envelope
/// (`None` for a model without one).
pub fn out_of_distribution(model: &Model, input: &CheckedInput) -> Option<OutOfDistribution> {
    let cal = model.meta.calibration.as_ref()?;
    if cal.envelope.is_empty() {
        return None;
    }
    let spec = &model.meta.data;
    let (w, c) = (spec.window, spec.channels.len());
    let n = input.time.len();
    let rows = standardised(model, input);
    let count = (n + 1).saturating_sub(w);
    Some(OutOfDistribution {
        channels: (0..count)
            .map(|s| cal.outside(&rows[s * c..(s + w) * c], c))
            .collect(),
    })
}

/// Intervals around identified forces: per estimate and target, the lower and upper bound in
/// N at `coverage` (split conformal on the model's validation runs, widened where an
/// ensemble's members disagree; `learn::uncertainty`).
#[derive(Debug, Clone, PartialEq)]
pub struct Bands {
    /// Nominal coverage, 0–1.
    pub coverage: f64,
    /// Per estimate, per target: (lower, upper), N.
    pub bounds: Vec<Vec<(f64, f64)>>,
}

/// [`identify`], and with `coverage` the interval around every estimate where the model is
/// calibrated (`None` where it is not).
pub fn identify_with_bands(
    model: &mut Model,
    input: &CheckedInput,
    coverage: Option<f64>,
) -> (Identified, Option<Bands>) {
    let spec = model.meta.data.clone();
    let (w, c) = (spec.window, spec.channels.len());
    let n = input.time.len();
    let rows = standardised(model, input);
    let count = n + 1 - w;
    let mut x = Vec::with_capacity(count.min(4096) * w * c);
    let mut out = Vec::with_capacity(count * spec.targets.len());
    let mut spread: Vec<f32> = Vec::new();
    for first in (0..count).step_by(4096) {
        let last = (first + 4096).min(count);
        x.clear();
        for s in first..last {
            x.extend_from_slice(&rows[s * c..(s + w) * c]);
        }
        let (m, sp) = model.predict_spread_on(&x, last - first, crate::dataset::default_jobs());
        out.extend(m);
        if let Some(sp) = sp {
            spread.extend(sp);
        }
    }
    let bands = match (coverage, &model.meta.calibration) {
        (Some(cov), Some(cal)) => {
            let o = spec.targets.len();
            let context = cal.context(&rows, c);
            Some(Bands {
                coverage: cov,
                bounds: (0..count)
                    .map(|s| {
                        let sp = (!spread.is_empty()).then(|| &spread[s * o..(s + 1) * o]);
                        let window = &rows[s * c..(s + w) * c];
                        let ctx = context.as_ref().map(|x| (x, s + w - 1));
                        bounds(model, &out[s * o..(s + 1) * o], sp, window, ctx, cov)
                    })
                    .collect(),
            })
        }
        _ => None,
    };
    (finish(model, &input.time, out, count), bands)
}

/// The interval (N) around one estimate: its standardised prediction `mean`, the members'
/// `spread` per target, its standardised input `window` and the record's context at its last
/// row, at `coverage` (the model must be calibrated).
fn bounds(
    model: &Model,
    mean: &[f32],
    spread: Option<&[f32]>,
    window: &[f32],
    context: Option<(&Context, usize)>,
    coverage: f64,
) -> Vec<(f64, f64)> {
    let cal = model.meta.calibration.as_ref().expect("a calibrated model");
    let ts = &model.meta.target_stats;
    let level = cal.difficulty_of(window, model.meta.data.channels.len(), mean, context);
    (0..mean.len())
        .map(|k| {
            let sp = spread.map_or(0.0, |s| s[k] as f64);
            let h = cal.half_width(k, coverage, sp, level[k]) * ts.std[k];
            let v = mean[k] as f64 * ts.std[k] + ts.mean[k];
            (v - h, v + h)
        })
        .collect()
}

fn finish(model: &Model, time: &[f64], out: Vec<f32>, count: usize) -> Identified {
    let spec = &model.meta.data;
    let o = spec.targets.len();
    let off = label_offset(spec.window, spec.label_at);
    let ts = &model.meta.target_stats;
    Identified {
        targets: spec.targets.clone(),
        time: (0..count).map(|s| time[s + off]).collect(),
        values: (0..count)
            .map(|s| {
                (0..o)
                    .map(|k| out[s * o + k] as f64 * ts.std[k] + ts.mean[k])
                    .collect()
            })
            .collect(),
    }
}

/// The values of `series` (one per input sample) at the label time of each complete window,
/// in the order [`identify`] returns its estimates (e.g. the track position `s_m`).
pub fn at_labels(model: &Model, series: &[f64]) -> Vec<f64> {
    let spec = &model.meta.data;
    let off = label_offset(spec.window, spec.label_at);
    let count = (series.len() + 1).saturating_sub(spec.window);
    (0..count).map(|s| series[s + off]).collect()
}

/// One streamed estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Label time, s.
    pub time: f64,
    /// Forces, N.
    pub forces: Vec<f64>,
    /// Each force's interval (N), where asked and the model is calibrated.
    pub bounds: Option<Vec<(f64, f64)>>,
    /// The input channels outside the training envelope in this window, where the model has
    /// one.
    pub outside: Option<Vec<usize>>,
}

/// One-sample-at-a-time identification: keeps the last `window` standardised samples and
/// answers as soon as a window is complete.
pub struct Streamer<'a> {
    model: &'a mut Model,
    ring: std::collections::VecDeque<f32>,
    times: std::collections::VecDeque<f64>,
    x: Vec<f32>,
    /// The running context of the intervals' difficulty, where the calibration reads one.
    context: Option<Context>,
}

impl<'a> Streamer<'a> {
    /// A streamer over `model`.
    pub fn new(model: &'a mut Model) -> Self {
        let c = model.meta.data.channels.len();
        let context = model
            .meta
            .calibration
            .as_ref()
            .and_then(|cal| cal.context_stream(c));
        Streamer {
            model,
            ring: Default::default(),
            times: Default::default(),
            x: Vec::new(),
            context,
        }
    }

    /// Feeds one sample (`values` in model channel order, physical units, one per channel);
    /// returns the estimate `(label time, forces in N)` once a window is complete.
    ///
    /// # Panics
    /// When `values` does not hold one value per model channel.
    pub fn push(&mut self, time: f64, values: &[f64]) -> Option<(f64, Vec<f64>)> {
        self.push_with_bands(time, values, None)
            .map(|e| (e.time, e.forces))
    }

    /// [`Streamer::push`], and with `coverage` the interval (N) around each force where the
    /// model is calibrated: the same numbers as [`identify_with_bands`] on the whole record.
    ///
    /// # Panics
    /// When `values` does not hold one value per model channel.
    pub fn push_with_bands(
        &mut self,
        time: f64,
        values: &[f64],
        coverage: Option<f64>,
    ) -> Option<Estimate> {
        let spec = &self.model.meta.data;
        let (w, c) = (spec.window, spec.channels.len());
        assert_eq!(
            values.len(),
            c,
            "one value per model channel ({})",
            spec.channels.join(", ")
        );
        let z = &self.model.meta.input_stats;
        let first = self.ring.len();
        for (k, v) in values.iter().enumerate().take(c) {
            self.ring.push_back(z.apply(k, *v) as f32);
        }
        if let Some(ctx) = &mut self.context {
            // The newest row, contiguous at the ring's back once made so.
            let newest = self.ring.make_contiguous();
            ctx.push(&newest[first..]);
        }
        self.times.push_back(time);
        while self.times.len() > w {
            self.times.pop_front();
            for _ in 0..c {
                self.ring.pop_front();
            }
        }
        if self.times.len() < w {
            return None;
        }
        self.x.clear();
        self.x.extend(self.ring.iter());
        let x = std::mem::take(&mut self.x);
        let (out, spread) = self.model.predict_spread(&x, 1);
        self.x = x;
        let band = match (coverage, &self.model.meta.calibration) {
            (Some(cov), Some(_)) => {
                let ctx = self.context.as_ref().map(|x| (x, x.rows() - 1));
                Some(bounds(
                    self.model,
                    &out,
                    spread.as_deref(),
                    &self.x,
                    ctx,
                    cov,
                ))
            }
            _ => None,
        };
        let outside_env = self
            .model
            .meta
            .calibration
            .as_ref()
            .filter(|cal| !cal.envelope.is_empty())
            .map(|cal| cal.outside(&self.x, c));
        let times: Vec<f64> = self.times.iter().copied().collect();
        let id = finish(self.model, &times, out, 1);
        Some(Estimate {
            time: id.time[0],
            forces: id.values[0].clone(),
            bounds: band,
            outside: outside_env,
        })
    }

    /// Label position of the model (estimates lag the newest sample by `window − 1 − offset`
    /// steps for a centre label).
    pub fn label_at(&self) -> LabelAt {
        self.model.meta.data.label_at
    }
}
