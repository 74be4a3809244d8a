//! Drawn values into the files: a key's path walked through the vehicle or track file's TOML
//! (every entry of an array of tables without an index), the value replaced or scaled, and the
//! file then loaded by its own loader, so a drawn value is validated as a written one would be.

use super::{Drawn, Draws, Target, target};
use crate::error::{Error, Result};
use crate::track::TrackSpec;
use crate::vehicle::{Body, Vehicle};
use std::path::Path;

/// The vehicle file `file` with the draws' `vehicle.` keys applied (the file itself when none
/// is drawn). The error names the keys.
pub fn vehicle_for(file: &Path, draws: &Draws) -> Result<Vehicle> {
    let file_keys: Vec<(&String, &Drawn)> = of(draws, Target::Vehicle);
    let body_keys: Vec<(&String, &Drawn)> = of(draws, Target::Body);
    if file_keys.is_empty() && body_keys.is_empty() {
        return Vehicle::load(file);
    }
    let text = edited_text(file, &file_keys)?;
    let mut bodies = |bodies: &mut [Body]| -> Result<()> {
        for (key, d) in &body_keys {
            edit_body(bodies, key, d).map_err(|m| Error::Domain(format!("{key}: {m}")))?;
        }
        Ok(())
    };
    Vehicle::load_edited(file, text.as_deref(), &mut bodies)
        .map_err(|e| with_keys(e, &file_keys, &body_keys))
}

/// The track file `file` with the draws' `track.` keys applied.
pub fn track_for(file: &Path, draws: &Draws) -> Result<TrackSpec> {
    let keys = of(draws, Target::Track);
    match edited_text(file, &keys)? {
        None => TrackSpec::load(file),
        Some(text) => TrackSpec::parse(&text, file).map_err(|e| with_keys(e, &keys, &[])),
    }
}

/// The speed of a run, km/h: the condition's `base`, replaced or scaled by a drawn
/// `speed_kmh`; it must stay in (0, 200] km/h.
pub fn speed_kmh(base: f64, draws: &Draws) -> Result<f64> {
    let Some(d) = draws.get("speed_kmh") else {
        return Ok(base);
    };
    let x = number(&d.value).map_err(Error::Domain)?;
    let v = if d.scale { base * x } else { x };
    if v > 0.0 && v <= 200.0 {
        Ok(v)
    } else {
        Err(Error::Domain(format!(
            "speed_kmh: {v} km/h is outside (0, 200] km/h"
        )))
    }
}

/// The wagon's place in its train for a run: the condition's `base` (None: the consist
/// file's own), or the drawn `position` (a fraction of the train's length from the head;
/// scaled, a factor on the base), checked to land on a wagon of `consist`. Drawn for a
/// condition in no train, an error.
pub fn position(
    base: Option<f64>,
    draws: &Draws,
    consist: Option<&crate::train::Consist>,
) -> Result<Option<f64>> {
    let Some(d) = draws.get("position") else {
        return Ok(base);
    };
    let Some(consist) = consist else {
        return Err(Error::Domain(
            "position: drawn for a condition in no train: give it a consist".into(),
        ));
    };
    let x = number(&d.value).map_err(Error::Domain)?;
    let p = if d.scale {
        base.unwrap_or(consist.position) * x
    } else {
        x
    };
    consist
        .index_at(p)
        .map_err(|e| Error::Domain(format!("position: {p}: {e}")))?;
    Ok(Some(p))
}

/// The condition's consist with the drawn `consist_mass` applied: every wagon's mass times
/// the drawn factor (the locomotives keep theirs; the 3-D wagon's own mass is its vehicle
/// file's). The factor must be drawn scaled and lie in (0, 2]; drawn for a condition in no
/// train, an error.
pub fn consist_for(
    consist: Option<&crate::train::Consist>,
    draws: &Draws,
) -> Result<Option<crate::train::Consist>> {
    let Some(d) = draws.get("consist_mass") else {
        return Ok(consist.cloned());
    };
    let Some(consist) = consist else {
        return Err(Error::Domain(
            "consist_mass: drawn for a condition in no train: give it a consist".into(),
        ));
    };
    let f = number(&d.value).map_err(Error::Domain)?;
    if !(d.scale && f > 0.0 && f <= 2.0) {
        return Err(Error::Domain(format!(
            "consist_mass: a factor in (0, 2] on the wagons' masses, drawn with scale = true (got {f})"
        )));
    }
    let mut c = consist.clone();
    for v in c
        .vehicles
        .iter_mut()
        .filter(|v| v.kind == crate::train::VehicleKind::Wagon)
    {
        v.mass *= f;
    }
    Ok(Some(c))
}

/// A condition as [`check`] sees it.
#[derive(Debug, Clone, Copy)]
pub struct Subject<'a> {
    /// Its place in the plan (`condition[3]`) and name.
    pub index: usize,
    /// Its name.
    pub name: &'a str,
    /// Its vehicle and track files.
    pub vehicle: &'a Path,
    /// See `vehicle`.
    pub track: &'a Path,
    /// Its speed, km/h.
    pub speed_kmh: f64,
    /// The FRA class it sets, if any.
    pub class: Option<i64>,
    /// Its train's consist and the wagon's place in it, if it runs in one.
    pub consist: Option<&'a crate::train::Consist>,
    /// See `consist`.
    pub position: Option<f64>,
}

