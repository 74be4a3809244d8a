//! The four networks as burn modules (<https://burn.dev>, 0.22): the fused engine's layer table
//! (assets/docs/learning.md §3) built from burn-nn's `Linear`, `BatchNorm`, `BiLstm` and `Gru`, so a
//! user can change or add a layer without writing its backward pass, and burn's autodiff is an
//! independent check of the engine's hand-written gradients (`tests/neural.rs`).
//!
//! The weights stay in the engine's [`ParamSet`]: [`BurnNet::load`] copies them in (each burn
//! tensor is a block of one engine slot, see `bridge.rs`) and [`BurnNet::gradients`] runs the
//! forward and backward passes in burn and writes the gradients back. Training with burn thus
//! keeps the engine's Adam, checkpoints, early stopping and model directory: a model trained by
//! either engine is the same files, loads in the other and predicts the same numbers.
//!
//! Two deliberate equivalences: a `Conv1d` with kernel 1 is a `Linear` over the channels at
//! every step (the same map and the same `[in, out]` weight), and batch norm runs on the
//! `[B·T, C]` rows, as the engine does.

mod bridge;

use super::linalg::LEAKY_SLOPE;
use super::neural::batch_norm::{EPS, MOMENTUM};
use super::neural::network::{HEAD, HIDDEN, STEM_WIDTH};
use super::neural::{Architecture, NetConfig, Network};
use crate::error::{Error, Result};
use ::burn::module::Module;
use ::burn::nn::{
    BatchNorm, BatchNormConfig, BiLstm, BiLstmConfig, Gru, GruConfig, Linear, LinearConfig,
};
use ::burn::tensor::activation::leaky_relu;
use ::burn::tensor::{Device, Tensor, TensorData};

/// The best GPU wgpu finds through Vulkan, probed with one small tensor: burn's runtime
/// panics (in its own thread) when there is no adapter, which becomes an error naming what is
/// missing.
#[cfg(feature = "burn-gpu")]
pub fn gpu() -> Result<Device> {
    use std::sync::{Arc, Mutex};
    let device = Device::vulkan(::burn::tensor::DeviceKind::DefaultDevice);
    let probe = device.clone();
    let said = Arc::new(Mutex::new(Vec::<String>::new()));
    let keep = Arc::clone(&said);
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if let Ok(mut v) = keep.lock() {
            v.push(info.to_string());
        }
    }));
    let probed = std::panic::catch_unwind(move || {
        Tensor::<1>::from_floats([1.0, 2.0], &probe)
            .sum()
            .into_data()
    });
    std::panic::set_hook(hook);
    match probed {
        Ok(_) => Ok(device),
        Err(_) => {
            let said = said
                .lock()
                .ok()
                .and_then(|v| v.first().cloned())
                .unwrap_or_default();
            Err(Error::Domain(format!(
                "no GPU reachable through Vulkan for the burn-gpu engine (install the GPU's Vulkan driver and loader, libvulkan1; or use burn-cpu or fused): {said}"
            )))
        }
    }
}

/// The convolutional stem: (Conv1d k=1 → LeakyReLU → BatchNorm) twice; max-pooling follows.
#[derive(Module, Debug)]
pub struct Stem {
    /// Conv1d(C → C, k = 1).
    pub conv1: Linear,
    /// BatchNorm1d(C).
    pub bn1: BatchNorm,
    /// Conv1d(C → 128, k = 1).
    pub conv2: Linear,
    /// BatchNorm1d(128).
    pub bn2: BatchNorm,
}

/// One of the four networks as a burn module.
#[derive(Module, Debug)]
pub struct BurnNet {
    /// The stem (CNN-BiLSTM and CNN).
    pub stem: Option<Stem>,
    /// BiLSTM(→ 20 per direction), final states (CNN-BiLSTM and BiLSTM).
    pub lstm: Option<BiLstm>,
    /// GRU(→ 20), final state.
    pub gru: Option<Gru>,
    /// Linear(F → 64).
    pub fc1: Linear,
    /// Linear(64 → 8).
    pub fc2: Linear,
    /// Linear(8 → outputs).
    pub out: Linear,
}

