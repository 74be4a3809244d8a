//! The experiments' `index.html`: rebuilt from every part's saved section and provenance, in
//! report order, whichever run wrote them.

use super::Which;
use crate::error::Result;
use crate::report::write_index;
use std::path::{Path, PathBuf};

/// Folder of an experiments report that holds a viewer page (`railforce demo` writes one).
pub const VIEW_FOLDER: &str = "view";

/// Rebuilds `index.html` of an experiments folder from every part present (each part's
/// `section.json` and `meta.json`), whichever order and run they came from; the intro states
/// the protocol of the latest run and warns when parts were computed on different data.
pub fn write_report(out: &Path) -> Result<PathBuf> {
    let meta = read_json(&out.join("meta.json")).unwrap_or_default();
    let mut intro = protocol_lines(&meta);
    intro.insert(
        1,
        "Paper numbers come from another simulator and an unstated (apparently shuffled) split: a bar, not a target to match digit for digit. Each part below states its own protocol and the data it was computed on.".into(),
    );
    let mut data: Vec<(String, String)> = Vec::new();
    for f in Which::FOLDERS {
        if let Some(m) = read_json(&out.join(f).join("meta.json")) {
            data.push((
                f.to_string(),
                m["data_fnv1a"].as_str().unwrap_or("?").to_string(),
            ));
        }
    }
    if data.windows(2).any(|w| w[0].1 != w[1].1) {
        intro.push(format!(
            "Note: these parts were computed on different data: {}.",
            data.iter()
                .map(|(f, h)| format!("{f} {h}"))
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    // After the parts, the viewer's folder where `railforce demo` wrote one.
    let mut folders = Which::FOLDERS.to_vec();
    folders.push(VIEW_FOLDER);
    write_index(
        out,
        "railforce: wheel–rail force identification experiments",
        &intro,
        &folders,
    )?;
    Ok(out.join("index.html"))
}

/// A JSON file, or `None` when it is absent or unreadable (a report shows what is there).
pub(super) fn read_json(p: &Path) -> Option<serde_json::Value> {
    crate::io::read_text(p)
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
}

/// The protocol of a run, from its `meta.json`: the data, noise, split and windows, then the
/// training settings. `index.html` and the results snapshot both print these lines.
pub(super) fn protocol_lines(meta: &serde_json::Value) -> Vec<String> {
    let s = |k: &str| meta[k].as_str().unwrap_or("?").to_string();
    let mut lines = vec![format!(
        "Latest run: railforce {}, plan {} ({} runs, data {}); noise: {}; split: {}; windows of {} steps, label {}.",
        s("railforce_version"),
        s("plan_name"),
        meta["runs"].as_u64().unwrap_or(0),
        s("data_fnv1a"),
        s("noise_definition"),
        s("split_description"),
        meta["window"].as_u64().unwrap_or(0),
        s("label_at").to_lowercase(),
    )];
    let t = &meta["training"];
    let count = |v: &serde_json::Value| v.as_u64().map_or("all".to_string(), |n| n.to_string());
    if t.is_object() {
        lines.push(format!(
            "Training: Adam lr {}{}, batch {}, at most {} epochs, early stopping patience {}, {} training windows drawn per epoch ({} on one condition), validation on at most {} windows{}; classical models on at most {} windows.",
            // lr is an f32: print its decimal, not its binary expansion.
            t["lr"].as_f64().map_or("?".into(), |v| format!("{}", v as f32)),
            match t["lr_plateau"].as_u64() {
                Some(n) if n > 0 => format!(", halved after {n} epochs without a better validation loss"),
                _ => String::new(),
            },
            t["batch"],
            t["epochs"],
            t["patience"],
            count(&t["windows_per_epoch"]),
            count(&meta["condition_windows_per_epoch"]),
            count(&t["val_windows"]),
            if meta["fresh_noise_every_epoch"].as_bool() == Some(true) {
                "; networks trained at an SNR draw new input noise every epoch (validation and test keep one fixed, seeded realisation)"
            } else {
                "; networks trained on one fixed noise realisation"
            },
            t["classical_rows"],
        ));
    }
    lines
}
