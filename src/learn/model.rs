//! A trained model and its directory: `model.json` (kind, shape, data spec, z-score
//! statistics, training summary) beside the weights (`weights.bin` for networks,
//! `model.bin` for classical regressors). Everything `evaluate` and `identify` need.

use super::classical::Classical;
use super::neural::params::Slot;
use super::neural::{Architecture, NetConfig, Network};
use super::windows::DataSpec;
use crate::error::{Error, Result};
use crate::features::ZScore;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Every model of the comparison.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ModelKind {
    /// The paper's network.
    CnnBiLstm,
    /// Convolutional baseline.
    Cnn,
    /// BiLSTM baseline.
    BiLstm,
    /// GRU baseline.
    Gru,
    /// Support-vector regression, RBF kernel.
    Svr,
    /// Gradient-boosted trees (100 trees, depth 3, learning rate 0.1).
    Gbdt,
    /// XGBoost-style histogram boosting (300 trees, depth 6, learning rate 0.1).
    Xgboost,
    /// One regression tree.
    Tree,
}

impl ModelKind {
    /// All kinds in the paper's table order.
    pub const ALL: [ModelKind; 8] = [
        ModelKind::CnnBiLstm,
        ModelKind::Cnn,
        ModelKind::BiLstm,
        ModelKind::Gru,
        ModelKind::Svr,
        ModelKind::Gbdt,
        ModelKind::Xgboost,
        ModelKind::Tree,
    ];

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::CnnBiLstm => "cnn-bilstm",
            ModelKind::Cnn => "cnn",
            ModelKind::BiLstm => "bilstm",
            ModelKind::Gru => "gru",
            ModelKind::Svr => "svr",
            ModelKind::Gbdt => "gbdt",
            ModelKind::Xgboost => "xgboost",
            ModelKind::Tree => "tree",
        }
    }

    /// Parses a command-line name.
    pub fn parse(s: &str) -> Result<Self> {
        ModelKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = ModelKind::ALL.iter().map(|k| k.name()).collect();
                Error::Domain(format!("unknown model `{s}` (one of {})", names.join(", ")))
            })
    }

    /// The network architecture, for the neural kinds.
    pub fn architecture(self) -> Option<Architecture> {
        match self {
            ModelKind::CnnBiLstm => Some(Architecture::CnnBiLstm),
            ModelKind::Cnn => Some(Architecture::Cnn),
            ModelKind::BiLstm => Some(Architecture::BiLstm),
            ModelKind::Gru => Some(Architecture::Gru),
            _ => None,
        }
    }
}

/// What `model.json` holds.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ModelMeta {
    /// Kind.
    pub kind: ModelKind,
    /// Windows the model reads.
    pub data: DataSpec,
    /// Input statistics (training blocks only).
    pub input_stats: ZScore,
    /// Target statistics (training blocks only).
    pub target_stats: ZScore,
    /// Network shape (neural kinds).
    pub net: Option<NetConfig>,
    /// Weight layout (neural kinds).
    pub slots: Option<Vec<Slot>>,
    /// Data set identity: manifest hash and folder.
    pub data_identity: serde_json::Value,
    /// Training summary (epochs, best validation loss, timings, settings).
    pub training: serde_json::Value,
    /// railforce version that trained it.
    pub version: String,
    /// Members of the ensemble (1: a single model); members 2… keep their weights in
    /// `weights_member<k>.bin` / `model_member<k>.bin`.
    #[serde(default = "one", skip_serializing_if = "is_one")]
    pub members: usize,
    /// Conformal calibration on the validation part (`learn::uncertainty`); absent in models
    /// written by versions without intervals (they identify without bands).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration: Option<super::calibration::Calibration>,
}

fn one() -> usize {
    1
}

fn is_one(n: &usize) -> bool {
    *n == 1
}

/// A quantile head's outputs (rows: `o` means, `o` lower, `o` upper quantiles at coverage
/// `c`) as the mean and a spread: half the quantiles' distance over the normal quantile of
/// `c`, i.e. the σ of a normal law with that central interval, so the spread means what an
/// ensemble's does and one calibration serves both (`learn::uncertainty`).
fn quantile_spread(all: &[f32], o: usize, c: f64) -> (Vec<f32>, Option<Vec<f32>>) {
    let z = crate::dsp::normal_quantile(0.5 + c / 2.0) as f32;
    let (mut mean, mut spread) = (Vec::new(), Vec::new());
    for row in all.chunks_exact(3 * o) {
        mean.extend_from_slice(&row[..o]);
        // Crossed quantiles (lower above upper) give no width, never a negative one.
        spread.extend((0..o).map(|k| (row[2 * o + k] - row[o + k]).max(0.0) / (2.0 * z)));
    }
    (mean, Some(spread))
}

