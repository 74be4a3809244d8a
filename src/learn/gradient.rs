//! What computes a network's gradients in training: the hand-fused engine or burn's autodiff
//! (`--features burn`). The trainer and `bench learn` run the same [`Stepper`].

use super::neural::{NetConfig, Network};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// What computes a network's forward and backward pass in training. The weights, Adam, the
/// dropout stream, checkpoints and the model directory are the same for all: a model or a
/// checkpoint of one engine loads (and resumes) in the other.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GradientEngine {
    /// The hand-fused engine (the fast CPU path).
    #[default]
    Fused,
    /// burn's autodiff on its CPU backend (Flex); needs `--features burn`.
    BurnCpu,
    /// burn's autodiff on a GPU through wgpu and Vulkan; needs `--features burn-gpu`.
    BurnGpu,
}

impl GradientEngine {
    /// Every engine, in command-line order.
    pub const ALL: [GradientEngine; 3] = [
        GradientEngine::Fused,
        GradientEngine::BurnCpu,
        GradientEngine::BurnGpu,
    ];

    /// The engine of a command-line name (`fused`, `burn-cpu`, `burn-gpu`).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|e| e.name() == name)
    }

    /// What it is, in words.
    pub fn describe(self) -> &'static str {
        match self {
            GradientEngine::Fused => "the fused engine",
            GradientEngine::BurnCpu => "burn (CPU, Flex backend)",
            GradientEngine::BurnGpu => "burn (GPU, wgpu over Vulkan)",
        }
    }

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            GradientEngine::Fused => "fused",
            GradientEngine::BurnCpu => "burn-cpu",
            GradientEngine::BurnGpu => "burn-gpu",
        }
    }
}

/// The gradient computation of one training step, by the chosen [`GradientEngine`]: what the
/// trainer runs and `bench learn` times.
pub enum Stepper {
    /// The hand-fused engine.
    Fused,
    /// burn's autodiff on a device.
    #[cfg(feature = "burn")]
    Burn(Box<super::burn::BurnNet>, ::burn::tensor::Device),
}

impl Stepper {
    /// The stepper of `engine` for networks of `config`; an error when this build lacks it.
    pub fn new(engine: GradientEngine, config: &NetConfig) -> Result<Self> {
        match engine {
            GradientEngine::Fused => Ok(Stepper::Fused),
            #[cfg(feature = "burn")]
            burn if config.quantiles.is_some() => Err(Error::Domain(format!(
                "quantile heads train with the fused engine only, not {}",
                burn.name()
            ))),
            #[cfg(feature = "burn")]
            burn => {
                let device = burn_device(burn)?;
                let net = super::burn::BurnNet::new(config, &device);
                Ok(Stepper::Burn(Box::new(net), device))
            }
            #[cfg(not(feature = "burn"))]
            other => {
                let _ = config;
                Err(Error::Domain(format!(
                    "the {} engine needs burn, and this railforce was built without it: rebuild with `cargo build --release --features {}`",
                    other.name(),
                    if other == GradientEngine::BurnGpu {
                        "burn-gpu"
                    } else {
                        "burn"
                    }
                )))
            }
        }
    }

    /// Gradients of the mean squared error of `y` on `x` (`n` windows, training mode) into
    /// `net.params.grad`, replacing them; returns the loss. `dout` is scratch space.
    pub fn step(
        &mut self,
        net: &mut Network,
        x: &[f32],
        y: &[f32],
        n: usize,
        dout: &mut Vec<f32>,
    ) -> Result<f64> {
        match self {
            Stepper::Fused => {
                net.params.zero_grad();
                let (quantiles, heads) = (net.config.quantiles, net.config.outputs);
                let pred = net.forward(x, n, true);
                dout.clear();
                let l = match quantiles {
                    None => squared_error(pred, y, dout),
                    Some(c) => with_quantiles(pred, y, heads / 3, c, dout),
                };
                net.backward(x, dout);
                Ok(l)
            }
            #[cfg(feature = "burn")]
            Stepper::Burn(module, device) => module.gradients(net, x, y, n, device),
        }
    }
}

/// Mean squared error of `pred` against `y` and its gradient into `dout`.
fn squared_error(pred: &[f32], y: &[f32], dout: &mut Vec<f32>) -> f64 {
    let scale = 2.0 / y.len() as f32;
    let mut l = 0.0f64;
    for (p, t) in pred.iter().zip(y) {
        let e = p - t;
        l += (e * e) as f64;
        dout.push(scale * e);
    }
    l / y.len() as f64
}

/// The loss of a head with quantiles at coverage `c` (rows of `pred`: the `o` means, the `o`
/// lower and the `o` upper quantiles; rows of `y`: the `o` targets): the means' squared error
/// plus the pinball loss of each quantile (Koenker & Bassett 1978,
/// `ρ_τ(e) = max(τ·e, (τ − 1)·e)` with `e = y − q`), averaged over the targets, and the
/// gradient into `dout`. Returns the mean heads' squared error (what validation compares).
fn with_quantiles(pred: &[f32], y: &[f32], o: usize, c: f64, dout: &mut Vec<f32>) -> f64 {
    let n = y.len() / o;
    let taus = [(1.0 - c as f32) / 2.0, (1.0 + c as f32) / 2.0];
    let scale = 1.0 / y.len() as f32;
    let mut l = 0.0f64;
    dout.resize(pred.len(), 0.0);
    for i in 0..n {
        let (row, t) = (&pred[i * 3 * o..(i + 1) * 3 * o], &y[i * o..(i + 1) * o]);
        let d = &mut dout[i * 3 * o..(i + 1) * 3 * o];
        for k in 0..o {
            let e = row[k] - t[k];
            l += (e * e) as f64;
            d[k] = 2.0 * scale * e;
            for (h, tau) in taus.iter().enumerate() {
                let q = row[(h + 1) * o + k];
                // ∂ρ_τ(y − q)/∂q: −τ below the target, 1 − τ above it.
                d[(h + 1) * o + k] = scale * if t[k] > q { -tau } else { 1.0 - tau };
            }
        }
    }
    l / y.len() as f64
}

/// The burn device (without autodiff) of a gradient engine: burn-flex on the CPU, or the best
/// GPU wgpu finds through Vulkan (an error when this build lacks the backend, or for the fused
/// engine).
#[cfg(feature = "burn")]
pub fn burn_device(engine: GradientEngine) -> Result<::burn::tensor::Device> {
    match engine {
        GradientEngine::BurnCpu => Ok(::burn::tensor::Device::flex()),
        #[cfg(feature = "burn-gpu")]
        GradientEngine::BurnGpu => super::burn::gpu(),
        #[cfg(not(feature = "burn-gpu"))]
        GradientEngine::BurnGpu => Err(Error::Domain(
            "this railforce was built without burn's GPU backend: rebuild with `cargo build --release --features burn-gpu`".into(),
        )),
        GradientEngine::Fused => Err(Error::Domain(
            "the fused engine is not a burn device".into(),
        )),
    }
}
