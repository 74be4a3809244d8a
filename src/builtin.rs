//! The project's vehicles, tracks and plans, built into the binary from `vehicles/` and
//! `tracks/` (the repository stays the one copy), so `railforce demo`, `simulate` and
//! `generate --plan tracks/paper34.plan.toml` work after `cargo install` from any folder.
//! A path that exists is always used as given (user files take precedence); a missing path
//! that names a built-in file is served from a copy of the built-in set written once per
//! process to a folder under the system's temporary directory (keeping the repository's
//! layout, so a plan's relative paths resolve); `railforce init DIR` writes the set out to
//! edit.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The built-in files: path relative to the repository root, and text.
pub const FILES: &[(&str, &str)] = &[
    ("vehicles/assessment.toml", crate::assess::criteria::DEFAULT),
    ("vehicles/c80.toml", include_str!("../vehicles/c80.toml")),
    (
        "vehicles/c80.estimates.toml",
        include_str!("../vehicles/c80.estimates.toml"),
    ),
    (
        "vehicles/daqin_10kt.consist.toml",
        crate::sim::hitch::BUILTIN_CONSISTS[0].1,
    ),
    (
        "vehicles/daqin_10kt_empty.consist.toml",
        crate::sim::hitch::BUILTIN_CONSISTS[1].1,
    ),
    (
        "vehicles/daqin_20kt.consist.toml",
        crate::sim::hitch::BUILTIN_CONSISTS[2].1,
    ),
    (
        "vehicles/daqin_20kt_empty.consist.toml",
        crate::sim::hitch::BUILTIN_CONSISTS[3].1,
    ),
    ("vehicles/c80.urdf", include_str!("../vehicles/c80.urdf")),
    (
        "vehicles/c80_empty.toml",
        include_str!("../vehicles/c80_empty.toml"),
    ),
    (
        "vehicles/c80_empty.urdf",
        include_str!("../vehicles/c80_empty.urdf"),
    ),
    (
        "vehicles/restrained_wheelset.toml",
        include_str!("../vehicles/restrained_wheelset.toml"),
    ),
    (
        "vehicles/single_wheelset.toml",
        include_str!("../vehicles/single_wheelset.toml"),
    ),
    (
        "vehicles/single_wheelset.urdf",
        include_str!("../vehicles/single_wheelset.urdf"),
    ),
    (
        "vehicles/profiles/cone_1_40.csv",
        include_str!("../vehicles/profiles/cone_1_40.csv"),
    ),
    (
        "vehicles/profiles/worn_heavy_haul_wheel.csv",
        include_str!("../vehicles/profiles/worn_heavy_haul_wheel.csv"),
    ),
    (
        "vehicles/profiles/worn_heavy_haul_rail.csv",
        include_str!("../vehicles/profiles/worn_heavy_haul_rail.csv"),
    ),
    (
        "tracks/curve_r1000.toml",
        include_str!("../tracks/curve_r1000.toml"),
    ),
    (
        "tracks/curve_r1200.toml",
        include_str!("../tracks/curve_r1200.toml"),
    ),
    (
        "tracks/curve_r400.toml",
        include_str!("../tracks/curve_r400.toml"),
    ),
    (
        "tracks/curve_r600.toml",
        include_str!("../tracks/curve_r600.toml"),
    ),
    (
        "tracks/curve_r800.toml",
        include_str!("../tracks/curve_r800.toml"),
    ),
    (
        "tracks/demo.plan.toml",
        include_str!("../tracks/demo.plan.toml"),
    ),
    (
        "tracks/grade10_L110.toml",
        include_str!("../tracks/grade10_L110.toml"),
    ),
    (
        "tracks/grade10_L12p5.toml",
        include_str!("../tracks/grade10_L12p5.toml"),
    ),
    (
        "tracks/grade10_L25.toml",
        include_str!("../tracks/grade10_L25.toml"),
    ),
    (
        "tracks/grade10_L37p5.toml",
        include_str!("../tracks/grade10_L37p5.toml"),
    ),
    (
        "tracks/grade10_L50.toml",
        include_str!("../tracks/grade10_L50.toml"),
    ),
    (
        "tracks/grade10_L62p5.toml",
        include_str!("../tracks/grade10_L62p5.toml"),
    ),
    (
        "tracks/grade10_L80.toml",
        include_str!("../tracks/grade10_L80.toml"),
    ),
    (
        "tracks/grade10_L92p5.toml",
        include_str!("../tracks/grade10_L92p5.toml"),
    ),
    (
        "tracks/grade20_L110.toml",
        include_str!("../tracks/grade20_L110.toml"),
    ),
    (
        "tracks/grade20_L12p5.toml",
        include_str!("../tracks/grade20_L12p5.toml"),
    ),
    (
        "tracks/grade20_L25.toml",
        include_str!("../tracks/grade20_L25.toml"),
    ),
    (
        "tracks/grade20_L37p5.toml",
        include_str!("../tracks/grade20_L37p5.toml"),
    ),
    (
        "tracks/grade20_L50.toml",
        include_str!("../tracks/grade20_L50.toml"),
    ),
    (
        "tracks/grade20_L62p5.toml",
        include_str!("../tracks/grade20_L62p5.toml"),
    ),
    (
        "tracks/grade20_L80.toml",
        include_str!("../tracks/grade20_L80.toml"),
    ),
    (
        "tracks/grade20_L92p5.toml",
        include_str!("../tracks/grade20_L92p5.toml"),
    ),
    (
        "tracks/paper34.plan.toml",
        include_str!("../tracks/paper34.plan.toml"),
    ),
    (
        "tracks/paper34_varied.plan.toml",
        include_str!("../tracks/paper34_varied.plan.toml"),
    ),
    (
        "tracks/sensitivity.plan.toml",
        include_str!("../tracks/sensitivity.plan.toml"),
    ),
    (
        "tracks/tangent.toml",
        include_str!("../tracks/tangent.toml"),
    ),
];

