//! Neural networks: the paper's CNN-BiLSTM and the CNN, BiLSTM and GRU baselines, with
//! hand-fused forward and backward passes on f32 buffers: the fast CPU path (the same networks
//! as burn modules are in `learn::burn`, `--features burn`).

mod adam;
pub mod batch_norm;
mod dense;
mod gru;
mod lstm;
pub mod network;
pub mod params;
mod pool;

pub use adam::Adam;
pub use network::{Architecture, NetConfig, Network};
pub use params::ParamSet;
