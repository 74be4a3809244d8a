//! Plan files: the list of working conditions a data set is generated from.
//!
//! A plan names a vehicle, default duration and seeds, optional data-set options
//! (`[dataset]`: a channel subset, float32 storage) and any number of `[[condition]]` tables
//! (name, track file, speed, and optional overrides: vehicle, duration, seeds, irregularity
//! class, start position). Paths are relative to the plan file; assets/docs/file-formats.md lists every key.

use crate::error::{Error, Result};
use crate::vary::Vary;
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PlanFile {
    name: Option<String>,
    vehicle: String,
    duration_s: f64,
    seeds: Option<SeedsFile>,
    dataset: Option<DatasetFile>,
    vary: Option<toml::Table>,
    /// The train of every condition that names none (`daqin_20kt`, a file or `none`).
    consist: Option<String>,
    /// The wagon's place in that train, a fraction of its length from the head.
    position: Option<f64>,
    /// Which way the curves turn: `as_drawn`, `mirrored` or `both`.
    turn: Option<String>,
    /// What a run that derails does to the data set: `fail` (the default) or `drop`.
    derailed: Option<String>,
    /// The rails' support of every condition that names none: `rigid`, `lumped` or
    /// `discrete` (absent: the track file's).
    rail_support: Option<String>,
    /// Rail roughness of every condition that names none: `iso3095`, `cnossos_m` or `none`
    /// (absent: the track file's).
    roughness: Option<String>,
    #[serde(default)]
    condition: Vec<ConditionFile>,
}

/// Seeds as a list (`[1, 2, 3]`) or an inclusive range (`"1-10"`).
#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum SeedsFile {
    List(Vec<u64>),
    Range(String),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct DatasetFile {
    channels: Option<Vec<String>>,
    float32: Option<bool>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ConditionFile {
    name: String,
    track: String,
    speed_kmh: f64,
    vehicle: Option<String>,
    duration_s: Option<f64>,
    seeds: Option<SeedsFile>,
    class: Option<i64>,
    start_m: Option<f64>,
    consist: Option<String>,
    position: Option<f64>,
    turn: Option<String>,
    gauge_face: Option<String>,
    rail_support: Option<String>,
    roughness: Option<String>,
    vary: Option<toml::Table>,
}

/// Friction of a lubricated gauge face: wayside lubrication brings the flange's friction "to
/// less than 0.2" with the top of rail at 0.3–0.4 (Prahl, *Mass Transit* 31(3), 2005,
/// 54–58); 0.15 is an estimate within that.
pub const LUBRICATED_GAUGE_FACE: f64 = 0.15;

/// Which way a condition's curves turn, run by run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Turns {
    /// As the track file draws them.
    #[default]
    AsDrawn,
    /// Every curve the other way (a left-hand track for a right-hand file).
    Mirrored,
    /// Half the runs each way: the condition's k-th seed runs mirrored when k plus the
    /// condition's place in the plan is odd, so the label wheel is the outer wheel in half the
    /// runs and the held-out seeds of neighbouring conditions turn opposite ways.
    Both,
}

impl Turns {
    /// The file's names.
    pub const NAMES: [&'static str; 3] = ["as_drawn", "mirrored", "both"];

    /// Parses a file's name.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "as_drawn" => Some(Turns::AsDrawn),
            "mirrored" => Some(Turns::Mirrored),
            "both" => Some(Turns::Both),
            _ => None,
        }
    }
}

/// Largest number of seeds one list or range may give (a typo such as `"1-100000000"` should
/// fail, not plan a hundred million runs).
const MAX_SEEDS: u64 = 100_000;

