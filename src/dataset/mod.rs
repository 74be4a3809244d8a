//! Data sets per working condition: runs every (condition, seed) of a plan, in parallel,
//! writes one file per run (CSV or NPZ) and a `manifest.json` that describes every channel and
//! run. Interruption loses nothing: files are written atomically, the manifest after every
//! finished run, and a rerun skips the runs the manifest lists as done with an unchanged
//! definition and a file that still holds the bytes it hashed. `--shard i/N` splits a plan across
//! machines; `merge` joins shard manifests.

mod data_set;
mod manifest;
pub mod npz;
pub mod parquet_file;
mod run_file;
mod table;

pub use data_set::{DataSet, Run};
pub use manifest::{
    ChannelEntry, Conventions, DroppedRun, FileRef, Integration, Labels, Manifest, RunEntry,
    data_identity, file_hash, fnv1a, manifest_path, merge, parse_shard, run_entry,
};
use manifest::{refuse_mixing, run_key};
pub use run_file::{CHANNEL_KINDS, RecordedRun, keeps_f64, recorded_run, write_run};
use run_file::{add_noise, keep_channels};
pub use table::{not_a_number, read_csv, read_table, row_length};

use crate::error::{Error, Result};
use crate::plan::{Condition, Plan};
use crate::sensors::{ChannelKind, NoiseModel, label_channels};
use crate::sim::output;
use crate::sim::{SimConfig, Simulation};
use crate::track::{Track, TrackSpec};
use crate::vehicle::Vehicle;
use std::path::PathBuf;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// File format of the runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Comma-separated values with a header row.
    Csv,
    /// NumPy `.npz`: one float64 array per channel.
    Npz,
    /// Apache Parquet: one DOUBLE column per channel (pandas, polars, pyarrow).
    Parquet,
}

impl Format {
    /// Parses `csv`, `npz` or `parquet`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "csv" => Some(Format::Csv),
            "npz" => Some(Format::Npz),
            "parquet" => Some(Format::Parquet),
            _ => None,
        }
    }

    /// File extension.
    pub fn ext(self) -> &'static str {
        match self {
            Format::Csv => "csv",
            Format::Npz => "npz",
            Format::Parquet => "parquet",
        }
    }
}

/// How to generate.
#[derive(Debug, Clone)]
pub struct GenerateOptions {
    /// Output folder.
    pub out: PathBuf,
    /// File format.
    pub format: Format,
    /// Runs in parallel.
    pub jobs: usize,
    /// This shard `(i, n)`, 1-based: runs with index `k` where `k % n == i − 1`.
    pub shard: Option<(usize, usize)>,
    /// Add noised copies (`<channel>_noisy`) of the paper's input channels with this noise
    /// model (assets/docs/learning.md §1.4).
    pub noise: Option<NoiseModel>,
    /// Settling time of each run, s.
    pub settle: f64,
    /// Integrator and step of every run (default: the default run's).
    pub stepping: crate::sim::Stepping,
}

/// Runs in parallel when a user names no number: one per core.
pub fn default_jobs() -> usize {
    std::thread::available_parallelism()
        .map(|p| p.get())
        .unwrap_or(1)
}

/// One run of a plan.
#[derive(Debug, Clone)]
pub struct RunSpec {
    /// Position in the plan's list of runs.
    pub index: usize,
    /// Its condition.
    pub condition: Condition,
    /// The run's seed: the unit the splits hold out (see [`realisation_seed`] for what it draws).
    pub seed: u64,
}

/// The seed of a run's random realisation — its track irregularities and its sensor noise —
/// from its condition's name and its seed (FNV-1a 64 of `realisation|<condition>|<seed>`).
///
/// Every condition draws its own realisation: with the seed alone, all conditions on tracks of
/// one length would share one irregularity profile and one noise sequence at a seed, so the
/// per-condition test runs of a seed would not be independent. A run is still fixed by
/// (condition, seed): `railforce track <file> --seed S --condition NAME` shows its rails.
pub fn realisation_seed(condition: &str, seed: u64) -> u64 {
    crate::io::fnv1a64(format!("realisation|{condition}|{seed}").as_bytes())
}

