//! Bidirectional LSTM returning the final state of each direction (assets/docs/learning.md §3,
//! layer 6): the forward state after the last step and the backward state after consuming the
//! whole window, concatenated to `[B, 2H]`.
//!
//! The input projection of all steps and both directions is one matrix product
//! `[B·T, D]·[D, 8H]` (three quarters of the cost); the recurrence then adds `h·W_hh` step by
//! step. Gates in PyTorch order (i, f, g, o); two bias vectors as PyTorch (b_ih, b_hh), so the
//! parameter count is the 24 000 of assets/docs/learning.md §3 for D = 128, H = 20.

use super::params::ParamSet;
use crate::learn::linalg::{
    add_bias, add_col_sums, affine, affine_backward, avx2_dispatch, fast_exp, gemm_strided,
    sigmoid_into, tanh_into,
};
use rand::Rng;
use std::ops::Range;

/// The layer with its caches for backpropagation through time.
#[derive(Debug, Clone)]
pub struct BiLstm {
    din: usize,
    h: usize,
    w_ih: Range<usize>,
    b_ih: Range<usize>,
    w_hh: Range<usize>,
    b_hh: Range<usize>,
    batch: usize,
    steps: usize,
    /// Gate pre-activations from the input, `[B·T, 8H]`.
    g: Vec<f32>,
    /// Gate activations, `[2][T][B][4H]`.
    act: Vec<f32>,
    /// Cell states, `[2][T+1][B][H]` (index 0 is the zero initial state).
    cs: Vec<f32>,
    /// Hidden states, same layout as `cs`.
    hs: Vec<f32>,
    /// `tanh(c)` after each step, `[2][T][B][H]`.
    tc: Vec<f32>,
    /// The backward pass's gate gradients `[B·T][2·4H]`, kept between steps (every entry is
    /// written before it is read).
    dg: Vec<f32>,
}

impl BiLstm {
    /// Adds the weights (uniform ±1/√H, as PyTorch).
    pub fn new<R: Rng>(p: &mut ParamSet, name: &str, din: usize, h: usize, rng: &mut R) -> Self {
        let k = 1.0 / (h as f32).sqrt();
        BiLstm {
            din,
            h,
            w_ih: p.uniform(&format!("{name}.w_ih"), &[din, 8 * h], k, rng),
            b_ih: p.uniform(&format!("{name}.b_ih"), &[8 * h], k, rng),
            w_hh: p.uniform(&format!("{name}.w_hh"), &[2, h, 4 * h], k, rng),
            b_hh: p.uniform(&format!("{name}.b_hh"), &[8 * h], k, rng),
            batch: 0,
            steps: 0,
            g: Vec::new(),
            act: Vec::new(),
            cs: Vec::new(),
            hs: Vec::new(),
            tc: Vec::new(),
            dg: Vec::new(),
        }
    }

    /// Output width (2H).
    pub fn out_dim(&self) -> usize {
        2 * self.h
    }

    /// `x[B, T, D]` → final states `out[B, 2H]`.
    pub fn forward(
        &mut self,
        p: &ParamSet,
        x: &[f32],
        batch: usize,
        steps: usize,
        out: &mut Vec<f32>,
    ) {
        let (h, g4, d) = (self.h, 4 * self.h, self.din);
        self.batch = batch;
        self.steps = steps;
        let rows = batch * steps;
        // Buffers below are fully overwritten: no zeroing but the initial states.
        let (w_ih, b_ih) = (&p.value[self.w_ih.clone()], &p.value[self.b_ih.clone()]);
        affine(x, rows, d, w_ih, b_ih, &mut self.g);
        add_bias(&mut self.g, &p.value[self.b_hh.clone()]);
        let state = 2 * (steps + 1) * batch * h;
        self.cs.resize(state, 0.0);
        self.hs.resize(state, 0.0);
        self.act.resize(2 * steps * batch * g4, 0.0);
        self.tc.resize(2 * steps * batch * h, 0.0);
        out.clear();
        out.resize(batch * 2 * h, 0.0);
        let w_hh = &p.value[self.w_hh.clone()];
        let ld = steps * 2 * g4;
        for dir in 0..2 {
            let wd = &w_hh[dir * h * g4..(dir + 1) * h * g4];
            let st = |k: usize| (dir * (steps + 1) + k) * batch * h;
            self.cs[st(0)..st(1)].fill(0.0);
            self.hs[st(0)..st(1)].fill(0.0);
            for s in 0..steps {
                let t = if dir == 0 { s } else { steps - 1 - s };
                // z = G[:, t, dir] + h·W_hh, in place in the gate block (rows `ld` apart).
                let z0 = t * 2 * g4 + dir * g4;
                let hprev = &self.hs[st(s)..st(s) + batch * h];
                gemm_strided(
                    batch,
                    h,
                    g4,
                    hprev,
                    h,
                    false,
                    wd,
                    g4,
                    false,
                    &mut self.g[z0..],
                    ld,
                    1.0,
                );
                let a0 = (dir * steps + s) * batch * g4;
                let t0 = (dir * steps + s) * batch * h;
                let (c_prev, c_next) = self.cs[st(s)..st(s + 2)].split_at_mut(batch * h);
                let h_next = &mut self.hs[st(s + 1)..st(s + 2)];
                let cell = Cell { batch, h, ld };
                cell.forward(
                    &self.g[z0..],
                    &mut self.act[a0..a0 + batch * g4],
                    c_prev,
                    c_next,
                    &mut self.tc[t0..t0 + batch * h],
                    h_next,
                );
            }
            let last = (dir * (steps + 1) + steps) * batch * h;
            for b in 0..batch {
                out[b * 2 * h + dir * h..b * 2 * h + (dir + 1) * h]
                    .copy_from_slice(&self.hs[last + b * h..last + (b + 1) * h]);
            }
        }
    }

