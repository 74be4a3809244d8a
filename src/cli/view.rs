//! `railforce view`: a thin shell over `railforce::view`.

use anyhow::{Context, Result, bail};
use clap::Args;
use railforce::assess::Criteria;
use railforce::identify::{SensorTable, check, identify};
use railforce::learn::model::Model;
use railforce::track::{Track, TrackSpec};
use railforce::vehicle::Vehicle;
use railforce::view::{DEFAULT_RATE_HZ, Inputs, Limits, Scene, page};
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
pub struct ViewArgs {
    /// Run file to replay: the CSV of `railforce simulate` or a data set's run file (NPZ,
    /// Parquet or CSV) with all channels.
    run: PathBuf,
    /// Output of `railforce identify` for this run: its forces of the label wheel are drawn
    /// over the true ones. Give it twice for separate FL and FQ models.
    #[arg(long)]
    identified: Vec<PathBuf>,
    /// Output HTML file [default: the run's name with `.view.html`].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Vehicle file [default: the one the run's `.meta.json` or data set manifest names, else
    /// vehicles/c80.toml].
    #[arg(long)]
    vehicle: Option<PathBuf>,
    /// Track file [default: the one the run's metadata names].
    #[arg(long)]
    track: Option<PathBuf>,
    /// Irregularity seed [default: the run's].
    #[arg(long)]
    seed: Option<u64>,
    /// Assessment criteria for the limits drawn on the traces [default: the built-in
    /// vehicles/assessment.toml].
    #[arg(long)]
    criteria: Option<PathBuf>,
    /// Frames per second of simulated time in the page (the run's rate at most): lower makes
    /// a smaller file.
    #[arg(long, default_value_t = DEFAULT_RATE_HZ)]
    rate_hz: f64,
}

/// `path` when it exists, else the built-in file of the same name in `folder`.
fn locate(path: &Path, folder: &str) -> Result<PathBuf> {
    if path.exists() {
        return Ok(path.to_path_buf());
    }
    match path.file_name() {
        Some(name) => super::builtin::resolve(&Path::new(folder).join(name)),
        None => Ok(path.to_path_buf()),
    }
}

/// Where the scene's vehicle, track, seed and limits come from, besides the run's metadata.
struct Sources<'a> {
    vehicle: Option<&'a Path>,
    track: Option<&'a Path>,
    seed: Option<u64>,
    criteria: Option<&'a Path>,
    rate_hz: f64,
}

/// The scene of `run` with the identified columns `identified`.
fn build(
    run: &Path,
    identified: Option<(String, Vec<railforce::view::Column>)>,
    src: &Sources,
) -> Result<Scene> {
    if !(src.rate_hz.is_finite() && src.rate_hz > 0.0) {
        bail!("--rate-hz {}: give a positive rate", src.rate_hz);
    }
    if !run.is_file() {
        bail!("{}: no such run file", run.display());
    }
    let meta = railforce::dataset::recorded_run(run);
    let vehicle_path = match (src.vehicle, &meta.vehicle) {
        (Some(p), _) => super::builtin::resolve(p)?,
        (None, Some(p)) => locate(p, "vehicles")?,
        (None, None) => super::builtin::resolve(Path::new("vehicles/c80.toml"))?,
    };
    let track_path = match (src.track, meta.track.as_ref().map(|t| &t.file)) {
        (Some(p), _) => super::builtin::resolve(p)?,
        (None, Some(p)) => locate(p, "tracks")?,
        (None, None) => bail!(
            "{}: no metadata names its track (no .meta.json beside it, no manifest.json entry): give --track",
            run.display()
        ),
    };
    let vehicle = Vehicle::load(&vehicle_path)?;
    let track = Track::new(TrackSpec::load(&track_path)?, src.seed.or(meta.seed));
    let criteria = match src.criteria {
        Some(p) => Criteria::load(&super::builtin::resolve(p)?)?,
        None => Criteria::builtin(),
    };
    let c = &criteria.chinese;
    let q0 = vehicle.static_wheel_load_kn();
    let limits = Limits {
        y_over_q: c.derailment,
        q_min: (1.0 - c.unloading) * q0,
        q_static: q0,
        source: format!(
            "|Y|/Q ≤ {} and ΔQ/Q̄ ≤ {} (Q̄ {q0:.1} kN) from {}",
            c.derailment,
            c.unloading,
            if src.criteria.is_some() {
                "the given criteria"
            } else {
                "vehicles/assessment.toml [chinese]"
            }
        ),
    };
    let cols = railforce::dataset::read_table(run)?;
    eprintln!(
        "building the view of {} ({} on {}) …",
        run.display(),
        vehicle.name,
        track.spec().name
    );
    Ok(Scene::build(
        &run.display().to_string(),
        &cols,
        &Inputs {
            vehicle: &vehicle,
            track: &track,
            identified,
            limits,
            rate_hz: src.rate_hz,
            speed_kmh: meta.speed_kmh,
        },
    )?)
}