impl RunSpec {
    /// The seed of the run's irregularities and noise: [`realisation_seed`] of its condition
    /// (or of the condition it shares its realisation with, `Condition::realisation_of`).
    pub fn realisation_seed(&self) -> u64 {
        let c = &self.condition;
        realisation_seed(c.realisation_of.as_deref().unwrap_or(&c.name), self.seed)
    }

    /// Output file name.
    pub fn file_name(&self, format: Format) -> String {
        format!("{}_seed{}.{}", self.condition.name, self.seed, format.ext())
    }
}

/// A run made ready before any runs: its track (drawn), the track file's hash, its draws and
/// its speed.
struct Prepared {
    spec: TrackSpec,
    /// Whether its curves turn the other way from the file's (and it has curves).
    mirrored: bool,
    track_hash: String,
    draws: crate::vary::Draws,
    speed_kmh: f64,
}

/// Every (condition, seed) pair of a plan, in plan order.
pub fn runs(plan: &Plan) -> Vec<RunSpec> {
    let mut out = Vec::new();
    for c in &plan.conditions {
        for &seed in &c.seeds {
            out.push(RunSpec {
                index: out.len(),
                condition: c.clone(),
                seed,
            });
        }
    }
    out
}

/// Progress events of a generation.
#[derive(Debug, Clone)]
pub enum Event {
    /// A run started.
    Started(String),
    /// A run was skipped: already done.
    Skipped(String),
    /// A run finished, with its wall time.
    Finished(String, f64),
    /// A run derailed and was left out (the plan's `derailed = "drop"`), with the reason.
    Dropped(String, String),
}

