//! The integration tests, one binary (as ripgrep does): each file of `tests/` is a module
//! here, so the library is linked once instead of once per file. Run one file's tests with a
//! filter: `cargo test --test all -- dataset::` (or several: `-- neural:: learn::`).

#[path = "assess.rs"]
mod assess;
#[path = "bogie.rs"]
mod bogie;
#[path = "cli.rs"]
mod cli;
#[path = "cli_daily.rs"]
mod cli_daily;
#[path = "common/mod.rs"]
mod common;
#[path = "contact.rs"]
mod contact;
#[path = "dataset.rs"]
mod dataset;
#[path = "dipped_joint.rs"]
mod dipped_joint;
#[path = "docs.rs"]
mod docs;
#[path = "dynamics.rs"]
mod dynamics;
#[path = "experiment.rs"]
mod experiment;
#[path = "export.rs"]
mod export;
#[path = "features.rs"]
mod features;
#[path = "fidelity.rs"]
mod fidelity;
#[path = "hardening.rs"]
mod hardening;
#[path = "identify.rs"]
mod identify;
#[path = "integrator.rs"]
mod integrator;
#[path = "learn.rs"]
mod learn;
#[path = "line.rs"]
mod line;
#[path = "mutation.rs"]
mod mutation;
#[path = "mutation_commands.rs"]
mod mutation_commands;
#[path = "neural.rs"]
mod neural;
#[path = "rails_on_sleepers.rs"]
mod rails_on_sleepers;
#[path = "sensitivity.rs"]
mod sensitivity;
#[path = "sensors.rs"]
mod sensors;
#[path = "short_waves.rs"]
mod short_waves;
#[path = "sklearn.rs"]
mod sklearn;
#[path = "stability.rs"]
mod stability;
#[path = "step_guard.rs"]
mod step_guard;
#[path = "track.rs"]
mod track;
#[path = "train.rs"]
mod train;
#[path = "train_coupling.rs"]
mod train_coupling;
#[path = "vary.rs"]
mod vary;
#[path = "view.rs"]
mod view;
