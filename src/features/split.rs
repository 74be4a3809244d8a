//! How the runs of a data set are split into training, validation and test parts
//! (assets/docs/learning.md §1.1): by seed (the default), in contiguous blocks, by condition, or
//! shuffled (leaky, labelled so).

use crate::dataset::DataSet;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// How runs are split.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Split {
    /// Whole runs by irregularity seed (the default, assets/docs/learning.md §1.1): a seed never
    /// serves two parts; the test runs are independent stretches of track.
    Seeds {
        /// Training seeds.
        train: Vec<u64>,
        /// Validation seeds.
        val: Vec<u64>,
        /// Test seeds.
        test: Vec<u64>,
    },
    /// Stride-1 windows of whole runs shuffled into parts. Leaky (neighbouring windows share
    /// all but one step): it exists only to show what such a protocol reports.
    Shuffled {
        /// Training fraction.
        train: f64,
        /// Validation fraction.
        val: f64,
        /// Shuffling seed.
        seed: u64,
    },
    /// Contiguous blocks of every run: the first `train`, then `val`, the rest test.
    Blocks {
        /// Training fraction.
        train: f64,
        /// Validation fraction.
        val: f64,
    },
    /// Whole runs (by position in the data set) held out for validation and test.
    Runs {
        /// Validation runs.
        val: Vec<usize>,
        /// Test runs.
        test: Vec<usize>,
    },
    /// Whole conditions held out for validation and test; all others train.
    Conditions {
        /// Validation conditions.
        val: Vec<String>,
        /// Test conditions.
        test: Vec<String>,
    },
}

/// 70/15/15 % contiguous blocks: the split every data set allows, even with one seed.
impl Default for Split {
    fn default() -> Self {
        Split::Blocks {
            train: 0.70,
            val: 0.15,
        }
    }
}

impl Split {
    /// The leaky shuffled split at its fractions, 70 % training and 15 % validation (the rest
    /// test), shuffled with `seed`: one definition for `train --split shuffled` and the
    /// protocols experiment.
    pub fn shuffled(seed: u64) -> Split {
        Split::Shuffled {
            train: 0.70,
            val: 0.15,
            seed,
        }
    }

    /// The protocol's default for a data set (assets/docs/learning.md §1.1): by seed when it has at
    /// least three (the last tests, the one before validates, the rest train), else
    /// 70/15/15 % blocks (say so: a data set of one seed cannot test on independent runs).
    pub fn standard(ds: &DataSet) -> Split {
        let seeds = ds.seeds();
        if seeds.len() >= 3 {
            let n = seeds.len();
            Split::Seeds {
                train: seeds[..n - 2].to_vec(),
                val: vec![seeds[n - 2]],
                test: vec![seeds[n - 1]],
            }
        } else {
            Split::default()
        }
    }

    /// Checks a seed split: no seed in two parts, every part non-empty.
    pub fn check(&self) -> Result<()> {
        if let Split::Seeds { train, val, test } = self {
            for (a, an, b, bn) in [
                (train, "train", val, "validation"),
                (train, "train", test, "test"),
                (val, "validation", test, "test"),
            ] {
                if let Some(s) = a.iter().find(|s| b.contains(s)) {
                    return Err(Error::Domain(format!(
                        "seed {s} is in both the {an} and the {bn} seeds: a seed never serves two parts"
                    )));
                }
            }
            if train.is_empty() || test.is_empty() {
                return Err(Error::Domain(
                    "a seed split needs at least one training and one test seed".into(),
                ));
            }
        }
        Ok(())
    }

