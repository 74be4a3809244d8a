//! # railforce
//!
//! Railway vehicle dynamics and wheel–rail force identification: a C80 heavy-haul wagon on
//! tracks with FRA irregularities, virtual sensors, data sets, and force identification.
//!
//! Data flows one way: [`track`] → simulation → sensors → data sets → features → models →
//! experiments and reports → identification and [`assess`]ment.
//! Every stage is a module with a small public surface.

#![warn(missing_docs)]

pub mod angle;
pub mod assess;
pub mod bounds;
pub mod builtin;
pub mod contact;
pub mod dataset;
pub mod dsp;
pub mod error;
pub mod experiment;
pub mod features;
pub mod identify;
pub mod io;
pub mod learn;
pub mod plan;
#[cfg(feature = "python")]
mod python;
pub mod report;
pub mod sensitivity;
pub mod sensors;
pub mod sim;
pub mod track;
pub mod train;
pub mod vary;
pub mod vehicle;
pub mod view;

pub use error::{Error, Result};

/// Standard gravity, m/s².
pub const GRAVITY: f64 = 9.81;
