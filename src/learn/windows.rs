//! Standardised windows ready for the learners: each run's selected input columns interleaved
//! row-major (`[rows × C]` f32, so a window is one contiguous slice) and its standardised
//! targets. Built per part from the leak-free [`Samples`] with the statistics of the training
//! blocks only (assets/docs/learning.md §1).

use crate::dataset::DataSet;
use crate::error::{Error, Result};
use crate::features::{LabelAt, NoiseProtocol, Part, Samples, Split, Window, ZScore};
use crate::sensors::NoiseModel;
use crate::sensors::noise::rng;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Per-run row-major matrices, shared between the parts that read them.
type Shared = Arc<Vec<Vec<f32>>>;

/// What a model is trained on: everything needed to rebuild the same windows later.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DataSpec {
    /// Input channels (clean names; `_noisy` copies are read where the protocol says).
    pub channels: Vec<String>,
    /// Label channels (one or two).
    pub targets: Vec<String>,
    /// Steps per window.
    pub window: usize,
    /// Label position.
    pub label_at: LabelAt,
    /// Stride of training windows (validation and test use 1).
    pub stride: usize,
    /// How runs are split.
    pub split: Split,
    /// Which inputs each part reads.
    pub noise: NoiseProtocol,
    /// The noise of the noisy inputs (SNR and its reference), when any part reads them or
    /// training draws fresh noise; `None` for a clean model.
    #[serde(default)]
    pub noise_model: Option<NoiseModel>,
}

/// What a user or an experiment asks of a data set, before [`DataSpec::resolve`] checks it
/// against the data and fills in the defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct DataRequest {
    /// Input channels (a `_noisy` suffix is dropped: the protocol says which copy is read).
    pub channels: Vec<String>,
    /// Targets, comma separated: `FL`, `FQ`, `both`, a wheel (`w1r`, `1R`) or channel names.
    pub targets: String,
    /// Steps per window.
    pub window: usize,
    /// Label position.
    pub label_at: LabelAt,
    /// Stride of training windows.
    pub stride: usize,
    /// The split ([`Split::resolve`] makes one from what a user asks).
    pub split: Split,
    /// The noise protocol; `None`: matched when the data set has noisy inputs, else clean.
    pub noise: Option<NoiseProtocol>,
}

impl DataSpec {
    /// The one place a data spec is made, for `train` and the experiments alike: targets
    /// resolved against the data set's labels, the split checked (no seed in two parts),
    /// the noise protocol (matched when the data set has noisy copies of the inputs, else
    /// clean, unless asked) and the noise model the data set records (none for a clean model).
    pub fn resolve(req: &DataRequest, ds: &DataSet) -> Result<DataSpec> {
        let channels: Vec<String> = req
            .channels
            .iter()
            .map(|c| c.strip_suffix("_noisy").unwrap_or(c).to_string())
            .collect();
        let targets = ds.targets(&req.targets)?;
        let has_noisy = ds.noise.is_some()
            || channels
                .iter()
                .all(|c| ds.channel(&crate::sensors::noisy_name(c)).is_ok());
        let noise = match req.noise {
            Some(n) => n,
            None if has_noisy => NoiseProtocol::Matched,
            None => NoiseProtocol::Clean,
        };
        if req.window == 0 || req.stride == 0 {
            return Err(Error::Domain(
                "the window and the stride must be at least one step".into(),
            ));
        }
        Ok(DataSpec {
            channels,
            targets,
            window: req.window,
            label_at: req.label_at,
            stride: req.stride,
            split: {
                req.split.check()?;
                req.split.clone()
            },
            noise,
            noise_model: if noise == NoiseProtocol::Clean {
                None
            } else {
                ds.noise
            },
        })
    }
}

/// Windows of one part.
#[derive(Debug, Clone)]
pub struct WindowSet {
    /// Steps per window.
    pub window: usize,
    /// Input channels.
    pub channels: usize,
    /// Outputs.
    pub outputs: usize,
    /// The windows (run, first step).
    pub windows: Vec<Window>,
    label_offset: usize,
    /// Per run, the standardised inputs `[rows × C]` (shared between parts reading the same
    /// columns).
    x: Shared,
    /// Per run, the standardised targets `[rows × outputs]` (shared by all parts).
    y: Shared,
}

