//! Samples (assets/docs/learning.md §1): split first, window second. The default test is a set of
//! independent runs: whole runs of irregularity seeds the model never saw ([`Split::Seeds`]).
//! Runs can also be cut into contiguous blocks, whole conditions held out, or (labelled as
//! leaky, for comparison only) stride-1 windows shuffled. Windows of `window` steps never
//! cross a block boundary; windows are indices into the runs, not copies. Z-score statistics
//! come from the training rows only.

pub use super::split::Split;
use crate::dataset::{npz, parquet_file};
use crate::error::{Error, Result};
use crate::sensors::{NoiseModel, SnrReference, label_channels};
use serde::{Deserialize, Serialize};
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
        let text = crate::io::read_text(&mpath)?;
        let m: serde_json::Value = serde_json::from_str(&text).map_err(|e| Error::Parse {
            file: mpath.clone(),
            message: e.to_string(),
        })?;
        let runs_meta = m["runs"].as_array().cloned().unwrap_or_default();
        if runs_meta.is_empty() {
            return Err(Error::config(&mpath, "runs", "the manifest lists no runs"));
        }
        let mut names: Option<Vec<String>> = None;
        let mut runs = Vec::new();
        for r in runs_meta {
            let file = dir.join(r["file"].as_str().unwrap_or_default());
            let cols = read_table(&file)?;
            let these: Vec<String> = cols.iter().map(|(n, _)| n.clone()).collect();
            match &names {
                None => names = Some(these),
                Some(n) if *n != these => {
                    return Err(Error::Parse {
                        file,
                        message: "its channels differ from the first run's".into(),
                    });
                }
                _ => {}
            }
            runs.push(Run {
                condition: r["condition"].as_str().unwrap_or_default().to_string(),
                seed: r["seed"].as_u64().unwrap_or(0),
                columns: cols.into_iter().map(|(_, v)| v).collect(),
            });
        }
        let labels = match (
            m["conventions"]["labels"]["FL"].as_str(),
            m["conventions"]["labels"]["FQ"].as_str(),
        ) {
            (Some(fl), Some(fq)) => [fl.to_string(), fq.to_string()],
            _ => label_channels("1L"),
        };
        let noise = match m["snr_db"].as_f64() {
            None => None,
            Some(snr) => {
                let reference = match &m["snr_reference"] {
                    // Data sets written before the reference was recorded used the rms.
                    serde_json::Value::Null => SnrReference::Rms,
                    r => r.as_str().and_then(SnrReference::parse).ok_or_else(|| {
                        Error::config(
                            &mpath,
                            "snr_reference",
                            format!("{r} is not a noise reference: std or rms"),
                        )
                    })?,
                };
                Some(NoiseModel::new(snr, reference))
            }
        };
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

/// Reads a table of named f64 columns from an `.npz`, `.parquet` or CSV file (by extension).
/// Every column has the same length (a run cut short, or one array of another length, is
/// refused naming the file and the column), so readers may index any column by row.
pub fn read_table(file: &Path) -> Result<Vec<(String, Vec<f64>)>> {
    let bytes = std::fs::read(file).map_err(|e| Error::io(file, e))?;
    let ext = file.extension().map(|e| e.to_string_lossy().into_owned());
    let table = match ext.as_deref() {
        Some("npz") => npz::read_npz(&bytes).map_err(|e| Error::io(file, e))?,
        Some("parquet") => parquet_file::read_parquet(bytes).map_err(|e| Error::Parse {
            file: file.to_path_buf(),
            message: e.to_string(),
        })?,
        _ => read_csv(&bytes, file)?,
    };
    let Some((first, x)) = table.first() else {
        return Err(Error::Parse {
            file: file.to_path_buf(),
            message: "holds no columns (empty, or cut short)".into(),
        });
    };
    if let Some((name, y)) = table.iter().find(|(_, y)| y.len() != x.len()) {
        return Err(Error::Parse {
            file: file.to_path_buf(),
            message: format!(
                "column {name} has {} rows but column {first} has {}: the file is cut short or mixes runs",
                y.len(),
                x.len()
            ),
        });
    }
    Ok(table)
}

/// Parses CSV text with a header of column names (as [`read_table`] does for `.csv`). Every
/// row must have as many fields as the header: a row cut short (a file truncated mid-row) or
/// one with extra fields is refused, naming the row counted from 1 after the header.
pub fn read_csv(bytes: &[u8], file: &Path) -> Result<Vec<(String, Vec<f64>)>> {
    let text = String::from_utf8_lossy(bytes);
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap_or_default()
        .split(',')
        .map(|s| s.to_string())
        .collect();
    let mut cols = vec![Vec::new(); header.len()];
    let parse_err = |message: String| Error::Parse {
        file: file.to_path_buf(),
        message,
    };
    for (ln, line) in lines.enumerate() {
        let fields = line.split(',').count();
        if fields != header.len() {
            return Err(parse_err(format!(
                "row {} has {fields} field(s) but the header names {} columns{}",
                ln + 1,
                header.len(),
                if fields < header.len() {
                    " (the file may be cut short)"
                } else {
                    ""
                }
            )));
        }
        for (k, v) in line.split(',').enumerate() {
            let x: f64 = v.parse().map_err(|_| {
                // The same wording as the identify checks: column, row from 1 after the header.
                parse_err(format!(
                    "column {}, row {}: \"{v}\" is not a number",
                    header[k],
                    ln + 1
                ))
            })?;
            cols[k].push(x);
        }
    }
    Ok(header.into_iter().zip(cols).collect())
}

