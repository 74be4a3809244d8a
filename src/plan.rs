//! Plan files: the list of working conditions a data set is generated from.
//!
//! A plan names a vehicle, default duration and seeds, and any number of `[[condition]]`
//! tables (name, track file, speed, optional overrides). Paths are relative to the plan file.

use crate::error::{Error, Result};
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PlanFile {
    name: Option<String>,
    vehicle: String,
    duration_s: f64,
    #[serde(default = "default_seeds")]
    seeds: Vec<u64>,
    #[serde(default)]
    condition: Vec<ConditionFile>,
}

fn default_seeds() -> Vec<u64> {
    vec![1]
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ConditionFile {
    name: String,
    track: String,
    speed_kmh: f64,
    duration_s: Option<f64>,
    seeds: Option<Vec<u64>>,
}

/// One working condition of a plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Condition {
    /// Unique name (used for output file names).
    pub name: String,
    /// Track file, resolved against the plan's folder.
    pub track: PathBuf,
    /// Running speed, km/h.
    pub speed_kmh: f64,
    /// Recorded duration after settling, s.
    pub duration: f64,
    /// Irregularity seeds: one run per seed.
    pub seeds: Vec<u64>,
}

impl Condition {
    /// Running speed, m/s.
    pub fn speed(&self) -> f64 {
        self.speed_kmh / 3.6
    }
}

/// A validated plan.
#[derive(Debug, Clone)]
pub struct Plan {
    /// File it came from.
    pub source: PathBuf,
    /// Name for reports.
    pub name: String,
    /// Vehicle file, resolved against the plan's folder.
    pub vehicle: PathBuf,
    /// Conditions in file order.
    pub conditions: Vec<Condition>,
}

impl Plan {
    /// Reads and validates a plan file (the track files themselves are checked by
    /// [`crate::track::TrackSpec::load`] when used).
    pub fn load(path: &Path) -> Result<Self> {
        let raw: PlanFile = crate::io::read_toml(path)?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let positive = |field: String, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(Error::config(
                    path,
                    field,
                    format!("must be positive, got {v}"),
                ))
            }
        };
        positive("duration_s".into(), raw.duration_s)?;
        if raw.seeds.is_empty() {
            return Err(Error::config(path, "seeds", "give at least one seed"));
        }
        if raw.condition.is_empty() {
            return Err(Error::config(
                path,
                "condition",
                "a plan needs at least one [[condition]]",
            ));
        }
        let mut conditions: Vec<Condition> = Vec::new();
        for (i, c) in raw.condition.into_iter().enumerate() {
            let f = |name: &str| format!("condition[{i}].{name}");
            if c.name.is_empty()
                || !c
                    .name
                    .chars()
                    .all(|ch| ch.is_ascii_alphanumeric() || "_-.".contains(ch))
            {
                return Err(Error::config(
                    path,
                    f("name"),
                    format!(
                        "\"{}\" must be non-empty and use only letters, digits, _ - .",
                        c.name
                    ),
                ));
            }
            if conditions.iter().any(|o| o.name == c.name) {
                return Err(Error::config(
                    path,
                    f("name"),
                    format!("\"{}\" is used twice", c.name),
                ));
            }
            let speed = positive(f("speed_kmh"), c.speed_kmh)?;
            if speed > 200.0 {
                return Err(Error::config(
                    path,
                    f("speed_kmh"),
                    format!("{speed} km/h is beyond the 200 km/h this freight model supports"),
                ));
            }
            let duration = positive(f("duration_s"), c.duration_s.unwrap_or(raw.duration_s))?;
            let seeds = c.seeds.unwrap_or_else(|| raw.seeds.clone());
            if seeds.is_empty() {
                return Err(Error::config(path, f("seeds"), "give at least one seed"));
            }
            conditions.push(Condition {
                name: c.name,
                track: dir.join(c.track),
                speed_kmh: speed,
                duration,
                seeds,
            });
        }
        Ok(Plan {
            source: path.to_path_buf(),
            name: raw.name.unwrap_or_else(|| {
                path.file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            }),
            vehicle: dir.join(raw.vehicle),
            conditions,
        })
    }
}
