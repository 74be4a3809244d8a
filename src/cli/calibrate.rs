//! `railforce calibrate`: (re)calibrates a trained model's intervals on the validation runs of
//! a data set, without training again (a thin shell over `learn::uncertainty`).

use super::train::with_noisy_copies;
use anyhow::Result;
use clap::Args;
use railforce::dataset::DataSet;
use railforce::features::NoiseProtocol;
use railforce::learn::model::Model;
use railforce::learn::uncertainty::calibrate_with;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Model directory written by `railforce train` (its model.json is rewritten, atomically).
    #[arg(long)]
    model: PathBuf,
    /// Data set folder: the validation part of the model's own split is calibrated on, the
    /// training part gives the input envelope. Noised as the model was where the files are
    /// clean.
    #[arg(long)]
    data: PathBuf,
    /// One interval width everywhere (but for an ensemble's spread) instead of one that
    /// follows each window's difficulty (the inputs' own level).
    #[arg(long)]
    uniform: bool,
}

pub fn run(args: CalibrateArgs) -> Result<()> {
    let mut model = Model::load(&args.model)?;
    let mut ds = DataSet::load(&args.data)?;
    if model.meta.data.noise != NoiseProtocol::Clean {
        ds = with_noisy_copies(ds, &model.meta.data.channels, model.meta.data.noise_model)?;
    }
    let cal = calibrate_with(&mut model, &ds, !args.uniform)?;
    let widths: Vec<String> = model
        .meta
        .data
        .targets
        .iter()
        .enumerate()
        .map(|(k, t)| {
            format!(
                "{t} ±{:.2} kN",
                cal.typical_half_width(k, 0.9) * model.meta.target_stats.std[k] * 1e-3
            )
        })
        .collect();
    println!(
        "calibrated on the {} ({} score{}); 90 % half-width of a typical window: {}",
        cal.part,
        cal.score.name(),
        if cal.difficulty.is_empty() {
            ", one width everywhere"
        } else {
            ", widened with each window's difficulty"
        },
        widths.join(", ")
    );
    model.meta.calibration = Some(cal);
    model.save(&args.model)?;
    println!("model: {}", args.model.display());
    Ok(())
}
