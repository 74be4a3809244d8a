//! Signal processing shared by several stages (spectral estimates, filters).

pub mod welch;

pub use welch::{WelchPsd, welch_psd};
