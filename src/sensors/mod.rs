//! The sensor contract: what passes from the simulator to the learner. Channel names, units
//! and kinds (`channels`), the paper's 21 inputs, the label wheel's force channels, the
//! on-board candidate signals the Filter–Wrapper may choose from, the `_noisy` naming, and the
//! one noise model ([`noise`]) that `generate`, training's fresh noise, the experiments and
//! `validate identify` all use (assets/docs/learning.md §1.4, §2; physics.md §5).

mod channels;
pub mod noise;

/// Sampling rate of every recorded channel and of the models trained on them, Hz.
pub const RATE_HZ: f64 = 200.0;

pub use channels::{
    Candidates, ChannelKind, DEFLECTION_PREFIXES, PAPER_CHANNELS, PAPER_UNITS, VEHICLE_MASS,
    clean_name, is_noisy, label_channels, noisy_name,
};
pub use noise::{NoiseModel, SnrReference};