    /// Evaluation-mode forward: `x[B, T, D]` → final states `out[B, 2H]`, keeping no caches.
    /// The input projection is one matrix product (both biases folded into its initial
    /// value); the recurrence runs window by window with the recurrent product and the cell
    /// fused (`Recurrence`), the state held in registers. Same numbers as [`BiLstm::forward`]
    /// up to rounding.
    pub fn forward_eval(
        &mut self,
        p: &ParamSet,
        x: &[f32],
        batch: usize,
        steps: usize,
        gates: &mut Vec<f32>,
        out: &mut Vec<f32>,
    ) {
        let (h, g4) = (self.h, 4 * self.h);
        if h != H {
            // The fused kernel is compiled for the networks' width; others take the
            // training path (same numbers, with caches).
            self.forward(p, x, batch, steps, out);
            return;
        }
        let bias: Vec<f32> = p.value[self.b_ih.clone()]
            .iter()
            .zip(&p.value[self.b_hh.clone()])
            .map(|(a, b)| a + b)
            .collect();
        affine(
            x,
            batch * steps,
            self.din,
            &p.value[self.w_ih.clone()],
            &bias,
            gates,
        );
        // W_hh with every gate padded to HP columns (zeros), `[2][H][4·HP]`.
        let w = &p.value[self.w_hh.clone()];
        let mut wp = vec![0.0f32; 2 * h * 4 * HP];
        for (dst, src) in wp.chunks_exact_mut(4 * HP).zip(w.chunks_exact(g4)) {
            for q in 0..4 {
                dst[q * HP..q * HP + h].copy_from_slice(&src[q * h..(q + 1) * h]);
            }
        }
        out.clear();
        out.resize(batch * 2 * h, 0.0);
        Recurrence { steps }.run(gates, &wp, out);
    }

    /// Backpropagation through time from `dout[B, 2H]`; accumulates the weight gradients and
    /// writes `dx[B, T, D]` when asked. `x` is the forward input.
    pub fn backward(
        &mut self,
        p: &mut ParamSet,
        x: &[f32],
        dout: &[f32],
        dx: Option<&mut Vec<f32>>,
    ) {
        let (h, g4, d) = (self.h, 4 * self.h, self.din);
        let (batch, steps) = (self.batch, self.steps);
        let rows = batch * steps;
        let mut dg = std::mem::take(&mut self.dg);
        dg.resize(rows * 2 * g4, 0.0);
        let mut dh = vec![0.0f32; batch * h];
        let mut dc = vec![0.0f32; batch * h];
        let ld = steps * 2 * g4;
        for dir in 0..2 {
            for b in 0..batch {
                dh[b * h..(b + 1) * h]
                    .copy_from_slice(&dout[b * 2 * h + dir * h..b * 2 * h + (dir + 1) * h]);
            }
            dc.fill(0.0);
            let woff = self.w_hh.start + dir * h * g4;
            for s in (0..steps).rev() {
                let t = if dir == 0 { s } else { steps - 1 - s };
                let st = |k: usize| (dir * (steps + 1) + k) * batch * h;
                let a0 = (dir * steps + s) * batch * g4;
                let t0 = (dir * steps + s) * batch * h;
                let z0 = t * 2 * g4 + dir * g4;
                let cell = Cell { batch, h, ld };
                cell.backward(
                    &self.act[a0..a0 + batch * g4],
                    &self.tc[t0..t0 + batch * h],
                    &self.cs[st(s)..st(s) + batch * h],
                    &dh,
                    &mut dc,
                    &mut dg[z0..],
                );
                let hprev = &self.hs[st(s)..st(s) + batch * h];
                let dz = &dg[z0..];
                let dw = &mut p.grad[woff..woff + h * g4];
                gemm_strided(h, batch, g4, hprev, h, true, dz, ld, false, dw, g4, 1.0);
                if s > 0 {
                    let w = &p.value[woff..woff + h * g4];
                    gemm_strided(batch, g4, h, dz, ld, false, w, g4, true, &mut dh, h, 0.0);
                }
            }
        }
        // The recurrent bias sees the same gradient as the input bias.
        let mut db = vec![0.0f32; 2 * g4];
        add_col_sums(&dg, 2 * g4, &mut db);
        for (k, v) in db.iter().enumerate() {
            p.grad[self.b_ih.start + k] += v;
            p.grad[self.b_hh.start + k] += v;
        }
        let w = &p.value[self.w_ih.clone()];
        let dw = &mut p.grad[self.w_ih.clone()];
        affine_backward(x, &dg, rows, d, 2 * g4, w, dw, dx);
        self.dg = dg;
    }
}

