//! Built-in benchmarks (`railforce bench …`): each measures a hot path and a reference in the
//! same run, and reports the ratio, so figures compare across machines.

pub mod contact;
pub mod learn;
pub mod simulate;
