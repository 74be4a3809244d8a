//! Gradient boosting of regression trees on squared loss (Friedman 2001), with histogram
//! splits: the GBDT (100 trees, depth 3, λ = 0) and XGBoost-style (300 trees, depth 6, λ = 1)
//! settings of assets/docs/learning.md §3, and a single tree (learning rate 1, one round).

use super::binning::Bins;
use super::tree::{Tree, TreeParams};
use serde::{Deserialize, Serialize};

/// Boosting settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BoostParams {
    /// Trees.
    pub trees: usize,
    /// Shrinkage.
    pub learning_rate: f32,
    /// Tree settings.
    pub tree: TreeParams,
}

/// A boosted ensemble for one output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Booster {
    /// Initial prediction (mean of the targets).
    pub base: f32,
    /// Shrinkage applied to every tree's leaves (already folded into the leaves).
    pub learning_rate: f32,
    /// Trees.
    pub trees: Vec<Tree>,
}

impl Booster {
    /// Fits `y[n]` from the binned rows `xb[n × f]`; `progress(tree)` after each tree.
    pub fn fit(
        xb: &[u8],
        f: usize,
        bins: &Bins,
        y: &[f32],
        p: &BoostParams,
        progress: &mut dyn FnMut(usize),
    ) -> Self {
        let n = y.len();
        let base = (y.iter().map(|&v| v as f64).sum::<f64>() / n.max(1) as f64) as f32;
        let mut pred = vec![base; n];
        let mut grad = vec![0.0f32; n];
        let mut trees = Vec::with_capacity(p.trees);
        let mut rows: Vec<u32> = (0..n as u32).collect();
        for t in 0..p.trees {
            for i in 0..n {
                grad[i] = pred[i] - y[i];
            }
            let mut tree = Tree::grow(xb, f, bins, &grad, &mut rows, &p.tree);
            for node in &mut tree.nodes {
                node.value *= p.learning_rate;
            }
            // Update the predictions from the leaves each row reached (rows are partitioned
            // by leaf, but walking the binned row is just as cheap and simpler).
            for i in 0..n {
                pred[i] += tree.predict_binned(&xb[i * f..(i + 1) * f]);
            }
            trees.push(tree);
            progress(t + 1);
        }
        Booster {
            base,
            learning_rate: p.learning_rate,
            trees,
        }
    }

    /// Prediction for one row of raw features.
    pub fn predict(&self, x: &[f32]) -> f32 {
        self.base + self.trees.iter().map(|t| t.predict(x)).sum::<f32>()
    }
}
