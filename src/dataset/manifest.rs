//! The data set's manifest (`manifest.json`), one typed record shared by the writer
//! (`generate`), the resume check, training, `view` and `assess`: what the runs are, how they
//! were made (integration step, settling, filter), their noise, conventions and channels.
//! Also the content hashes (the data identity), the resume key of each run, refusing to mix
//! data sets in one folder, and merging shard manifests.
//!
//! The JSON keeps its keys in alphabetical order at every level (the records pass through
//! `serde_json::Value`), so a manifest written by this code has the bytes of the untyped
//! writer before it. Fields that older manifests did not write (`integration`, `dataset`,
//! `accelerometers`, `labels`, `class`, `start_m`) read as absent; a field that is there but
//! cannot be read is an error naming the file, the line and the field.

use super::{GenerateOptions, RunSpec};
use crate::error::{Error, Result};
use crate::plan::DatasetOptions;
use crate::sensors::{NoiseModel, SnrReference, label_channels};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A file the data set was made from, with the FNV-1a hash of its bytes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FileRef {
    /// Path as the plan resolved it.
    pub file: PathBuf,
    /// FNV-1a 64 of the file's bytes, hex.
    pub hash_fnv1a: String,
    /// The name inside the file.
    pub name: String,
}

/// How the runs were integrated and filtered (absent in format 1 and 2 manifests).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Integration {
    /// The integrator, in words.
    pub integrator: String,
    /// Integration step, s.
    pub dt_s: f64,
    /// Settling time before recording, s (not written).
    pub settle_s: f64,
    /// The anti-alias filter before decimation, in words.
    pub anti_alias: String,
}

impl Integration {
    /// How `generate` with `opts` integrates every run, as its manifest says it.
    pub(super) fn of(opts: &GenerateOptions) -> Self {
        use crate::sim::Integrator;
        Integration {
            integrator: match opts.stepping.integrator {
                Integrator::SemiImplicit => "semi-implicit Euler, fixed step (src/sim/mod.rs)".into(),
                Integrator::LinearlyImplicit => {
                    "linearly implicit: semi-implicit Euler with each wheelset and its two rail masses \
                     solved together in the wheel–rail damping at the step's midpoint, the rails' \
                     support implicit, fixed step (src/sim/integrator.rs)"
                        .into()
                }
                Integrator::LinearlyImplicitHertz => format!(
                    "linearly implicit with the contact's Hertz spring: as linearly implicit, and \
                     the contact's normal stiffness at the share {} of dt^2 K seeing the rail \
                     surface's passing, each wheelset's gyroscopic moment at the step's \
                     midpoint, each side frame solved in its pads' damping, every share on the \
                     velocities relative to the turning track, fixed step \
                     (src/sim/wheelset_solve.rs, src/sim/integrator.rs)",
                    Integrator::LinearlyImplicitHertz.stiffness_share()
                ),
                Integrator::Heun => "Heun's method (explicit trapezoidal, second order), fixed step \
                     (src/sim/integrator.rs)"
                    .into(),
            },
            dt_s: opts.stepping.dt,
            settle_s: opts.settle,
            anti_alias: format!(
                "8th-order Butterworth low-pass at {} Hz at the integration rate, then decimated",
                crate::sim::SimConfig::default().cutoff
            ),
        }
    }
}

/// The label channels and their wheel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Labels {
    /// Lateral force channel (FL).
    #[serde(rename = "FL")]
    pub fl: String,
    /// Vertical force channel (FQ).
    #[serde(rename = "FQ")]
    pub fq: String,
    /// The label wheel (`1L` … `4R`; absent in manifests before it was a setting).
    #[serde(default)]
    pub wheel: Option<String>,
}

/// Frames, signs and what the sensors read, in words and names.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Conventions {
    /// The track frame.
    pub frame: String,
    /// Force signs and names.
    pub forces: String,
    /// Wheel numbering.
    pub wheels: String,
    /// What the accelerations are, in words.
    pub accelerations: String,
    /// `specific-force` or `kinematic` (absent in manifests before it was recorded).
    #[serde(default)]
    pub accelerometers: Option<String>,
    /// The label channels (absent in manifests before the label wheel was a setting: 1L).
    #[serde(default)]
    pub labels: Option<Labels>,
}

/// One channel of the run files.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelEntry {
    /// Column name.
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Kind (`input`, `input_noisy`, `label`, `wheel`, `body`, `deflection`, `axis`).
    pub kind: String,
    /// The wheel of a wheel or label channel (`1L` …).
    pub wheel: Option<String>,
}