impl WindowSet {
    /// Number of windows.
    pub fn len(&self) -> usize {
        self.windows.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.windows.is_empty()
    }

    /// Values per window (`window × channels`).
    pub fn features(&self) -> usize {
        self.window * self.channels
    }

    /// Copies the windows `idx` into `x[n, window, channels]` and their labels into
    /// `y[n, outputs]`.
    pub fn gather(&self, idx: &[usize], x: &mut Vec<f32>, y: &mut Vec<f32>) {
        let per = self.features();
        x.clear();
        y.clear();
        x.reserve(idx.len() * per);
        for &i in idx {
            let w = self.windows[i];
            let (r, s) = (w.run as usize, w.start as usize);
            x.extend_from_slice(&self.x[r][s * self.channels..s * self.channels + per]);
            let l = (s + self.label_offset) * self.outputs;
            y.extend_from_slice(&self.y[r][l..l + self.outputs]);
        }
    }

    /// All windows, in order: `x[n, window, channels]`, `y[n, outputs]`. Copied by every core
    /// at once (a copy of this size is bound by memory and page faults, not arithmetic).
    pub fn all(&self) -> (Vec<f32>, Vec<f32>) {
        let (per, o, n, c) = (self.features(), self.outputs, self.len(), self.channels);
        let mut x: Vec<f32> = Vec::with_capacity(n * per);
        let mut y: Vec<f32> = Vec::with_capacity(n * o);
        huge_pages(&mut x);
        let threads = parallelism().min(n.div_ceil(4096)).max(1);
        let chunk = n.div_ceil(threads).max(1);
        // Every element of the spare capacity is written exactly once below (each window's
        // `per` inputs and `o` labels), so no pass zeroes memory about to be overwritten.
        std::thread::scope(|scope| {
            for (k, (xs, ys)) in x.spare_capacity_mut()[..n * per]
                .chunks_mut(chunk * per.max(1))
                .zip(y.spare_capacity_mut()[..n * o].chunks_mut(chunk * o.max(1)))
                .enumerate()
            {
                scope.spawn(move || {
                    let first = k * chunk;
                    for (j, (xw, yw)) in xs
                        .chunks_exact_mut(per.max(1))
                        .zip(ys.chunks_exact_mut(o.max(1)))
                        .enumerate()
                    {
                        let w = self.windows[first + j];
                        let (r, s) = (w.run as usize, w.start as usize);
                        let l = (s + self.label_offset) * o;
                        for (d, v) in xw.iter_mut().zip(&self.x[r][s * c..s * c + per]) {
                            d.write(*v);
                        }
                        for (d, v) in yw.iter_mut().zip(&self.y[r][l..l + o]) {
                            d.write(*v);
                        }
                    }
                });
            }
        });
        // SAFETY: the threads above initialised all `n·per` and `n·o` elements (the chunks
        // cover the ranges exactly, each window's slices in full).
        unsafe {
            x.set_len(n * per);
            y.set_len(n * o);
        }
        (x, y)
    }

    /// The same windows reading other (equally standardised) inputs, as
    /// [`NoiseRefresher::draw`] makes them.
    pub fn with_inputs(&self, x: Arc<Vec<Vec<f32>>>) -> WindowSet {
        assert_eq!(x.len(), self.x.len(), "one input matrix per run");
        WindowSet { x, ..self.clone() }
    }

    /// Per run, the standardised inputs `[rows × channels]` row-major (shared, not copied).
    pub fn inputs(&self) -> &Arc<Vec<Vec<f32>>> {
        &self.x
    }

    /// Per run, the standardised targets `[rows × outputs]` row-major.
    pub fn target_rows(&self) -> &Arc<Vec<Vec<f32>>> {
        &self.y
    }

    /// Steps from a window's first step to its label.
    pub fn label_offset(&self) -> usize {
        self.label_offset
    }

    /// Row (time step) of window `i`'s last step in its run.
    pub fn last_row(&self, i: usize) -> usize {
        self.windows[i].start as usize + self.window - 1
    }

    /// Row (time step) of window `i`'s label in its run.
    pub fn label_row(&self, i: usize) -> (usize, usize) {
        let w = self.windows[i];
        (w.run as usize, w.start as usize + self.label_offset)
    }
}

