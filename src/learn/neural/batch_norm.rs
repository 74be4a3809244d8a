//! Batch normalisation over rows (BatchNorm1d on `[B, C, T]` normalises each channel over
//! batch and time; here the rows are the `B·T` positions). Training uses the batch
//! statistics and updates running ones (momentum 0.1, unbiased variance, as PyTorch);
//! evaluation uses the running statistics.

use super::params::ParamSet;
use std::ops::Range;

/// Variance floor ε (PyTorch's default).
pub const EPS: f32 = 1e-5;
/// Running-statistics momentum (PyTorch's default).
pub const MOMENTUM: f32 = 0.1;

/// A batch-norm layer and its cache for the backward pass.
#[derive(Debug, Clone)]
pub struct BatchNorm {
    c: usize,
    gamma: Range<usize>,
    beta: Range<usize>,
    running_mean: Range<usize>,
    running_var: Range<usize>,
    xhat: Vec<f32>,
    inv_std: Vec<f32>,
}

impl BatchNorm {
    /// Adds γ = 1, β = 0 (trainable) and running mean 0, variance 1 (not trainable).
    pub fn new(p: &mut ParamSet, name: &str, c: usize) -> Self {
        BatchNorm {
            c,
            gamma: p.constant(&format!("{name}.weight"), &[c], 1.0, true),
            beta: p.constant(&format!("{name}.bias"), &[c], 0.0, true),
            running_mean: p.constant(&format!("{name}.running_mean"), &[c], 0.0, false),
            running_var: p.constant(&format!("{name}.running_var"), &[c], 1.0, false),
            xhat: Vec::new(),
            inv_std: Vec::new(),
        }
    }

    /// Normalises `x[rows×c]` in place.
    pub fn forward(&mut self, p: &mut ParamSet, x: &mut [f32], train: bool) {
        let c = self.c;
        let rows = x.len() / c;
        let (mean, var) = if train && rows > 1 {
            let mut mean = vec![0.0f64; c];
            let mut sq = vec![0.0f64; c];
            // Each channel summed over the rows in order (the same sums as a row-by-row loop);
            // across channels the loop vectorises.
            for row in x.chunks_exact(c) {
                let (m, s) = (&mut mean[..c], &mut sq[..c]);
                for k in 0..c {
                    let v = row[k] as f64;
                    m[k] += v;
                    s[k] += v * v;
                }
            }
            let n = rows as f64;
            let mean: Vec<f32> = mean.iter().map(|m| (m / n) as f32).collect();
            let var: Vec<f32> = sq
                .iter()
                .zip(&mean)
                .map(|(s, &m)| ((s / n) - (m as f64) * (m as f64)).max(0.0) as f32)
                .collect();
            let unbias = n as f32 / (n as f32 - 1.0);
            for k in 0..c {
                let rm = &mut p.value[self.running_mean.start + k];
                *rm = (1.0 - MOMENTUM) * *rm + MOMENTUM * mean[k];
                let rv = &mut p.value[self.running_var.start + k];
                *rv = (1.0 - MOMENTUM) * *rv + MOMENTUM * var[k] * unbias;
            }
            (mean, var)
        } else {
            (
                p.value[self.running_mean.clone()].to_vec(),
                p.value[self.running_var.clone()].to_vec(),
            )
        };
        self.inv_std = var.iter().map(|v| 1.0 / (v + EPS).sqrt()).collect();
        let gamma = &p.value[self.gamma.clone()];
        let beta = &p.value[self.beta.clone()];
        if train {
            self.xhat.resize(x.len(), 0.0);
            let (mean, inv, gamma, beta) =
                (&mean[..c], &self.inv_std[..c], &gamma[..c], &beta[..c]);
            for (row, xh) in x.chunks_exact_mut(c).zip(self.xhat.chunks_exact_mut(c)) {
                let (row, xh) = (&mut row[..c], &mut xh[..c]);
                for k in 0..c {
                    xh[k] = (row[k] - mean[k]) * inv[k];
                    row[k] = gamma[k] * xh[k] + beta[k];
                }
            }
        } else {
            let scale: Vec<f32> = (0..c).map(|k| gamma[k] * self.inv_std[k]).collect();
            let shift: Vec<f32> = (0..c).map(|k| beta[k] - mean[k] * scale[k]).collect();
            for row in x.chunks_exact_mut(c) {
                for ((v, a), b) in row.iter_mut().zip(&scale).zip(&shift) {
                    *v = *v * a + b;
                }
            }
        }
    }

    /// The evaluation-mode layer as a per-channel affine map `y = scale·x + shift` (running
    /// statistics).
    pub fn eval_affine(&self, p: &ParamSet) -> (Vec<f32>, Vec<f32>) {
        let (gamma, beta) = (&p.value[self.gamma.clone()], &p.value[self.beta.clone()]);
        let (mean, var) = (
            &p.value[self.running_mean.clone()],
            &p.value[self.running_var.clone()],
        );
        let scale: Vec<f32> = (0..self.c)
            .map(|k| gamma[k] * (1.0 / (var[k] + EPS).sqrt()))
            .collect();
        let shift = (0..self.c).map(|k| beta[k] - mean[k] * scale[k]).collect();
        (scale, shift)
    }

    /// Turns `dy` into `dx` in place and accumulates dγ, dβ:
    /// `dx = γ/σ · (dy − mean(dy) − x̂·mean(dy·x̂))`.
    pub fn backward(&self, p: &mut ParamSet, dy: &mut [f32]) {
        let c = self.c;
        let rows = dy.len() / c;
        let mut sum_dy = vec![0.0f32; c];
        let mut sum_dy_xhat = vec![0.0f32; c];
        for (row, xh) in dy.chunks_exact(c).zip(self.xhat.chunks_exact(c)) {
            let (row, xh) = (&row[..c], &xh[..c]);
            let (sd, sx) = (&mut sum_dy[..c], &mut sum_dy_xhat[..c]);
            for k in 0..c {
                sd[k] += row[k];
                sx[k] += row[k] * xh[k];
            }
        }
        for k in 0..c {
            p.grad[self.beta.start + k] += sum_dy[k];
            p.grad[self.gamma.start + k] += sum_dy_xhat[k];
        }
        let n = rows as f32;
        let scale: Vec<f32> = (0..c)
            .map(|k| p.value[self.gamma.start + k] * self.inv_std[k])
            .collect();
        let (scale, sd, sx) = (&scale[..c], &sum_dy[..c], &sum_dy_xhat[..c]);
        for (row, xh) in dy.chunks_exact_mut(c).zip(self.xhat.chunks_exact(c)) {
            let (row, xh) = (&mut row[..c], &xh[..c]);
            for k in 0..c {
                row[k] = scale[k] * (row[k] - sd[k] / n - xh[k] * sx[k] / n);
            }
        }
    }
}
