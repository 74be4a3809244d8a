//! Data sets and windows for Python: `Dataset` (runs, channels, labels, manifest, split) and
//! the windows of one part, standardised as the trainer makes them, for PyTorch.

use super::py_err;
use crate::dataset::{DataSet, Manifest};
use crate::features::{LabelAt, NoiseProtocol, Part, Split};
use crate::learn::windows::{DataRequest, DataSpec, NoiseRefresher, Prepared, WindowSet, prepare};
use numpy::{IntoPyArray, PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyIndexError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// A data set written by `generate`, loaded into memory.
#[pyclass(name = "Dataset", module = "railforce", frozen)]
pub struct PyDataset {
    ds: Arc<DataSet>,
    manifest: String,
    /// The windows last prepared (standardised views of every run, all three parts) and the
    /// spec they answer: asking for another part of the same spec reuses them.
    prepared: Mutex<Option<(DataSpec, Arc<Prepared>)>>,
}

#[pymethods]
impl PyDataset {
    /// The data set's folder.
    #[getter]
    fn path(&self) -> PathBuf {
        self.ds.dir.clone()
    }

    /// Channel names, in the runs' column order.
    #[getter]
    fn channels(&self) -> Vec<String> {
        self.ds.names.clone()
    }

    /// The label channels (FL, FQ).
    #[getter]
    fn labels(&self) -> Vec<String> {
        self.ds.labels.to_vec()
    }

    /// The runs: (condition, seed, rows) in manifest order.
    #[getter]
    fn runs(&self) -> Vec<(String, u64, usize)> {
        self.ds
            .runs
            .iter()
            .map(|r| (r.condition.clone(), r.seed, r.len()))
            .collect()
    }

    /// The manifest, as a dict.
    #[getter]
    fn manifest<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?
            .call_method1("loads", (self.manifest.as_str(),))
    }

    /// The SNR of the `_noisy` copies, dB (None: clean).
    #[getter]
    fn snr_db(&self) -> Option<f64> {
        self.ds.snr_db()
    }

    /// The leak-free default split `windows` uses: `{"kind": "seeds", "train": [seeds],
    /// "val": [...], "test": [...]}` (blocks of every run when the data set has too few
    /// seeds: `{"kind": "blocks", "train": 0.7, "val": 0.15}`), with `describe` in words.
    #[getter]
    fn split<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let split = Split::standard(&self.ds);
        let mut v =
            serde_json::to_value(&split).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let mut out = serde_json::Map::new();
        out.insert("kind".into(), split.name().into());
        if let Some(parts) = v.get_mut(split.name()).and_then(|p| p.as_object_mut()) {
            out.append(parts);
        }
        out.insert("describe".into(), split.describe().into());
        py.import("json")?
            .call_method1("loads", (serde_json::Value::Object(out).to_string(),))
    }

    /// Run `i`'s columns, each a NumPy array.
    fn run<'py>(&self, py: Python<'py>, i: usize) -> PyResult<Bound<'py, PyDict>> {
        let run = self.ds.runs.get(i).ok_or_else(|| {
            PyIndexError::new_err(format!(
                "run {i}: the data set has {} runs",
                self.ds.runs.len()
            ))
        })?;
        let d = PyDict::new(py);
        for (name, col) in self.ds.names.iter().zip(&run.columns) {
            d.set_item(name, PyArray1::from_slice(py, col))?;
        }
        Ok(d)
    }

    fn __len__(&self) -> usize {
        self.ds.runs.len()
    }

    fn __repr__(&self) -> String {
        format!(
            "Dataset('{}': {} runs, {} channels, labels {})",
            self.ds.dir.display(),
            self.ds.runs.len(),
            self.ds.names.len(),
            self.ds.labels.join(", ")
        )
    }
}

/// Reads a data set (its manifest and every run).
#[pyfunction]
fn open_dataset(py: Python<'_>, path: PathBuf) -> PyResult<PyDataset> {
    let (ds, manifest) = py
        .detach(|| -> crate::Result<_> { Ok((DataSet::load(&path)?, Manifest::load(&path)?)) })
        .map_err(py_err)?;
    Ok(PyDataset {
        ds: Arc::new(ds),
        manifest: serde_json::to_string(&manifest)
            .map_err(|e| PyValueError::new_err(e.to_string()))?,
        prepared: Mutex::new(None),
    })
}

fn part_of(p: &Prepared, part: Part) -> &WindowSet {
    match part {
        Part::Train => &p.train,
        Part::Val => &p.val,
        Part::Test => &p.test,
    }
}

/// Standardisation and naming shared by both window calls.
fn describe<'py>(
    py: Python<'py>,
    spec: &DataSpec,
    p: &Prepared,
    set: &WindowSet,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("channels", spec.channels.clone())?;
    d.set_item("targets", spec.targets.clone())?;
    d.set_item("input_mean", p.input_stats.mean.clone().into_pyarray(py))?;
    d.set_item("input_std", p.input_stats.std.clone().into_pyarray(py))?;
    d.set_item("target_mean", p.target_stats.mean.clone().into_pyarray(py))?;
    d.set_item("target_std", p.target_stats.std.clone().into_pyarray(py))?;
    d.set_item("label_offset", set.label_offset())?;
    d.set_item(
        "run",
        set.windows
            .iter()
            .map(|w| w.run as i64)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item(
        "start",
        set.windows
            .iter()
            .map(|w| w.start as i64)
            .collect::<Vec<_>>()
            .into_pyarray(py),
    )?;
    d.set_item("split", spec.split.describe())?;
    Ok(d)
}

