//! Measured data as it comes: a channel map (TOML) tells `identify` which column of a field
//! recording holds each model channel, in which unit and with which sign, so a recording with
//! its own names (`SF_L_AY`), units (g, mm, degrees, mrad/s) and axes is read without editing.
//!
//! ```toml
//! # railforce channel map: model channel = column, unit, sign (−1 where the recorder's axis
//! # points the other way from railforce's: x ahead, y left, z up)
//! time = { column = "Time", unit = "ms" }
//! [channels]
//! frame_l_acc_y = { column = "SF_L_AY", unit = "g", sign = -1 }
//! ws1_y_rel = { column = "WS1_LAT", unit = "mm" }
//! body_yaw_rate = { column = "GYRO_Z", unit = "deg/s" }
//! ```
//!
//! Channels the map does not name are read under their own names. A column that is missing,
//! a unit that is unknown or does not convert to the channel's own (g to rad/s), or a map that
//! names a channel the model does not read, is an error naming the map, the channel and the
//! column.

use super::SensorTable;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Units a map may give: (unit, the SI unit it converts to, factor to it).
const UNITS: [(&str, &str, f64); 18] = [
    ("m/s2", "m/s2", 1.0),
    ("m/s^2", "m/s2", 1.0),
    ("g", "m/s2", 9.80665),
    ("m", "m", 1.0),
    ("mm", "m", 1e-3),
    ("rad", "rad", 1.0),
    ("mrad", "rad", 1e-3),
    ("deg", "rad", std::f64::consts::PI / 180.0),
    ("rad/s", "rad/s", 1.0),
    ("mrad/s", "rad/s", 1e-3),
    ("deg/s", "rad/s", std::f64::consts::PI / 180.0),
    ("1", "1", 1.0),
    ("1/m", "1/m", 1.0),
    ("N", "N", 1.0),
    ("kN", "N", 1e3),
    ("s", "s", 1.0),
    ("ms", "s", 1e-3),
    ("km", "m", 1e3),
];

/// One model channel in a recording.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mapping {
    /// Column of the recording.
    pub column: String,
    /// Its unit (one of the map's units; default: the channel's own SI unit).
    #[serde(default)]
    pub unit: Option<String>,
    /// +1, or −1 where the recorder's axis points the other way.
    #[serde(default = "plus")]
    pub sign: f64,
}

fn plus() -> f64 {
    1.0
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MapFile {
    time: Option<Mapping>,
    #[serde(default)]
    channels: BTreeMap<String, Mapping>,
}

/// A channel map.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ChannelMap {
    /// The map file.
    pub source: PathBuf,
    /// The time column, if the recording's is not `time_s` in seconds.
    pub time: Option<Mapping>,
    /// Model channel → its column.
    pub channels: BTreeMap<String, Mapping>,
}

/// The SI unit and factor of `unit`, or `None`.
fn unit(unit: &str) -> Option<(&'static str, f64)> {
    UNITS.iter().find(|u| u.0 == unit).map(|u| (u.1, u.2))
}

impl ChannelMap {
    /// Reads and checks a map file: known units, signs ±1.
    pub fn load(path: &Path) -> Result<Self> {
        let raw: MapFile = crate::io::read_toml(path)?;
        let known = || UNITS.iter().map(|u| u.0).collect::<Vec<_>>().join(", ");
        for (name, m) in raw
            .channels
            .iter()
            .map(|(k, m)| (format!("channels.{k}"), m))
            .chain(raw.time.iter().map(|m| ("time".to_string(), m)))
        {
            if let Some(u) = &m.unit
                && unit(u).is_none()
            {
                return Err(Error::config(
                    path,
                    format!("{name}.unit"),
                    format!("unknown unit \"{u}\" (known: {})", known()),
                ));
            }
            if m.sign != 1.0 && m.sign != -1.0 {
                return Err(Error::config(
                    path,
                    format!("{name}.sign"),
                    format!("{}: give 1 or -1", m.sign),
                ));
            }
        }
        // Two model channels read from one column: one sensor cannot be two.
        let mut seen: Vec<(&str, &str)> = Vec::new();
        for (name, m) in &raw.channels {
            if let Some((other, _)) = seen.iter().find(|(_, c)| *c == m.column) {
                return Err(Error::config(
                    path,
                    format!("channels.{name}.column"),
                    format!(
                        "\"{}\" is already channels.{other}'s: each channel needs a column of its own",
                        m.column
                    ),
                ));
            }
            seen.push((name, &m.column));
        }
        if let Some(t) = &raw.time
            && t.unit
                .as_deref()
                .and_then(unit)
                .is_some_and(|(si, _)| si != "s")
        {
            return Err(Error::config(
                path,
                "time.unit",
                format!(
                    "\"{}\" is not a time unit (s, ms)",
                    t.unit.as_deref().unwrap_or("")
                ),
            ));
        }
        Ok(ChannelMap {
            source: path.to_path_buf(),
            time: raw.time,
            channels: raw.channels,
        })
    }