/// The fitted function.
pub enum Engine {
    /// A network.
    Net(Box<Network>),
    /// A classical regressor on flattened windows.
    Classical(Box<Classical>),
}

/// A trained model.
pub struct Model {
    /// Metadata.
    pub meta: ModelMeta,
    /// Weights (of the first member).
    pub engine: Engine,
    /// The other members of an ensemble (empty for one model).
    pub members: Vec<Engine>,
}

const MAGIC: &[u8; 8] = b"RFWEIGHT";

/// The prediction and spread of `engine` with its ensemble `members` for `n` windows `x`, each
/// network on up to `threads` threads ([`Model::predict_spread`]).
fn spread_of(
    engine: &mut Engine,
    members: &mut [Engine],
    x: &[f32],
    n: usize,
    threads: usize,
) -> (Vec<f32>, Option<Vec<f32>>) {
    let run = |e: &mut Engine| match e {
        Engine::Net(net) => {
            let all = net.predict_all_on(x, n, threads);
            match net.config.quantiles {
                Some(c) => quantile_spread(&all, net.config.outputs / 3, c),
                None => (net.means(all), None),
            }
        }
        Engine::Classical(c) => (c.predict(x, n), None),
    };
    let first = run(engine);
    if members.is_empty() {
        return first;
    }
    let mut all = vec![first];
    for m in members.iter_mut() {
        all.push(run(m));
    }
    let k = all.len() as f32;
    let mean: Vec<f32> = (0..all[0].0.len())
        .map(|i| all.iter().map(|p| p.0[i]).sum::<f32>() / k)
        .collect();
    let spread = (0..mean.len())
        .map(|i| {
            let own: f32 = all
                .iter()
                .filter_map(|p| p.1.as_ref().map(|s| s[i] * s[i]))
                .sum();
            let between: f32 = all.iter().map(|p| (p.0[i] - mean[i]).powi(2)).sum();
            ((between + own) / k).sqrt()
        })
        .collect();
    (mean, Some(spread))
}

impl Model {
    /// Standardised predictions `[n, outputs]` for windows `x[n, window, channels]` (an
    /// ensemble's mean).
    pub fn predict(&mut self, x: &[f32], n: usize) -> Vec<f32> {
        self.predict_spread(x, n).0
    }

    /// The prediction and its spread, both standardised `[n, outputs]`: one network with
    /// quantile heads gives the heads' σ; an ensemble gives its members' mean, and as spread
    /// the law of total variance over them, `σ² = Var_k(ŷ_k) + E_k(σ_k²)` (the members'
    /// disagreement plus their own heads' σ where they have heads; Lakshminarayanan et al.
    /// 2017, eq. 5); one plain network gives none.
    pub fn predict_spread(&mut self, x: &[f32], n: usize) -> (Vec<f32>, Option<Vec<f32>>) {
        spread_of(&mut self.engine, &mut self.members, x, n, 1)
    }

    /// [`Model::predict_spread`] with each network's windows shared out between up to
    /// `threads` threads ([`Network::predict_all_on`]): the same numbers bit for bit.
    pub fn predict_spread_on(
        &mut self,
        x: &[f32],
        n: usize,
        threads: usize,
    ) -> (Vec<f32>, Option<Vec<f32>>) {
        spread_of(&mut self.engine, &mut self.members, x, n, threads)
    }

    /// Writes the model directory (atomically file by file).
    pub fn save(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        let json = crate::io::to_json_pretty(&self.meta, &dir.join("model.json"))?;
        crate::io::write_atomic(&dir.join("model.json"), |w| w.write_all(json.as_bytes()))?;
        for (k, e) in std::iter::once(&self.engine)
            .chain(&self.members)
            .enumerate()
        {
            let suffix = if k == 0 {
                String::new()
            } else {
                format!("_member{}", k + 1)
            };
            match e {
                Engine::Net(net) => {
                    write_weights(&dir.join(format!("weights{suffix}.bin")), &net.params.value)?
                }
                Engine::Classical(c) => {
                    let bytes = c.to_bytes();
                    crate::io::write_atomic(&dir.join(format!("model{suffix}.bin")), |w| {
                        w.write_all(&bytes)
                    })?
                }
            }
        }
        Ok(())
    }

