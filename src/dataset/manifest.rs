//! The data set's manifest: content hashes (the data identity), the resume key of each run,
//! reading and writing `manifest.json`, refusing to mix data sets in one folder, and merging
//! shard manifests.

use super::{GenerateOptions, RunSpec};
use crate::error::{Error, Result};
use crate::plan::DatasetOptions;
use serde_json::Value;
use std::path::{Path, PathBuf};

/// FNV-1a 64 of bytes, hex.
pub fn fnv1a(bytes: &[u8]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// Identity of a data set's contents: FNV-1a 64 over every run file's name and the hash of its
/// bytes as `manifest.json` records them, in name order. Wall times, tool versions and the
/// order runs finished in are left out, so a rerun that changes no data keeps the identity
/// and any changed byte of any run changes it.
pub fn data_identity(dir: &Path) -> Result<String> {
    let path = dir.join("manifest.json");
    let m = read_manifest(&path)?
        .ok_or_else(|| Error::io(&path, std::io::ErrorKind::NotFound.into()))?;
    let mut runs: Vec<(String, String)> = m["runs"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|r| {
                    (
                        r["file"].as_str().unwrap_or_default().to_string(),
                        r["bytes_hash_fnv1a"]
                            .as_str()
                            .unwrap_or_default()
                            .to_string(),
                    )
                })
                .collect()
        })
        .unwrap_or_default();
    if runs.is_empty() {
        return Err(Error::config(&path, "runs", "the manifest lists no runs"));
    }
    runs.sort();
    let text: String = runs.iter().map(|(f, h)| format!("{f}:{h}\n")).collect();
    Ok(fnv1a(text.as_bytes()))
}

/// FNV-1a 64 of a file's bytes, hex: identifies the inputs of a run.
pub fn file_hash(path: &Path) -> Result<String> {
    Ok(fnv1a(&std::fs::read(path).map_err(|e| Error::io(path, e))?))
}

/// Definition of a run for resuming: changes whenever anything that shapes its data changes.
pub(super) fn run_key(
    run: &RunSpec,
    opts: &GenerateOptions,
    track_hash: &str,
    vehicle_hash: &str,
    dataset: &DatasetOptions,
) -> String {
    // Options added later enter the key only when set, so existing data sets keep their keys.
    let mut extra = String::new();
    if let Some(c) = run.condition.class {
        extra += &format!("|class={c}");
    }
    if let Some(s) = run.condition.start_m {
        extra += &format!("|start={s}");
    }
    if *dataset != DatasetOptions::default() {
        extra += &format!("|dataset={dataset:?}");
    }
    fnv1a(
        format!(
            "{}|{}|{}|{}|{}|{}|{:?}|{}|{}|{}{extra}",
            run.condition.name,
            track_hash,
            vehicle_hash,
            run.condition.speed_kmh,
            run.condition.duration,
            run.seed,
            opts.noise,
            opts.format.ext(),
            opts.settle,
            env!("CARGO_PKG_VERSION")
        )
        .as_bytes(),
    )
}

/// Manifest file of this generation (`manifest.json`, or `manifest.shard-i-of-n.json`).
pub fn manifest_path(opts: &GenerateOptions) -> PathBuf {
    match opts.shard {
        None => opts.out.join("manifest.json"),
        Some((i, n)) => opts.out.join(format!("manifest.shard-{i}-of-{n}.json")),
    }
}

pub(super) fn write_manifest(path: &Path, manifest: &Value) -> Result<()> {
    crate::io::write_atomic(path, |w| {
        serde_json::to_writer_pretty(&mut *w, manifest).map_err(std::io::Error::other)?;
        w.write_all(b"\n")
    })
}

pub(super) fn read_manifest(path: &Path) -> Result<Option<Value>> {
    if !path.exists() {
        return Ok(None);
    }
    let text = crate::io::read_text(path)?;
    serde_json::from_str(&text)
        .map(Some)
        .map_err(|e| Error::Parse {
            file: path.to_path_buf(),
            message: e.to_string(),
        })
}

pub(super) fn sort_runs(m: &mut Value) {
    if let Some(runs) = m["runs"].as_array_mut() {
        runs.sort_by(|a, b| {
            (a["condition"].as_str(), a["seed"].as_u64())
                .cmp(&(b["condition"].as_str(), b["seed"].as_u64()))
        });
    }
}