fn seeds(path: &Path, field: &str, s: SeedsFile) -> Result<Vec<u64>> {
    let v = match s {
        SeedsFile::List(v) => v,
        SeedsFile::Range(r) => {
            let bad = || {
                Error::config(
                    path,
                    field,
                    format!("\"{r}\": give a list such as [1, 2, 3] or a range such as \"1-10\""),
                )
            };
            let (a, b) = r.split_once('-').ok_or_else(bad)?;
            let (a, b): (u64, u64) = (
                a.trim().parse().map_err(|_| bad())?,
                b.trim().parse().map_err(|_| bad())?,
            );
            if b < a || b - a >= MAX_SEEDS {
                return Err(Error::config(
                    path,
                    field,
                    format!(
                        "\"{r}\": the range must run upwards and hold at most {MAX_SEEDS} seeds"
                    ),
                ));
            }
            (a..=b).collect()
        }
    };
    if v.is_empty() {
        return Err(Error::config(path, field, "give at least one seed"));
    }
    if v.len() as u64 > MAX_SEEDS {
        return Err(Error::config(
            path,
            field,
            format!("more than {MAX_SEEDS} seeds"),
        ));
    }
    let mut sorted = v.clone();
    sorted.sort_unstable();
    if sorted.windows(2).any(|w| w[0] == w[1]) {
        return Err(Error::config(path, field, "a seed is listed twice"));
    }
    Ok(v)
}

/// Data-set options of a plan (`[dataset]`), recorded in the manifest.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct DatasetOptions {
    /// Channels to keep, by name or kind (`input`, `input_noisy`, `label`, `wheel`, `truth`
    /// …, see the manifest's `channels`); `time_s`, `s_m` and the labels are always kept.
    /// Empty: every channel.
    pub channels: Vec<String>,
    /// Store the values as 32-bit floats (half the size; time and position stay f64 in
    /// NPZ and Parquet, CSV prints float32 precision).
    pub float32: bool,
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
    /// Vehicle file (the plan's unless the condition names its own).
    pub vehicle: PathBuf,
    /// FRA class of the irregularities instead of the track file's (1–6).
    pub class: Option<i64>,
    /// Distance along the track of the vehicle centre at the start, m (default: just far
    /// enough for the rear wheelset to be on the track).
    pub start_m: Option<f64>,
    /// What varies from run to run: the plan's `[vary]` with the condition's own over it.
    pub vary: Vary,
    /// The train around the wagon (`consist` and `position`; None: the wagon alone).
    pub train: Option<crate::sim::hitch::TrainSetup>,
    /// The consist as the plan names it (`daqin_20kt` or a file), for the manifest.
    pub consist: Option<String>,
    /// The condition whose irregularities this one's runs share, seed for seed (None: its
    /// own, from its name). A sensitivity study's copies of a condition share their base's,
    /// so a parameter's effect is not buried under a new track (common random numbers).
    pub realisation_of: Option<String>,
    /// Which way the curves turn, run by run.
    pub turns: Turns,
    /// The condition's place in its plan (0 first), for [`Turns::Both`].
    pub order: usize,
    /// Friction of the rail's gauge face instead of the vehicle file's (`gauge_face =
    /// "lubricated"`: [`LUBRICATED_GAUGE_FACE`]; `"dry"` or absent: the file's).
    pub flange_friction: Option<f64>,
    /// The rails' support instead of the track file's (`rail_support = "rigid"`, `"lumped"`
    /// or `"discrete"`, [`crate::track::TrackSpec::set_rail_model`]; None: the file's).
    pub rail_support: Option<String>,
    /// Rail roughness instead of the track file's (`roughness = "iso3095"`, `"cnossos_m"` or
    /// `"none"`, [`crate::track::TrackSpec::set_roughness`]; None: the file's).
    pub roughness: Option<String>,
    /// The seeds as the plan file lists them, which [`Turns::Both`] counts in: a plan narrowed
    /// to some of them ([`Condition::only_seeds`]) turns each kept run as the whole plan does.
    pub turn_order: Vec<u64>,
}

