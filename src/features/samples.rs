//! Samples (assets/docs/learning.md §1): split first, window second. The default test is a set of
//! independent runs: whole runs of irregularity seeds the model never saw ([`Split::Seeds`]).
//! Runs can also be cut into contiguous blocks, whole conditions held out, or (labelled as
//! leaky, for comparison only) stride-1 windows shuffled. Windows of `window` steps never
//! cross a block boundary; windows are indices into the runs, not copies. Z-score statistics
//! come from the training rows only.

pub use super::split::Split;
use crate::dataset::DataSet;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Where the label of a window sits. The default is the centre, the paper's "intermediate
/// time point", in every front end (`train --label`, Python's `windows(label=…)`,
/// `WindowDataset`, the experiments).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum LabelAt {
    /// The last step (causal: usable on board in real time).
    Last,
    /// The centre step (non-causal, as the paper reads).
    #[default]
    Centre,
}

impl LabelAt {
    /// The names both front ends accept, the default first (`center` too, as [`Self::parse`]).
    pub const NAMES: [&'static str; 3] = ["centre", "last", "center"];

    /// The position a name gives (`centre`, `center` or `last`); the error names the choices.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "centre" | "center" => Ok(LabelAt::Centre),
            "last" => Ok(LabelAt::Last),
            _ => Err(Error::Domain(format!(
                "label {name}: centre (the paper's, the default) or last (causal)"
            ))),
        }
    }

    /// The name [`Self::parse`] reads back.
    pub fn name(self) -> &'static str {
        match self {
            LabelAt::Centre => "centre",
            LabelAt::Last => "last",
        }
    }
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
                    let a = crate::bounds::to_count((n as f64 * train).round());
                    let b = crate::bounds::to_count((n as f64 * (train + val)).round());
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
        let a = crate::bounds::to_count((all.len() as f64 * train).round());
        let b = crate::bounds::to_count((all.len() as f64 * (train + val)).round());
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
    /// Checks statistics read from a file: one mean and one standard deviation per name,
    /// every mean finite, every standard deviation finite and above zero (a zero would
    /// divide every input into infinities, a negative flip its sign). The error names the
    /// file, the field and the channel.
    pub fn check(&self, file: &std::path::Path, field: &str) -> Result<()> {
        let n = self.names.len();
        if self.mean.len() != n || self.std.len() != n {
            return Err(Error::config(
                file,
                field,
                format!(
                    "{} names, {} means and {} standard deviations: one of each per channel",
                    n,
                    self.mean.len(),
                    self.std.len()
                ),
            ));
        }
        for ((name, m), s) in self.names.iter().zip(&self.mean).zip(&self.std) {
            if !m.is_finite() {
                return Err(Error::config(
                    file,
                    format!("{field}.mean"),
                    format!("{name}: {m} is not a finite mean"),
                ));
            }
            if !(s.is_finite() && *s > 0.0) {
                return Err(Error::config(
                    file,
                    format!("{field}.std"),
                    format!("{name}: {s}: a standard deviation must be finite and above zero"),
                ));
            }
        }
        Ok(())
    }

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