/// One run of the data set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunEntry {
    /// Resume key: the hash of everything that shapes the run's data.
    pub key: String,
    /// Condition name.
    pub condition: String,
    /// The run's seed (the unit the splits hold out).
    pub seed: u64,
    /// Seed of the run's irregularities and noise, [`super::realisation_seed`] of the
    /// condition and seed (absent in manifests of formats 1–4, whose runs drew both
    /// from `seed` itself).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub realisation_seed: Option<u64>,
    /// Run file, relative to the data set's folder.
    pub file: String,
    /// FNV-1a 64 of the run file's bytes.
    pub bytes_hash_fnv1a: String,
    /// The track file.
    pub track: FileRef,
    /// Running speed, km/h.
    pub speed_kmh: f64,
    /// Recorded duration, s.
    pub duration_s: f64,
    /// Vehicle name (absent in manifests before conditions had their own vehicle).
    #[serde(default)]
    pub vehicle: Option<String>,
    /// FRA class the plan set instead of the track file's.
    #[serde(default)]
    pub class: Option<i64>,
    /// Start position along the track, m.
    #[serde(default)]
    pub start_m: Option<f64>,
    /// The train around the wagon, as the plan names it (absent: the wagon alone).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub consist: Option<String>,
    /// The wagon's place in the train, a fraction of its length from the head (absent: the
    /// consist file's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<f64>,
    /// Whether the run's curves turned the other way from its track file's (the plan's
    /// `turn`; absent: as drawn).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub mirrored: bool,
    /// The rails' support the plan chose over the track file's (`rigid`, `lumped`,
    /// `discrete`; absent: the file's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rail_support: Option<String>,
    /// The rail roughness the plan chose over the track file's (absent: the file's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub roughness: Option<String>,
    /// Rows written. (Format 3 manifests also held each run's wall time, read and
    /// dropped: a manifest holds only what shapes the data, so one plan gives one manifest's
    /// bytes whether one process, shards or workers made it.)
    pub rows: usize,
    /// Largest |Y/Q| of each wheel, 1L … 4R.
    pub peak_y_over_q: Vec<f64>,
    /// What the plan's `[vary]` drew for this run, by key: a value, or `{"scale": factor}`
    /// (absent when nothing varies).
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub draws: std::collections::BTreeMap<String, serde_json::Value>,
}

/// The manifest of a data set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// `railforce <version>` that wrote it.
    pub tool: String,
    /// The plan file.
    pub plan: PathBuf,
    /// The plan's name.
    pub plan_name: String,
    /// The plan's vehicle.
    pub vehicle: FileRef,
    /// Run file format: `npz`, `parquet` or `csv`.
    pub format: String,
    /// Output sampling rate, Hz.
    pub sampling_rate_hz: f64,
    /// How the runs were made (absent in format 1 and 2 manifests).
    #[serde(default)]
    pub integration: Option<Integration>,
    /// The plan's `[dataset]` options (absent in older manifests: the defaults).
    #[serde(default)]
    pub dataset: DatasetOptions,
    /// SNR of the `_noisy` copies, dB (`null`: clean).
    #[serde(default)]
    pub snr_db: Option<f64>,
    /// `std` or `rms` (`null` with an SNR: written before it was recorded, the rms).
    #[serde(default)]
    pub snr_reference: Option<String>,
    /// The noise, in words.
    #[serde(default)]
    pub noise: Option<String>,
    /// `i/N` for a shard manifest.
    #[serde(default)]
    pub shard: Option<String>,
    /// The shard manifests a merge joined (in memory only: a merged manifest is written with
    /// the bytes of one process's; earlier merges wrote the list, read and dropped).
    #[serde(skip)]
    pub merged_from: Option<Vec<String>>,
    /// Conventions.
    pub conventions: Conventions,
    /// The run files' channels (`null` until the first run finished).
    #[serde(default)]
    pub channels: Option<Vec<ChannelEntry>>,
    /// The runs, sorted by condition and seed.
    pub runs: Vec<RunEntry>,
    /// Runs that derailed and were left out (the plan's `derailed = "drop"`), sorted by
    /// condition and seed.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub dropped: Vec<DroppedRun>,
}

/// A run left out of a data set because its wagon derailed.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DroppedRun {
    /// Condition name.
    pub condition: String,
    /// The run's seed.
    pub seed: u64,
    /// Where and how it derailed.
    pub reason: String,
}

impl Manifest {
    /// Reads a manifest; `Ok(None)` when the file does not exist.
    pub fn read(path: &Path) -> Result<Option<Self>> {
        if !path.exists() {
            return Ok(None);
        }
        let text = crate::io::read_text(path)?;
        serde_json::from_str(&text).map(Some).map_err(|e| {
            // serde names the line; the key on that line names the field.
            let key = text
                .lines()
                .nth(e.line().saturating_sub(1))
                .and_then(|l| l.trim().strip_prefix('"'))
                .and_then(|l| l.split('"').next())
                .map(|k| format!(" (field \"{k}\")"))
                .unwrap_or_default();
            Error::Parse {
                file: path.to_path_buf(),
                message: format!("not a railforce manifest{key}: {e}"),
            }
        })
    }