/// The path to read for `path`: itself when it exists, else the built-in copy of the same
/// file when there is one, else itself (the loader then says it is missing).
pub fn resolve(path: &Path) -> Result<PathBuf> {
    // A folder never stands for a file: `railforce demo` writes `demo/`, and `--plan demo`
    // run beside it still means the built-in plan.
    if path.exists() && !path.is_dir() {
        return Ok(path.to_path_buf());
    }
    let rel = path.strip_prefix("./").unwrap_or(path);
    // A bare name stands for a built-in plan or vehicle: `paper34`, `demo`, `c80_empty`.
    let named = rel
        .to_str()
        .filter(|r| !r.contains('/') && !r.contains('.'))
        .and_then(|n| {
            [
                format!("tracks/{n}.plan.toml"),
                format!("vehicles/{n}.toml"),
                format!("tracks/{n}.toml"),
            ]
            .into_iter()
            .find(|c| FILES.iter().any(|(p, _)| p == c))
        });
    if named.is_none()
        && rel
            .to_str()
            .is_some_and(|r| !r.contains('/') && !r.contains('.'))
    {
        return Err(Error::Domain(format!(
            "{}: no such file, and no built-in plan, vehicle or track of that name (built-in: {})",
            path.display(),
            names().join(", ")
        )));
    }
    let rel = named.as_deref().map(Path::new).unwrap_or(rel);
    let Some(rel) = rel.to_str().filter(|r| FILES.iter().any(|(p, _)| p == r)) else {
        return Ok(path.to_path_buf());
    };
    static DIR: OnceLock<std::result::Result<PathBuf, String>> = OnceLock::new();
    let dir = DIR
        .get_or_init(|| {
            // One folder per version; every process rewrites it (atomically, file by file),
            // so it always holds this binary's files and concurrent runs agree.
            let dir = std::env::temp_dir()
                .join(format!("railforce-{}-builtin", env!("CARGO_PKG_VERSION")));
            write_all(&dir, true).map_err(|e| format!("{e:#}"))?;
            Ok(dir)
        })
        .as_ref()
        .map_err(|e| Error::Domain(format!("writing the built-in files: {e}")))?;
    Ok(dir.join(rel))
}

/// The bare names that stand for built-in plans, vehicles and tracks, in that order (the
/// names `resolve` accepts: no dot, so a plan is not also listed as a track).
pub fn names() -> Vec<&'static str> {
    let kind = |prefix: &'static str, suffix: &'static str| {
        FILES
            .iter()
            .filter_map(move |(p, _)| p.strip_prefix(prefix)?.strip_suffix(suffix))
            .filter(|n| !n.contains('.'))
    };
    kind("tracks/", ".plan.toml")
        .chain(kind("vehicles/", ".toml"))
        .chain(kind("tracks/", ".toml"))
        .collect()
}

/// Writes every built-in file under `dir` (the repository's layout); refuses to overwrite an
/// existing file unless `force`.
pub fn write_all(dir: &Path, force: bool) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for (rel, text) in FILES {
        let p = dir.join(rel);
        if p.exists() && !force {
            return Err(Error::Domain(format!(
                "{} exists: remove it, or overwrite (`init --force`)",
                p.display()
            )));
        }
        if let Some(parent) = p.parent() {
            std::fs::create_dir_all(parent).map_err(|e| Error::io(parent, e))?;
        }
        crate::io::write_atomic(&p, |w| w.write_all(text.as_bytes()))?;
        written.push(p);
    }
    Ok(written)
}
