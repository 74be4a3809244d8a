//! A data set on disk, read through its manifest: the runs' columns in one channel order, the
//! label channels, and the noise of the `_noisy` copies. The data set's one owner of what is
//! on disk is this module (`dataset`); learning reads it, never the files.

use super::manifest::Manifest;
use super::table::read_table;
use crate::error::{Error, Result};
use crate::sensors::{NoiseModel, label_channels};
use std::path::{Path, PathBuf};

/// One run of a data set: its columns in the data set's channel order.
#[derive(Debug, Clone)]
pub struct Run {
    /// Condition name.
    pub condition: String,
    /// Seed.
    pub seed: u64,
    /// Columns (same order as [`DataSet::names`]).
    pub columns: Vec<Vec<f64>>,
}

impl Run {
    /// Number of time steps.
    pub fn len(&self) -> usize {
        self.columns.first().map(|c| c.len()).unwrap_or(0)
    }

    /// Whether the run has no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A data set written by `railforce generate`, read through its manifest.
#[derive(Debug, Clone)]
pub struct DataSet {
    /// Folder.
    pub dir: PathBuf,
    /// Channel names.
    pub names: Vec<String>,
    /// Runs in manifest order.
    pub runs: Vec<Run>,
    /// The label channels FL and FQ (the vehicle's label wheel, manifest
    /// `conventions.labels`; `w1l_force_y`/`w1l_force_z` where it says nothing).
    pub labels: [String; 2],
    /// The noise of the `_noisy` copies, as the manifest records it (`None`: clean data).
    pub noise: Option<NoiseModel>,
}

impl DataSet {
    /// The SNR of the noisy input copies, dB (`None` for a clean data set).
    pub fn snr_db(&self) -> Option<f64> {
        self.noise.map(|n| n.snr_db)
    }

    /// A data set held in memory, clean, labelled on wheel 1L.
    pub fn in_memory(dir: &Path, names: Vec<String>, runs: Vec<Run>) -> Self {
        DataSet {
            dir: dir.to_path_buf(),
            names,
            runs,
            labels: label_channels("1L"),
            noise: None,
        }
    }

    /// The label channels a target list names (comma separated): `FL`, `FQ`, `both`, a wheel
    /// (`w2r` or `2R`: its Y and Q), or a channel name; in the order given, without repeats.
    /// Unknown names are refused with what is accepted.
    pub fn targets(&self, list: &str) -> Result<Vec<String>> {
        let mut out: Vec<String> = Vec::new();
        for item in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let wheel = item.to_ascii_lowercase();
            let wheel = if wheel.len() == 2 && wheel.as_bytes()[0].is_ascii_digit() {
                format!("w{wheel}")
            } else {
                wheel
            };
            let names: Vec<String> = match item {
                "both" => self.labels.to_vec(),
                "FL" | "FQ" => vec![self.target_channel(item)],
                _ if self.channel(&format!("{wheel}_force_y")).is_ok() => {
                    vec![format!("{wheel}_force_y"), format!("{wheel}_force_z")]
                }
                _ if self.channel(item).is_ok() && !crate::sensors::is_noisy(item) => {
                    vec![item.to_string()]
                }
                _ => {
                    return Err(Error::Domain(format!(
                        "unknown target {item}: use FL, FQ, both, a wheel (w1l … w4r, or 1L … 4R) or a channel such as w2r_force_y, comma separated"
                    )));
                }
            };
            for n in names {
                if !out.contains(&n) {
                    out.push(n);
                }
            }
        }
        if out.is_empty() {
            return Err(Error::Domain("no target given".into()));
        }
        Ok(out)
    }

    /// Resolves `FL`/`FQ` to this data set's label channels; any other name is a channel.
    pub fn target_channel(&self, target: &str) -> String {
        match target {
            "FL" => self.labels[0].clone(),
            "FQ" => self.labels[1].clone(),
            other => other.to_string(),
        }
    }

    /// A copy with `<channel>_noisy` copies of `channels` drawn with `noise` (replacing any
    /// noisy columns), seeded by each run's seed and channel name: the same noise
    /// `railforce generate --snr-db` writes.
    pub fn with_noise(&self, noise: NoiseModel, channels: &[String]) -> Result<DataSet> {
        let keep: Vec<usize> = (0..self.names.len())
            .filter(|&i| !crate::sensors::is_noisy(&self.names[i]))
            .collect();
        let base = channels
            .iter()
            .map(|c| self.channel(c))
            .collect::<Result<Vec<_>>>()?;
        let mut out = DataSet {
            names: keep.iter().map(|&i| self.names[i].clone()).collect(),
            runs: Vec::with_capacity(self.runs.len()),
            noise: Some(noise),
            ..self.clone_empty()
        };
        out.names
            .extend(channels.iter().map(|c| crate::sensors::noisy_name(c)));
        for run in &self.runs {
            let mut cols: Vec<Vec<f64>> = keep.iter().map(|&i| run.columns[i].clone()).collect();
            for (&c, name) in base.iter().zip(channels) {
                cols.push(noise.apply(&run.columns[c], run.seed, name));
            }
            out.runs.push(Run {
                condition: run.condition.clone(),
                seed: run.seed,
                columns: cols,
            });
        }
        Ok(out)
    }

