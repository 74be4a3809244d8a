//! GRU (one direction) returning its final state, PyTorch's equations (gates r, z, n):
//! `r = σ(x·W_ir + b_ir + h·W_hr + b_hr)`, `z = σ(…)`, `n = tanh(x·W_in + b_in + r⊙(h·W_hn + b_hn))`,
//! `h' = (1 − z)⊙n + z⊙h`. The input projection of all steps is one matrix product.

use super::params::ParamSet;
use crate::learn::linalg::{add_col_sums, affine, affine_backward, fast_exp, gemm, sigmoid};
use rand::Rng;
use std::ops::Range;

/// The layer with its caches.
#[derive(Debug, Clone)]
pub struct Gru {
    din: usize,
    h: usize,
    w_ih: Range<usize>,
    b_ih: Range<usize>,
    w_hh: Range<usize>,
    b_hh: Range<usize>,
    batch: usize,
    steps: usize,
    g: Vec<f32>,
    /// r, z, n and `h·W_hn + b_hn` per step: `[T][B][4H]`.
    act: Vec<f32>,
    /// Hidden states `[T+1][B][H]`.
    hs: Vec<f32>,
    gh: Vec<f32>,
}

impl Gru {
    /// Adds the weights (uniform ±1/√H).
    pub fn new<R: Rng>(p: &mut ParamSet, name: &str, din: usize, h: usize, rng: &mut R) -> Self {
        let k = 1.0 / (h as f32).sqrt();
        Gru {
            din,
            h,
            w_ih: p.uniform(&format!("{name}.w_ih"), &[din, 3 * h], k, rng),
            b_ih: p.uniform(&format!("{name}.b_ih"), &[3 * h], k, rng),
            w_hh: p.uniform(&format!("{name}.w_hh"), &[h, 3 * h], k, rng),
            b_hh: p.uniform(&format!("{name}.b_hh"), &[3 * h], k, rng),
            batch: 0,
            steps: 0,
            g: Vec::new(),
            act: Vec::new(),
            hs: Vec::new(),
            gh: Vec::new(),
        }
    }

    /// Output width (H).
    pub fn out_dim(&self) -> usize {
        self.h
    }

    /// `x[B, T, D]` → final state `out[B, H]`.
    pub fn forward(
        &mut self,
        p: &ParamSet,
        x: &[f32],
        batch: usize,
        steps: usize,
        out: &mut Vec<f32>,
    ) {
        let (h, g3, d) = (self.h, 3 * self.h, self.din);
        self.batch = batch;
        self.steps = steps;
        let rows = batch * steps;
        affine(
            x,
            rows,
            d,
            &p.value[self.w_ih.clone()],
            &p.value[self.b_ih.clone()],
            &mut self.g,
        );
        self.hs.clear();
        self.hs.resize((steps + 1) * batch * h, 0.0);
        self.act.clear();
        self.act.resize(steps * batch * 4 * h, 0.0);
        self.gh.resize(batch * g3, 0.0);
        let b_hh = &p.value[self.b_hh.clone()];
        for s in 0..steps {
            for b in 0..batch {
                self.gh[b * g3..(b + 1) * g3].copy_from_slice(b_hh);
            }
            let hprev = &self.hs[s * batch * h..(s + 1) * batch * h];
            gemm(
                batch,
                h,
                g3,
                hprev,
                false,
                &p.value[self.w_hh.clone()],
                false,
                &mut self.gh,
                1.0,
            );
            for b in 0..batch {
                let gi = &self.g[(b * steps + s) * g3..(b * steps + s + 1) * g3];
                let gh = &self.gh[b * g3..(b + 1) * g3];
                let a0 = (s * batch + b) * 4 * h;
                for k in 0..h {
                    let r = sigmoid(gi[k] + gh[k]);
                    let z = sigmoid(gi[h + k] + gh[h + k]);
                    let n = 1.0 - 2.0 / (fast_exp(2.0 * (gi[2 * h + k] + r * gh[2 * h + k])) + 1.0);
                    let hp = self.hs[s * batch * h + b * h + k];
                    self.act[a0 + k] = r;
                    self.act[a0 + h + k] = z;
                    self.act[a0 + 2 * h + k] = n;
                    self.act[a0 + 3 * h + k] = gh[2 * h + k];
                    self.hs[(s + 1) * batch * h + b * h + k] = (1.0 - z) * n + z * hp;
                }
            }
        }
        out.clear();
        out.extend_from_slice(&self.hs[steps * batch * h..]);
    }

    /// Backpropagation through time from `dout[B, H]`.
    pub fn backward(
        &mut self,
        p: &mut ParamSet,
        x: &[f32],
        dout: &[f32],
        dx: Option<&mut Vec<f32>>,
    ) {
        let (h, g3, d) = (self.h, 3 * self.h, self.din);
        let (batch, steps) = (self.batch, self.steps);
        let rows = batch * steps;
        let mut dgi = vec![0.0f32; rows * g3];
        let mut dgh = vec![0.0f32; batch * g3];
        let mut dh = dout.to_vec();
        let mut dh_next = vec![0.0f32; batch * h];
        for s in (0..steps).rev() {
            for b in 0..batch {
                let a0 = (s * batch + b) * 4 * h;
                let gi = &mut dgi[(b * steps + s) * g3..(b * steps + s + 1) * g3];
                for k in 0..h {
                    let (r, z, n, hn) = (
                        self.act[a0 + k],
                        self.act[a0 + h + k],
                        self.act[a0 + 2 * h + k],
                        self.act[a0 + 3 * h + k],
                    );
                    let hp = self.hs[s * batch * h + b * h + k];
                    let dhk = dh[b * h + k];
                    let dn = dhk * (1.0 - z) * (1.0 - n * n);
                    let dz = dhk * (hp - n) * z * (1.0 - z);
                    let dr = dn * hn * r * (1.0 - r);
                    gi[k] = dr;
                    gi[h + k] = dz;
                    gi[2 * h + k] = dn;
                    dgh[b * g3 + k] = dr;
                    dgh[b * g3 + h + k] = dz;
                    dgh[b * g3 + 2 * h + k] = dn * r;
                    dh_next[b * h + k] = dhk * z;
                }
            }
            let hprev = &self.hs[s * batch * h..(s + 1) * batch * h];
            gemm(
                h,
                batch,
                g3,
                hprev,
                true,
                &dgh,
                false,
                &mut p.grad[self.w_hh.clone()],
                1.0,
            );
            add_col_sums(&dgh, g3, &mut p.grad[self.b_hh.clone()]);
            gemm(
                batch,
                g3,
                h,
                &dgh,
                false,
                &p.value[self.w_hh.clone()],
                true,
                &mut dh_next,
                1.0,
            );
            std::mem::swap(&mut dh, &mut dh_next);
        }
        add_col_sums(&dgi, g3, &mut p.grad[self.b_ih.clone()]);
        let w = &p.value[self.w_ih.clone()];
        let dw = &mut p.grad[self.w_ih.clone()];
        affine_backward(x, &dgi, rows, d, g3, w, dw, dx);
    }
}