    /// Reads a recording (CSV, NPZ or Parquet) through the map: its time column (the map's,
    /// converted to seconds, or `time_s`) and every mapped channel ([`ChannelMap::apply`]).
    pub fn read(&self, path: &Path, model_channels: &[String]) -> Result<SensorTable> {
        let mut cols = crate::dataset::read_table(path)?;
        if let Some(t) = &self.time {
            let k = cols
                .iter()
                .position(|(n, _)| *n == t.column)
                .ok_or_else(|| {
                    Error::Domain(format!(
                        "{}: time: {}: no column \"{}\" (columns: {})",
                        self.source.display(),
                        path.display(),
                        t.column,
                        cols.iter()
                            .map(|(n, _)| n.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ))
                })?;
            let f = t.unit.as_deref().and_then(unit).map_or(1.0, |u| u.1);
            let (_, v) = cols.remove(k);
            cols.retain(|(n, _)| !super::TIME_COLUMNS.contains(&n.as_str()));
            cols.insert(
                0,
                ("time_s".into(), v.iter().map(|x| x * f * t.sign).collect()),
            );
        }
        let table = SensorTable::from_columns(path.display().to_string(), cols)?;
        self.apply(&table, model_channels)
    }

    /// The recording with the map's channels applied: each mapped column converted to its
    /// model channel's SI unit and sign and named after the channel (replacing a column of that
    /// name and its `_noisy` copy); `model_channels` are the channels the model reads (a mapped
    /// channel outside them is refused, so a typo is not silently ignored).
    pub fn apply(&self, table: &SensorTable, model_channels: &[String]) -> Result<SensorTable> {
        let map = self.source.display();
        let mut out = table.clone();
        for (channel, m) in &self.channels {
            if !model_channels.iter().any(|c| c == channel) {
                return Err(Error::Domain(format!(
                    "{map}: channels.{channel}: the model does not read this channel (it reads {})",
                    model_channels.join(", ")
                )));
            }
            let col = table.column(&m.column).ok_or_else(|| {
                Error::Domain(format!(
                    "{map}: channels.{channel}: {}: no column \"{}\" (columns: {})",
                    table.source,
                    m.column,
                    names(table)
                ))
            })?;
            let own = crate::sim::output::unit_of(channel).ok_or_else(|| {
                Error::Domain(format!(
                    "{map}: channels.{channel}: not a channel railforce records"
                ))
            })?;
            let factor = match m.unit.as_deref() {
                None => 1.0,
                Some(u) => {
                    let (si, f) = unit(u).expect("checked on load");
                    if si != own {
                        return Err(Error::Domain(format!(
                            "{map}: channels.{channel}: column \"{}\" in {u} does not convert to the channel's {own}",
                            m.column
                        )));
                    }
                    f
                }
            };
            let values: Vec<f64> = col.iter().map(|v| v * factor * m.sign).collect();
            out.columns
                .retain(|(n, _)| n != channel && *n != crate::sensors::noisy_name(channel));
            out.columns.push((channel.clone(), values));
        }
        Ok(out)
    }

    /// The columns a recorder following this map writes for the model's `channels` of
    /// `table` (each from its `_noisy` copy where the table has one: a recorder's values are
    /// noisy), with the track position `s_m` where the table has it: the map's time column in
    /// its unit, each mapped channel under its column in its unit and sign, the others under
    /// their own names. [`ChannelMap::read`] of a file of these columns gives the channels back:
    /// closed-loop validation through a field recording's conventions.
    pub fn record(
        &self,
        table: &SensorTable,
        channels: &[String],
    ) -> Result<Vec<(String, Vec<f64>)>> {
        let factor = |m: &Mapping| m.unit.as_deref().and_then(unit).map_or(1.0, |u| u.1) * m.sign;
        let mut out = vec![match &self.time {
            Some(t) => (
                t.column.clone(),
                table.time.iter().map(|v| v / factor(t)).collect(),
            ),
            None => ("time_s".to_string(), table.time.clone()),
        }];
        if let Some(s) = table.column("s_m") {
            out.push(("s_m".into(), s.to_vec()));
        }
        for c in channels {
            let noisy = crate::sensors::noisy_name(c);
            let v = table
                .column(&noisy)
                .or_else(|| table.column(c))
                .ok_or_else(|| {
                    Error::Domain(format!("{}: no channel {c} to record", table.source))
                })?;
            out.push(match self.channels.get(c) {
                Some(m) => (m.column.clone(), v.iter().map(|x| x / factor(m)).collect()),
                None => (c.clone(), v.to_vec()),
            });
        }
        Ok(out)
    }

    /// What the output's metadata records.
    pub fn describe(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or_default()
    }
}

fn names(table: &SensorTable) -> String {
    table
        .columns
        .iter()
        .map(|(n, _)| n.as_str())
        .collect::<Vec<_>>()
        .join(", ")
}