impl Condition {
    /// The condition as [`crate::vary::check`] sees it (`index`: its place in the plan).
    pub fn subject(&self, index: usize) -> crate::vary::Subject<'_> {
        crate::vary::Subject {
            index,
            name: &self.name,
            vehicle: &self.vehicle,
            track: &self.track,
            speed_kmh: self.speed_kmh,
            class: self.class,
            consist: self.train.as_ref().map(|t| &t.consist),
            position: self.train.as_ref().and_then(|t| t.position),
        }
    }

    /// Running speed, m/s.
    pub fn speed(&self) -> f64 {
        self.speed_kmh / 3.6
    }

    /// The condition with only `seeds` to run, each turning as it does in the whole plan.
    pub fn only_seeds(&mut self, seeds: &[u64]) {
        self.seeds = seeds.to_vec();
    }

    /// Whether the run of seed `seed` turns its curves the other way from its track file.
    pub fn mirrored(&self, seed: u64) -> bool {
        match self.turns {
            Turns::AsDrawn => false,
            Turns::Mirrored => true,
            Turns::Both => {
                let k = self.turn_order.iter().position(|&s| s == seed).unwrap_or(0);
                (k + self.order) % 2 == 1
            }
        }
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
    /// Data-set options.
    pub dataset: DatasetOptions,
    /// Whether a run that derails is dropped from the data set (listed in its manifest with
    /// the reason) instead of stopping the generation (`derailed = "drop"`; a fleet that
    /// draws light wagons on poor track at speed may derail, as such wagons do).
    pub drop_derailed: bool,
}