/// One time step of the LSTM cell over a batch: gates from the pre-activations, cell and
/// hidden state. Compiled twice — for the baseline target and with AVX2 + FMA, chosen at run
/// time — since the gate arithmetic is the largest cost after the matrix products.
struct Cell {
    batch: usize,
    h: usize,
    ld: usize,
}

impl Cell {
    avx2_dispatch! {
        /// Gates, cell and hidden state of one step (rows of `z` are `ld` apart).
        fn forward / forward_avx2 => forward_body(
            &self,
            z: &[f32],
            act: &mut [f32],
            c_prev: &[f32],
            c_next: &mut [f32],
            tc: &mut [f32],
            h_next: &mut [f32],
        )
    }

    avx2_dispatch! {
        /// Gate gradients of one step into `dz` (rows `ld` apart) from `dh` and the running
        /// `dc` (updated to the previous step's).
        fn backward / backward_avx2 => backward_body(
            &self,
            act: &[f32],
            tc: &[f32],
            c_prev: &[f32],
            dh: &[f32],
            dc: &mut [f32],
            dz: &mut [f32],
        )
    }

    #[inline(always)]
    fn backward_body(
        &self,
        act: &[f32],
        tc: &[f32],
        c_prev: &[f32],
        dh: &[f32],
        dc: &mut [f32],
        dz: &mut [f32],
    ) {
        let (h, g4) = (self.h, 4 * self.h);
        for b in 0..self.batch {
            let a = &act[b * g4..(b + 1) * g4];
            let z = &mut dz[b * self.ld..b * self.ld + g4];
            let (tc, cp, dh, dc) = (
                &tc[b * h..(b + 1) * h],
                &c_prev[b * h..(b + 1) * h],
                &dh[b * h..(b + 1) * h],
                &mut dc[b * h..(b + 1) * h],
            );
            for k in 0..h {
                let (i, f, g, o) = (a[k], a[h + k], a[2 * h + k], a[3 * h + k]);
                let dck = dc[k] + dh[k] * o * (1.0 - tc[k] * tc[k]);
                z[k] = dck * g * i * (1.0 - i);
                z[h + k] = dck * cp[k] * f * (1.0 - f);
                z[2 * h + k] = dck * i * (1.0 - g * g);
                z[3 * h + k] = dh[k] * tc[k] * o * (1.0 - o);
                dc[k] = dck * f;
            }
        }
    }

    #[inline(always)]
    fn forward_body(
        &self,
        z: &[f32],
        act: &mut [f32],
        c_prev: &[f32],
        c_next: &mut [f32],
        tc: &mut [f32],
        h_next: &mut [f32],
    ) {
        let (h, g4) = (self.h, 4 * self.h);
        for b in 0..self.batch {
            let z = &z[b * self.ld..b * self.ld + g4];
            let a = &mut act[b * g4..(b + 1) * g4];
            sigmoid_into(&z[..2 * h], &mut a[..2 * h]);
            tanh_into(&z[2 * h..3 * h], &mut a[2 * h..3 * h]);
            sigmoid_into(&z[3 * h..], &mut a[3 * h..]);
            let (cp, cn) = (&c_prev[b * h..(b + 1) * h], &mut c_next[b * h..(b + 1) * h]);
            for k in 0..h {
                cn[k] = a[h + k] * cp[k] + a[k] * a[2 * h + k];
            }
            let t = &mut tc[b * h..(b + 1) * h];
            tanh_into(cn, t);
            let hn = &mut h_next[b * h..(b + 1) * h];
            for k in 0..h {
                hn[k] = a[3 * h + k] * t[k];
            }
        }
    }
}

