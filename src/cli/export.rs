//! `railforce export`: a thin shell over `railforce::learn::export`.

use anyhow::{Context, Result, bail};
use clap::Args;
use railforce::learn::model::Model;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct ExportArgs {
    /// Model directory written by `railforce train` (a network: cnn-bilstm, cnn, bilstm, gru).
    #[arg(long)]
    model: PathBuf,
    /// Format: safetensors (PyTorch names and layouts; see assets/python/railforce_nets.py).
    #[arg(long, default_value = "safetensors")]
    format: String,
    /// Output file [default: MODEL/model.safetensors].
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn run(args: ExportArgs) -> Result<()> {
    if args.format != "safetensors" {
        bail!("--format {}: the one format is safetensors", args.format);
    }
    let model = Model::load(&args.model)?;
    let bytes = railforce::learn::export::to_safetensors(&model)
        .with_context(|| format!("exporting {}", args.model.display()))?;
    let out = args
        .out
        .unwrap_or_else(|| args.model.join("model.safetensors"));
    railforce::io::write_atomic(&out, |w| w.write_all(&bytes))?;
    println!(
        "wrote {} ({} bytes, {} {}); in Python: railforce_nets.load(\"{}\") from assets/python/",
        out.display(),
        bytes.len(),
        model.meta.kind.name(),
        model.meta.data.targets.join("+"),
        out.display()
    );
    Ok(())
}