    /// Short name: `seeds`, `blocks`, `conditions`, `runs` or `shuffled`.
    pub fn name(&self) -> &'static str {
        match self {
            Split::Seeds { .. } => "seeds",
            Split::Blocks { .. } => "blocks",
            Split::Runs { .. } => "runs",
            Split::Conditions { .. } => "conditions",
            Split::Shuffled { .. } => "shuffled",
        }
    }

    /// One line for tables and reports.
    pub fn describe(&self) -> String {
        let list = |v: &[u64]| {
            v.iter()
                .map(|s| s.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        match self {
            Split::Seeds { train, val, test } => format!(
                "by seed: train on seeds {}, validate on {}, test on whole runs of seed {} (independent track irregularities)",
                list(train),
                list(val),
                list(test)
            ),
            Split::Blocks { train, val } => format!(
                "blocks: each run cut into contiguous {:.0}/{:.0}/{:.0} % train/validation/test blocks (the test block is the end of each run)",
                100.0 * train,
                100.0 * val,
                100.0 * (1.0 - train - val)
            ),
            Split::Runs { val, test } => {
                format!("whole runs held out: validation {val:?}, test {test:?}")
            }
            Split::Conditions { val, test } => format!(
                "whole conditions held out: test {}, validation {}",
                test.join(", "),
                val.join(", ")
            ),
            Split::Shuffled { train, val, .. } => format!(
                "SHUFFLED (leaky): stride-1 windows shuffled {:.0}/{:.0}/{:.0} % into train/validation/test; neighbouring windows share all but one step, so the test is not independent",
                100.0 * train,
                100.0 * val,
                100.0 * (1.0 - train - val)
            ),
        }
    }
}

/// What a user asks of the split, before it is resolved against a data set: a kind
/// (`seeds`, `blocks`, `conditions`, `shuffled`; none: the protocol's default), seeds for the
/// seed split's parts, conditions held out.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SplitRequest {
    /// The kind, as named in [`Split::name`]; `None`: from what else is given.
    pub kind: Option<String>,
    /// Training seeds instead of all but the last two.
    pub train_seeds: Vec<u64>,
    /// Validation seeds instead of the one before last.
    pub val_seeds: Vec<u64>,
    /// Test seeds instead of the last.
    pub test_seeds: Vec<u64>,
    /// Conditions held out for validation.
    pub val_conditions: Vec<String>,
    /// Conditions held out for the test.
    pub test_conditions: Vec<String>,
}

/// The kinds a [`SplitRequest`] names.
pub const SPLIT_KINDS: [&str; 4] = ["seeds", "blocks", "conditions", "shuffled"];

impl Split {
    /// Resolves `req` against the data set's seeds and conditions: held-out conditions give
    /// the condition split, given seeds the seed split, nothing the protocol's default
    /// ([`Split::standard`]). Every seed and condition must be in the data set, and no seed
    /// serves two parts.
    pub fn resolve(req: &SplitRequest, ds: &DataSet) -> Result<Split> {
        let seeds_given =
            !(req.train_seeds.is_empty() && req.val_seeds.is_empty() && req.test_seeds.is_empty());
        let kind = match req.kind.as_deref() {
            Some(k) => k,
            None if !req.test_conditions.is_empty() => "conditions",
            None if seeds_given => "seeds",
            None => return Ok(Split::standard(ds)),
        };
        let split = match kind {
            "blocks" => Split::default(),
            "shuffled" => Split::shuffled(1),
            "conditions" => {
                if req.test_conditions.is_empty() {
                    return Err(Error::Domain(
                        "the condition split needs test conditions (and validation conditions)"
                            .into(),
                    ));
                }
                let mut known: Vec<&str> = ds.runs.iter().map(|r| r.condition.as_str()).collect();
                known.sort_unstable();
                known.dedup();
                for (part, list) in [
                    ("test conditions", &req.test_conditions),
                    ("validation conditions", &req.val_conditions),
                ] {
                    if let Some(c) = list.iter().find(|c| !known.contains(&c.as_str())) {
                        return Err(Error::Domain(format!(
                            "{part}: unknown condition {c}; {} has: {}",
                            ds.dir.display(),
                            known.join(", ")
                        )));
                    }
                }
                Split::Conditions {
                    val: req.val_conditions.clone(),
                    test: req.test_conditions.clone(),
                }
            }
            "seeds" => {
                let all = ds.seeds();
                let (mut train, mut val, mut test) = match Split::standard(ds) {
                    Split::Seeds { train, val, test } => (train, val, test),
                    _ if seeds_given => (Vec::new(), Vec::new(), Vec::new()),
                    _ => {
                        return Err(Error::Domain(format!(
                            "the seed split needs three or more seeds in {} (it has {all:?}); generate more with the plan's `seeds`, or name the training, validation and test seeds",
                            ds.dir.display()
                        )));
                    }
                };
                for (given, part) in [
                    (&req.train_seeds, &mut train),
                    (&req.val_seeds, &mut val),
                    (&req.test_seeds, &mut test),
                ] {
                    if !given.is_empty() {
                        *part = given.clone();
                    }
                }
                for s in train.iter().chain(&val).chain(&test) {
                    if !all.contains(s) {
                        return Err(Error::Domain(format!(
                            "seed {s} is not in {} (it has {all:?})",
                            ds.dir.display()
                        )));
                    }
                }
                Split::Seeds { train, val, test }
            }
            other => {
                return Err(Error::Domain(format!(
                    "unknown split {other}: {}",
                    SPLIT_KINDS.join(", ")
                )));
            }
        };
        split.check()?;
        Ok(split)
    }
}
