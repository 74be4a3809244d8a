//! Learning: networks and classical regressors on leak-free windows, the trainer, metrics and
//! model directories.

#[cfg(feature = "burn")]
pub mod burn;
mod calibration;
pub mod classical;
mod difficulty;
pub mod evaluate;
pub mod export;
mod gradient;
pub mod linalg;
pub mod metrics;
pub mod model;
pub mod neural;
pub mod train;
pub mod uncertainty;
pub mod windows;