/// The three parts and their statistics.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// Training windows.
    pub train: WindowSet,
    /// Validation windows.
    pub val: WindowSet,
    /// Test windows.
    pub test: WindowSet,
    /// Input statistics (training blocks, training view).
    pub input_stats: ZScore,
    /// Target statistics (training blocks).
    pub target_stats: ZScore,
}

/// Label offset inside a window.
pub fn label_offset(window: usize, label_at: LabelAt) -> usize {
    match label_at {
        LabelAt::Last => window - 1,
        LabelAt::Centre => window / 2,
    }
}

/// Builds the windows of a data set. Statistics are fitted here unless given (a trained model
/// evaluated on new data brings its own).
pub fn prepare(
    ds: &DataSet,
    spec: &DataSpec,
    stats: Option<(&ZScore, &ZScore)>,
) -> Result<Prepared> {
    if spec.channels.is_empty() || spec.targets.is_empty() {
        return Err(Error::Domain("no input channels or no targets".into()));
    }
    let samples = Samples::build(ds, &spec.split, spec.window, spec.stride, spec.label_at)?;
    let view = |part: Part| -> Result<Vec<usize>> {
        spec.channels
            .iter()
            .map(|c| {
                let name = spec.noise.column(c, part);
                ds.channel(&name).map_err(|_| {
                    Error::Domain(format!(
                        "the data set in {} has no column `{name}` (noise protocol {:?}; generate the data set with an SNR for `_noisy` inputs)",
                        ds.dir.display(),
                        spec.noise
                    ))
                })
            })
            .collect()
    };
    let (train_cols, val_cols, test_cols) =
        (view(Part::Train)?, view(Part::Val)?, view(Part::Test)?);
    let target_cols = spec
        .targets
        .iter()
        .map(|t| ds.channel(t))
        .collect::<Result<Vec<_>>>()?;
    let (input_stats, target_stats) = match stats {
        Some((i, t)) => (i.clone(), t.clone()),
        None => (
            ZScore::fit(ds, &samples.train_blocks, &train_cols),
            ZScore::fit(ds, &samples.train_blocks, &target_cols),
        ),
    };
    let offset = label_offset(spec.window, spec.label_at);
    let y: Shared = Arc::new(per_run(ds, |r| interleave(r, &target_cols, &target_stats)));
    // Each distinct column list is standardised once (the parts usually read the same view).
    let mut views: Vec<(Vec<usize>, Shared)> = Vec::new();
    let mut set = |cols: &[usize], windows: &[Window]| -> WindowSet {
        let x = match views.iter().find(|(c, _)| c == cols) {
            Some((_, x)) => x.clone(),
            None => {
                let x: Shared = Arc::new(per_run(ds, |r| interleave(r, cols, &input_stats)));
                views.push((cols.to_vec(), x.clone()));
                x
            }
        };
        WindowSet {
            window: spec.window,
            channels: cols.len(),
            outputs: target_cols.len(),
            windows: windows.to_vec(),
            label_offset: offset,
            x,
            y: y.clone(),
        }
    };
    Ok(Prepared {
        train: set(&train_cols, &samples.train),
        val: set(&val_cols, &samples.val),
        test: set(&test_cols, &samples.test),
        input_stats,
        target_stats,
    })
}

/// Fresh input noise for the training windows, one draw per epoch (matched protocol): the
/// clean inputs plus white Gaussian noise with the σ of [`NoiseModel::sigma`] per run and
/// channel, exactly the data set's noise model (assets/docs/learning.md §1.4), in the training
/// view's standardisation. A network trained on one fixed noise realisation learns that
/// realisation (the training loss keeps falling while the validation loss stalls); a new
/// draw every epoch leaves it only the signal. Validation and test keep the data set's
/// fixed, seeded noise.
#[derive(Debug, Clone)]
pub struct NoiseRefresher {
    /// Per run, standardised clean inputs `[rows × C]`.
    clean: Vec<Vec<f32>>,
    /// Per run and channel, the noise σ in standardised units.
    sigma: Vec<Vec<f32>>,
}