impl Plan {
    /// Reads and validates a plan file: its fields, then that every vehicle and track file it
    /// names exists (their contents are checked by their own loaders when used).
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
        let plan_vary = match &raw.vary {
            Some(t) => Vary::parse(t, path, "vary")?,
            None => Vary::default(),
        };
        let plan_seeds = match raw.seeds {
            Some(s) => seeds(path, "seeds", s)?,
            None => vec![1],
        };
        let dataset = match raw.dataset {
            None => DatasetOptions::default(),
            Some(d) => {
                let channels = d.channels.unwrap_or_default();
                if let Some(c) = channels.iter().find(|c| c.trim().is_empty()) {
                    return Err(Error::config(
                        path,
                        "dataset.channels",
                        format!("\"{c}\" is empty: name a channel or a kind"),
                    ));
                }
                DatasetOptions {
                    channels,
                    float32: d.float32.unwrap_or(false),
                }
            }
        };
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
            let seeds = match c.seeds {
                Some(s) => seeds(path, &f("seeds"), s)?,
                None => plan_seeds.clone(),
            };
            if let Some(k) = c.class
                && !(1..=6).contains(&k)
            {
                return Err(Error::config(
                    path,
                    f("class"),
                    format!("unknown FRA class {k}: use 1 to 6"),
                ));
            }
            if let Some(s) = c.start_m
                && !(s.is_finite() && s >= 0.0)
            {
                return Err(Error::config(
                    path,
                    f("start_m"),
                    format!("must be a distance ≥ 0 along the track, got {s}"),
                ));
            }
            let vary = match &c.vary {
                Some(t) => plan_vary.merged(&Vary::parse(t, path, &f("vary"))?),
                None => plan_vary.clone(),
            };
            let consist = c.consist.clone().or_else(|| raw.consist.clone());
            let position = c.position.or(raw.position);
            if position.is_some() && consist.is_none() {
                return Err(Error::config(
                    path,
                    f("position"),
                    "a position in no train: name its `consist` too",
                ));
            }
            let turns = match c.turn.as_deref().or(raw.turn.as_deref()) {
                None => Turns::AsDrawn,
                Some(t) => Turns::parse(t).ok_or_else(|| {
                    Error::config(
                        path,
                        if c.turn.is_some() {
                            f("turn")
                        } else {
                            "turn".into()
                        },
                        format!("{t:?}: give one of {:?}", Turns::NAMES),
                    )
                })?,
            };
            let flange_friction = match c.gauge_face.as_deref() {
                None | Some("dry") => None,
                Some("lubricated") => Some(LUBRICATED_GAUGE_FACE),
                Some(g) => {
                    return Err(Error::config(
                        path,
                        f("gauge_face"),
                        format!(
                            "{g:?}: give \"dry\" (the vehicle file's flange friction) or \"lubricated\""
                        ),
                    ));
                }
            };
            let rail_support = track_choice(
                path,
                (&c.rail_support, &raw.rail_support),
                (f("rail_support"), "rail_support"),
                |m| crate::track::RAIL_SUPPORT_MODELS.contains(&m),
                &format!("one of {:?}", crate::track::RAIL_SUPPORT_MODELS),
            )?;
            let roughness = track_choice(
                path,
                (&c.roughness, &raw.roughness),
                (f("roughness"), "roughness"),
                |r| r == "none" || crate::track::short_wave::RoughnessSpectrum::parse(r).is_some(),
                &format!(
                    "\"none\" or one of {:?}",
                    crate::track::short_wave::RoughnessSpectrum::NAMES
                ),
            )?;
            let train = match &consist {
                Some(name) => crate::sim::hitch::TrainSetup::resolve(
                    name,
                    position,
                    dir,
                    &format!("{}: {}", path.display(), f("consist")),
                )?,
                None => None,
            };
            let turn_order = seeds.clone();
            conditions.push(Condition {
                turn_order,
                vary,
                name: c.name,
                track: dir.join(c.track),
                speed_kmh: speed,
                duration,
                seeds,
                vehicle: dir.join(c.vehicle.as_deref().unwrap_or(&raw.vehicle)),
                class: c.class,
                start_m: c.start_m,
                train,
                consist: consist.filter(|n| n != crate::sim::hitch::ALONE),
                realisation_of: None,
                turns,
                order: conditions.len(),
                flange_friction,
                rail_support,
                roughness,
            });
        }
        // Every file the plan names must be there now, not when its run comes up (checked last,
        // so a malformed plan is told what is malformed first).
        let vehicle = dir.join(&raw.vehicle);
        let missing = |field: String, p: &Path| {
            Error::config(
                path,
                field,
                format!(
                    "{} is not a file (paths are relative to the plan file)",
                    p.display()
                ),
            )
        };
        if !vehicle.is_file() {
            return Err(missing("vehicle".into(), &vehicle));
        }
        for (i, c) in conditions.iter().enumerate() {
            if !c.track.is_file() {
                return Err(missing(format!("condition[{i}].track"), &c.track));
            }
            if !c.vehicle.is_file() {
                return Err(missing(format!("condition[{i}].vehicle"), &c.vehicle));
            }
        }
        let drop_derailed = match raw.derailed.as_deref() {
            None | Some("fail") => false,
            Some("drop") => true,
            Some(d) => {
                return Err(Error::config(
                    path,
                    "derailed",
                    format!(
                        "{d:?}: give \"fail\" (stop the generation) or \"drop\" (leave the run out, listed in the manifest)"
                    ),
                ));
            }
        };
        Ok(Plan {
            source: path.to_path_buf(),
            name: raw.name.unwrap_or_else(|| {
                path.file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            }),
            vehicle,
            conditions,
            dataset,
            drop_derailed,
        })
    }
}

impl Plan {
    /// Tries every condition's variations at the ends of their ranges on the condition's own
    /// files ([`crate::vary::check`]), before any run: an error names the plan key.
    pub fn check_vary(&self) -> Result<()> {
        let mut tried = Vec::new();
        for (index, c) in self.conditions.iter().enumerate() {
            crate::vary::check(&self.source, c.subject(index), &c.vary, &mut tried)?;
        }
        Ok(())
    }
}

/// What a condition chooses over its track file (`own`, else the plan's), checked by `ok`; an
/// unknown value is refused naming the condition's key, or the plan's where it came from there.
fn track_choice(
    path: &Path,
    (own, plan): (&Option<String>, &Option<String>),
    (own_key, plan_key): (String, &str),
    ok: impl Fn(&str) -> bool,
    allowed: &str,
) -> Result<Option<String>> {
    let value = own.clone().or_else(|| plan.clone());
    match &value {
        Some(v) if !ok(v) => Err(Error::config(
            path,
            if own.is_some() {
                own_key
            } else {
                plan_key.into()
            },
            format!("{v:?}: give {allowed}"),
        )),
        _ => Ok(value),
    }
}