/// Tries every variation of a condition at the ends of its range (each value of a list), one
/// key at a time on the condition's own files, before any run: a key that names nothing, or a
/// value the file's loader refuses, is an error naming the plan key (`source` the plan file).
/// `tried` carries (file, key, value) already tried across conditions.
pub fn check(
    source: &Path,
    c: Subject<'_>,
    vary: &super::Vary,
    tried: &mut Vec<(std::path::PathBuf, String, String)>,
) -> Result<()> {
    if let Some(class) = c.class
        && let Some(v) = vary
            .variations
            .iter()
            .find(|v| v.key == "track.irregularity.class")
    {
        return Err(Error::config(
            source,
            format!("{}.\"{}\"", v.origin, v.key),
            format!(
                "condition[{}] ({}) sets class = {class} too: give one of the two",
                c.index, c.name
            ),
        ));
    }
    for v in &vary.variations {
        for value in v.draw.extremes() {
            let mut draws = Draws::new();
            v.insert(&mut draws, value.clone());
            let which = match &v.draw {
                super::Draw::OneOf(_) => "a listed value",
                _ => "an end of its range",
            };
            for (key, d) in &draws {
                let t = target(key).map_err(Error::Domain)?;
                let file = match t {
                    Target::Vehicle | Target::Body => c.vehicle,
                    Target::Track => c.track,
                    Target::Speed | Target::Position | Target::ConsistMass => source,
                };
                let id = (file.to_path_buf(), key.clone(), value.to_string());
                if matches!(t, Target::Vehicle | Target::Body | Target::Track)
                    && tried.contains(&id)
                {
                    continue;
                }
                let only: Draws = [(key.clone(), d.clone())].into_iter().collect();
                let outcome = match t {
                    Target::Vehicle | Target::Body => vehicle_for(file, &only).map(|_| ()),
                    Target::Track => track_for(file, &only).map(|_| ()),
                    Target::Speed => speed_kmh(c.speed_kmh, &only).map(|_| ()),
                    Target::Position => position(c.position, &only, c.consist).map(|_| ()),
                    Target::ConsistMass => consist_for(c.consist, &only).map(|_| ()),
                };
                if let Err(e) = outcome {
                    return Err(Error::config(
                        source,
                        format!("{}.\"{}\"", v.origin, v.key),
                        format!(
                            "at {value}{} ({which}), condition {} is refused: {e}",
                            if v.scale {
                                " times the file's value"
                            } else {
                                ""
                            },
                            c.name
                        ),
                    ));
                }
                tried.push(id);
            }
        }
    }
    Ok(())
}

/// The draws that point at `t`.
fn of(draws: &Draws, t: Target) -> Vec<(&String, &Drawn)> {
    draws.iter().filter(|(k, _)| target(k) == Ok(t)).collect()
}

/// An error of the loader with the drawn keys that led to it.
fn with_keys(e: Error, a: &[(&String, &Drawn)], b: &[(&String, &Drawn)]) -> Error {
    let keys: Vec<String> = a
        .iter()
        .chain(b)
        .map(|(k, d)| format!("{k} = {}{}", d.value, if d.scale { " (scale)" } else { "" }))
        .collect();
    Error::Domain(format!("{e} (drawn: {})", keys.join(", ")))
}

/// The file's text with `keys` applied (their first segment dropped), or `None` with none.
fn edited_text(file: &Path, keys: &[(&String, &Drawn)]) -> Result<Option<String>> {
    if keys.is_empty() {
        return Ok(None);
    }
    let mut doc: toml::Table = crate::io::read_toml(file)?;
    for (key, d) in keys {
        let path = key.split_once('.').map_or("", |p| p.1);
        let segments: Vec<&str> = path.split('.').collect();
        edit(&mut doc, &segments, d).map_err(|m| Error::config(file, key.as_str(), m))?;
    }
    toml::to_string(&doc)
        .map(Some)
        .map_err(|e| Error::Domain(format!("{}: {e}", file.display())))
}

