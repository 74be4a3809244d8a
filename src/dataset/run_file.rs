//! What a run's file holds: the channels a plan keeps, the noisy copies of the paper's
//! inputs, and the bytes in each format, written atomically.

use super::{Format, npz, parquet_file};
use crate::error::{Error, Result};
use crate::sensors::{ChannelKind, NoiseModel, PAPER_CHANNELS, noisy_name};
use crate::sim::output::Recording;
use std::path::{Path, PathBuf};

/// Columns a float32 data set still stores as float64: time and track position (f32 would
/// lose the sample time after about a minute and the position to centimetres).
pub fn keeps_f64(name: &str) -> bool {
    name == "time_s" || name == "s_m"
}

/// Whether the channel `name` (of `kind`) is kept by a plan's channel subset: time, position
/// and the labels always; otherwise when the subset names it, its kind, or (for a noisy copy)
/// the channel it copies.
fn kept(name: &str, kind: ChannelKind, subset: &[String]) -> bool {
    if let (ChannelKind::InputNoisy, Some(base)) = (kind, name.strip_suffix("_noisy"))
        && kept(base, ChannelKind::Input, subset)
    {
        return true;
    }
    subset.is_empty()
        || matches!(kind, ChannelKind::Axis | ChannelKind::Label)
        || subset.iter().any(|k| k == name || k == kind.name())
}

/// The kinds a plan's `dataset.channels` may name.
pub const CHANNEL_KINDS: [&str; 9] = [
    "axis",
    "input",
    "input_noisy",
    "label",
    "wheel",
    "body",
    "deflection",
    "known",
    "train",
];

/// Drops the channels a plan's subset does not keep (see [`kept`]).
pub(super) fn keep_channels(
    rec: &mut Recording,
    labels: &[String; 2],
    subset: &[String],
) -> std::result::Result<(), String> {
    if subset.is_empty() {
        return Ok(());
    }
    let kinds: Vec<ChannelKind> = rec
        .names
        .iter()
        .map(|n| ChannelKind::of(n, labels))
        .collect();
    for k in subset {
        let named = rec.names.iter().any(|n| n == k) || CHANNEL_KINDS.contains(&k.as_str());
        if !named {
            return Err(format!(
                "\"{k}\" is neither a channel of this vehicle nor a kind ({}); a data set's manifest lists them under `channels`",
                CHANNEL_KINDS.join(", ")
            ));
        }
    }
    let keep: Vec<bool> = rec
        .names
        .iter()
        .zip(&kinds)
        .map(|(n, k)| kept(n, *k, subset))
        .collect();
    fn pick<T>(v: &mut Vec<T>, keep: &[bool]) {
        let mut i = 0;
        v.retain(|_| {
            i += 1;
            keep[i - 1]
        })
    }
    pick(&mut rec.names, &keep);
    pick(&mut rec.units, &keep);
    for row in &mut rec.rows {
        pick(row, &keep);
    }
    Ok(())
}

/// Appends `<name>_noisy` copies of the paper's input channels.
pub(super) fn add_noise(rec: &mut Recording, noise: &NoiseModel, seed: u64) {
    let inputs: Vec<(usize, String)> = rec
        .names
        .iter()
        .enumerate()
        .filter(|(_, n)| PAPER_CHANNELS.contains(&n.as_str()))
        .map(|(i, n)| (i, n.clone()))
        .collect();
    for (i, name) in inputs {
        let noisy = noise.apply(&rec.column(i), seed, &name);
        rec.names.push(noisy_name(&name));
        rec.units.push(rec.units[i]);
        for (row, v) in rec.rows.iter_mut().zip(noisy) {
            row.push(v);
        }
    }
}

/// Writes a recording in a format, atomically.
pub fn write_run(path: &Path, rec: &Recording, format: Format, float32: bool) -> Result<()> {
    rec.check_finite(path)?;
    match format {
        Format::Csv => {
            let single: Vec<bool> = rec.names.iter().map(|n| float32 && !keeps_f64(n)).collect();
            crate::io::write_atomic(path, |w| rec.write_csv_as(w, &single))
        }
        Format::Npz | Format::Parquet => {
            let cols: Vec<Vec<f64>> = (0..rec.names.len()).map(|i| rec.column(i)).collect();
            let named: Vec<(&str, &[f64])> = rec
                .names
                .iter()
                .map(|n| n.as_str())
                .zip(cols.iter().map(|c| c.as_slice()))
                .collect();
            if format == Format::Npz {
                crate::io::write_atomic(path, |w| npz::write_npz(w, &named, float32))
            } else {
                let bytes = parquet_file::write_parquet(&named, float32).map_err(|e| {
                    Error::Domain(format!("{}: Parquet encoding failed: {e}", path.display()))
                })?;
                crate::io::write_atomic(path, |w| w.write_all(&bytes))
            }
        }
    }
}

/// What a run file's record says of how it was made: its own `<run>.meta.json` (written by
/// `simulate`) or else its entry in its data set's `manifest.json`. `view` and `assess` read it.
#[derive(Debug, Clone, Default)]
pub struct RecordedRun {
    /// The vehicle file.
    pub vehicle: Option<PathBuf>,
    /// The track file, with its hash and name where recorded.
    pub track: Option<super::FileRef>,
    /// The irregularity seed.
    pub seed: Option<u64>,
    /// The speed, km/h.
    pub speed_kmh: Option<f64>,
}

/// The record of `run_file` ([`RecordedRun`]); empty where neither record exists.
pub fn recorded_run(run_file: &Path) -> RecordedRun {
    let meta = std::fs::read_to_string(run_file.with_extension("meta.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok());
    if let Some(m) = meta {
        let file = |v: &serde_json::Value| v["file"].as_str().map(PathBuf::from);
        let text = |v: &serde_json::Value| v.as_str().unwrap_or_default().to_string();
        return RecordedRun {
            vehicle: file(&m["vehicle"]),
            track: file(&m["track"]).map(|f| super::FileRef {
                file: f,
                hash_fnv1a: text(&m["track"]["hash_fnv1a"]),
                name: text(&m["track"]["name"]),
            }),
            seed: m["seed"].as_u64(),
            speed_kmh: m["speed_kmh"].as_f64(),
        };
    }
    match super::run_entry(run_file) {
        Some((m, r)) => RecordedRun {
            vehicle: Some(m.vehicle.file),
            track: Some(r.track),
            seed: Some(r.realisation_seed.unwrap_or(r.seed)),
            speed_kmh: Some(r.speed_kmh),
        },
        None => RecordedRun::default(),
    }
}