/// Writes the page and says where, how large and what to do with it.
fn write(scene: &Scene, out: &Path) -> Result<()> {
    let bytes = page::write(scene, out).with_context(|| format!("writing {}", out.display()))?;
    println!(
        "wrote {} ({:.1} MB, {} frames over {:.1} s); open it in a browser (no network needed)",
        out.display(),
        bytes as f64 / 1e6,
        scene.time.len(),
        scene.time.last().unwrap_or(&0.0) - scene.time.first().unwrap_or(&0.0)
    );
    Ok(())
}

pub fn run(args: ViewArgs) -> Result<()> {
    let mut identified: Option<(String, Vec<railforce::view::Column>)> = None;
    for p in &args.identified {
        let id = railforce::dataset::read_table(p)?;
        identified = Some(match identified {
            None => (p.display().to_string(), id),
            Some((src, all)) => (
                format!("{src} + {}", p.display()),
                merge(&src, all, &p.display().to_string(), id)?,
            ),
        });
    }
    let scene = build(
        &args.run,
        identified,
        &Sources {
            vehicle: args.vehicle.as_deref(),
            track: args.track.as_deref(),
            seed: args.seed,
            criteria: args.criteria.as_deref(),
            rate_hz: args.rate_hz,
        },
    )?;
    let out = args.out.clone().unwrap_or_else(|| {
        let stem = args
            .run
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "run".into());
        args.run.with_file_name(format!("{stem}.view.html"))
    });
    write(&scene, &out)
}

/// Adds the force columns of a second identified file to the first (same time axis).
fn merge(
    first: &str,
    mut all: Vec<railforce::view::Column>,
    second: &str,
    id: Vec<railforce::view::Column>,
) -> Result<Vec<railforce::view::Column>> {
    let time = |cols: &[railforce::view::Column]| {
        cols.iter()
            .find(|(n, _)| n == "time_s")
            .map(|c| c.1.clone())
    };
    if time(&id) != time(&all) {
        bail!("{second}: its time_s differs from {first}'s: identify both from the same run");
    }
    let new: Vec<_> = id
        .into_iter()
        .filter(|(n, _)| !all.iter().any(|c| &c.0 == n))
        .collect();
    all.extend(new);
    Ok(all)
}

/// The demo's viewer: the test run of its first curve condition, identified by the demo's
/// CNN-BiLSTM models (FL and FQ), as `out/view/view.html`, with a section that links it
/// from the demo report. Returns the page's path.
pub fn write_demo_view(out: &Path) -> Result<PathBuf> {
    let data = out.join("data");
    let manifest = railforce::dataset::Manifest::load(&data)?;
    let runs = &manifest.runs;
    let top_seed = runs.iter().map(|r| r.seed).max();
    let pick = runs
        .iter()
        .filter(|r| Some(r.seed) == top_seed)
        .find(|r| r.condition.starts_with("curve"))
        .or_else(|| runs.iter().find(|r| Some(r.seed) == top_seed))
        .map(|r| r.file.as_str())
        .context("the demo data set lists no run")?;
    let run = data.join(pick);
    let cols = railforce::dataset::read_table(&run)?;
    let mut identified: Vec<railforce::view::Column> = Vec::new();
    let mut names = Vec::new();
    for target in ["fl", "fq"] {
        let dir = out
            .join("comparison/models")
            .join(format!("cnn-bilstm_{target}"));
        if !dir.join("model.json").exists() {
            continue;
        }
        let mut model = Model::load(&dir)?;
        let table = SensorTable::from_columns(run.display().to_string(), cols.clone())?;
        let input = check(&table, &model, false)?;
        let id = identify(&mut model, &input);
        if identified.is_empty() {
            identified.push(("time_s".into(), id.time.clone()));
        }
        for (k, t) in id.targets.iter().enumerate() {
            identified.push((
                format!("{t}_N"),
                id.values.iter().map(|row| row[k]).collect(),
            ));
        }
        names.push(dir.display().to_string());
    }
    let identified = (!names.is_empty()).then(|| (names.join(" + "), identified));
    let scene = build(
        &run,
        identified,
        &Sources {
            vehicle: None,
            track: None,
            seed: None,
            criteria: None,
            rate_hz: DEFAULT_RATE_HZ,
        },
    )?;
    let folder = out.join(railforce::experiment::VIEW_FOLDER);
    let page = folder.join("view.html");
    write(&scene, &page)?;
    railforce::report::SavedSection {
        title: "Viewer".into(),
        text: vec![format!(
            "The test run {pick} replayed: the leading wheelset on its rails, the wagon on the track and the label wheel's forces, true and identified by the CNN-BiLSTM above. One self-contained page (no network); `railforce view RUN --identified FILE` makes one for any run."
        )],
        tables: Vec::new(),
        figures: Vec::new(),
        links: vec![("Open the viewer".into(), "view.html".into())],
    }
    .write(&folder)?;
    Ok(page)
}

/// The command that opens `file` in the viewer, for other commands to print.
pub fn hint(file: &Path, identified: Option<&Path>) -> String {
    let mut s = format!("railforce view {}", file.display());
    if let Some(i) = identified {
        s.push_str(&format!(" --identified {}", i.display()));
    }
    s
}
