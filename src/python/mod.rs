//! The Python binding (`--features python`): the extension module `railforce._native`, which
//! the pure-Python package in `python/railforce/` wraps. As thin as the command line: every
//! decision is the library's, every error the library's message (an I/O error raises
//! `OSError`, a missing file `FileNotFoundError`, anything else `ValueError`). Long work runs
//! with the interpreter detached, so Python threads run simulations in parallel.

mod data;

use crate::Error;
use crate::assess::{Criteria, assess_columns, spans};
use crate::builtin;
use crate::dataset::{self, Format, GenerateOptions};
use crate::identify::safety::Limits;
use crate::identify::{ChannelMap, SensorTable, check};
use crate::learn::model::Model;
use crate::plan::Plan;
use crate::sensors::{NoiseModel, SnrReference};
use crate::sim::{Integrator, RunRequest, Simulation, Stepping, output};
use crate::track::{Track, TrackSpec};
use crate::vehicle::Vehicle;
use numpy::{IntoPyArray, PyReadonlyArray1};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::{Path, PathBuf};

/// A library error as the Python exception a caller expects, with the library's message.
pub(crate) fn py_err(e: Error) -> PyErr {
    match &e {
        Error::Io { error, .. } if error.kind() == std::io::ErrorKind::NotFound => {
            PyFileNotFoundError::new_err(e.to_string())
        }
        Error::Io { .. } => PyOSError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// A path as given, or the built-in file a bare name or missing path stands for.
pub(crate) fn resolve(path: &Path) -> PyResult<PathBuf> {
    builtin::resolve(path).map_err(py_err)
}

/// The integrator named (default: the library's) at step `dt` (default: its own step).
fn stepping(name: Option<&str>, dt: Option<f64>) -> PyResult<Stepping> {
    if let Some(name) = name
        && Integrator::parse(name).is_none()
    {
        return Err(PyValueError::new_err(format!(
            "integrator {name}: one of {}",
            Integrator::NAMES.join(", ")
        )));
    }
    Ok(Stepping::chosen(name, dt))
}

/// Columns given from Python (name, float64 array) as the library's columns.
fn columns(cols: Vec<(String, PyReadonlyArray1<'_, f64>)>) -> PyResult<Vec<(String, Vec<f64>)>> {
    cols.into_iter()
        .map(|(n, a)| Ok((n, a.as_slice()?.to_vec())))
        .collect::<Result<_, numpy::AsSliceError>>()
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Named columns as a dict of NumPy arrays (each vector moved into NumPy, not copied).
fn dict_of_arrays<'py>(
    py: Python<'py>,
    cols: Vec<(String, Vec<f64>)>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, v) in cols {
        d.set_item(name, v.into_pyarray(py))?;
    }
    Ok(d)
}

/// One run, as `railforce simulate` makes it; returns its recorded channels.
#[pyfunction]
#[pyo3(signature = (track, vehicle, speed_kmh, duration_s, seed, channels, settle_s, dt, integrator, keep_going, consist="none", position=None, rail_support=None, roughness=None))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    track: PathBuf,
    vehicle: PathBuf,
    speed_kmh: f64,
    duration_s: f64,
    seed: Option<u64>,
    channels: Option<Vec<String>>,
    settle_s: f64,
    dt: Option<f64>,
    integrator: Option<&str>,
    keep_going: bool,
    consist: &str,
    position: Option<f64>,
    rail_support: Option<&str>,
    roughness: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let request = RunRequest {
        speed_kmh,
        duration: duration_s,
        settle: settle_s,
        stepping: stepping(integrator, dt)?,
        stop_on_derailment: !keep_going,
    };
    let mut cfg = request.config().map_err(py_err)?;
    cfg.train = crate::sim::hitch::TrainSetup::resolve(
        consist,
        position,
        std::path::Path::new("."),
        "consist",
    )
    .map_err(py_err)?;
    let (vehicle, track) = (resolve(&vehicle)?, resolve(&track)?);
    let rec = py
        .detach(|| -> crate::Result<output::Recording> {
            let vehicle = Vehicle::load(&vehicle)?;
            let mut spec = TrackSpec::load(&track)?;
            if let Some(m) = rail_support {
                spec.set_rail_model(m)?;
            }
            if let Some(r) = roughness {
                spec.set_roughness(r)?;
            }
            let mut cfg = cfg;
            cfg.dt = request.stepping.step_on(&spec, &vehicle, cfg.speed)?;
            let track = Track::new(spec, seed);
            let mut sim = Simulation::new(&vehicle, &track, cfg)?;
            output::record(&mut sim, |_| {})
        })
        .map_err(py_err)?;
    let wanted: Vec<usize> = match &channels {
        None => (0..rec.names.len()).collect(),
        Some(list) => {
            let mut idx = vec![0];
            for c in list {
                match rec.names.iter().position(|n| n == c) {
                    Some(k) if !idx.contains(&k) => idx.push(k),
                    Some(_) => {}
                    None => {
                        return Err(PyValueError::new_err(format!(
                            "channel {c}: the run records no such channel (it records {})",
                            rec.names.join(", ")
                        )));
                    }
                }
            }
            idx
        }
    };
    let cols = wanted
        .iter()
        .map(|&k| (rec.names[k].clone(), rec.column(k)))
        .collect();
    dict_of_arrays(py, cols)
}

/// Generates a plan's data set (or one shard of it) into `out`; returns the manifest (JSON).
#[pyfunction]
#[pyo3(signature = (plan, out, shard, format, jobs, snr_db, snr_reference, settle_s, integrator, dt))]
#[allow(clippy::too_many_arguments)]
fn generate(
    py: Python<'_>,
    plan: PathBuf,
    out: PathBuf,
    shard: Option<String>,
    format: &str,
    jobs: Option<usize>,
    snr_db: Option<f64>,
    snr_reference: &str,
    settle_s: f64,
    integrator: Option<&str>,
    dt: Option<f64>,
) -> PyResult<String> {
    let plan = Plan::load(&resolve(&plan)?).map_err(py_err)?;
    let format = Format::parse(format).ok_or_else(|| {
        PyValueError::new_err(format!("format {format}: one of npz, parquet, csv"))
    })?;
    let shard = shard
        .as_deref()
        .map(dataset::parse_shard)
        .transpose()
        .map_err(py_err)?;
    let noise = match snr_db {
        None => None,
        Some(snr) => Some(NoiseModel::new(
            snr,
            SnrReference::parse(snr_reference).ok_or_else(|| {
                PyValueError::new_err(format!("snr_reference {snr_reference}: std or rms"))
            })?,
        )),
    };
    let opts = GenerateOptions {
        out,
        format,
        jobs: jobs.unwrap_or_else(dataset::default_jobs),
        shard,
        noise,
        settle: settle_s,
        stepping: stepping(integrator, dt)?,
    };
    let m = py
        .detach(|| dataset::generate(&plan, &opts, &|_| {}))
        .map_err(py_err)?;
    serde_json::to_string(&m).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Joins the shard manifests in `out` into `manifest.json`; returns it (JSON).
#[pyfunction]
fn merge(py: Python<'_>, out: PathBuf) -> PyResult<String> {
    let m = py.detach(|| dataset::merge(&out)).map_err(py_err)?;
    serde_json::to_string(&m).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// The names that stand for built-in plans, vehicles and tracks.
#[pyfunction]
fn builtins() -> Vec<&'static str> {
    builtin::names()
}

/// Forces and safety indices from sensor columns with a trained model: the columns of
/// `identify`'s CSV at full precision, the exceedance reports and the out-of-distribution
/// stretches (JSON).
#[pyfunction]
#[pyo3(signature = (model, columns, source, coverage, resample, channel_map, static_wheel_load_kn, vehicle))]
#[allow(clippy::too_many_arguments)]
fn identify<'py>(
    py: Python<'py>,
    model: PathBuf,
    columns: Vec<(String, PyReadonlyArray1<'py, f64>)>,
    source: String,
    coverage: f64,
    resample: bool,
    channel_map: Option<PathBuf>,
    static_wheel_load_kn: Option<f64>,
    vehicle: PathBuf,
) -> PyResult<(Bound<'py, PyDict>, String)> {
    if !(coverage > 0.0 && coverage < 1.0) {
        return Err(PyValueError::new_err(format!(
            "coverage {coverage}: give a fraction between 0 and 1, e.g. 0.9"
        )));
    }
    let cols = self::columns(columns)?;
    let q0 = match static_wheel_load_kn {
        Some(q) => q,
        None => Vehicle::load(&resolve(&vehicle)?)
            .map_err(py_err)?
            .static_wheel_load_kn(),
    };
    let limits = Limits::from_criteria(&Criteria::builtin(), q0);
    let (out, json) = py
        .detach(|| -> crate::Result<_> {
            let mut model = Model::load(&model)?;
            let table = SensorTable::from_columns(source, cols)?;
            let table = match channel_map {
                Some(p) => ChannelMap::load(&p)?.apply(&table, &model.meta.data.channels)?,
                None => table,
            };
            let input = check(&table, &model, resample)?;
            let out = crate::identify::output::run(&mut model, &input, &limits, coverage);
            let json = serde_json::json!({
                "limits": limits,
                "indices": out.reports,
                "out_of_distribution": out.ood_spans.as_ref().map(|(share, spans)| {
                    serde_json::json!({"share": share, "spans": spans})
                }),
                "calibrated": out.bands.is_some(),
            });
            Ok((out.columns(), json.to_string()))
        })
        .map_err(py_err)?;
    Ok((dict_of_arrays(py, out)?, json))
}

/// Assesses a run (a file, or columns) as acceptance engineers do; returns the assessment
/// (JSON: every quantity per section with its limit and source).
#[pyfunction]
#[pyo3(signature = (file, columns, track, criteria, static_wheel_load_kn, vehicle, coverage))]
#[allow(clippy::too_many_arguments)]
fn assess(
    py: Python<'_>,
    file: Option<PathBuf>,
    columns: Option<Vec<(String, PyReadonlyArray1<'_, f64>)>>,
    track: Option<PathBuf>,
    criteria: Option<PathBuf>,
    static_wheel_load_kn: Option<f64>,
    vehicle: PathBuf,
    coverage: f64,
) -> PyResult<String> {
    let criteria = match criteria {
        Some(p) => Criteria::load(&resolve(&p)?).map_err(py_err)?,
        None => Criteria::builtin(),
    };
    let q0 = match static_wheel_load_kn {
        Some(q) if q.is_finite() && q > 0.0 => q,
        Some(q) => {
            return Err(PyValueError::new_err(format!(
                "static_wheel_load_kn must be positive, got {q}"
            )));
        }
        None => Vehicle::load(&resolve(&vehicle)?)
            .map_err(py_err)?
            .static_wheel_load_kn(),
    };
    let (source, cols) = match (file, columns) {
        (Some(f), _) => (
            f.display().to_string(),
            dataset::read_table(&f).map_err(py_err)?,
        ),
        (None, Some(c)) => ("<columns>".to_string(), self::columns(c)?),
        (None, None) => return Err(PyValueError::new_err("give a run file or its columns")),
    };
    let sections = match track {
        Some(t) => spans(&TrackSpec::load(&resolve(&t)?).map_err(py_err)?),
        None => Vec::new(),
    };
    let a = py
        .detach(|| assess_columns(&source, &cols, &sections, &criteria, q0, coverage))
        .map_err(py_err)?;
    serde_json::to_string(&a).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// The quasi-static contact of a vehicle's wheelset at a lateral shift and yaw: both wheels'
/// patches and forces (JSON).
#[pyfunction]
#[pyo3(signature = (vehicle, y_mm, yaw_mrad, load_kn, speed_kmh, extra_roll_mrad, spin, lateral_velocity, yaw_rate))]
#[allow(clippy::too_many_arguments)]
fn contact(
    vehicle: PathBuf,
    y_mm: f64,
    yaw_mrad: f64,
    load_kn: Option<f64>,
    speed_kmh: f64,
    extra_roll_mrad: f64,
    spin: Option<f64>,
    lateral_velocity: f64,
    yaw_rate: f64,
) -> PyResult<String> {
    let v = Vehicle::load(&resolve(&vehicle)?).map_err(py_err)?;
    let load = load_kn.unwrap_or_else(|| v.static_wheel_load_kn());
    if !(load > 0.0 && speed_kmh > 0.0) {
        return Err(PyValueError::new_err(
            "load_kn and speed_kmh must be positive",
        ));
    }
    let setup = v.quasi_static(load * 1e3);
    let st = setup.solve(&crate::contact::WheelsetState {
        y: y_mm * 1e-3,
        yaw: yaw_mrad * 1e-3,
        extra_roll: extra_roll_mrad * 1e-3,
        speed: speed_kmh / 3.6,
        lateral_velocity,
        yaw_rate,
        spin,
    });
    let wheels: Vec<serde_json::Value> = st
        .wheels
        .iter()
        .map(|w| {
            let f = &w.forces;
            serde_json::json!({
                "side": if w.side == crate::contact::Side::Left { "left" } else { "right" },
                "approach_m": w.approach,
                "Y_N": f.force[1],
                "Q_N": f.force[2],
                "y_over_q": f.y_over_q(),
                "patches": f.patches.iter().flatten().map(|p| serde_json::json!({
                    "track_y_m": y_mm * 1e-3 + p.point[1],
                    "rolling_radius_m": p.radius,
                    "contact_angle_rad": p.angle,
                    "normal_N": p.normal,
                    "a_m": p.ellipse.a,
                    "b_m": p.ellipse.b,
                    "p0_Pa": p.ellipse.p0,
                    "creepage": [p.creepage.x, p.creepage.y, p.creepage.spin],
                    "creep_force_N": [p.creep.x, p.creep.y],
                    "force_N": [p.force[0], p.force[1], p.force[2]],
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    let doc = serde_json::json!({
        "roll_rad": st.roll,
        "height_m": st.height,
        "spin_rad_s": st.spin,
        "rolling_radius_m": st.rolling_radius,
        "nadal_limit": setup.nadal_limit(),
        "wheels": wheels,
    });
    Ok(doc.to_string())
}

/// The extension module: `railforce._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(generate, m)?)?;
    m.add_function(wrap_pyfunction!(merge, m)?)?;
    m.add_function(wrap_pyfunction!(builtins, m)?)?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add_function(wrap_pyfunction!(assess, m)?)?;
    m.add_function(wrap_pyfunction!(contact, m)?)?;
    data::register(m)
}