impl BurnNet {
    /// The layers of `config` on `device` (burn's initial weights: call [`BurnNet::load`]).
    pub fn new(config: &NetConfig, device: &Device) -> Self {
        let c = config.channels;
        let stem = matches!(
            config.architecture,
            Architecture::CnnBiLstm | Architecture::Cnn
        )
        .then(|| Stem {
            conv1: LinearConfig::new(c, c).init(device),
            bn1: batch_norm(c, device),
            conv2: LinearConfig::new(c, STEM_WIDTH).init(device),
            bn2: batch_norm(STEM_WIDTH, device),
        });
        let seq_in = if stem.is_some() { STEM_WIDTH } else { c };
        let (lstm, gru, feat) = match config.architecture {
            Architecture::CnnBiLstm | Architecture::BiLstm => (
                Some(BiLstmConfig::new(seq_in, HIDDEN, true).init(device)),
                None,
                2 * HIDDEN,
            ),
            Architecture::Gru => (
                None,
                Some(GruConfig::new(seq_in, HIDDEN, true).init(device)),
                HIDDEN,
            ),
            Architecture::Cnn => (None, None, (config.window - 1) * STEM_WIDTH),
        };
        BurnNet {
            stem,
            lstm,
            gru,
            fc1: LinearConfig::new(feat, HEAD[0]).init(device),
            fc2: LinearConfig::new(HEAD[0], HEAD[1]).init(device),
            out: LinearConfig::new(HEAD[1], config.outputs).init(device),
        }
    }

    /// `x[B, T, C]` → `[B, outputs]`. On an autodiff device batch norm uses the batch's
    /// statistics (and updates its running ones), elsewhere the running statistics. `masks`
    /// are the head's inverted-dropout multipliers (`[B, F]` and `[B, 64]`), none in evaluation.
    pub fn forward(&self, x: Tensor<3>, masks: Option<[Tensor<2>; 2]>) -> Tensor<2> {
        let [b, t, _] = x.dims();
        let slope = f64::from(LEAKY_SLOPE);
        let seq = match &self.stem {
            Some(stem) => {
                let h = norm_rows(&stem.bn1, leaky_relu(stem.conv1.forward(x), slope));
                let h = norm_rows(&stem.bn2, leaky_relu(stem.conv2.forward(h), slope));
                // MaxPool1d(2, stride 1) over time.
                let w = STEM_WIDTH;
                let early = h.clone().slice([0..b, 0..t - 1, 0..w]);
                let late = h.slice([0..b, 1..t, 0..w]);
                early.max_pair(late)
            }
            None => x,
        };
        let feat: Tensor<2> = if let Some(lstm) = &self.lstm {
            // Final states `[2, B, H]` (forward after the last step, backward after the first).
            let (_, state) = lstm.forward(seq, None);
            state.hidden.swap_dims(0, 1).reshape([b as i64, -1])
        } else if let Some(gru) = &self.gru {
            let states = gru.forward(seq, None);
            let [_, steps, h] = states.dims();
            states.slice([0..b, steps - 1..steps, 0..h]).reshape([b, h])
        } else {
            seq.reshape([b as i64, -1])
        };
        let (feat, m1) = match masks {
            Some([m0, m1]) => (feat * m0, Some(m1)),
            None => (feat, None),
        };
        let h1 = leaky_relu(self.fc1.forward(feat), slope);
        let h1 = match m1 {
            Some(m) => h1 * m,
            None => h1,
        };
        let h2 = leaky_relu(self.fc2.forward(h1), slope);
        self.out.forward(h2)
    }