    /// Reads `manifest.json` in a data set's folder; a missing file is an error.
    pub fn load(dir: &Path) -> Result<Self> {
        let path = dir.join("manifest.json");
        Self::read(&path)?.ok_or_else(|| Error::io(&path, std::io::ErrorKind::NotFound.into()))
    }

    /// Writes the manifest atomically, keys in alphabetical order, pretty-printed.
    pub fn write(&self, path: &Path) -> Result<()> {
        crate::io::check_json_finite(self, path)?;
        let value = serde_json::to_value(self).map_err(|e| Error::Domain(e.to_string()))?;
        crate::io::write_atomic(path, |w| {
            serde_json::to_writer_pretty(&mut *w, &value).map_err(std::io::Error::other)?;
            w.write_all(b"\n")
        })
    }

    /// The noise of the `_noisy` copies (`None`: clean). An unknown reference is an error
    /// naming `path` and the field; none with an SNR is the rms of manifests before it was
    /// recorded.
    pub fn noise_model(&self, path: &Path) -> Result<Option<NoiseModel>> {
        let Some(snr) = self.snr_db else {
            return Ok(None);
        };
        let reference = match self.snr_reference.as_deref() {
            None => SnrReference::Rms,
            Some(r) => SnrReference::parse(r).ok_or_else(|| {
                Error::config(
                    path,
                    "snr_reference",
                    format!("\"{r}\" is not a noise reference: std or rms"),
                )
            })?,
        };
        Ok(Some(NoiseModel::new(snr, reference)))
    }

    /// The label channels FL and FQ (wheel 1L's where the manifest names none).
    pub fn labels(&self) -> [String; 2] {
        match &self.conventions.labels {
            Some(l) => [l.fl.clone(), l.fq.clone()],
            None => label_channels("1L"),
        }
    }

    /// The entry of the run file named `name`.
    pub fn run(&self, name: &str) -> Option<&RunEntry> {
        self.runs.iter().find(|r| r.file == name)
    }

    pub(super) fn sort_runs(&mut self) {
        self.runs
            .sort_by(|a, b| (&a.condition, a.seed).cmp(&(&b.condition, b.seed)));
        self.dropped
            .sort_by(|a, b| (&a.condition, a.seed).cmp(&(&b.condition, b.seed)));
    }
}

/// FNV-1a 64 of bytes, hex.
pub fn fnv1a(bytes: &[u8]) -> String {
    format!("{:016x}", crate::io::fnv1a64(bytes))
}