impl NoiseRefresher {
    /// Noise of `model` for the inputs of `spec` with the training statistics `stats`.
    pub fn new(ds: &DataSet, spec: &DataSpec, stats: &ZScore, model: &NoiseModel) -> Result<Self> {
        if !model.snr_db.is_finite() {
            return Err(Error::Domain(format!(
                "the SNR of fresh noise must be finite, got {}",
                model.snr_db
            )));
        }
        let cols = spec
            .channels
            .iter()
            .map(|c| ds.channel(c))
            .collect::<Result<Vec<_>>>()?;
        let clean = ds
            .runs
            .iter()
            .map(|r| interleave(r, &cols, stats))
            .collect();
        let sigma = ds
            .runs
            .iter()
            .map(|r| {
                cols.iter()
                    .enumerate()
                    .map(|(k, &c)| {
                        (model.sigma_of(&r.columns[c], &ds.names[c]) / stats.std[k]) as f32
                    })
                    .collect()
            })
            .collect();
        Ok(NoiseRefresher { clean, sigma })
    }

    /// Per run, the standardised clean inputs `[rows × channels]` the noise is added to.
    pub fn clean(&self) -> &[Vec<f32>] {
        &self.clean
    }

    /// Per run and channel, the σ of the fresh noise in standardised units.
    pub fn sigma(&self) -> &[Vec<f32>] {
        &self.sigma
    }

    /// A new noisy copy of the inputs, determined by `seed`.
    pub fn draw(&self, seed: u64) -> Arc<Vec<Vec<f32>>> {
        use rand_distr::{Distribution, StandardNormal};
        Arc::new(
            self.clean
                .iter()
                .zip(&self.sigma)
                .enumerate()
                .map(|(r, (x, sig))| {
                    let mut rng = rng(seed, r as u64);
                    let mut out = Vec::with_capacity(x.len());
                    for row in x.chunks_exact(sig.len()) {
                        for (v, s) in row.iter().zip(sig) {
                            let n: f32 = StandardNormal.sample(&mut rng);
                            out.push(v + s * n);
                        }
                    }
                    out
                })
                .collect(),
        )
    }
}

/// Asks Linux to back the spare capacity of `v` with transparent huge pages where the system
/// offers them on request (`madvise` mode): a window array of a gigabyte then faults in 2 MiB
/// at a time instead of 4 KiB, which on this project's machine is most of the first call's
/// time (measured: 1.4 GB first touched in about 1.4 s with 4 KiB pages). Advice only: any
/// failure leaves ordinary pages.
fn huge_pages(v: &mut Vec<f32>) {
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let spare = v.spare_capacity_mut();
        let (start, len) = (spare.as_mut_ptr() as usize, std::mem::size_of_val(spare));
        let first = start.next_multiple_of(HUGE);
        let end = (start + len) / HUGE * HUGE;
        if end > first {
            // SAFETY: the range lies inside this vector's allocation; MADV_HUGEPAGE changes
            // how the pages are backed, never their contents.
            unsafe {
                libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = v;
}

/// Cores to copy with (at most 8: the copies are bound by memory bandwidth).
fn parallelism() -> usize {
    std::thread::available_parallelism()
        .map(|p| p.get())
        .unwrap_or(1)
        .min(8)
}

/// `f` of every run of `ds`, in order, the runs shared out between the cores.
fn per_run<F>(ds: &DataSet, f: F) -> Vec<Vec<f32>>
where
    F: Fn(&crate::dataset::Run) -> Vec<f32> + Sync,
{
    let threads = parallelism().min(ds.runs.len()).max(1);
    let chunk = ds.runs.len().div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        let handles: Vec<_> = ds
            .runs
            .chunks(chunk)
            .map(|runs| scope.spawn(|| runs.iter().map(&f).collect::<Vec<_>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("a standardising thread panicked"))
            .collect()
    })
}

/// A run's columns standardised and interleaved row-major.
fn interleave(run: &crate::dataset::Run, cols: &[usize], z: &ZScore) -> Vec<f32> {
    let n = run.len();
    let columns: Vec<&[f64]> = cols.iter().map(|&c| run.columns[c].as_slice()).collect();
    let mut out = Vec::with_capacity(n * cols.len());
    // Row by row: the output is written once, in order, and each column read in order.
    for i in 0..n {
        for (k, col) in columns.iter().enumerate() {
            out.push(z.apply(k, col[i]) as f32);
        }
    }
    out
}
