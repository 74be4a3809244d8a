//! Wagons and tracks that vary: a plan's `[vary]` table (and a condition's `[condition.vary]`)
//! draws, per run and from the run's seed, any key of the vehicle file, the URDF's bodies, the
//! track file or the condition's speed (assets/docs/file-formats.md, "Variation").
//!
//! ```toml
//! [vary]
//! "vehicle.contact.friction" = { uniform = [0.15, 0.5] }                # wet to dry rail
//! "vehicle.body.carbody.mass" = { uniform = [0.5, 1.0], scale = true,   # part-loaded
//!                                 with = ["vehicle.body.carbody.inertia"] }
//! "vehicle.shear_pad.stiffness" = { uniform = [0.8, 1.1], scale = true } # every pad, x y z
//! "track.irregularity.class" = { one_of = [4, 5, 6] }
//! "speed_kmh" = { normal = [80.0, 5.0] }                                # truncated at ±3σ
//! ```
//!
//! Each key is a path in its file (`vehicle.` the vehicle file, `vehicle.body.<link>.` a URDF
//! body's `mass`, `inertia` or centre-of-gravity height `z`, `track.` the track file,
//! `speed_kmh`); an array of tables without an index (`shear_pad`) means every entry, with one
//! (`shear_pad[2]`) that entry. A draw is `uniform = [lo, hi]`, `normal = [mean, std]`
//! (truncated at ±3σ) or `one_of = [...]`; `scale = true` multiplies the file's value (every
//! number of a list) instead of replacing it; `with` applies the same drawn value to more keys.
//!
//! The draw of a run depends only on its condition's name, its seed and the key: the same seed
//! gives the same wagon and the same bytes, and no two runs share a wagon unless they share
//! condition and seed. Every key is tried on the files at the ends of its range before any run
//! ([`check`], through `Plan::check_vary`): a key that does not exist or a value the file's loader refuses is named with
//! the plan key.

mod apply;

pub use apply::{Subject, check, consist_for, position, speed_kmh, track_for, vehicle_for};

use crate::error::{Error, Result};
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use rand_distr::{Distribution, Normal, Uniform};
use std::collections::BTreeMap;
use std::path::Path;

/// How one key is drawn.
#[derive(Debug, Clone, PartialEq)]
pub enum Draw {
    /// Uniform on `[lo, hi]`.
    Uniform(f64, f64),
    /// Normal with mean and standard deviation, truncated at ±3σ (redrawn beyond).
    Normal(f64, f64),
    /// One of a list, each equally likely (numbers or strings).
    OneOf(Vec<toml::Value>),
}

impl Draw {
    /// The values at the ends of its range (every item of a list): what [`check`] tries.
    pub fn extremes(&self) -> Vec<toml::Value> {
        match self {
            Draw::Uniform(lo, hi) => vec![toml::Value::Float(*lo), toml::Value::Float(*hi)],
            Draw::Normal(m, s) => vec![
                toml::Value::Float(m - 3.0 * s),
                toml::Value::Float(m + 3.0 * s),
            ],
            Draw::OneOf(v) => v.clone(),
        }
    }

    fn sample(&self, rng: &mut ChaCha8Rng) -> toml::Value {
        match self {
            Draw::Uniform(lo, hi) if lo == hi => toml::Value::Float(*lo),
            Draw::Uniform(lo, hi) => toml::Value::Float(
                Uniform::new_inclusive(*lo, *hi)
                    .expect("checked lo < hi")
                    .sample(rng),
            ),
            Draw::Normal(m, s) => {
                let d = Normal::new(*m, *s).expect("checked std ≥ 0");
                let x = (0..1000)
                    .map(|_| d.sample(rng))
                    .find(|x| (x - m).abs() <= 3.0 * s)
                    .unwrap_or(*m);
                toml::Value::Float(x)
            }
            Draw::OneOf(v) => {
                let i = Uniform::new(0, v.len())
                    .expect("checked non-empty")
                    .sample(rng);
                v[i].clone()
            }
        }
    }
}

/// One key's variation.
#[derive(Debug, Clone, PartialEq)]
pub struct Variation {
    /// The key as the plan writes it (`vehicle.contact.friction`).
    pub key: String,
    /// Where the plan writes it (`vary` or `condition[3].vary`), for messages.
    pub origin: String,
    /// More keys that take the same drawn value (`with`).
    pub with: Vec<String>,
    /// How it is drawn.
    pub draw: Draw,
    /// Multiply the file's value instead of replacing it.
    pub scale: bool,
}