/// The windows of one part. Materialised (`source` false): `x[n, window, channels]` and
/// `y[n, targets]` (float32, standardised with the training part's statistics), with each
/// window's run and first step. As a source for a window dataset (`source` true): per run the
/// part's standardised inputs `[rows, channels]` and targets `[rows, targets]`, and, for the
/// matched protocol's training part, each run's noise σ per channel (standardised units) for a
/// fresh draw every epoch, as the trainer makes it.
#[pyfunction]
#[pyo3(signature = (dataset, split, channels, window, label, targets, stride, noise, source))]
#[allow(clippy::too_many_arguments)]
fn windows<'py>(
    py: Python<'py>,
    dataset: &PyDataset,
    split: &str,
    channels: Option<Vec<String>>,
    window: usize,
    label: &str,
    targets: &str,
    stride: usize,
    noise: Option<&str>,
    source: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (part, spec, p) = py.detach(|| -> PyResult<_> {
        let ds = &dataset.ds;
        let part = match split {
            "train" => Part::Train,
            "val" | "validation" => Part::Val,
            "test" => Part::Test,
            _ => {
                return Err(PyValueError::new_err(format!(
                    "split {split}: one of train, val, test"
                )));
            }
        };
        let label_at = LabelAt::parse(label).map_err(|e| PyValueError::new_err(e.to_string()))?;
        let noise = noise
            .map(|n| {
                NoiseProtocol::parse(n).ok_or_else(|| {
                    PyValueError::new_err(format!(
                        "noise {n}: one of clean, matched, train-clean-test-noisy"
                    ))
                })
            })
            .transpose()?;
        let req = DataRequest {
            channels: channels.unwrap_or_else(|| {
                crate::sensors::PAPER_CHANNELS
                    .iter()
                    .map(|c| c.to_string())
                    .collect()
            }),
            targets: targets.to_string(),
            window,
            label_at,
            stride,
            split: Split::standard(ds),
            noise,
        };
        let spec = DataSpec::resolve(&req, ds).map_err(py_err)?;
        let mut cache = dataset.prepared.lock().expect("windows cache lock");
        if let Some((cached, p)) = cache.as_ref()
            && *cached == spec
        {
            return Ok((part, spec, p.clone()));
        }
        let prepared = Arc::new(prepare(ds, &spec, None).map_err(py_err)?);
        *cache = Some((spec.clone(), prepared.clone()));
        Ok((part, spec, prepared))
    })?;
    let set = part_of(&p, part);
    let d = describe(py, &spec, &p, set)?;
    if source {
        return window_source(py, dataset, part, &spec, &p, set, d);
    }
    let (x, y) = py.detach(|| set.all());
    let (n, w, c, o) = (set.len(), set.window, set.channels, set.outputs);
    d.set_item("x", x.into_pyarray(py).reshape([n, w, c])?)?;
    d.set_item("y", y.into_pyarray(py).reshape([n, o])?)?;
    Ok(d)
}

/// [`windows`]' source form: `d` with the per-run inputs, targets and noise σ added.
fn window_source<'py>(
    py: Python<'py>,
    dataset: &PyDataset,
    part: Part,
    spec: &DataSpec,
    p: &Prepared,
    set: &WindowSet,
    d: Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    let ds = dataset.ds.clone();
    // Training under the matched protocol draws fresh noise on the clean inputs per epoch.
    let fresh = part == Part::Train && spec.noise == NoiseProtocol::Matched;
    let refresher = match (fresh, spec.noise_model) {
        (true, Some(model)) => Some(
            py.detach(|| NoiseRefresher::new(&ds, spec, &p.input_stats, &model))
                .map_err(py_err)?,
        ),
        _ => None,
    };
    let c = set.channels;
    let o = set.outputs;
    let (inputs, sigma): (Vec<Vec<f32>>, Option<Vec<Vec<f32>>>) = match &refresher {
        Some(r) => (r.clean().to_vec(), Some(r.sigma().to_vec())),
        None => (set.inputs().as_ref().clone(), None),
    };
    let mut xs = Vec::with_capacity(inputs.len());
    for x in inputs {
        let rows = x.len() / c.max(1);
        xs.push(x.into_pyarray(py).reshape([rows, c])?);
    }
    let mut ys = Vec::with_capacity(set.target_rows().len());
    for y in set.target_rows().iter() {
        let rows = y.len() / o.max(1);
        ys.push(PyArray1::from_slice(py, y).reshape([rows, o])?);
    }
    d.set_item("inputs", xs)?;
    d.set_item("target_rows", ys)?;
    match sigma {
        Some(s) => {
            let runs = s.len();
            let flat: Vec<f32> = s.into_iter().flatten().collect();
            d.set_item("sigma", flat.into_pyarray(py).reshape([runs, c])?)?;
        }
        None => d.set_item("sigma", py.None())?,
    }
    Ok(d)
}

/// Adds the data-set functions and class to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyDataset>()?;
    m.add_function(wrap_pyfunction!(open_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(windows, m)?)?;
    Ok(())
}
