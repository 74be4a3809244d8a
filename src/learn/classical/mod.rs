//! Classical regressors on flattened windows (`window × channels` features): SVR (RBF), GBDT,
//! XGBoost-style histogram boosting and a decision tree (assets/docs/learning.md §3). Written here
//! rather than taken from a crate; see assets/docs/results.md (learning engine) for the measurements behind that.

mod binning;
mod boosting;
mod svr;
mod tree;

use binning::Bins;
use boosting::{BoostParams, Booster};
use serde::{Deserialize, Serialize};
use svr::{Svr, SvrParams};
use tree::TreeParams;

/// Which classical model, with its settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ClassicalParams {
    /// Support-vector regression.
    Svr(SvrParams),
    /// Boosted trees (GBDT, XGBoost-style) or one tree.
    Boost(BoostParams),
}

impl ClassicalParams {
    /// The spec's GBDT: 100 trees, depth 3, learning rate 0.1 (λ = 0, 255 bins).
    pub fn gbdt() -> Self {
        ClassicalParams::Boost(BoostParams {
            trees: 100,
            learning_rate: 0.1,
            tree: TreeParams {
                max_depth: 3,
                min_leaf: 1,
                lambda: 0.0,
            },
        })
    }

    /// XGBoost-style: 300 trees, depth 6, learning rate 0.1, λ = 1, min leaf 1.
    pub fn xgboost() -> Self {
        ClassicalParams::Boost(BoostParams {
            trees: 300,
            learning_rate: 0.1,
            tree: TreeParams {
                max_depth: 6,
                min_leaf: 1,
                lambda: 1.0,
            },
        })
    }

    /// One regression tree: depth 12, at least 5 rows per leaf.
    pub fn tree() -> Self {
        ClassicalParams::Boost(BoostParams {
            trees: 1,
            learning_rate: 1.0,
            tree: TreeParams {
                max_depth: 12,
                min_leaf: 5,
                lambda: 0.0,
            },
        })
    }

    /// RBF SVR on an evenly strided subsample of 4 000 training windows.
    pub fn svr() -> Self {
        ClassicalParams::Svr(SvrParams {
            c: 1.0,
            epsilon: 0.1,
            max_samples: 4000,
            max_sweeps: 5000,
            tol: 1e-3,
        })
    }
}

/// A fitted classical model (one per output).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Classical {
    /// Settings.
    pub params: ClassicalParams,
    /// Features per row.
    pub features: usize,
    /// Outputs.
    pub outputs: usize,
    /// Bin edges (boosting).
    pub bins: Option<Bins>,
    /// Boosters per output.
    pub boosters: Vec<Booster>,
    /// SVRs per output.
    pub svrs: Vec<Svr>,
    /// Rows the model was fitted on.
    pub fitted_rows: usize,
}

impl Classical {
    /// Fits on rows `x[n × f]` and targets `y[n × outputs]`; `progress(done, total)`.
    pub fn fit(
        params: ClassicalParams,
        x: &[f32],
        f: usize,
        y: &[f32],
        outputs: usize,
        progress: &mut dyn FnMut(usize, usize),
    ) -> Classical {
        let n = y.len() / outputs;
        let column = |k: usize, rows: &[usize]| -> Vec<f32> {
            rows.iter().map(|&r| y[r * outputs + k]).collect()
        };
        match params {
            ClassicalParams::Boost(bp) => {
                let bins = Bins::fit(x, n, f, 255, 50_000);
                let xb = bins.apply(x, n);
                let all: Vec<usize> = (0..n).collect();
                let total = bp.trees * outputs;
                let boosters = (0..outputs)
                    .map(|k| {
                        let yk = column(k, &all);
                        Booster::fit(&xb, f, &bins, &yk, &bp, &mut |t| {
                            progress(k * bp.trees + t, total)
                        })
                    })
                    .collect();
                Classical {
                    params,
                    features: f,
                    outputs,
                    bins: Some(bins),
                    boosters,
                    svrs: Vec::new(),
                    fitted_rows: n,
                }
            }
            ClassicalParams::Svr(sp) => {
                let step = n.div_ceil(sp.max_samples.max(1)).max(1);
                let rows: Vec<usize> = (0..n).step_by(step).collect();
                let xs: Vec<f32> = rows
                    .iter()
                    .flat_map(|&r| x[r * f..(r + 1) * f].iter().copied())
                    .collect();
                let svrs = (0..outputs)
                    .map(|k| {
                        let s = Svr::fit(&xs, f, &column(k, &rows), &sp);
                        if !s.converged {
                            eprintln!(
                                "warning: SVR output {k} stopped at the cap of {} sweeps before reaching its tolerance {}",
                                sp.max_sweeps, sp.tol
                            );
                        }
                        progress(k + 1, outputs);
                        s
                    })
                    .collect();
                Classical {
                    params,
                    features: f,
                    outputs,
                    bins: None,
                    boosters: Vec::new(),
                    svrs,
                    fitted_rows: rows.len(),
                }
            }
        }
    }

    /// Predictions `[n × outputs]` for rows `x[n × f]`.
    pub fn predict(&self, x: &[f32], n: usize) -> Vec<f32> {
        let f = self.features;
        let mut out = vec![0.0f32; n * self.outputs];
        if !self.svrs.is_empty() {
            for (k, s) in self.svrs.iter().enumerate() {
                for (r, v) in s.predict(x, n).into_iter().enumerate() {
                    out[r * self.outputs + k] = v;
                }
            }
        } else {
            for r in 0..n {
                let row = &x[r * f..(r + 1) * f];
                for (k, b) in self.boosters.iter().enumerate() {
                    out[r * self.outputs + k] = b.predict(row);
                }
            }
        }
        out
    }

    /// Serialised form (JSON).
    pub fn to_bytes(&self) -> Vec<u8> {
        serde_json::to_vec(self).expect("classical model serialises")
    }

    /// Reads [`Classical::to_bytes`].
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, String> {
        serde_json::from_slice(bytes).map_err(|e| e.to_string())
    }
}