    /// Copies the engine network's weights and batch-norm statistics into this module,
    /// tracked for gradients when `device` is an autodiff device.
    pub fn load(&mut self, net: &Network, device: &Device) {
        bridge::load(self, &net.params, device);
    }

    /// One training step's gradients: `x[B, T, C]` and `y[B, outputs]` (standardised), the
    /// engine network's weights, its dropout masks (drawn from its stream, so the engine would
    /// have drawn the same), forward and backward in burn's autodiff on `device` (a plain
    /// device: autodiff is added here). Writes the gradients into `net.params.grad` (replacing
    /// them) and the batch-norm running statistics into `net.params.value` (PyTorch's unbiased
    /// running variance, as the engine keeps it). Returns the batch's mean squared error.
    pub fn gradients(
        &mut self,
        net: &mut Network,
        x: &[f32],
        y: &[f32],
        batch: usize,
        device: &Device,
    ) -> Result<f64> {
        let config = &net.config;
        let (t, c, o) = (config.window, config.channels, config.outputs);
        if x.len() != batch * t * c || y.len() != batch * o {
            return Err(Error::Domain(format!(
                "burn step: {} inputs and {} targets do not make {batch} windows of {t}×{c} → {o}",
                x.len(),
                y.len()
            )));
        }
        let ad = device.clone().autodiff();
        bridge::load(self, &net.params, &ad);
        let [m0, m1] = net.dropout_masks(batch);
        let f = net.feature_width();
        let masks = [
            Tensor::from_data(TensorData::new(m0, [batch, f]), &ad),
            Tensor::from_data(TensorData::new(m1, [batch, HEAD[0]]), &ad),
        ];
        let xt = Tensor::<3>::from_data(TensorData::new(x.to_vec(), [batch, t, c]), &ad);
        let yt = Tensor::<2>::from_data(TensorData::new(y.to_vec(), [batch, o]), &ad);
        let pred = self.forward(xt, Some(masks));
        let err = pred - yt;
        let loss = (err.clone() * err).mean();
        let value = to_vec(loss.clone().inner())?;
        let grads = loss.backward();
        bridge::store_gradients(self, &grads, &mut net.params)?;
        bridge::store_running_stats(self, &mut net.params, batch * t)?;
        Ok(f64::from(value[0]))
    }

    /// Evaluation-mode predictions `[B, outputs]` of `x[B, T, C]` in chunks of 1024 windows.
    pub fn predict(&self, x: &[f32], batch: usize, t: usize, device: &Device) -> Result<Vec<f32>> {
        if batch == 0 || t == 0 || x.is_empty() || !x.len().is_multiple_of(batch * t) {
            return Err(Error::Domain(format!(
                "burn predict: {} inputs are not {batch} windows of {t} steps",
                x.len()
            )));
        }
        let per = x.len() / batch;
        let c = per / t;
        let mut out = Vec::new();
        for chunk in x.chunks(per * 1024) {
            let n = chunk.len() / per;
            let xt = Tensor::<3>::from_data(TensorData::new(chunk.to_vec(), [n, t, c]), device);
            out.extend(to_vec(self.forward(xt, None))?);
        }
        Ok(out)
    }
}

fn batch_norm(c: usize, device: &Device) -> BatchNorm {
    BatchNormConfig::new(c)
        .with_epsilon(f64::from(EPS))
        .with_momentum(f64::from(MOMENTUM))
        .init(device)
}

/// Batch norm over the `[B·T, C]` rows of `h[B, T, C]`.
fn norm_rows(bn: &BatchNorm, h: Tensor<3>) -> Tensor<3> {
    let [b, t, c] = h.dims();
    bn.forward(h.reshape([b * t, c])).reshape([b, t, c])
}

/// A tensor's values as f32.
fn to_vec<const D: usize>(t: Tensor<D>) -> Result<Vec<f32>> {
    t.into_data()
        .try_into_vec::<f32>()
        .map_err(|e| Error::Domain(format!("burn tensor: {e:?}")))
}
