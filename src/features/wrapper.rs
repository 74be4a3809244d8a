//! Wrapper selection: sequential forward selection of channels scored by the validation R² of
//! ridge regression on flattened windows. The Gram matrices of all candidate features over
//! the training and validation windows are built once; each candidate subset is then a
//! Cholesky solve on a sub-block, so the search costs milliseconds.

use super::samples::{Samples, Window, ZScore};
use crate::dataset::DataSet;

/// Lags (offsets from the last step backwards) used by the fast model: every 2nd step of the
/// window (half the features at a quarter of the cost). A stand-in for the network, not the
/// network: it only ranks channels.
pub fn lags(window: usize) -> Vec<usize> {
    (0..window).step_by(2).collect()
}

/// Accumulated normal equations over a set of windows.
struct Gram {
    xtx: Vec<f64>,
    xty: Vec<f64>,
    yty: f64,
    ysum: f64,
    n: usize,
    p: usize,
}

/// The regression problem: which channels, target and standardisation, on which samples.
struct Problem<'a> {
    ds: &'a DataSet,
    s: &'a Samples,
    channels: &'a [usize],
    z: &'a ZScore,
    target: usize,
    zt: &'a ZScore,
    lags: &'a [usize],
}

fn gram(pb: &Problem, windows: &[Window]) -> Gram {
    let Problem {
        ds,
        s,
        channels,
        z,
        target,
        zt,
        lags,
    } = *pb;
    let p = channels.len() * lags.len();
    let mut g = Gram {
        xtx: vec![0.0; p * p],
        xty: vec![0.0; p],
        yty: 0.0,
        ysum: 0.0,
        n: 0,
        p,
    };
    let mut x = vec![0.0; p];
    for w in windows {
        let run = &ds.runs[w.run as usize];
        let last = w.start as usize + s.window - 1;
        for (k, &c) in channels.iter().enumerate() {
            for (l, &lag) in lags.iter().enumerate() {
                x[k * lags.len() + l] = z.apply(k, run.columns[c][last - lag]);
            }
        }
        let y = zt.apply(0, run.columns[target][s.label_row(w)]);
        for i in 0..p {
            g.xty[i] += x[i] * y;
            for j in i..p {
                g.xtx[i * p + j] += x[i] * x[j];
            }
        }
        g.yty += y * y;
        g.ysum += y;
        g.n += 1;
    }
    for i in 0..p {
        for j in 0..i {
            g.xtx[i * p + j] = g.xtx[j * p + i];
        }
    }
    g
}

/// Solves `(A + λI) β = b` by Cholesky (A symmetric positive semi-definite).
fn ridge_solve(a: &[f64], b: &[f64], lambda: f64) -> Vec<f64> {
    let n = b.len();
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let mut s = a[i * n + j] + if i == j { lambda } else { 0.0 };
            for k in 0..j {
                s -= l[i * n + k] * l[j * n + k];
            }
            l[i * n + j] = if i == j {
                s.max(1e-12).sqrt()
            } else {
                s / l[j * n + j]
            };
        }
    }
    let mut y = vec![0.0; n];
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i * n + k] * y[k];
        }
        y[i] = s / l[i * n + i];
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let mut s = y[i];
        for k in i + 1..n {
            s -= l[k * n + i] * x[k];
        }
        x[i] = s / l[i * n + i];
    }
    x
}

/// One step of the forward search.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// Channel added (index into the candidates).
    pub candidate: usize,
    /// Validation R² with it.
    pub r2: f64,
    /// Gain over the previous step.
    pub gain: f64,
}

/// Forward selection over `candidates` (data-set channel indices) for `target`, stopping
/// when the best gain falls below `tolerance`. Returns the steps taken (the kept channels in
/// order) and the gain each remaining candidate would have added at the last step.
#[allow(clippy::too_many_arguments)]
pub fn forward_selection(
    ds: &DataSet,
    s: &Samples,
    candidates: &[usize],
    zx: &ZScore,
    target: usize,
    zt: &ZScore,
    tolerance: f64,
    lambda: f64,
) -> (Vec<Step>, Vec<(usize, f64)>) {
    let lg = lags(s.window);
    let nl = lg.len();
    let pb = Problem {
        ds,
        s,
        channels: candidates,
        z: zx,
        target,
        zt,
        lags: &lg,
    };
    let tr = gram(&pb, &s.train);
    let va = gram(&pb, &s.val);
    let p = tr.p;
    let sst = va.yty - va.ysum * va.ysum / va.n.max(1) as f64;
    let score = |chosen: &[usize]| -> f64 {
        let idx: Vec<usize> = chosen
            .iter()
            .flat_map(|&c| (0..nl).map(move |l| c * nl + l))
            .collect();
        let m = idx.len();
        let sub = |g: &Gram| -> (Vec<f64>, Vec<f64>) {
            let mut a = vec![0.0; m * m];
            let mut b = vec![0.0; m];
            for (i, &ii) in idx.iter().enumerate() {
                b[i] = g.xty[ii];
                for (j, &jj) in idx.iter().enumerate() {
                    a[i * m + j] = g.xtx[ii * p + jj];
                }
            }
            (a, b)
        };
        let (a, b) = sub(&tr);
        let beta = ridge_solve(&a, &b, lambda * tr.n as f64);
        let (ga, gb) = sub(&va);
        let mut quad = 0.0;
        for i in 0..m {
            for j in 0..m {
                quad += beta[i] * ga[i * m + j] * beta[j];
            }
        }
        let lin: f64 = beta.iter().zip(&gb).map(|(x, y)| x * y).sum();
        let sse = va.yty - 2.0 * lin + quad;
        1.0 - sse / sst.max(1e-300)
    };
    let mut chosen: Vec<usize> = Vec::new();
    let mut steps = Vec::new();
    let mut current = 0.0;
    let mut last_gains = Vec::new();
    loop {
        let remaining: Vec<usize> = (0..candidates.len())
            .filter(|c| !chosen.contains(c))
            .collect();
        if remaining.is_empty() {
            break;
        }
        let gains: Vec<(usize, f64)> = remaining
            .iter()
            .map(|&c| {
                let mut trial = chosen.clone();
                trial.push(c);
                (c, score(&trial) - current)
            })
            .collect();
        let best = gains
            .iter()
            .copied()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .expect("remaining is not empty");
        last_gains = gains;
        if best.1 < tolerance {
            break;
        }
        chosen.push(best.0);
        current += best.1;
        steps.push(Step {
            candidate: best.0,
            r2: current,
            gain: best.1,
        });
    }
    (steps, last_gains)
}