/// Where the label of a window sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum LabelAt {
    /// The last step (causal: usable on board in real time).
    Last,
    /// The centre step (non-causal, as the paper reads).
    Centre,
}

/// A window: steps `start .. start + window` of run `run`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    /// Run index.
    pub run: u32,
    /// First step.
    pub start: u32,
}

/// A block of rows `[from, to)` of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Block {
    /// Run index.
    pub run: usize,
    /// First row.
    pub from: usize,
    /// One past the last row.
    pub to: usize,
}

/// Windows of the three parts, and the blocks they come from.
#[derive(Debug, Clone)]
pub struct Samples {
    /// Steps per window.
    pub window: usize,
    /// Label position.
    pub label_at: LabelAt,
    /// Training blocks.
    pub train_blocks: Vec<Block>,
    /// Validation blocks.
    pub val_blocks: Vec<Block>,
    /// Test blocks.
    pub test_blocks: Vec<Block>,
    /// Windows per part.
    pub train: Vec<Window>,
    /// See `train`.
    pub val: Vec<Window>,
    /// See `train`.
    pub test: Vec<Window>,
}

impl Samples {
    /// Splits and windows a data set.
    pub fn build(
        ds: &DataSet,
        split: &Split,
        window: usize,
        stride: usize,
        label_at: LabelAt,
    ) -> Result<Self> {
        if window == 0 || stride == 0 {
            return Err(Error::Domain("window and stride must be at least 1".into()));
        }
        split.check()?;
        if let Split::Shuffled { train, val, seed } = split {
            return Self::shuffled(ds, window, label_at, *train, *val, *seed);
        }
        let (mut tr, mut va, mut te) = (Vec::new(), Vec::new(), Vec::new());
        for (i, run) in ds.runs.iter().enumerate() {
            let n = run.len();
            match split {
                Split::Shuffled { .. } => unreachable!("handled above"),
                Split::Seeds { train, val, test } => {
                    let block = Block {
                        run: i,
                        from: 0,
                        to: n,
                    };
                    if test.contains(&run.seed) {
                        te.push(block);
                    } else if val.contains(&run.seed) {
                        va.push(block);
                    } else if train.contains(&run.seed) {
                        tr.push(block);
                    }
                }
                Split::Blocks { train, val } => {
                    if !(*train > 0.0 && *val >= 0.0 && train + val < 1.0) {
                        return Err(Error::Domain(format!(
                            "block fractions must satisfy 0 < train, 0 ≤ val, train + val < 1 (got {train}, {val})"
                        )));
                    }
                    let a = (n as f64 * train).round() as usize;
                    let b = (n as f64 * (train + val)).round() as usize;
                    tr.push(Block {
                        run: i,
                        from: 0,
                        to: a,
                    });
                    va.push(Block {
                        run: i,
                        from: a,
                        to: b,
                    });
                    te.push(Block {
                        run: i,
                        from: b,
                        to: n,
                    });
                }
                Split::Runs { val, test } => {
                    let block = Block {
                        run: i,
                        from: 0,
                        to: n,
                    };
                    if test.contains(&i) {
                        te.push(block);
                    } else if val.contains(&i) {
                        va.push(block);
                    } else {
                        tr.push(block);
                    }
                }
                Split::Conditions { val, test } => {
                    let block = Block {
                        run: i,
                        from: 0,
                        to: n,
                    };
                    if test.contains(&run.condition) {
                        te.push(block);
                    } else if val.contains(&run.condition) {
                        va.push(block);
                    } else {
                        tr.push(block);
                    }
                }
            }
        }
        let windows = |blocks: &[Block], stride: usize| -> Vec<Window> {
            let mut out = Vec::new();
            for b in blocks {
                let mut s = b.from;
                while s + window <= b.to {
                    out.push(Window {
                        run: b.run as u32,
                        start: s as u32,
                    });
                    s += stride;
                }
            }
            out
        };
        Ok(Samples {
            window,
            label_at,
            train: windows(&tr, stride),
            val: windows(&va, 1),
            test: windows(&te, 1),
            train_blocks: tr,
            val_blocks: va,
            test_blocks: te,
        })
    }