/// The variations of a plan or a condition.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Vary {
    /// In key order.
    pub variations: Vec<Variation>,
}

/// One drawn value: a replacement, or a factor where the variation scales.
#[derive(Debug, Clone, PartialEq)]
pub struct Drawn {
    /// The value drawn.
    pub value: toml::Value,
    /// It multiplies the file's value.
    pub scale: bool,
}

/// The values drawn for one run, by key (each `with` key under its own name).
pub type Draws = BTreeMap<String, Drawn>;

/// Where a key points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// The vehicle file.
    Vehicle,
    /// A URDF body of the vehicle.
    Body,
    /// The track file.
    Track,
    /// The condition's speed.
    Speed,
    /// The wagon's place in the condition's train.
    Position,
    /// The mass of the wagons of the condition's train (a factor).
    ConsistMass,
}

/// Where `key` points, or why it cannot.
pub fn target(key: &str) -> std::result::Result<Target, String> {
    let first = key.split('.').next().unwrap_or_default();
    match first {
        "speed_kmh" if key == "speed_kmh" => Ok(Target::Speed),
        "position" if key == "position" => Ok(Target::Position),
        "consist_mass" if key == "consist_mass" => Ok(Target::ConsistMass),
        "vehicle" if key.starts_with("vehicle.body.") => Ok(Target::Body),
        "vehicle" | "track" if key.len() > first.len() + 1 => Ok(if first == "vehicle" {
            Target::Vehicle
        } else {
            Target::Track
        }),
        _ => Err(format!(
            "\"{key}\": a key starts with vehicle. (a key of the vehicle file, or vehicle.body.<link>.mass / inertia / z), track. (a key of the track file) or is speed_kmh, position (the wagon's place in its train) or consist_mass (a factor on its train's wagons' masses)"
        )),
    }
}

impl Vary {
    /// Reads a `[vary]` table of `source` (`field` its place, `vary` or `condition[3].vary`).
    pub fn parse(table: &toml::Table, source: &Path, field: &str) -> Result<Self> {
        let mut variations = Vec::new();
        for (key, spec) in table {
            let here = format!("{field}.\"{key}\"");
            let bad = |m: String| Error::config(source, &here, m);
            target(key).map_err(bad)?;
            let t = spec.as_table().ok_or_else(|| {
                bad("give a table such as { uniform = [0.3, 0.5] }, { normal = [80, 5] } or { one_of = [4, 5, 6] }".into())
            })?;
            let mut draw = None;
            let (mut scale, mut with) = (false, Vec::new());
            for (k, v) in t {
                let pair = || -> std::result::Result<(f64, f64), String> {
                    let a = v
                        .as_array()
                        .filter(|a| a.len() == 2)
                        .ok_or(format!("{k} takes two numbers, e.g. {k} = [0.3, 0.5]"))?;
                    let num = |x: &toml::Value| {
                        x.as_float()
                            .or_else(|| x.as_integer().map(|i| i as f64))
                            .filter(|f| f.is_finite())
                            .ok_or(format!("{k}: {x} is not a finite number"))
                    };
                    Ok((num(&a[0])?, num(&a[1])?))
                };
                let d = match k.as_str() {
                    "uniform" => {
                        let (lo, hi) = pair().map_err(bad)?;
                        if lo > hi {
                            return Err(bad(format!("uniform = [{lo}, {hi}] runs downwards")));
                        }
                        Draw::Uniform(lo, hi)
                    }
                    "normal" => {
                        let (m, s) = pair().map_err(bad)?;
                        if s < 0.0 {
                            return Err(bad(format!("normal = [{m}, {s}]: the std is negative")));
                        }
                        Draw::Normal(m, s)
                    }
                    "one_of" => {
                        let a = v
                            .as_array()
                            .filter(|a| !a.is_empty())
                            .ok_or_else(|| bad("one_of takes a non-empty list".into()))?;
                        if let Some(x) = a.iter().find(|x| {
                            !(x.is_str()
                                || x.is_integer()
                                || x.as_float().is_some_and(f64::is_finite))
                        }) {
                            return Err(bad(format!(
                                "one_of: {x} is neither a number nor a string"
                            )));
                        }
                        Draw::OneOf(a.clone())
                    }
                    "scale" => {
                        scale = v
                            .as_bool()
                            .ok_or_else(|| bad("scale is true or false".into()))?;
                        continue;
                    }
                    "with" => {
                        let a = v
                            .as_array()
                            .ok_or_else(|| bad("with takes a list of keys".into()))?;
                        for w in a {
                            let w = w
                                .as_str()
                                .ok_or_else(|| bad(format!("with: {w} is not a key")))?;
                            target(w).map_err(bad)?;
                            with.push(w.to_string());
                        }
                        continue;
                    }
                    other => {
                        return Err(bad(format!(
                            "unknown \"{other}\": a draw takes uniform, normal or one_of, with optional scale and with"
                        )));
                    }
                };
                if draw.replace(d).is_some() {
                    return Err(bad("give one of uniform, normal and one_of".into()));
                }
            }
            let draw = draw.ok_or_else(|| bad("give one of uniform, normal and one_of".into()))?;
            if scale && matches!(&draw, Draw::OneOf(v) if v.iter().any(toml::Value::is_str)) {
                return Err(bad("scale needs numbers to multiply by".into()));
            }
            variations.push(Variation {
                key: key.clone(),
                origin: field.to_string(),
                with,
                draw,
                scale,
            });
        }
        Ok(Vary { variations })
    }