    /// Reads a model directory.
    pub fn load(dir: &Path) -> Result<Self> {
        let path = dir.join("model.json");
        let meta: ModelMeta = crate::io::read_json(&path)?;
        if !(1..=32).contains(&meta.members) {
            return Err(Error::config(
                &path,
                "members",
                format!("{} is outside 1..=32", meta.members),
            ));
        }
        meta.input_stats.check(&path, "input_stats")?;
        meta.target_stats.check(&path, "target_stats")?;
        for (field, names) in [
            ("data.channels", &meta.data.channels),
            ("data.targets", &meta.data.targets),
        ] {
            if let Some(i) = (1..names.len()).find(|&i| names[..i].contains(&names[i])) {
                return Err(Error::config(
                    &path,
                    format!("{field}[{i}]"),
                    format!("\"{}\" is named twice", names[i]),
                ));
            }
        }
        let engine = read_engine(dir, &path, &meta, "")?;
        let members = (2..=meta.members)
            .map(|k| read_engine(dir, &path, &meta, &format!("_member{k}")))
            .collect::<Result<Vec<_>>>()?;
        Ok(Model {
            meta,
            engine,
            members,
        })
    }
}

/// One member's engine from `dir` (`suffix` "" for the first, `_member<k>` for the others).
fn read_engine(dir: &Path, path: &Path, meta: &ModelMeta, suffix: &str) -> Result<Engine> {
    let engine = if meta.kind.architecture().is_some() {
        let config = meta
            .net
            .clone()
            .ok_or_else(|| Error::config(path, "net", "missing for a network"))?;
        // Sizes from the file: bounded before anything is allocated from them.
        for (field, v, max) in [
            ("net.window", config.window, 100_000),
            ("net.channels", config.channels, 10_000),
            ("net.outputs", config.outputs, 64),
        ] {
            if v == 0 || v > max {
                return Err(Error::config(
                    path,
                    field,
                    format!("{v} is outside 1..={max}"),
                ));
            }
        }
        let least = config.architecture.min_window();
        if config.window < least {
            return Err(Error::config(
                path,
                "net.window",
                format!(
                    "{} steps: a {} reads at least {least}",
                    config.window,
                    config.architecture.name()
                ),
            ));
        }
        if let Some(c) = config.quantiles
            && !(c > 0.0 && c < 1.0)
        {
            return Err(Error::config(
                path,
                "net.quantiles",
                format!("{c} is not a coverage in (0, 1)"),
            ));
        }
        let mut net = Network::new(config);
        if meta.slots.as_ref() != Some(&net.params.slots) {
            return Err(Error::config(
                path,
                "slots",
                "weight layout differs from this version's network",
            ));
        }
        let values = read_weights(&dir.join(format!("weights{suffix}.bin")))?;
        if values.len() != net.params.value.len() {
            return Err(Error::config(
                &dir.join(format!("weights{suffix}.bin")),
                "values",
                format!(
                    "{} weights, the network has {}",
                    values.len(),
                    net.params.value.len()
                ),
            ));
        }
        // A non-finite weight would make every estimate NaN: refused here, by index.
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(Error::config(
                &dir.join(format!("weights{suffix}.bin")),
                format!("values[{i}]"),
                format!("{} is not a finite weight", values[i]),
            ));
        }
        net.params.value = values;
        Engine::Net(Box::new(net))
    } else {
        let p = dir.join(format!("model{suffix}.bin"));
        let bytes = std::fs::read(&p).map_err(|e| Error::io(&p, e))?;
        Engine::Classical(Box::new(
            Classical::from_bytes(&bytes).map_err(|m| Error::config(&p, "model", &m))?,
        ))
    };
    Ok(engine)
}

/// Writes f32 values: magic, count (u64 LE), values (f32 LE).
pub fn write_weights(path: &Path, values: &[f32]) -> Result<()> {
    crate::io::write_atomic(path, |w| {
        w.write_all(MAGIC)?;
        w.write_all(&(values.len() as u64).to_le_bytes())?;
        for v in values {
            w.write_all(&v.to_le_bytes())?;
        }
        Ok(())
    })
}

/// Reads what [`write_weights`] wrote.
pub fn read_weights(path: &Path) -> Result<Vec<f32>> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    if bytes.len() < 16 || &bytes[..8] != MAGIC {
        return Err(Error::config(path, "header", "not a railforce weight file"));
    }
    let n = u64::from_le_bytes(bytes[8..16].try_into().expect("8 bytes"));
    // A count from the file: checked, never trusted to fit.
    let expected = n
        .checked_mul(4)
        .and_then(|b| b.checked_add(16))
        .and_then(|b| usize::try_from(b).ok());
    if expected != Some(bytes.len()) {
        let held = (bytes.len() - 16) / 4;
        return Err(Error::config(
            path,
            "length",
            format!(
                "the header counts {n} weights and the file holds {} bytes after it ({held} weights{}): {}",
                bytes.len() - 16,
                if (bytes.len() - 16) % 4 == 0 {
                    ""
                } else {
                    " and a part"
                },
                if expected.is_none_or(|e| bytes.len() < e) {
                    "cut short"
                } else {
                    "bytes beyond the weights"
                }
            ),
        ));
    }
    Ok(bytes[16..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect())
}
