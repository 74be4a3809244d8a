//! Fully connected layer on rows: `y = x·W + b` with `W[in×out]`. Applied to `[B·T, C]` rows
//! it is exactly a Conv1d with kernel 1 over time (assets/docs/assets/docs/learning.md §3, layers 1 and 3).

use super::params::ParamSet;
use crate::learn::linalg::{add_col_sums, affine, affine_backward};
use rand::Rng;
use std::ops::Range;

/// A dense layer: ranges of its weight and bias in the [`ParamSet`].
#[derive(Debug, Clone)]
pub struct Dense {
    /// Input width.
    pub din: usize,
    /// Output width.
    pub dout: usize,
    w: Range<usize>,
    b: Range<usize>,
}

impl Dense {
    /// Adds the layer's weights to `p` (uniform ±1/√in, as PyTorch).
    pub fn new<R: Rng>(p: &mut ParamSet, name: &str, din: usize, dout: usize, rng: &mut R) -> Self {
        let bound = 1.0 / (din as f32).sqrt();
        let w = p.uniform(&format!("{name}.weight"), &[din, dout], bound, rng);
        let b = p.uniform(&format!("{name}.bias"), &[dout], bound, rng);
        Dense { din, dout, w, b }
    }

    /// `y[rows×out] = x·W + b`.
    pub fn forward(&self, p: &ParamSet, x: &[f32], rows: usize, y: &mut Vec<f32>) {
        affine(
            x,
            rows,
            self.din,
            &p.value[self.w.clone()],
            &p.value[self.b.clone()],
            y,
        );
    }

    /// Accumulates `dW += xᵀ·dy`, `db += Σ dy`; writes `dx = dy·Wᵀ` when asked.
    pub fn backward(
        &self,
        p: &mut ParamSet,
        x: &[f32],
        dy: &[f32],
        rows: usize,
        dx: Option<&mut Vec<f32>>,
    ) {
        let w = &p.value[self.w.clone()];
        let dw = &mut p.grad[self.w.clone()];
        affine_backward(x, dy, rows, self.din, self.dout, w, dw, dx);
        add_col_sums(dy, self.dout, &mut p.grad[self.b.clone()]);
    }
}