/// Refuses to add runs to a folder whose data set was written in another format, at another
/// SNR or with other data-set options: one folder, one data set.
pub(super) fn refuse_mixing(
    manifest: &Path,
    previous: Option<&Value>,
    opts: &GenerateOptions,
    dataset: &DatasetOptions,
) -> Result<()> {
    let Some(m) = previous else {
        return Ok(());
    };
    let snr = |v: Option<f64>| v.map_or("clean".to_string(), |s| format!("{s} dB"));
    let (had_format, had_snr) = (m["format"].as_str().unwrap_or("?"), m["snr_db"].as_f64());
    let had_ref = m["snr_reference"].as_str();
    let now_ref = opts.noise.map(|n| n.reference.name());
    let mut differ = Vec::new();
    if had_format != opts.format.ext() {
        differ.push(format!("format {had_format} (now {})", opts.format.ext()));
    }
    if had_snr != opts.noise.map(|n| n.snr_db) || (had_snr.is_some() && had_ref != now_ref) {
        differ.push(format!(
            "noise {}{} (now {}{})",
            snr(had_snr),
            had_ref
                .map(|r| format!(", σ from the {r}"))
                .unwrap_or_default(),
            snr(opts.noise.map(|n| n.snr_db)),
            now_ref
                .map(|r| format!(", σ from the {r}"))
                .unwrap_or_default(),
        ));
    }
    let had_ds = &m["dataset"];
    let now_ds = serde_json::to_value(dataset).expect("options serialise");
    if !(had_ds == &now_ds || (had_ds.is_null() && *dataset == DatasetOptions::default())) {
        differ.push(format!("data-set options {had_ds} (now {now_ds})"));
    }
    if differ.is_empty() {
        return Ok(());
    }
    Err(Error::Domain(format!(
        "{} holds a data set with {}: write to another --out folder, or delete that folder to start again (runs are never mixed)",
        manifest.display(),
        differ.join(" and ")
    )))
}

/// The manifest of the data set a run file belongs to (`manifest.json` beside it) and the
/// run's entry in it, when the file is listed there.
pub fn run_entry(run_file: &Path) -> Option<(Value, Value)> {
    let dir = run_file.parent().unwrap_or(Path::new("."));
    let text = std::fs::read_to_string(dir.join("manifest.json")).ok()?;
    let m: Value = serde_json::from_str(&text).ok()?;
    let name = run_file.file_name()?.to_str()?;
    let entry = m["runs"]
        .as_array()?
        .iter()
        .find(|r| r["file"] == name)?
        .clone();
    Some((m, entry))
}

/// Joins the shard manifests in `out` into `manifest.json` (runs sorted by condition and seed).
pub fn merge(out: &Path) -> Result<Value> {
    let mut shards: Vec<PathBuf> = std::fs::read_dir(out)
        .map_err(|e| Error::io(out, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .map(|n| n.to_string_lossy().starts_with("manifest.shard-"))
                .unwrap_or(false)
        })
        .collect();
    shards.sort();
    if shards.is_empty() {
        return Err(Error::Domain(format!(
            "no manifest.shard-*.json in {}",
            out.display()
        )));
    }
    let mut merged: Option<Value> = None;
    for path in &shards {
        let m = read_manifest(path)?
            .ok_or_else(|| Error::Domain(format!("{} disappeared", path.display())))?;
        if !m.is_object() || !m["runs"].is_array() {
            return Err(Error::config(
                path,
                "runs",
                "missing or not a list: not a railforce shard manifest",
            ));
        }
        match merged.as_mut() {
            None => merged = Some(m),
            Some(all) => {
                for key in ["vehicle", "format", "snr_db", "snr_reference", "plan"] {
                    if all[key] != m[key] {
                        return Err(Error::Domain(format!(
                            "{} disagrees with the other shards on '{key}'",
                            path.display()
                        )));
                    }
                }
                if all["channels"].is_null() {
                    all["channels"] = m["channels"].clone();
                }
                let runs = m["runs"].as_array().cloned().unwrap_or_default();
                if let Some(all_runs) = all["runs"].as_array_mut() {
                    all_runs.extend(runs);
                }
            }
        }
    }
    let Some(mut m) = merged else {
        return Err(Error::Domain(format!(
            "no shard manifest in {}",
            out.display()
        )));
    };
    m["shard"] = Value::Null;
    m["merged_from"] = shards
        .iter()
        .map(|p| Value::from(p.file_name().unwrap().to_string_lossy().into_owned()))
        .collect();
    sort_runs(&mut m);
    write_manifest(&out.join("manifest.json"), &m)?;
    Ok(m)
}