    /// The runs whose condition is in `conditions`, and only the columns `channels`.
    pub fn subset(
        &self,
        conditions: Option<&[String]>,
        channels: Option<&[String]>,
    ) -> Result<DataSet> {
        let idx: Vec<usize> = match channels {
            Some(c) => c.iter().map(|n| self.channel(n)).collect::<Result<_>>()?,
            None => (0..self.names.len()).collect(),
        };
        Ok(DataSet {
            names: idx.iter().map(|&i| self.names[i].clone()).collect(),
            runs: self
                .runs
                .iter()
                .filter(|r| conditions.is_none_or(|c| c.contains(&r.condition)))
                .map(|r| Run {
                    condition: r.condition.clone(),
                    seed: r.seed,
                    columns: idx.iter().map(|&i| r.columns[i].clone()).collect(),
                })
                .collect(),
            ..self.clone_empty()
        })
    }

    fn clone_empty(&self) -> DataSet {
        DataSet {
            dir: self.dir.clone(),
            names: Vec::new(),
            runs: Vec::new(),
            labels: self.labels.clone(),
            noise: self.noise,
        }
    }

    /// `names` without the channels that repeat an earlier one of the list value for value on
    /// every run (one signal recorded under two names, such as the paper's `ws1_acc_y` and
    /// the body signal `wheelset1_acc_y`: one sensor, one candidate). Unknown names are kept.
    pub fn distinct_channels(&self, names: &[String]) -> Vec<String> {
        let mut kept: Vec<(String, Option<usize>)> = Vec::new();
        for n in names {
            let c = self.channel(n).ok();
            let repeats = c.is_some_and(|c| {
                kept.iter().any(|(_, k)| {
                    k.is_some_and(|k| self.runs.iter().all(|r| r.columns[k] == r.columns[c]))
                })
            });
            if !repeats {
                kept.push((n.clone(), c));
            }
        }
        kept.into_iter().map(|(n, _)| n).collect()
    }

    /// The distinct seeds of the runs, ascending.
    pub fn seeds(&self) -> Vec<u64> {
        let s: std::collections::BTreeSet<u64> = self.runs.iter().map(|r| r.seed).collect();
        s.into_iter().collect()
    }

    /// Reads `manifest.json` and every run file it lists (npz, parquet or csv).
    pub fn load(dir: &Path) -> Result<Self> {
        let mpath = dir.join("manifest.json");
        let m = Manifest::load(dir)?;
        if m.runs.is_empty() {
            return Err(Error::config(&mpath, "runs", "the manifest lists no runs"));
        }
        // The manifest's own fields first: a bad one fails before any run is read.
        let (labels, noise) = (m.labels(), m.noise_model(&mpath)?);
        let mut names: Option<Vec<String>> = None;
        let mut runs = Vec::new();
        for r in &m.runs {
            let file = dir.join(&r.file);
            let cols = read_table(&file)?;
            // A NaN or infinity in a run would reach training, calibration and every metric
            // unnoticed: refused here, by column and row.
            for (name, v) in &cols {
                if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                    return Err(Error::config(
                        &file,
                        format!("{name}[{i}]"),
                        format!("{} is not a finite number", v[i]),
                    ));
                }
            }
            let these: Vec<String> = cols.iter().map(|(n, _)| n.clone()).collect();
            match &names {
                None => names = Some(these),
                Some(n) if *n != these => {
                    return Err(Error::Parse {
                        file,
                        message: channels_differ(n, &these),
                    });
                }
                _ => {}
            }
            runs.push(Run {
                condition: r.condition.clone(),
                seed: r.seed,
                columns: cols.into_iter().map(|(_, v)| v).collect(),
            });
        }
        Ok(DataSet {
            dir: dir.to_path_buf(),
            names: names.unwrap_or_default(),
            runs,
            labels,
            noise,
        })
    }

    /// Index of a channel, or an error naming it and the data set.
    pub fn channel(&self, name: &str) -> Result<usize> {
        self.names.iter().position(|n| n == name).ok_or_else(|| {
            Error::Domain(format!(
                "unknown channel '{name}' in {} (it has {} channels, e.g. {})",
                self.dir.display(),
                self.names.len(),
                self.names
                    .iter()
                    .take(5)
                    .cloned()
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })
    }
}

/// Why a run's channels differ from the first run's: the first channel one has and the other
/// lacks, or the first place their order differs.
fn channels_differ(first: &[String], these: &[String]) -> String {
    if let Some(c) = first.iter().find(|c| !these.contains(c)) {
        return format!("its channels differ from the first run's: it lacks '{c}'");
    }
    if let Some(c) = these.iter().find(|c| !first.contains(c)) {
        return format!(
            "its channels differ from the first run's: it has '{c}', which the first lacks"
        );
    }
    match first.iter().zip(these).position(|(a, b)| a != b) {
        Some(i) => format!(
            "its channels differ from the first run's: column {i} is '{}', the first run's '{}'",
            these[i], first[i]
        ),
        None => format!(
            "its channels differ from the first run's: {} columns against {} (a name repeated)",
            these.len(),
            first.len()
        ),
    }
}