/// Walks `segments` from `table` and replaces or scales what they name.
fn edit(table: &mut toml::Table, segments: &[&str], d: &Drawn) -> std::result::Result<(), String> {
    let (first, rest) = segments.split_first().ok_or("an empty key")?;
    let (name, index) = match first.split_once('[') {
        Some((n, i)) => {
            let i: usize = i
                .strip_suffix(']')
                .and_then(|i| i.parse().ok())
                .ok_or(format!("\"{first}\": an index is written name[0]"))?;
            (n, Some(i))
        }
        None => (*first, None),
    };
    let here = table.keys().cloned().collect::<Vec<_>>().join(", ");
    if rest.is_empty() && index.is_none() {
        return match table.get_mut(name) {
            Some(v) => set(v, d),
            None if !d.scale => {
                // A key the file leaves at its default: the loader says whether it exists.
                table.insert(name.to_string(), d.value.clone());
                Ok(())
            }
            None => Err(format!(
                "no \"{name}\" in the file to scale (keys there: {here})"
            )),
        };
    }
    let value = table
        .get_mut(name)
        .ok_or(format!("no \"{name}\" in the file (keys there: {here})"))?;
    let mut targets: Vec<&mut toml::Value> = match (value, index) {
        (toml::Value::Array(a), Some(i)) => {
            let n = a.len();
            vec![
                a.get_mut(i)
                    .ok_or(format!("{name}[{i}]: the file has {n} entries"))?,
            ]
        }
        (toml::Value::Array(a), None) => a.iter_mut().collect(),
        (v, None) => vec![v],
        (_, Some(_)) => return Err(format!("\"{name}\" is not a list to index")),
    };
    for t in targets.iter_mut() {
        if rest.is_empty() {
            set(t, d)?;
        } else {
            let inner = t
                .as_table_mut()
                .ok_or(format!("\"{name}\" is a value, not a table to go into"))?;
            edit(inner, rest, d)?;
        }
    }
    Ok(())
}

/// Replaces `v` by the drawn value, or multiplies it (every number of a list).
fn set(v: &mut toml::Value, d: &Drawn) -> std::result::Result<(), String> {
    if d.scale {
        let f = number(&d.value)?;
        let scale_one = |x: &mut toml::Value| match x {
            toml::Value::Float(y) => {
                *y *= f;
                Ok(())
            }
            toml::Value::Integer(_) => {
                Err("an integer cannot be scaled: draw it with one_of".to_string())
            }
            other => Err(format!("{other} is not a number to scale")),
        };
        return match v {
            toml::Value::Array(a) => a.iter_mut().try_for_each(scale_one),
            x => scale_one(x),
        };
    }
    let new = match (&*v, &d.value) {
        (toml::Value::Array(_), _) => {
            return Err("the file has a list here: scale it (scale = true)".into());
        }
        (toml::Value::Integer(_), toml::Value::Integer(i)) => toml::Value::Integer(*i),
        (toml::Value::Integer(_), toml::Value::Float(f)) if f.fract() == 0.0 => {
            toml::Value::Integer(*f as i64)
        }
        (toml::Value::Integer(_), other) => {
            return Err(format!(
                "the file has an integer here, the draw gives {other}: draw it with one_of"
            ));
        }
        (toml::Value::Float(_), toml::Value::Integer(i)) => toml::Value::Float(*i as f64),
        (toml::Value::Float(_), toml::Value::Float(f)) => toml::Value::Float(*f),
        (toml::Value::String(_), toml::Value::String(s)) => toml::Value::String(s.clone()),
        (old, new) => {
            return Err(format!(
                "the file has {old} here, the draw gives {new}: not the same kind of value"
            ));
        }
    };
    *v = new;
    Ok(())
}

/// A URDF body's `mass` (kg), `inertia` (scaled, all three principal moments) or `z` (height of
/// its centre of gravity above the rail, m): `vehicle.body.<link>.<field>`.
fn edit_body(bodies: &mut [Body], key: &str, d: &Drawn) -> std::result::Result<(), String> {
    let rest = key.strip_prefix("vehicle.body.").unwrap_or(key);
    let (link, field) = rest
        .split_once('.')
        .ok_or("write vehicle.body.<link>.mass, .inertia or .z")?;
    let names = || {
        bodies
            .iter()
            .map(|b| b.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let all = names();
    let b = bodies
        .iter_mut()
        .find(|b| b.name == link)
        .ok_or(format!("no body \"{link}\" in the URDF (bodies: {all})"))?;
    let x = number(&d.value)?;
    let apply = |old: f64| if d.scale { old * x } else { x };
    match field {
        "mass" => b.mass = apply(b.mass),
        "z" => b.position.z = apply(b.position.z),
        "inertia" if d.scale => b.inertia *= x,
        "inertia" => {
            return Err("inertia is scaled (scale = true): all three moments by one factor".into());
        }
        other => return Err(format!("\"{other}\": a body takes mass, inertia or z")),
    }
    if !(b.mass > 0.0 && b.mass.is_finite()) {
        return Err(format!("mass {} kg must be positive", b.mass));
    }
    if !(b.inertia.min() > 0.0 && b.inertia.iter().all(|v| v.is_finite())) {
        return Err("the moments of inertia must be positive".into());
    }
    if !(b.position.z > 0.0 && b.position.z.is_finite()) {
        return Err(format!(
            "centre of gravity {} m must lie above the rail",
            b.position.z
        ));
    }
    Ok(())
}

/// A drawn number.
fn number(v: &toml::Value) -> std::result::Result<f64, String> {
    v.as_float()
        .or_else(|| v.as_integer().map(|i| i as f64))
        .ok_or(format!("{v} is not a number"))
}