/// Generates the data set of a plan (or of one shard of it). Returns the manifest.
pub fn generate(
    plan: &Plan,
    opts: &GenerateOptions,
    events: &(dyn Fn(Event) + Sync),
) -> Result<Manifest> {
    let dt = opts.stepping.dt;
    if !(dt > 0.0 && dt <= 1e-3) {
        return Err(Error::Domain(format!(
            "integration step {dt} s: it must be in (0, 1 ms]"
        )));
    }
    if let Some((i, n)) = opts.shard
        && !(n >= 1 && (1..=n).contains(&i))
    {
        return Err(Error::Domain(format!(
            "shard {i}/{n}: a shard is i/N with 1 ≤ i ≤ N"
        )));
    }
    if let Some(n) = opts.noise
        && !n.snr_db.is_finite()
    {
        return Err(Error::Domain(format!(
            "the SNR must be finite, got {} dB",
            n.snr_db
        )));
    }
    let dataset = &plan.dataset;
    for c in &dataset.channels {
        // Every channel name has an underscore (`ws1_acc_z`); a bare word must be a kind.
        if c.contains('_') || CHANNEL_KINDS.contains(&c.as_str()) {
            continue;
        }
        return Err(Error::config(
            &plan.source,
            "dataset.channels",
            format!(
                "\"{c}\" is neither a channel name nor a kind ({})",
                CHANNEL_KINDS.join(", ")
            ),
        ));
    }
    let manifest_file = manifest_path(opts);
    let previous = Manifest::read(&manifest_file)?;
    refuse_mixing(&manifest_file, previous.as_ref(), opts, dataset)?;
    if opts.out.exists() && !opts.out.is_dir() {
        return Err(Error::Domain(format!(
            "{}: a file, not a folder: a data set is a folder of runs and its manifest (give another --out)",
            opts.out.display()
        )));
    }
    std::fs::create_dir_all(&opts.out).map_err(|e| Error::io(&opts.out, e))?;
    let vehicle = Vehicle::load(&plan.vehicle)?;
    let labels = label_channels(&vehicle.label_wheel_name());
    // Every vehicle the plan's conditions use, loaded and checked once.
    let mut vehicles: Vec<(PathBuf, Vehicle, String)> = Vec::new();
    for c in &plan.conditions {
        if vehicles.iter().any(|v| v.0 == c.vehicle) {
            continue;
        }
        let v = Vehicle::load(&c.vehicle)?;
        if label_channels(&v.label_wheel_name()) != labels {
            return Err(Error::Domain(format!(
                "condition {}: its vehicle {} labels wheel {}, the plan's {} labels {}: one data set has one label wheel",
                c.name,
                c.vehicle.display(),
                v.label_wheel_name(),
                plan.vehicle.display(),
                vehicle.label_wheel_name()
            )));
        }
        let hash = file_hash(&c.vehicle)?;
        vehicles.push((c.vehicle.clone(), v, hash));
    }
    // Check every track before any run (a bad file should fail now, not after an hour).
    let mine: Vec<RunSpec> = runs(plan)
        .into_iter()
        .filter(|r| opts.shard.is_none_or(|(i, n)| r.index % n == i - 1))
        .collect();
    // Every variation tried at the ends of its range, naming the plan key, before any run.
    plan.check_vary()?;
    let mut tracks = Vec::new();
    for r in &mine {
        let draws = r.condition.vary.draw(&r.condition.name, r.seed);
        let speed_kmh = crate::vary::speed_kmh(r.condition.speed_kmh, &draws).map_err(|e| {
            Error::config(
                &plan.source,
                format!("condition {} (seed {})", r.condition.name, r.seed),
                e.to_string(),
            )
        })?;
        let mut spec = crate::vary::track_for(&r.condition.track, &draws)?;
        if let Some(class) = r.condition.class {
            set_class(&mut spec, class).map_err(|m| {
                Error::config(
                    &plan.source,
                    format!("condition {}.class", r.condition.name),
                    m,
                )
            })?;
        }
        if let Some(s) = r.condition.start_m
            && s > spec.length()
        {
            return Err(Error::config(
                &plan.source,
                format!("condition {}.start_m", r.condition.name),
                format!(
                    "{s} m is beyond the end of {} ({:.0} m)",
                    r.condition.track.display(),
                    spec.length()
                ),
            ));
        }
        // A run that turns the other way: every curve mirrored (a track without curves is its
        // own mirror image, and stays as it is).
        let mirrored = r.condition.mirrored(r.seed) && spec.has_curves();
        if mirrored {
            spec.mirror();
        }
        let at = |key: &str, e: Error| {
            Error::config(
                &plan.source,
                format!("condition {}.{key}", r.condition.name),
                e.to_string(),
            )
        };
        if let Some(m) = &r.condition.rail_support {
            spec.set_rail_model(m).map_err(|e| at("rail_support", e))?;
        }
        if let Some(name) = &r.condition.roughness {
            spec.set_roughness(name).map_err(|e| at("roughness", e))?;
        }
        tracks.push(Prepared {
            spec,
            mirrored,
            track_hash: file_hash(&r.condition.track)?,
            draws,
            speed_kmh,
        });
    }
    let done: &[RunEntry] = previous.as_ref().map_or(&[], |m| &m.runs);
    for (_, v, _) in &vehicles {
        v.contact.table(); // build once, before the threads
    }
    let integration = Integration::of(opts);
    let manifest = Mutex::new(Manifest {
        tool: format!("railforce {}", env!("CARGO_PKG_VERSION")),
        plan: plan.source.clone(),
        plan_name: plan.name.clone(),
        vehicle: FileRef {
            file: plan.vehicle.clone(),
            hash_fnv1a: file_hash(&plan.vehicle)?,
            name: vehicle.name.clone(),
        },
        format: opts.format.ext().into(),
        sampling_rate_hz: SimConfig::default().output_rate,
        // How the runs were made, so a data set says how to regenerate it.
        integration: Some(integration),
        dataset: dataset.clone(),
        snr_db: opts.noise.map(|n| n.snr_db),
        snr_reference: opts.noise.map(|n| n.reference.name().into()),
        noise: opts.noise.map(|n| format!("{}; the paper's input channels only (suffix _noisy), clean channels always kept", n.describe())),
        shard: opts.shard.map(|(i, n)| format!("{i}/{n}")),
        merged_from: None,
        conventions: Conventions {
            frame: "track frame: x along the running direction, y to the left, z up".into(),
            forces: "forces of the rail on the wheel in the track frame: force_y = Y (+ left), force_z = Q (+ up) (EN: Y lateral, Q vertical; Chinese standards: Q lateral, P vertical)".into(),
            wheels: "1L..4R numbered from the front, left/right facing the running direction".into(),
            accelerations: vehicle.accelerometers.describe().into(),
            accelerometers: Some(vehicle.accelerometers.name().into()),
            labels: Some(Labels {
                fl: labels[0].clone(),
                fq: labels[1].clone(),
                wheel: Some(vehicle.label_wheel_name()),
            }),
        },
        channels: None,
        runs: Vec::new(),
        dropped: Vec::new(),
    });
    let next = AtomicUsize::new(0);
    let first_error: Mutex<Option<Error>> = Mutex::new(None);
    let work = |k: usize| -> Result<()> {
        let run = &mine[k];
        let Prepared {
            spec,
            mirrored,
            track_hash,
            draws,
            speed_kmh,
        } = &tracks[k];
        let (_, shared, vehicle_hash) = vehicles
            .iter()
            .find(|v| v.0 == run.condition.vehicle)
            .expect("every condition's vehicle is loaded");
        let key = run_key(
            run,
            opts,
            track_hash,
            vehicle_hash,
            dataset,
            draws,
            *mirrored,
        );
        let file = run.file_name(opts.format);
        let path = opts.out.join(&file);
        // Done means listed with the same key and its file still holding the bytes the
        // manifest hashed: a file cut short or edited since is simulated again.
        if let Some(entry) = done.iter().find(|e| e.key == key)
            && path.exists()
            && file_hash(&path).is_ok_and(|h| h == entry.bytes_hash_fnv1a)
        {
            events(Event::Skipped(file.clone()));
            let mut m = manifest.lock().expect("manifest lock");
            if m.channels.is_none() {
                m.channels = previous.as_ref().and_then(|p| p.channels.clone());
            }
            m.runs.push(entry.clone());
            return Ok(());
        }
        events(Event::Started(file.clone()));
        // A wagon drawn for this run, or the condition's own.
        let drawn_vehicle = if draws.keys().any(|k| k.starts_with("vehicle.")) {
            Some(
                crate::vary::vehicle_for(&run.condition.vehicle, draws).map_err(|e| {
                    Error::Domain(format!("{} (seed {}): {e}", run.condition.name, run.seed))
                })?,
            )
        } else {
            None
        };
        // A lubricated gauge face: the wagon's flange friction as the condition has it.
        let lubricated = run.condition.flange_friction.map(|mu| {
            let mut v = drawn_vehicle.as_ref().unwrap_or(shared).clone();
            v.contact.flange_friction = mu;
            v
        });
        let vehicle = lubricated
            .as_ref()
            .or(drawn_vehicle.as_ref())
            .unwrap_or(shared);
        let track = Track::new(spec.clone(), Some(run.realisation_seed()));
        // The wagon's place in its train, drawn or the condition's.
        let at =
            |e: Error| Error::Domain(format!("{} (seed {}): {e}", run.condition.name, run.seed));
        let train = match &run.condition.train {
            Some(t) => Some(crate::sim::hitch::TrainSetup {
                consist: crate::vary::consist_for(Some(&t.consist), draws)
                    .map_err(at)?
                    .unwrap_or_else(|| t.consist.clone()),
                position: crate::vary::position(t.position, draws, Some(&t.consist)).map_err(at)?,
            }),
            None => {
                crate::vary::position(None, draws, None).map_err(at)?;
                crate::vary::consist_for(None, draws).map_err(at)?;
                None
            }
        };
        let cfg = SimConfig {
            speed: speed_kmh / 3.6,
            duration: run.condition.duration,
            settle: opts.settle,
            start: run.condition.start_m,
            train: train.clone(),
            // One set of channels in a data set: every run records the couplers when any
            // condition runs in a train.
            coupler_channels: plan.conditions.iter().any(|c| c.train.is_some()),
            dt: opts.stepping.step_on(spec, vehicle, speed_kmh / 3.6)?,
            integrator: opts.stepping.integrator,
            // A derailment risk (Nadal's limit held 50 ms) is reported and the run kept: a
            // data set wants those forces; a flange climb still stops the run.
            stop_on_derailment_risk: false,
            ..SimConfig::default()
        };
        let mut sim = Simulation::new(vehicle, &track, cfg)
            .map_err(|e| Error::Domain(format!("{}: {e}", run.condition.name)))?;
        let mut rec = match output::record(&mut sim, |_| {}) {
            Ok(rec) => rec,
            Err(Error::Derailment(reason)) if plan.drop_derailed => {
                events(Event::Dropped(file.clone(), reason.clone()));
                manifest
                    .lock()
                    .expect("manifest lock")
                    .dropped
                    .push(manifest::DroppedRun {
                        condition: run.condition.name.clone(),
                        seed: run.seed,
                        reason,
                    });
                return Ok(());
            }
            Err(e) => {
                return Err(Error::Domain(format!(
                    "{} (seed {}): {e}",
                    run.condition.name, run.seed
                )));
            }
        };
        if let Some(noise) = opts.noise {
            add_noise(&mut rec, &noise, run.realisation_seed());
        }
        keep_channels(&mut rec, &labels, &dataset.channels)
            .map_err(|m| Error::config(&plan.source, "dataset.channels", m))?;
        write_run(&path, &rec, opts.format, dataset.float32)?;
        let bytes_hash = file_hash(&path)?;
        let entry = RunEntry {
            key,
            condition: run.condition.name.clone(),
            seed: run.seed,
            realisation_seed: Some(run.realisation_seed()),
            file: file.clone(),
            bytes_hash_fnv1a: bytes_hash,
            track: FileRef {
                file: run.condition.track.clone(),
                hash_fnv1a: track_hash.clone(),
                name: spec.name.clone(),
            },
            speed_kmh: *speed_kmh,
            duration_s: run.condition.duration,
            vehicle: Some(vehicle.name.clone()),
            class: run.condition.class,
            start_m: run.condition.start_m,
            consist: run.condition.consist.clone(),
            position: train.as_ref().and_then(|t| t.position),
            mirrored: *mirrored,
            rail_support: run.condition.rail_support.clone(),
            roughness: run.condition.roughness.clone(),
            rows: rec.rows.len(),
            peak_y_over_q: rec.summary.peak_y_over_q,
            draws: crate::vary::to_json(draws),
        };
        let mut m = manifest.lock().expect("manifest lock");
        if let Some(channels) = &m.channels {
            let names: Vec<&str> = channels.iter().map(|c| c.name.as_str()).collect();
            if names != rec.names.iter().map(|n| n.as_str()).collect::<Vec<_>>() {
                return Err(Error::Domain(format!(
                    "{} (vehicle {}) records other channels than the data set's first run: one data set has one set of channels",
                    run.condition.name, vehicle.name
                )));
            }
        }
        if m.channels.is_none() {
            m.channels = Some(
                rec.names
                    .iter()
                    .zip(&rec.units)
                    .map(|(n, u)| {
                        let kind = ChannelKind::of(n, &labels);
                        let wheel = (kind == ChannelKind::Label || kind == ChannelKind::Wheel)
                            .then(|| n[1..3].to_ascii_uppercase());
                        ChannelEntry {
                            name: n.clone(),
                            unit: u.to_string(),
                            kind: kind.name().into(),
                            wheel,
                        }
                    })
                    .collect(),
            );
        }
        m.runs.push(entry);
        m.sort_runs();
        m.write(&manifest_file)?;
        events(Event::Finished(file, rec.summary.wall));
        Ok(())
    };
    std::thread::scope(|scope| {
        for _ in 0..opts.jobs.max(1).min(mine.len().max(1)) {
            scope.spawn(|| {
                loop {
                    if first_error.lock().expect("error lock").is_some() {
                        return;
                    }
                    let k = next.fetch_add(1, Ordering::SeqCst);
                    if k >= mine.len() {
                        return;
                    }
                    if let Err(e) = work(k) {
                        first_error.lock().expect("error lock").get_or_insert(e);
                        return;
                    }
                }
            });
        }
    });
    let mut m = manifest.into_inner().expect("manifest lock");
    m.sort_runs();
    m.write(&manifest_file)?;
    if let Some(e) = first_error.into_inner().expect("error lock") {
        return Err(e);
    }
    Ok(m)
}

/// The irregularity class of a track replaced by `class` (1–6); the gauge limits follow the
/// class unless the track file set its own.
fn set_class(spec: &mut TrackSpec, class: i64) -> std::result::Result<(), String> {
    let new = crate::track::FraClass::new(class).ok_or(format!("unknown FRA class {class}"))?;
    let irr = spec.irregularity.as_mut().ok_or(format!(
        "{} has no [irregularity] table to take a class",
        spec.source.display()
    ))?;
    if irr.gauge_limits == irr.class.gauge_limits() {
        irr.gauge_limits = new.gauge_limits();
    }
    irr.class = new;
    Ok(())
}