/// Hidden width the evaluation kernel is compiled for (the networks' 20 units).
const H: usize = 20;
/// Width of the evaluation kernel's gate blocks: [`H`] padded to whole 8-lane vectors.
const HP: usize = 24;

/// The evaluation-mode recurrence of both directions, one window at a time: for each step
/// `z = G[t] + h·W_hh` and the cell, on gate blocks padded to [`HP`] lanes (the padded
/// weights are zero, so padded lanes stay at c = h = 0). The state of one window never
/// leaves the core's registers and L1; a batch-wide product per step (the training path)
/// pays packing and strided stores for a 20-deep product instead.
struct Recurrence {
    steps: usize,
}

impl Recurrence {
    /// `g[B·T, 8H]` gate inputs, `wp[2][H][4·HP]`, `out[B, 2H]`: the AVX2 + FMA kernel where
    /// the CPU has them, portable code otherwise.
    fn run(&self, g: &[f32], wp: &[f32], out: &mut [f32]) {
        assert!(g.len() >= out.len() / (2 * H) * self.steps * 8 * H);
        assert_eq!(wp.len(), 2 * H * 4 * HP);
        #[cfg(target_arch = "x86_64")]
        if crate::learn::linalg::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA (checked just above); the lengths are checked
            // above.
            unsafe { avx2::run(self.steps, g, wp, out) };
            return;
        }
        self.run_body(g, wp, out);
    }

    /// Portable version of `avx2::run`.
    fn run_body(&self, g: &[f32], wp: &[f32], out: &mut [f32]) {
        let (h, steps) = (H, self.steps);
        let (g4, g8) = (4 * h, 8 * h);
        for (b, out) in out.chunks_exact_mut(2 * h).enumerate() {
            let gb = &g[b * steps * g8..];
            for dir in 0..2 {
                let w = &wp[dir * h * 4 * HP..(dir + 1) * h * 4 * HP];
                let mut hs = [0.0f32; HP];
                let mut c = [0.0f32; HP];
                for s in 0..steps {
                    let t = if dir == 0 { s } else { steps - 1 - s };
                    let gin = &gb[t * g8 + dir * g4..];
                    let mut z = [0.0f32; 4 * HP];
                    for q in 0..4 {
                        z[q * HP..q * HP + h].copy_from_slice(&gin[q * h..(q + 1) * h]);
                    }
                    for (k, &hk) in hs.iter().enumerate().take(h) {
                        let wr: &[f32; 4 * HP] = w[k * 4 * HP..(k + 1) * 4 * HP]
                            .try_into()
                            .expect("row of 4·HP");
                        for (zj, &wj) in z.iter_mut().zip(wr) {
                            *zj += hk * wj;
                        }
                    }
                    for j in 0..HP {
                        let i = 1.0 / (1.0 + fast_exp(-z[j]));
                        let f = 1.0 / (1.0 + fast_exp(-z[HP + j]));
                        let gg = 1.0 - 2.0 / (fast_exp(2.0 * z[2 * HP + j]) + 1.0);
                        let o = 1.0 / (1.0 + fast_exp(-z[3 * HP + j]));
                        c[j] = f * c[j] + i * gg;
                        hs[j] = o * (1.0 - 2.0 / (fast_exp(2.0 * c[j]) + 1.0));
                    }
                }
                out[dir * h..(dir + 1) * h].copy_from_slice(&hs[..h]);
            }
        }
    }
}