/// Identity of a data set's contents: FNV-1a 64 over every run file's name and the hash of its
/// bytes as `manifest.json` records them, in name order. Wall times, tool versions and the
/// order runs finished in are left out, so a rerun that changes no data keeps the identity
/// and any changed byte of any run changes it.
pub fn data_identity(dir: &Path) -> Result<String> {
    let m = Manifest::load(dir)?;
    let mut runs: Vec<(&str, &str)> = m
        .runs
        .iter()
        .map(|r| (r.file.as_str(), r.bytes_hash_fnv1a.as_str()))
        .collect();
    if runs.is_empty() {
        let path = dir.join("manifest.json");
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
    draws: &crate::vary::Draws,
    mirrored: bool,
) -> String {
    // Options added later enter the key only when set, so existing data sets keep their keys.
    let mut extra = String::new();
    if mirrored {
        extra += "|mirrored";
    }
    if let Some(mu) = run.condition.flange_friction {
        extra += &format!("|gauge_face={mu}");
    }
    if let Some(m) = &run.condition.rail_support {
        extra += &format!("|rail_support={m}");
    }
    if let Some(r) = &run.condition.roughness {
        extra += &format!("|roughness={r}");
    }
    if !draws.is_empty() {
        extra += &format!(
            "|vary={}",
            serde_json::to_string(&crate::vary::to_json(draws)).unwrap_or_default()
        );
    }
    if let Some(c) = run.condition.class {
        extra += &format!("|class={c}");
    }
    if let Some(s) = run.condition.start_m {
        extra += &format!("|start={s}");
    }
    if let Some(c) = &run.condition.consist {
        // The consist's content too: an edited consist file regenerates its runs.
        let t = run.condition.train.as_ref();
        extra += &format!(
            "|consist={c}@{:?}#{:016x}",
            t.and_then(|t| t.position),
            t.map_or(0, |t| crate::io::fnv1a64(
                format!("{:?}", t.consist).as_bytes()
            ))
        );
    }
    if *dataset != DatasetOptions::default() {
        extra += &format!("|dataset={dataset:?}");
    }
    if opts.stepping != crate::sim::Stepping::default() {
        extra += &format!(
            "|stepping={}@{}",
            opts.stepping.integrator.name(),
            opts.stepping.dt
        );
    }
    // Each condition draws its own realisation: keys of runs that drew it from the seed alone
    // (formats 1–4) no longer match.
    extra += &format!("|realisation={}", run.realisation_seed());
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

/// Refuses to add runs to a folder whose data set was written in another format, at another
/// SNR or with other data-set options: one folder, one data set.
pub(super) fn refuse_mixing(
    manifest: &Path,
    previous: Option<&Manifest>,
    opts: &GenerateOptions,
    dataset: &DatasetOptions,
) -> Result<()> {
    let Some(m) = previous else {
        return Ok(());
    };
    let snr = |v: Option<f64>| v.map_or("clean".to_string(), |s| format!("{s} dB"));
    let (had_format, had_snr) = (m.format.as_str(), m.snr_db);
    let had_ref = m.snr_reference.as_deref();
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
    if m.dataset != *dataset {
        let json = |d: &DatasetOptions| serde_json::to_string(d).unwrap_or_default();
        differ.push(format!(
            "data-set options {} (now {})",
            json(&m.dataset),
            json(dataset)
        ));
    }
    // A run's key names its stepping only when it is not the default, and defaults can
    // change between versions: the manifest says how its
    // runs were integrated, so a data set never resumes at another step or integrator.
    if let Some(had) = &m.integration {
        let now = Integration::of(opts);
        if had.integrator != now.integrator || had.dt_s != now.dt_s {
            let ms = |dt: f64| (dt * 1e7).round() / 1e4;
            differ.push(format!(
                "integration at {} ms, {} (now {} ms, {}; `--integrator`, `--dt`)",
                ms(had.dt_s),
                had.integrator.split(':').next().unwrap_or_default(),
                ms(now.dt_s),
                now.integrator.split(':').next().unwrap_or_default()
            ));
        }
    }
    if differ.is_empty() {
        return Ok(());
    }
    Err(Error::Domain(format!(
        "{} holds a data set with {}: write to another folder, or delete that folder to start again (runs are never mixed)",
        manifest.display(),
        differ.join(" and ")
    )))
}

/// The manifest of the data set a run file belongs to (`manifest.json` beside it) and the
/// run's entry in it, when the file is listed there.
pub fn run_entry(run_file: &Path) -> Option<(Manifest, RunEntry)> {
    let dir = run_file.parent().unwrap_or(Path::new("."));
    let m = Manifest::read(&dir.join("manifest.json")).ok()??;
    let entry = m.run(run_file.file_name()?.to_str()?)?.clone();
    Some((m, entry))
}

/// Parses a shard `i/N` (1-based, 1 ≤ i ≤ N), as `generate --shard` and Python take it.
pub fn parse_shard(text: &str) -> Result<(usize, usize)> {
    let parsed = text.split_once('/').and_then(|(i, n)| {
        i.trim()
            .parse::<usize>()
            .ok()
            .zip(n.trim().parse::<usize>().ok())
    });
    match parsed {
        Some((i, n)) if n >= 1 && (1..=n).contains(&i) => Ok((i, n)),
        _ => Err(Error::Domain(format!(
            "shard {text}: a shard is i/N with 1 ≤ i ≤ N, e.g. 2/4"
        ))),
    }
}

/// Joins the shard manifests in `out` into `manifest.json` (runs sorted by condition and seed).
pub fn merge(out: &Path) -> Result<Manifest> {
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
    let mut merged: Option<Manifest> = None;
    for path in &shards {
        let m = Manifest::read(path)?
            .ok_or_else(|| Error::Domain(format!("{} disappeared", path.display())))?;
        match merged.as_mut() {
            None => merged = Some(m),
            Some(all) => {
                let differs = [
                    ("vehicle", all.vehicle != m.vehicle),
                    ("format", all.format != m.format),
                    ("snr_db", all.snr_db != m.snr_db),
                    ("snr_reference", all.snr_reference != m.snr_reference),
                    ("plan", all.plan != m.plan),
                ];
                if let Some((key, _)) = differs.iter().find(|(_, d)| *d) {
                    return Err(Error::Domain(format!(
                        "{} disagrees with the other shards on '{key}'",
                        path.display()
                    )));
                }
                if all.channels.is_none() {
                    all.channels = m.channels;
                }
                all.runs.extend(m.runs);
                all.dropped.extend(m.dropped);
            }
        }
    }
    let Some(mut m) = merged else {
        return Err(Error::Domain(format!(
            "no manifest.shard-*.json in {}",
            out.display()
        )));
    };
    m.shard = None;
    m.merged_from = Some(
        shards
            .iter()
            .map(|p| {
                p.file_name()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .into_owned()
            })
            .collect(),
    );
    m.sort_runs();
    m.write(&out.join("manifest.json"))?;
    Ok(m)
}
