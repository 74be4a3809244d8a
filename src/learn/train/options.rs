//! Training settings: what `train` and the experiments pass to the trainer, recorded in each
//! model's `model.json` (`training.options`).

use super::GradientEngine;
use crate::learn::model::ModelKind;
use crate::sensors::NoiseModel;
use serde::{Deserialize, Serialize};

/// Training settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrainOptions {
    /// Epochs at most.
    pub epochs: usize,
    /// Early-stopping patience (epochs without a better validation loss).
    pub patience: usize,
    /// Minibatch size.
    pub batch: usize,
    /// Adam learning rate.
    pub lr: f32,
    /// Seed of weights, shuffling and dropout.
    pub seed: u64,
    /// Head dropout.
    pub dropout: f32,
    /// Training windows drawn per epoch at most (all when `None`).
    pub windows_per_epoch: Option<usize>,
    /// Training windows a classical model is fitted on at most (evenly strided).
    pub classical_rows: usize,
    /// Continue from the checkpoint in the output folder.
    pub resume: bool,
    /// Matched protocol only: draw new training-input noise with this model every epoch
    /// instead of reading the data set's one fixed noisy copy (validation and test keep it).
    #[serde(default)]
    pub fresh_noise: Option<NoiseModel>,
    /// Validation windows scored each epoch at most (evenly strided; all when `None`).
    #[serde(default)]
    pub val_windows: Option<usize>,
    /// What computes each minibatch's forward and backward pass (networks only).
    #[serde(default)]
    pub engine: GradientEngine,
    /// Networks: quantile heads at this nominal coverage beside the mean (the
    /// intervals then follow the heads' width, `learn::uncertainty`). The default,
    /// [`DEFAULT_QUANTILE_HEADS`]: as well calibrated as a 5-member ensemble for a fifth of
    /// its training time (assets/docs/learning.md §3.1). Where heads cannot apply (classical
    /// models, an ensemble's members, the burn engine) they are left out:
    /// [`TrainOptions::heads_for`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quantile_heads: Option<f64>,
    /// Halve the learning rate each time this many epochs in a row bring no better
    /// validation loss (reduce-on-plateau; 0: a constant rate). Early stopping still counts
    /// from the last improvement, so a patience of 10 with a plateau of 4 halves the rate
    /// twice before it stops.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub lr_plateau: usize,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// Nominal coverage of the default quantile heads (the intervals' default coverage).
pub const DEFAULT_QUANTILE_HEADS: f64 = 0.9;

impl TrainOptions {
    /// The quantile heads a training of `kind` as one of `members` gets: the options' own,
    /// but none for a model without a network, for an ensemble (its members' disagreement is
    /// its spread) and for the burn engine (heads train with the fused one).
    pub fn heads_for(&self, kind: ModelKind, members: usize) -> Option<f64> {
        self.quantile_heads.filter(|_| {
            members == 1 && kind.architecture().is_some() && self.engine == GradientEngine::Fused
        })
    }
}

impl Default for TrainOptions {
    fn default() -> Self {
        TrainOptions {
            epochs: 200,
            patience: 20,
            batch: 64,
            lr: 1e-3,
            seed: 1,
            dropout: 0.2,
            windows_per_epoch: None,
            classical_rows: 40_000,
            resume: false,
            fresh_noise: None,
            val_windows: None,
            engine: GradientEngine::Fused,
            quantile_heads: Some(DEFAULT_QUANTILE_HEADS),
            lr_plateau: 0,
        }
    }
}