    /// This set with `other`'s variations added, `other` winning on a shared key (a
    /// condition's `[condition.vary]` over its plan's `[vary]`).
    pub fn merged(&self, other: &Vary) -> Vary {
        let mut variations: Vec<Variation> = self
            .variations
            .iter()
            .filter(|v| !other.variations.iter().any(|o| o.key == v.key))
            .cloned()
            .collect();
        variations.extend(other.variations.iter().cloned());
        variations.sort_by(|a, b| a.key.cmp(&b.key));
        Vary { variations }
    }

    /// Whether nothing varies.
    pub fn is_empty(&self) -> bool {
        self.variations.is_empty()
    }

    /// The draw of the run of `condition` with `seed`: each key from its own stream, seeded
    /// by the condition's name, the seed and the key.
    pub fn draw(&self, condition: &str, seed: u64) -> Draws {
        let mut out = Draws::new();
        for v in &self.variations {
            let mut rng = ChaCha8Rng::seed_from_u64(stream(condition, seed, &v.key));
            v.insert(&mut out, v.draw.sample(&mut rng));
        }
        out
    }
}

impl Variation {
    /// One line for reports: `key (and with-keys): uniform 0.8–1.2 × the file's value`.
    pub fn describe(&self) -> String {
        let show = |v: &toml::Value| match v {
            toml::Value::Float(f) => format!("{f}"),
            other => other.to_string(),
        };
        let draw = match &self.draw {
            Draw::Uniform(lo, hi) => format!("uniform {lo}–{hi}"),
            Draw::Normal(m, s) => format!("normal {m} ± {s} (cut at ±3σ)"),
            Draw::OneOf(v) if v.len() == 1 => show(&v[0]),
            Draw::OneOf(v) => format!(
                "one of {}",
                v.iter().map(show).collect::<Vec<_>>().join(" / ")
            ),
        };
        let with = if self.with.is_empty() {
            String::new()
        } else {
            format!(" (with {})", self.with.join(", "))
        };
        let scale = if self.scale {
            " × the file's value"
        } else {
            ""
        };
        format!("{}{with}: {draw}{scale}", self.key)
    }

    /// Puts `value` into `draws` under this variation's key and its `with` keys.
    pub fn insert(&self, draws: &mut Draws, value: toml::Value) {
        for k in std::iter::once(&self.key).chain(&self.with) {
            draws.insert(
                k.clone(),
                Drawn {
                    value: value.clone(),
                    scale: self.scale,
                },
            );
        }
    }
}

/// FNV-1a 64 of `condition|seed|key`: the seed of one key's stream.
fn stream(condition: &str, seed: u64, key: &str) -> u64 {
    crate::io::fnv1a64(format!("vary|{condition}|{seed}|{key}").as_bytes())
}

/// The draws of a run as the manifest records them: `{key: value}`, a factor as
/// `{key: {"scale": factor}}`.
pub fn to_json(draws: &Draws) -> BTreeMap<String, serde_json::Value> {
    draws
        .iter()
        .map(|(k, d)| {
            let v = value_json(&d.value);
            (
                k.clone(),
                if d.scale {
                    serde_json::json!({ "scale": v })
                } else {
                    v
                },
            )
        })
        .collect()
}

fn value_json(v: &toml::Value) -> serde_json::Value {
    match v {
        toml::Value::Float(f) => serde_json::json!(f),
        toml::Value::Integer(i) => serde_json::json!(i),
        toml::Value::String(s) => serde_json::json!(s),
        toml::Value::Boolean(b) => serde_json::json!(b),
        other => serde_json::json!(other.to_string()),
    }
}
