//! ε-support-vector regression with an RBF kernel `k(a, b) = exp(−γ‖a − b‖²)`, exact on a
//! subsample of the training windows (the kernel matrix is n², so the full 285 k windows would
//! not fit). Solved in the dual by coordinate descent (Ho & Lin 2012, the LIBLINEAR ε-SVR
//! solver, here with a precomputed kernel): minimise `½βᵀ(K + 1)β − tᵀβ + ε‖β‖₁` subject to
//! `|β_i| ≤ C`, with `t` the targets less their mean. The `+ 1` is the bias feature of
//! LIBLINEAR (B = 1): it fits the intercept `b = Σβ_i` beside the mean offset. Sweeps run
//! until no coordinate moves the objective's gradient by more than the tolerance (scikit-
//! learn's `tol = 1e-3`), or to the cap, which is reported.

use crate::learn::linalg::gemm;
use serde::{Deserialize, Serialize};

/// Settings (scikit-learn's defaults: C = 1, ε = 0.1, γ = 1/(features·Var x)).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SvrParams {
    /// Box constraint.
    pub c: f64,
    /// Insensitive-tube half width (standardised target units).
    pub epsilon: f64,
    /// Training rows used (evenly strided subsample).
    pub max_samples: usize,
    /// Coordinate-descent sweeps at most.
    pub max_sweeps: usize,
    /// Stopping tolerance on the largest coordinate step times its curvature.
    #[serde(default = "default_tol")]
    pub tol: f64,
}

fn default_tol() -> f64 {
    1e-3
}

/// A fitted SVR: support vectors (rows with β ≠ 0), their coefficients, γ, offset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Svr {
    /// Features per row.
    pub f: usize,
    /// Kernel width.
    pub gamma: f32,
    /// Offset.
    pub offset: f32,
    /// Coefficients β of the support vectors.
    pub beta: Vec<f32>,
    /// Support vectors, row-major.
    pub sv: Vec<f32>,
    /// Sweeps taken (diagnostics).
    pub sweeps: usize,
    /// Whether the solver reached its tolerance before the sweep cap.
    #[serde(default)]
    pub converged: bool,
}

impl Svr {
    /// Fits on rows `x[n × f]`, targets `y[n]` (already subsampled by the caller).
    pub fn fit(x: &[f32], f: usize, y: &[f32], p: &SvrParams) -> Svr {
        let n = y.len();
        let mean_x = x.iter().map(|&v| v as f64).sum::<f64>() / x.len().max(1) as f64;
        let var_x =
            x.iter().map(|&v| (v as f64 - mean_x).powi(2)).sum::<f64>() / x.len().max(1) as f64;
        let gamma = (1.0 / (f as f64 * var_x.max(1e-12))) as f32;
        let offset = (y.iter().map(|&v| v as f64).sum::<f64>() / n.max(1) as f64) as f32;
        let mut k = kernel(x, x, n, n, f, gamma);
        for v in &mut k {
            *v += 1.0; // the bias feature
        }
        let t: Vec<f64> = y.iter().map(|&v| (v - offset) as f64).collect();
        let mut beta = vec![0.0f64; n];
        let mut fx = vec![0.0f64; n]; // (Kβ)_i
        let (mut sweeps, mut converged) = (0, false);
        // Coordinates in a new random order every sweep (as LIBLINEAR): a fixed order
        // converges far more slowly on the strongly correlated windows of a run.
        let mut order: Vec<usize> = (0..n).collect();
        let mut rng = crate::sensors::noise::rng(n as u64, 0x0053_5652);
        for sweep in 0..p.max_sweeps {
            sweeps = sweep + 1;
            let mut max_step = 0.0f64;
            {
                use rand::seq::SliceRandom;
                order.shuffle(&mut rng);
            }
            for &i in &order {
                let kii = k[i * n + i] as f64;
                let g = fx[i] - t[i];
                // argmin_b ½k_ii(b − β_i)² + g(b − β_i) + ε|b|: soft threshold, then the box.
                let z = beta[i] - g / kii;
                let thr = p.epsilon / kii;
                let b = (z.signum() * (z.abs() - thr).max(0.0)).clamp(-p.c, p.c);
                let d = b - beta[i];
                if d != 0.0 {
                    beta[i] = b;
                    for (fj, kj) in fx.iter_mut().zip(&k[i * n..(i + 1) * n]) {
                        *fj += d * *kj as f64;
                    }
                    max_step = max_step.max(d.abs() * kii);
                }
            }
            if max_step < p.tol {
                converged = true;
                break;
            }
        }
        let keep: Vec<usize> = (0..n).filter(|&i| beta[i] != 0.0).collect();
        let bias: f64 = beta.iter().sum();
        Svr {
            f,
            gamma,
            offset: offset + bias as f32,
            beta: keep.iter().map(|&i| beta[i] as f32).collect(),
            sv: keep
                .iter()
                .flat_map(|&i| x[i * f..(i + 1) * f].iter().copied())
                .collect(),
            sweeps,
            converged,
        }
    }

    /// Predictions for rows `x[n × f]`, in blocks so the kernel block stays small.
    pub fn predict(&self, x: &[f32], n: usize) -> Vec<f32> {
        let m = self.beta.len();
        let mut out = Vec::with_capacity(n);
        for block in x.chunks(self.f * 2048) {
            let nb = block.len() / self.f;
            let k = kernel(block, &self.sv, nb, m, self.f, self.gamma);
            for r in 0..nb {
                let s: f32 = k[r * m..(r + 1) * m]
                    .iter()
                    .zip(&self.beta)
                    .map(|(a, b)| a * b)
                    .sum();
                out.push(self.offset + s);
            }
        }
        out
    }
}

/// `K[i, j] = exp(−γ‖a_i − b_j‖²)` via `‖a‖² + ‖b‖² − 2a·b` (one GEMM).
fn kernel(a: &[f32], b: &[f32], na: usize, nb: usize, f: usize, gamma: f32) -> Vec<f32> {
    let mut k = vec![0.0f32; na * nb];
    if na == 0 || nb == 0 {
        return k;
    }
    gemm(na, f, nb, a, false, b, true, &mut k, 0.0);
    let sq = |m: &[f32], n: usize| -> Vec<f32> {
        (0..n)
            .map(|i| m[i * f..(i + 1) * f].iter().map(|v| v * v).sum())
            .collect()
    };
    let (sa, sb) = (sq(a, na), sq(b, nb));
    for i in 0..na {
        for j in 0..nb {
            let d = (sa[i] + sb[j] - 2.0 * k[i * nb + j]).max(0.0);
            k[i * nb + j] = (-gamma * d).exp();
        }
    }
    k
}
