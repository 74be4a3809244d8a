//! The built-in vehicles, tracks and plans ([`railforce::builtin`]) as the commands use them:
//! a note on standard error whenever a built-in copy stands in for a missing path.

use anyhow::Result;
use std::path::{Path, PathBuf};

/// [`railforce::builtin::resolve`], saying when the built-in copy is used.
pub fn resolve(path: &Path) -> Result<PathBuf> {
    let resolved = railforce::builtin::resolve(path)?;
    if resolved != path {
        eprintln!(
            "note: {} is not here; using the built-in copy ({})",
            path.display(),
            resolved.display()
        );
    }
    Ok(resolved)
}

pub use railforce::builtin::write_all;
