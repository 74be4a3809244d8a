//! Quantile binning of features (at most 255 bins each), as histogram boosting does: splits
//! are searched over bin edges instead of every distinct value.

use serde::{Deserialize, Serialize};

/// Upper edges of each feature's bins: value `x` falls in the first bin `b` with
/// `x <= edges[b]` (the last bin takes everything above).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bins {
    /// Per feature, ascending upper edges (the last bin has none).
    pub edges: Vec<Vec<f32>>,
}

impl Bins {
    /// Edges from the quantiles of (at most `sample` evenly strided rows of) `x[n × f]`.
    pub fn fit(x: &[f32], n: usize, f: usize, max_bins: usize, sample: usize) -> Self {
        let step = n.div_ceil(sample.max(1)).max(1);
        let rows: Vec<usize> = (0..n).step_by(step).collect();
        let edges = (0..f)
            .map(|j| {
                let mut v: Vec<f32> = rows.iter().map(|&r| x[r * f + j]).collect();
                v.sort_by(|a, b| a.total_cmp(b));
                let mut e = Vec::new();
                for q in 1..max_bins {
                    let val = v[(q * v.len() / max_bins).min(v.len() - 1)];
                    if e.last().is_none_or(|&l| val > l) {
                        e.push(val);
                    }
                }
                // The top quantile edge would leave an empty last bin: drop it.
                if e.last().is_some_and(|&l| l >= v[v.len() - 1]) {
                    e.pop();
                }
                e
            })
            .collect();
        Bins { edges }
    }

    /// Bin of value `x` of feature `j`.
    #[inline]
    pub fn bin(&self, j: usize, x: f32) -> u8 {
        self.edges[j].partition_point(|&e| e < x) as u8
    }

    /// Row-major binned matrix.
    pub fn apply(&self, x: &[f32], n: usize) -> Vec<u8> {
        let f = self.edges.len();
        let mut out = vec![0u8; n * f];
        for r in 0..n {
            for j in 0..f {
                out[r * f + j] = self.bin(j, x[r * f + j]);
            }
        }
        out
    }
}