    /// Stride-1 windows of whole runs, shuffled into the parts (leaky: for comparison only).
    fn shuffled(
        ds: &DataSet,
        window: usize,
        label_at: LabelAt,
        train: f64,
        val: f64,
        seed: u64,
    ) -> Result<Self> {
        use rand::seq::SliceRandom;
        if !(train > 0.0 && val >= 0.0 && train + val < 1.0) {
            return Err(Error::Domain(format!(
                "shuffled fractions must satisfy 0 < train, 0 ≤ val, train + val < 1 (got {train}, {val})"
            )));
        }
        let blocks: Vec<Block> = (0..ds.runs.len())
            .map(|i| Block {
                run: i,
                from: 0,
                to: ds.runs[i].len(),
            })
            .collect();
        let mut all = Vec::new();
        for b in &blocks {
            for s in (b.from..).take_while(|s| s + window <= b.to) {
                all.push(Window {
                    run: b.run as u32,
                    start: s as u32,
                });
            }
        }
        all.shuffle(&mut crate::sensors::noise::rng(seed, 0x5348_5546));
        let a = (all.len() as f64 * train).round() as usize;
        let b = (all.len() as f64 * (train + val)).round() as usize;
        Ok(Samples {
            window,
            label_at,
            test: all[b..].to_vec(),
            val: all[a..b].to_vec(),
            train: all[..a].to_vec(),
            train_blocks: blocks,
            val_blocks: Vec::new(),
            test_blocks: Vec::new(),
        })
    }

    /// Row of a window's label.
    pub fn label_row(&self, w: &Window) -> usize {
        w.start as usize
            + match self.label_at {
                LabelAt::Last => self.window - 1,
                LabelAt::Centre => self.window / 2,
            }
    }
}

/// Mean and standard deviation per channel, from the training blocks only.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ZScore {
    /// Channel names.
    pub names: Vec<String>,
    /// Means.
    pub mean: Vec<f64>,
    /// Standard deviations (1 where a channel is constant).
    pub std: Vec<f64>,
}

impl ZScore {
    /// Statistics of `channels` over the training blocks.
    pub fn fit(ds: &DataSet, blocks: &[Block], channels: &[usize]) -> Self {
        let mut mean = vec![0.0; channels.len()];
        let mut sq = vec![0.0; channels.len()];
        let mut n = 0usize;
        for b in blocks {
            for r in b.from..b.to {
                for (k, &c) in channels.iter().enumerate() {
                    let v = ds.runs[b.run].columns[c][r];
                    mean[k] += v;
                    sq[k] += v * v;
                }
                n += 1;
            }
        }
        let n = n.max(1) as f64;
        let mean: Vec<f64> = mean.iter().map(|m| m / n).collect();
        let std = sq
            .iter()
            .zip(&mean)
            .map(|(s, m)| {
                let v = (s / n - m * m).max(0.0).sqrt();
                if v > 0.0 { v } else { 1.0 }
            })
            .collect();
        ZScore {
            names: channels.iter().map(|&c| ds.names[c].clone()).collect(),
            mean,
            std,
        }
    }

    /// Standardised value of channel `k` (position in this statistic).
    #[inline]
    pub fn apply(&self, k: usize, v: f64) -> f64 {
        (v - self.mean[k]) / self.std[k]
    }
}

/// Which inputs each part reads when the data set has `_noisy` copies (assets/docs/learning.md §1.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum NoiseProtocol {
    /// Train and validate on clean inputs, test on noisy ones.
    TrainCleanTestNoisy,
    /// Every part reads the noisy inputs (train and test at the same SNR).
    Matched,
    /// No noise anywhere.
    Clean,
}

impl NoiseProtocol {
    /// Parses `clean`, `matched` or `train-clean-test-noisy` (the names `train --noise` takes).
    pub fn parse(name: &str) -> Option<Self> {
        match name {
            "clean" => Some(Self::Clean),
            "matched" => Some(Self::Matched),
            "train-clean-test-noisy" => Some(Self::TrainCleanTestNoisy),
            _ => None,
        }
    }
}

/// A part of the samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// Training windows.
    Train,
    /// Validation windows.
    Val,
    /// Test windows.
    Test,
}

impl NoiseProtocol {
    /// In words, for people (`train and test on noisy inputs`).
    pub fn describe(self) -> &'static str {
        match self {
            NoiseProtocol::Clean => "clean inputs throughout",
            NoiseProtocol::Matched => "trained and tested on noisy inputs (matched)",
            NoiseProtocol::TrainCleanTestNoisy => "trained on clean inputs, tested on noisy ones",
        }
    }

    /// The column a part reads for the input `channel`.
    pub fn column(self, channel: &str, part: Part) -> String {
        let noisy = match self {
            NoiseProtocol::Clean => false,
            NoiseProtocol::Matched => true,
            NoiseProtocol::TrainCleanTestNoisy => part == Part::Test,
        };
        if noisy {
            format!("{channel}_noisy")
        } else {
            channel.to_string()
        }
    }
}