/// The evaluation recurrence with AVX2 + FMA intrinsics: the twelve 8-lane gate accumulators
/// of one step and the cell state stay in registers; `e^x` as [`fast_exp`] (same reduction and
/// polynomial) and reciprocals by `rcp` with one Newton step (relative error ~1e-7).
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{H, HP};
    use crate::learn::linalg::{EXP_LIMIT, EXP_POLY, EXP_ROUND, LN2_HI, LN2_LO};
    use std::arch::x86_64::*;

    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn exp(x: __m256) -> __m256 {
        let x = _mm256_min_ps(
            _mm256_max_ps(x, _mm256_set1_ps(-EXP_LIMIT)),
            _mm256_set1_ps(EXP_LIMIT),
        );
        let shifted = _mm256_fmadd_ps(
            x,
            _mm256_set1_ps(std::f32::consts::LOG2_E),
            _mm256_set1_ps(EXP_ROUND),
        );
        let n = _mm256_sub_ps(shifted, _mm256_set1_ps(EXP_ROUND));
        let r = _mm256_fnmadd_ps(n, _mm256_set1_ps(LN2_HI), x);
        let r = _mm256_fnmadd_ps(n, _mm256_set1_ps(LN2_LO), r);
        let mut p = _mm256_set1_ps(EXP_POLY[0]);
        for &c in &EXP_POLY[1..] {
            p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(c));
        }
        let e = _mm256_fmadd_ps(
            p,
            _mm256_mul_ps(r, r),
            _mm256_add_ps(r, _mm256_set1_ps(1.0)),
        );
        // 2^n from the low mantissa bits of `shifted` (see `fast_exp`).
        let bits = _mm256_add_epi32(
            _mm256_castps_si256(shifted),
            _mm256_set1_epi32(127 - EXP_ROUND.to_bits() as i32),
        );
        _mm256_mul_ps(e, _mm256_castsi256_ps(_mm256_slli_epi32::<23>(bits)))
    }

    /// `1/d` for d ≥ 1: `rcp` (12 bits) and one Newton step `r·(2 − d·r)`.
    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn recip(d: __m256) -> __m256 {
        let r = _mm256_rcp_ps(d);
        _mm256_mul_ps(r, _mm256_fnmadd_ps(d, r, _mm256_set1_ps(2.0)))
    }

    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn sigmoid(x: __m256) -> __m256 {
        let e = exp(_mm256_sub_ps(_mm256_setzero_ps(), x));
        recip(_mm256_add_ps(_mm256_set1_ps(1.0), e))
    }

    #[inline]
    #[target_feature(enable = "avx2,fma")]
    fn tanh(x: __m256) -> __m256 {
        let e = exp(_mm256_add_ps(x, x));
        let q = recip(_mm256_add_ps(e, _mm256_set1_ps(1.0)));
        _mm256_fnmadd_ps(_mm256_set1_ps(2.0), q, _mm256_set1_ps(1.0))
    }

    /// See [`super::Recurrence::run`]; the caller checks the lengths.
    #[target_feature(enable = "avx2,fma")]
    pub(super) unsafe fn run(steps: usize, g: &[f32], wp: &[f32], out: &mut [f32]) {
        // SAFETY: the caller checked that `g` holds every window's gates and `wp` both
        // directions' padded weights; every pointer below stays inside them.
        unsafe {
            // The third vector of a 20-wide gate holds 4 values: masked load, zeros beyond.
            let tail = _mm256_setr_epi32(-1, -1, -1, -1, 0, 0, 0, 0);
            for (b, out) in out.chunks_exact_mut(2 * H).enumerate() {
                let gb = g.as_ptr().add(b * steps * 8 * H);
                for dir in 0..2 {
                    let w = wp.as_ptr().add(dir * H * 4 * HP);
                    let mut hbuf = [0.0f32; HP];
                    let mut c = [_mm256_setzero_ps(); 3];
                    for s in 0..steps {
                        let t = if dir == 0 { s } else { steps - 1 - s };
                        let gin = gb.add(t * 8 * H + dir * 4 * H);
                        let mut z = [_mm256_setzero_ps(); 12];
                        for q in 0..4 {
                            let gq = gin.add(q * H);
                            z[3 * q] = _mm256_loadu_ps(gq);
                            z[3 * q + 1] = _mm256_loadu_ps(gq.add(8));
                            z[3 * q + 2] = _mm256_maskload_ps(gq.add(16), tail);
                        }
                        for (k, hk) in hbuf.iter().enumerate().take(H) {
                            let hk = _mm256_broadcast_ss(hk);
                            let wr = w.add(k * 4 * HP);
                            for (j, zj) in z.iter_mut().enumerate() {
                                *zj = _mm256_fmadd_ps(hk, _mm256_loadu_ps(wr.add(8 * j)), *zj);
                            }
                        }
                        for (v, cv) in c.iter_mut().enumerate() {
                            let i = sigmoid(z[v]);
                            let f = sigmoid(z[3 + v]);
                            let gg = tanh(z[6 + v]);
                            let o = sigmoid(z[9 + v]);
                            *cv = _mm256_fmadd_ps(f, *cv, _mm256_mul_ps(i, gg));
                            _mm256_storeu_ps(
                                hbuf.as_mut_ptr().add(8 * v),
                                _mm256_mul_ps(o, tanh(*cv)),
                            );
                        }
                    }
                    out[dir * H..(dir + 1) * H].copy_from_slice(&hbuf[..H]);
                }
            }
        }
    }
}
