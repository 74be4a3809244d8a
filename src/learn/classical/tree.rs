//! Regression trees grown on binned features with gradient histograms (the histogram method of
//! LightGBM / XGBoost `hist`): per node, sums of gradients and counts per bin; the larger child's
//! histogram is the parent's minus the smaller child's. Squared loss, so the hessian is the
//! count and a leaf's value is `−G/(n + λ)`.

use super::binning::Bins;
use serde::{Deserialize, Serialize};

/// A node: a split (`x[feature] <= threshold` goes left) or a leaf (`feature == u32::MAX`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Node {
    /// Split feature, or `u32::MAX` for a leaf.
    pub feature: u32,
    /// Split threshold (a bin edge).
    pub threshold: f32,
    /// The same split in bins: bins `<= bin` go left.
    pub bin: u8,
    /// Left child.
    pub left: u32,
    /// Right child.
    pub right: u32,
    /// Leaf value.
    pub value: f32,
}

/// A tree as a flat node array (root first).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tree {
    /// Nodes.
    pub nodes: Vec<Node>,
}

/// Growth settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TreeParams {
    /// Maximum depth.
    pub max_depth: usize,
    /// Minimum rows per leaf.
    pub min_leaf: usize,
    /// L2 penalty on leaf values.
    pub lambda: f64,
}

impl Tree {
    /// Prediction for one row of raw features.
    #[inline]
    pub fn predict(&self, x: &[f32]) -> f32 {
        let mut i = 0usize;
        loop {
            let n = &self.nodes[i];
            if n.feature == u32::MAX {
                return n.value;
            }
            i = if x[n.feature as usize] <= n.threshold {
                n.left as usize
            } else {
                n.right as usize
            };
        }
    }

    /// Grows a tree fitting `−grad` on the rows `rows` of the binned matrix `xb[n × f]`.
    /// Leaf values are `−G/(n + λ)`; the caller scales them (learning rate).
    pub fn grow(
        xb: &[u8],
        f: usize,
        bins: &Bins,
        grad: &[f32],
        rows: &mut [u32],
        p: &TreeParams,
    ) -> Tree {
        let nb = 256;
        let mut nodes = vec![leaf(0.0)];
        struct Open {
            node: usize,
            from: usize,
            to: usize,
            depth: usize,
            hist: Hist,
        }
        let root = Hist::build(xb, f, nb, grad, rows);
        let mut open = vec![Open {
            node: 0,
            from: 0,
            to: rows.len(),
            depth: 0,
            hist: root,
        }];
        while let Some(o) = open.pop() {
            let (g, c) = o.hist.totals(nb);
            nodes[o.node].value = (-g / (c as f64 + p.lambda)) as f32;
            if o.depth >= p.max_depth || c < 2 * p.min_leaf as u64 {
                continue;
            }
            let Some((feat, bin)) = o.hist.best_split(f, nb, bins, p) else {
                continue;
            };
            // Partition rows in place: bins ≤ `bin` first.
            let slice = &mut rows[o.from..o.to];
            let mut mid = 0;
            for i in 0..slice.len() {
                if xb[slice[i] as usize * f + feat] <= bin {
                    slice.swap(i, mid);
                    mid += 1;
                }
            }
            let mid = o.from + mid;
            let (l, r) = (nodes.len(), nodes.len() + 1);
            nodes.push(leaf(0.0));
            nodes.push(leaf(0.0));
            nodes[o.node] = Node {
                feature: feat as u32,
                threshold: bins.edges[feat][bin as usize],
                bin,
                left: l as u32,
                right: r as u32,
                value: nodes[o.node].value,
            };
            let left_small = mid - o.from <= o.to - mid;
            let small = if left_small {
                &rows[o.from..mid]
            } else {
                &rows[mid..o.to]
            };
            let hs = Hist::build(xb, f, nb, grad, small);
            let hl = o.hist.minus(&hs);
            let (hleft, hright) = if left_small { (hs, hl) } else { (hl, hs) };
            open.push(Open {
                node: l,
                from: o.from,
                to: mid,
                depth: o.depth + 1,
                hist: hleft,
            });
            open.push(Open {
                node: r,
                from: mid,
                to: o.to,
                depth: o.depth + 1,
                hist: hright,
            });
        }
        Tree { nodes }
    }
}

fn leaf(value: f32) -> Node {
    Node {
        feature: u32::MAX,
        threshold: 0.0,
        bin: 0,
        left: 0,
        right: 0,
        value,
    }
}

/// Gradient sums and counts per (feature, bin).
struct Hist {
    g: Vec<f64>,
    c: Vec<u32>,
}

impl Hist {
    fn build(xb: &[u8], f: usize, nb: usize, grad: &[f32], rows: &[u32]) -> Hist {
        let mut g = vec![0.0f64; f * nb];
        let mut c = vec![0u32; f * nb];
        for &r in rows {
            let row = &xb[r as usize * f..(r as usize + 1) * f];
            let gr = grad[r as usize] as f64;
            for (j, &b) in row.iter().enumerate() {
                let k = j * nb + b as usize;
                g[k] += gr;
                c[k] += 1;
            }
        }
        Hist { g, c }
    }

    fn minus(&self, other: &Hist) -> Hist {
        Hist {
            g: self.g.iter().zip(&other.g).map(|(a, b)| a - b).collect(),
            c: self.c.iter().zip(&other.c).map(|(a, b)| a - b).collect(),
        }
    }

    fn totals(&self, nb: usize) -> (f64, u64) {
        (
            self.g[..nb].iter().sum(),
            self.c[..nb].iter().map(|&c| c as u64).sum(),
        )
    }

    /// Best (feature, last left bin) by the gain `G_L²/(n_L+λ) + G_R²/(n_R+λ) − G²/(n+λ)`.
    fn best_split(&self, f: usize, nb: usize, bins: &Bins, p: &TreeParams) -> Option<(usize, u8)> {
        let (gt, ct) = self.totals(nb);
        let parent = gt * gt / (ct as f64 + p.lambda);
        let mut best: Option<(f64, usize, u8)> = None;
        for j in 0..f {
            let (mut gl, mut cl) = (0.0f64, 0u64);
            let nbins = bins.edges[j].len(); // splits after bins 0..nbins-1
            for b in 0..nbins {
                gl += self.g[j * nb + b];
                cl += self.c[j * nb + b] as u64;
                let cr = ct - cl;
                if cl < p.min_leaf as u64 {
                    continue;
                }
                if cr < p.min_leaf as u64 {
                    break;
                }
                let gr = gt - gl;
                let gain =
                    gl * gl / (cl as f64 + p.lambda) + gr * gr / (cr as f64 + p.lambda) - parent;
                if gain > 1e-12 && best.is_none_or(|(bg, _, _)| gain > bg) {
                    best = Some((gain, j, b as u8));
                }
            }
        }
        best.map(|(_, j, b)| (j, b))
    }
}
