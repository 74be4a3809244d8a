//! Signal processing shared by several stages (spectral estimates, filters).

mod butterworth;
mod interp;
mod spectrum;
mod stats;
pub mod welch;

pub use butterworth::{Butterworth, FilterBank};
pub use interp::catmull_rom;
pub use spectrum::amplitude_spectrum;
pub use stats::{normal_cdf, normal_quantile, percentile};
pub use welch::{WelchPsd, welch_psd};
